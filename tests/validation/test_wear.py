"""Worn bores and Archard wear in whole runs: a circular profile changes nothing, a journal follows a worn bore,
Archard's depth under a steady load, and the energy balance with a worn bore."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from typer.testing import CliRunner

from clearsim.cli import app

from tests.support.worn_bore import nearest_bore_contact, rotate
from tests.validation.conftest import CONFIGS
from tests.validation.test_energy import CLEARANCE_PENDULUM, total_energy

FORCE, STIFFNESS = 1000.0, 1e12  # N, N/m^1.5: a static penetration (F/K)^(2/3) = 1 µm
BEARING_RADIUS, CLEARANCE = 0.02, 1e-4
JOURNAL_RADIUS = BEARING_RADIUS - CLEARANCE
SETTLED = (FORCE / STIFFNESS) ** (2 / 3)


def test_a_zero_profile_gives_the_circular_bore_bit_for_bit(simulate):
    """The bundled breaker with all-zero wear profiles on A and J: every dataset equal to the run without them."""
    short = "solver.t_end=5ms"
    plain = simulate("uhv_breaker.yaml", short)
    zero = simulate("uhv_breaker.yaml", short, "joints.J.wear={profile: {cos: [0 mm, 0, 0], sin: [0 mm]}}",
                    "joints.A.wear={profile: {cos: [0 mm]}, wall: 2 mm}")
    names = sorted(set(plain) - {"attrs"})
    assert sorted(set(zero) - {"attrs"}) == names
    assert len(names) > 50
    for name in names:
        assert np.array_equal(plain[name], zero[name], equal_nan=True), name


def test_accumulating_wear_leaves_the_motion_as_it_is(simulate):
    """The accumulated profile feeds nothing back within a run and steers no step (dopri.error_norm): the bundled
    breaker with Archard wear at A and J over 20 ms takes the same steps and has every history of the run without it
    to round-off (the longer state vector changes how the compiled loops over it are vectorised: 7e-26 of a history's
    scale over 85 ms), and wears. With the wear states in the step control the run took 5 724 steps, not 6 442."""
    short = "solver.t_end=20ms"
    plain = simulate("uhv_breaker.yaml", short)
    archard = "{archard: {coefficient: 1e-4, hardness: 2 GPa, length: 40 mm}}"
    worn = simulate("uhv_breaker.yaml", short, f"joints.J.wear={archard}", f"joints.A.wear={archard}")
    names = sorted(set(plain) - {"attrs"})
    assert set(names) < set(worn)
    assert worn["attrs"]["steps"] == plain["attrs"]["steps"]
    assert worn["attrs"]["rejected_steps"] == plain["attrs"]["rejected_steps"]
    for name in names:
        expected = np.asarray(plain[name], float)
        scale = np.max(np.abs(expected[np.isfinite(expected)]), initial=0.0)  # NaN samples (e.g. unset) excluded
        assert np.allclose(worn[name], expected, rtol=0.0, atol=1e-15 * scale, equal_nan=True), name
    assert worn["joints/J/wear/max_depth"][-1] > 0.0 and worn["joints/A/wear/max_depth"][-1] > 0.0


def loaded_pin(wear: str, friction: str = "{law: coulomb, mu_d: 0.1, stick: smooth}", spin: str = "100 rad/s",
               turn: str = "0 rad/s", t_end: str = "10 ms") -> str:
    """A pin (journal) held in x, turned at `spin` and pressed down by FORCE into a bearing `sleeve` turned at
    `turn` about its fixed centre, starting at its static penetration."""
    return f"""
name: loaded pin
points: {{O: [0 m, 0 m]}}
bodies:
  - {{name: sleeve, mass: 1 kg, inertia: 1e-3 kg*m^2, position: [0 m, 0 m]}}
  - {{name: pin, mass: 0.01 kg, inertia: 1e-6 kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: pivot, type: revolute, bodies: [ground, sleeve], at: O}}
  - {{name: J, type: revolute, bodies: [sleeve, pin], at: O, bearing_radius: {BEARING_RADIUS} m,
      clearance: {CLEARANCE} m, initial_eccentricity: [0 m, {-(CLEARANCE + SETTLED)} m],
      contact: {{law: lankarani_nikravesh, restitution: 0.9, exponent: 1.5, stiffness: {STIFFNESS} N/m^1.5}},
      friction: {friction}, wear: {wear}}}
drivers:
  - {{name: turn, joint: pivot, motion: {{law: constant_speed, speed: {turn}}}}}
  - {{name: hold, body: pin, coordinate: x, motion: {{law: constant_speed, speed: 0 m/s}}}}
  - {{name: spin, body: pin, coordinate: angle, motion: {{law: constant_speed, speed: {spin}}}}}
forces:
  - {{name: load, type: constant, body: pin, force: [0 N, {-FORCE} N]}}
solver: {{t_end: {t_end}, output_rate: 10 kHz, rtol: 1e-10, atol: 1e-13, max_step: 0.1 ms}}
"""


def test_archard_depth_under_a_steady_load_grows_as_the_closed_form(simulate):
    """A pin turning at ω under F on a fixed bore: depth k_w F ω R_J t / (H L w) at the loaded angle (270°), volume
    k_w F ω R_J t / H, both to 1e-6, and the profile's peak there."""
    k_w, hardness, length, width, omega = 1e-4, 2e9, 0.02, 0.004, 100.0
    result = simulate(loaded_pin(f"{{archard: {{coefficient: {k_w}, hardness: {hardness} Pa, length: {length} m, "
                                 f"width: {width} m}}}}"))
    t = result["time"]
    assert np.all(result["joints/J/mode"][1:] == 2)  # in contact throughout
    assert result["joints/J/normal_force"] == pytest.approx(FORCE, rel=1e-9)
    volume_rate = k_w * FORCE * omega * JOURNAL_RADIUS / hardness
    assert result["joints/J/wear/volume"] == pytest.approx(volume_rate * t, rel=1e-6, abs=1e-30)
    assert result["joints/J/wear/max_depth"] == pytest.approx(volume_rate * t / (length * width), rel=1e-6, abs=1e-30)
    angles, depth = result["joints/J/wear/angle"], result["joints/J/wear/depth"]
    loaded = np.argmin(np.abs(angles - 1.5 * math.pi))
    assert depth[loaded] == pytest.approx(volume_rate * t[-1] / (length * width), rel=1e-6)
    assert np.argmax(depth) == loaded
    assert depth[np.argmin(np.abs(angles - 0.5 * math.pi))] < 1e-3 * depth[loaded]  # nothing worn opposite


@pytest.mark.parametrize("harmonics", [16, 512])
def test_archard_depth_under_a_steady_load_follows_its_contact_width(simulate, harmonics):
    """Without a stated width the band follows the load: a half-cosine over the Hertz line contact's half-angle
    α = b/R_B, b = √(4 F R_J R_B/(c π L E*)) (1.49 mm here), smoothed by the narrowest Gaussian (σ = 4/M). The depth
    at the loaded angle is k_w F ω R_J t/(H L w) with w = R_B/K(0) of that kernel, written out here from its
    definition; the volume k_w F ω R_J t/H whatever the width (both 1e-6)."""
    k_w, hardness, length, omega = 1e-4, 2e9, 0.02, 100.0
    result = simulate(loaded_pin(f"{{archard: {{coefficient: {k_w}, hardness: {hardness} Pa, length: {length} m, "
                                 f"harmonics: {harmonics}}}}}"))
    t = result["time"]
    assert np.all(result["joints/J/mode"][1:] == 2)
    modulus = 207e9 / (2 * (1 - 0.3**2))  # E* of the default steel
    half_width = math.sqrt(4 * FORCE * JOURNAL_RADIUS * BEARING_RADIUS / (CLEARANCE * math.pi * length * modulus))
    alpha, sigma, m = half_width / BEARING_RADIUS, 4 / harmonics, np.arange(1, harmonics + 1)
    band = np.cos(m * alpha) / (1 - (2 * m * alpha / math.pi) ** 2)  # ∫cos(πφ/2α) cos mφ dφ / ∫cos(πφ/2α) dφ
    peak = (1 + 2 * np.sum(np.exp(-0.5 * (m * sigma) ** 2) * band)) / (2 * math.pi)
    width = BEARING_RADIUS / peak
    volume_rate = k_w * FORCE * omega * JOURNAL_RADIUS / hardness
    assert result["joints/J/wear/volume"] == pytest.approx(volume_rate * t, rel=1e-6, abs=1e-30)
    assert result["joints/J/wear/max_depth"] == pytest.approx(volume_rate * t / (length * width), rel=1e-6, abs=1e-30)
    angles, depth = result["joints/J/wear/angle"], result["joints/J/wear/depth"]
    assert np.argmax(depth) == np.argmin(np.abs(angles - 1.5 * math.pi))
    if harmonics == 512:  # the band, not the kernel, sets the width: near the half-cosine's 4b/π
        assert width == pytest.approx(4 * half_width / math.pi, rel=0.05)


def test_a_bearing_turning_under_a_steady_load_wears_evenly_in_its_own_frame(simulate):
    """The bearing turns once at ω under the pin (pressed down by F, not turning): the contact sweeps the whole bore
    in the bearing's frame, so after the turn the profile is even, k_w F ω R_B t/(2π R_B L H) deep (1e-6)."""
    k_w, hardness, length, omega = 1e-4, 2e9, 0.02, 100.0
    turn_time = 2 * math.pi / omega
    result = simulate(loaded_pin(f"{{archard: {{coefficient: {k_w}, hardness: {hardness} Pa, length: {length} m}}}}",
                                 spin="0 rad/s", turn=f"{omega} rad/s", t_end=f"{turn_time} s"))
    volume = k_w * FORCE * omega * BEARING_RADIUS * turn_time / hardness
    assert result["joints/J/wear/volume"][-1] == pytest.approx(volume, rel=1e-6)
    depth = result["joints/J/wear/depth"]
    assert depth == pytest.approx(volume / (2 * math.pi * BEARING_RADIUS * length), rel=1e-6)


def test_no_sliding_no_wear(simulate):
    result = simulate(loaded_pin("{archard: {coefficient: 1e-4, hardness: 2 GPa, length: 20 mm}}", spin="0 rad/s",
                                 t_end="2 ms"))
    # round-off sliding only (|v_t| ~ 1e-20 m/s); spinning at 100 rad/s the same 2 ms wear 5e-10 m
    assert np.max(np.abs(result["joints/J/wear/depth"])) < 1e-20


OVAL = 2e-5  # m: an oval bore, h(θ) = OVAL (1 + cos 2θ)


def oval(theta):
    return OVAL * (1 + np.cos(2 * theta)), -2 * OVAL * np.sin(2 * theta), -4 * OVAL * np.cos(2 * theta)


def settled_pin(turn):
    """(y, F_n) of the pin held at x = 0 and pressed down by FORCE into the oval bore turned by `turn`, at rest:
    K δ(y)^1.5 (−n_y(y)) = F with δ and n from the reference geometry."""
    def contact(y):
        penetration, normal = nearest_bore_contact(oval, BEARING_RADIUS, JOURNAL_RADIUS, rotate(-turn, [0.0, y]))
        return penetration, rotate(turn, normal)

    def excess(y):
        penetration, normal = contact(y)
        return STIFFNESS * max(penetration, 0.0) ** 1.5 * -normal[1] - FORCE

    top = -CLEARANCE
    while contact(top)[0] > 0.0:
        top += 1e-6
    y = brentq(excess, top - 2 * OVAL - 1e-5, top, xtol=1e-16)
    return y, STIFFNESS * contact(y)[0] ** 1.5


def test_a_journal_follows_a_turning_oval_bore_in_contact_under_its_load(simulate):
    """The oval bore turns at ω under an undamped, frictionless pin pressed down by F: the pin stays in contact and
    sits where the bore's contact holds F (settled_pin; the pin's inertia, m ÿ ≈ 2e-4 N, is left out). In so
    conformal a bore (c = 1e-4 m) the contact wanders up to 17° from the bottom: F_n is 5 % above F."""
    omega = 10.0
    text = loaded_pin(f"{{profile: {{cos: [{OVAL} m, 0, {OVAL} m]}}}}", friction="{law: none}", spin="0 rad/s",
                      turn=f"{omega} rad/s", t_end="0.2 s").replace("law: lankarani_nikravesh, restitution: 0.9",
                                                                   "law: hertz, restitution: 1.0")
    result = simulate(text)
    t, y, force = result["time"], result["bodies/pin/q"][:, 1], result["joints/J/normal_force"]
    assert np.all(result["joints/J/mode"][1:] == 2)
    assert np.ptp(y) > 0.95 * 2 * OVAL  # the pin went down the oval's full depth and back up
    for i in range(0, len(t), 50):
        expected_y, expected_force = settled_pin(omega * t[i])
        assert y[i] == pytest.approx(expected_y, abs=1e-10)
        assert force[i] == pytest.approx(expected_force, rel=1e-5)
    assert np.max(force) > 1.04 * FORCE


@pytest.mark.parametrize("bodies", ["[ground, link]", "[link, ground]"], ids=["fixed_bore", "swinging_bore"])
def test_elastic_impacts_on_a_worn_bore_conserve_energy(simulate, bodies):
    """The clearance pendulum of test_energy on an oval worn bore, the bore fixed or swinging with the link:
    δ, its potential, the normal and the force's points of application agree (no energy made or lost)."""
    text = CLEARANCE_PENDULUM.replace("bodies: [ground, link]", f"bodies: {bodies}").replace(
        "clearance: 0.1 mm}", "clearance: 0.1 mm, wear: {profile: {cos: [0.03 mm, 0, 0.02 mm], sin: [0.01 mm]}}}")
    result = simulate(text)
    assert len(result["joints/O/episodes/onset"]) >= 100
    energy = total_energy(result)
    scale = np.max(result["energy/kinetic"])
    assert np.max(np.abs(energy - energy[0])) <= 1e-4 * scale
    assert np.max(np.abs(result["energy/contact_dissipated"])) <= 1e-9 * scale


@pytest.mark.parametrize("bodies, friction", [
    ("[ground, link]", "{law: coulomb, mu_d: 0.15, stick: smooth}"),
    ("[link, ground]", "{law: stiction_step, mu_s: 0.2, mu_d: 0.15, v_s: 1e-4 m/s, v_d: 1e-2 m/s}"),
], ids=["fixed_bore_smooth", "swinging_bore_exact_stick"])
def test_with_wear_the_written_dissipation_closes_the_energy_balance(simulate, bodies, friction):
    """A damped, frictional worn bore accumulating wear, fixed or swinging with the link and then held by the exact
    stick constraint while it sticks: wear takes no energy of its own (the friction work it comes from is booked
    once), and the balance closes as on a circular bore."""
    text = CLEARANCE_PENDULUM.replace("law: hertz, restitution: 1.0", "law: lankarani_nikravesh, restitution: 0.7")
    text = text.replace("bodies: [ground, link]", f"bodies: {bodies}")
    text = text.replace("  contact:", f"  friction: {friction}\n  contact:")
    text = text.replace("clearance: 0.1 mm}", "clearance: 0.1 mm, wear: {profile: {cos: [0.03 mm, 0, 0.02 mm]}, "
                        "archard: {coefficient: 1e-4, hardness: 2 GPa, length: 10 mm}}}")
    result = simulate(text)
    lost = result["energy/contact_dissipated"][-1] + result["energy/friction_dissipated"][-1]
    assert lost > 1e-4 * np.max(result["energy/kinetic"])
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-3 * lost
    assert result["joints/O/wear/volume"][-1] > 0.0
    if "stiction" in friction:
        assert np.any(result["joints/O/stick"] == 1)  # the exact stick row of the worn bore was used


@pytest.mark.parametrize("wear, place, message", [
    ("{profile: {cos: [0.01 mm, 0.02 mm]}}", "joints[9] 'J' → wear", "depth is negative (-0.01 mm at 180.0°)"),
    ("{profile: {cos: [1 mm, 0.5 mm]}, wall: 1 mm}", "joints[9] 'J' → wear", "1.5 mm deep at 0.0°, deeper than the wall"),
    ("{archard: {coefficient: -1e-4, hardness: 2 GPa, length: 40 mm}}", "joints[9] 'J' → wear → archard → coefficient",
     "must be at least 0"),
    ("{archard: {coefficient: 1e-4, hardness: 2 GPa}}", "joints[9] 'J' → wear → archard → length",
     "needs the length L of the worn band"),
    ("{archard: {coefficient: 1e-4, hardness: 2 GPa, length: 40 mm, width: 400 mm}}",
     "joints[9] 'J' → wear → archard → width", "not shorter than the bore's circumference 314.159 mm"),
    ("{profile: {angles: [0 deg, 120 deg, 240 deg], depth: [0.01 mm, 0.02 mm, 0.01 mm], harmonics: 2}}",
     "joints[9] 'J' → wear → profile", "3 distinct angles fit at most 1 harmonics, not 2"),
    ("{profile: {angles: [0 deg, 120 deg], depth: [0.01 mm]}}", "joints[9] 'J' → wear → profile",
     "2 angles but 1 depths"),
], ids=["negative_depth", "deeper_than_wall", "negative_coefficient", "no_length", "too_wide", "too_few_angles",
        "one_depth_per_angle"])
def test_bad_wear_input_exits_2_with_a_located_message(wear, place, message):
    override = f"joints.J.wear={wear}"
    result = CliRunner().invoke(app, ["validate", str(CONFIGS / "uhv_breaker.yaml"), "--set", override])
    assert result.exit_code == 2, result.output
    assert f"in --set {override}  {place}\n" in result.output and message in result.output
    assert "Traceback" not in result.output
