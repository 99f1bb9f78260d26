"""The whirl criterion (clearsim.whirl) on synthetic journal paths: a steady orbit, a rattling journal, a journal
carried round by its load."""

import numpy as np
import pytest

from clearsim.whirl import MIN_ORBITS, Whirl, journal_paths, orbit_angle, orbit_rate, whirl_warnings, whirl_windows

RATE = 100e3  # Hz: samples per second, the UHV model's output rate
CLEARANCE = 1e-5  # m


def path(angle: np.ndarray, radius: float = 1.4 * CLEARANCE, noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """Eccentricity vectors (S, 2) at `angle` (rad), |e| = radius, with Gaussian noise of `noise` × radius."""
    rng = np.random.default_rng(seed)
    e = radius * np.column_stack([np.cos(angle), np.sin(angle)])
    return e + noise * radius * rng.standard_normal(e.shape)


def whirls_of(t: np.ndarray, e: np.ndarray, relative: np.ndarray | None = None):
    """whirl_windows of a journal path e (S, 2) in a bearing that does not turn."""
    relative = np.zeros_like(t) if relative is None else relative
    return whirl_windows(t, orbit_angle(e), relative, np.hypot(e[:, 0], e[:, 1]) / CLEARANCE)


def test_a_steady_orbit_of_k_turns_with_noise_is_one_whirl_of_k_orbits():
    k, frequency, begin = 12, 2000.0, 0.010  # turns, Hz, s
    t = np.arange(0.0, 0.030, 1.0 / RATE)
    angle = -2 * np.pi * frequency * np.clip(t - begin, 0.0, k / frequency)  # still, k turns backward, still
    e = path(angle, noise=0.05)
    phi = orbit_angle(e)
    whirls = whirls_of(t, e)
    assert len(whirls) == 1, whirls
    assert whirls[0].orbits == -k
    assert whirls[0].start == pytest.approx(begin, abs=2e-5)
    assert whirls[0].end == pytest.approx(begin + k / frequency, abs=2e-5)
    assert whirls[0].frequency == pytest.approx(frequency, rel=0.01)
    inside = (t > begin + 1e-3) & (t < begin + k / frequency - 1e-3)
    assert orbit_rate(t, phi)[inside] == pytest.approx(-frequency, rel=0.02)


def test_the_orbit_angle_is_taken_in_the_bearing_s_frame():
    """A journal fixed in a bearing that spins k turns makes no orbit of its bore."""
    t = np.arange(0.0, 0.010, 1.0 / RATE)
    spin = 2 * np.pi * 2000.0 * t  # 20 turns of the bearing body
    phi = orbit_angle(path(spin + 0.3), spin)
    assert np.ptp(phi) < 1e-9
    assert whirls_of(t, path(spin + 0.3))  # in the global frame: 20 turns


def test_fewer_than_the_minimum_orbits_are_not_a_whirl():
    t = np.arange(0.0, 0.010, 1.0 / RATE)
    angle = 2 * np.pi * 2000.0 * np.clip(t - 0.001, 0.0, (MIN_ORBITS - 0.5) / 2000.0)
    assert whirls_of(t, path(angle)) == []


def test_a_rattling_journal_does_not_whirl():
    """Impacts across the bore at random places: the orbit angle jumps back and forth, however long it goes on."""
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 0.200, 1.0 / RATE)
    places = rng.uniform(-np.pi, np.pi, 200)  # a new side of the bore every ms
    angle = np.repeat(places, len(t) // len(places))
    assert whirls_of(t, path(angle, noise=0.05)) == []


def test_a_journal_carried_round_by_its_load_does_not_whirl():
    """The load turns with the links' relative rotation (a crank pin): one orbit per relative turn is not a whirl;
    the same orbit with a twentieth of that relative rotation is."""
    t = np.arange(0.0, 0.125, 1.0 / RATE)
    relative = 2 * np.pi * 5000.0 / 60.0 * t  # 5000 rpm: 10.4 turns
    assert whirls_of(t, path(relative), relative) == []
    assert [w.orbits for w in whirls_of(t, path(relative), relative / 20)] == [10]


def test_a_journal_wandering_round_the_bearing_centre_does_not_whirl():
    """Near the centre the angle of a small e wanders at random and its turns can line up; along the wall the same
    angles would be a whirl."""
    t = np.arange(0.0, 0.200, 1.0 / RATE)
    angle = np.cumsum(np.random.default_rng(2).normal(0.0, 0.3, len(t)))
    assert whirls_of(t, path(angle, radius=0.05 * CLEARANCE)) == []
    assert whirls_of(t, path(angle))


def test_journal_paths_take_the_angles_of_the_bearing_and_journal_bodies_and_zero_for_the_ground():
    states = np.array([[0.0, 0.0, 0.5, 1.0, 2.0, 0.25], [0.0, 0.0, 0.75, 1.0, 2.0, 1.5]])  # q of two bodies, (x, y, θ)
    e = np.array([[[1.0, 0.0], [0.0, 1.0]], [[0.0, 1.0], [-1.0, 0.0]]])  # (S, joints, 2)
    clearances = np.array([0.5, 2.0])
    paths = journal_paths(np.array([[0, 1], [-1, 0]]), clearances, states, e)  # bearing 0, journal 1; ground, 0
    assert paths[:, 0, 0] == pytest.approx([0.0 - 0.5, np.pi / 2 - 0.75])
    assert paths[:, 0, 1] == pytest.approx([0.25 - 0.5, 1.5 - 0.75])
    assert paths[:, 1, 0] == pytest.approx([np.pi / 2, np.pi])
    assert paths[:, 1, 1] == pytest.approx([0.5, 0.75])
    assert paths[:, :, 2].ravel() == pytest.approx([2.0, 0.5, 2.0, 0.5])  # |e|/c
    assert journal_paths(np.zeros((0, 2), int), np.zeros(0), states, np.zeros((2, 0, 2))).shape == (2, 0, 3)


def test_the_warning_of_a_model_with_compliant_links_does_not_blame_rigid_links():
    """A whirl in a model with flexible links is not "an effect of the rigid links", and modelling the links'
    compliance is no remedy there: the other remedies stay."""
    found = {"J": [Whirl(0.0671, 0.0806, 25, 0.0073)]}
    (rigid,), (compliant,) = whirl_warnings(found), whirl_warnings(found, compliant_links=True)
    assert "67.1 to 80.6 ms, 25 orbits (1.9 kHz)" in rigid and "67.1 to 80.6 ms, 25 orbits (1.9 kHz)" in compliant
    assert "an effect of the rigid links" in rigid and "model the links' compliance" in rigid
    assert "rigid links" not in compliant and "model the links' compliance" not in compliant
    assert "a gas load" in compliant and "a force drive" in compliant
