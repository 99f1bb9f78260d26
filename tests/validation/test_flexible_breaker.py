"""The breaker with flexible links (configs/uhv_breaker_flexible.yaml): the bundled breaker with its pole a GFRP
tube and its two-joint steel links stretching, its two crank arms steel beams. Its links keep the rigid file's mass,
centre of mass and inertia, its ideal stroke is the rigid one's within 1 %, its energy balance closes, its beam
segments are no two-force members, the summary gives the crank arms' bending modes, and J whirls less at 0.01 mm
than in the rigid chain."""

from pathlib import Path

import numpy as np
import pytest

from clearsim.model.loader import load_mechanism

ROOT = Path(__file__).resolve().parents[2]
RIGID, FLEXIBLE = ROOT / "configs" / "uhv_breaker.yaml", ROOT / "configs" / "uhv_breaker_flexible.yaml"
AXIAL_LINKS = ("lower_linkage", "lower_linking_board", "insulating_pole", "upper_linking_board")
BEAM_LINKS = ("lower_turn_arm", "main_crank_arm")
FLEXIBLE_LINKS = AXIAL_LINKS + BEAM_LINKS
SEGMENTS = 3  # the file's beam segments: n = 3 elements, n + 1 segments
POLE_MODE_AXIAL_CHAIN = 85.7  # Hz: the pole's axial mode in the chain with rigid crank arms (docs/validation.md §7)
IDEAL = ("joints.A.clearance=0", "joints.J.clearance=0")
MID_STROKE = 42.5e-3  # s: half the 85 ms stroke


def link_parts(mechanism, name: str) -> list:
    """The bodies a link of the file became: itself, its second half when it stretches, its segments when it bends."""
    def part_of(body: str) -> bool:
        suffix = body[len(name) + 1:] if body.startswith(f"{name}_") else ""
        return body == name or suffix.endswith("_half") or suffix[:1] == "s" and suffix[1:].isdigit()

    return [body for body in mechanism.bodies if part_of(body.name)]


@pytest.fixture(scope="module")
def models():
    return load_mechanism(RIGID).mechanism, load_mechanism(FLEXIBLE).mechanism


@pytest.mark.parametrize("link", FLEXIBLE_LINKS)
def test_each_flexible_link_keeps_the_rigid_links_mass_centre_of_mass_and_inertia(models, link):
    rigid, flexible = models
    parts, (whole,) = link_parts(flexible, link), link_parts(rigid, link)
    assert len(parts) == (2 if link in AXIAL_LINKS else SEGMENTS + 1)  # the link is flexible: split or segmented
    mass = sum(p.mass for p in parts)
    centre = sum(p.mass * np.asarray(p.position) for p in parts) / mass
    inertia = sum(p.inertia + p.mass * float(np.sum((np.asarray(p.position) - centre) ** 2)) for p in parts)
    assert mass == pytest.approx(whole.mass, rel=1e-12)
    assert centre == pytest.approx(np.asarray(whole.position), abs=1e-12)
    assert inertia == pytest.approx(whole.inertia, rel=1e-12)


def test_the_other_bodies_are_those_of_the_rigid_file(models):
    rigid, flexible = models
    halves = {b.name for link in FLEXIBLE_LINKS for b in link_parts(flexible, link)} - set(FLEXIBLE_LINKS)
    assert [b for b in flexible.bodies if b.name not in halves and b.name not in FLEXIBLE_LINKS] == \
           [b for b in rigid.bodies if b.name not in FLEXIBLE_LINKS]


def test_no_beam_segment_is_a_two_joint_link_for_the_compliance_candidate(models):
    from clearsim.model.flexible import two_joint_links

    _, flexible = models
    segments = {b.name for link in BEAM_LINKS for b in link_parts(flexible, link)}
    assert len(segments) == 2 * (SEGMENTS + 1)
    assert not segments & {name for name, _ in two_joint_links(flexible)}


def output_at(result: dict, time: float) -> float:
    return float(np.interp(time, result["time"], result["sensors/contact_displacement"]))


def envelope_work(system) -> int:
    """Σ over the constraint rows of (row − first column of its envelope)²: what the envelope Cholesky of
    S = Φ_q M⁻¹ Φ_qᵀ (assembly/dynamics.py factorize) costs, rows coupling where they share a body."""
    mechanism = system.mechanism
    bodies = {joint.name: set(joint.bodies) for joint in mechanism.joints}
    bodies |= {driver.name: bodies[driver.joint] if driver.joint else {driver.body} for driver in mechanism.drivers}
    rows = [bodies[owner] - {"ground"} for owner in system.row_owners]
    first = [next(j for j, other in enumerate(rows) if row & other) for row in rows]
    return sum((i - f) ** 2 for i, f in enumerate(first))


def test_the_joints_are_put_in_chain_order_so_the_constraint_envelope_narrows(monkeypatch):
    """The expansion appends the split links' slides and the segments' hinges after the file's joints, where their
    rows would reach back across all the others; in chain order (flexible.chain_ordered) the envelope's work falls
    from 11 769 to 6 213 (the rigid breaker's: 535), the integration time by ≈ 20 % (docs/performance.md)."""
    from clearsim.assembly.system import assemble
    from clearsim.model import flexible

    def work() -> int:
        loaded = load_mechanism(FLEXIBLE)
        return envelope_work(assemble(loaded.mechanism, loaded.base_dir))

    ordered = work()
    monkeypatch.setattr(flexible, "chain_ordered", lambda joints: joints)
    assert ordered <= 0.6 * work()


def test_the_ideal_flexible_stroke_is_the_rigid_one_within_1_percent(simulate):
    rigid, flexible = simulate(str(RIGID), *IDEAL), simulate(str(FLEXIBLE), *IDEAL)
    stroke = float(np.ptp(rigid["sensors/contact_displacement"]))
    assert stroke == pytest.approx(0.300, rel=1e-3)  # the bundled breaker's stroke
    for time in (MID_STROKE, rigid["time"][-1]):
        assert abs(output_at(flexible, time) - output_at(rigid, time)) <= 0.01 * output_at(rigid, time)


def test_the_energy_balance_of_the_flexible_breaker_with_clearance_closes(simulate):
    result = simulate(str(FLEXIBLE))
    lost = sum(result[f"energy/{kind}_dissipated"][-1] for kind in ("contact", "friction", "damping"))
    assert result["energy/damping_dissipated"][-1] > 0.0  # the links' damping did work: the balance accounts for it
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-5 * lost


@pytest.fixture(scope="module")
def runs_at_10_micrometres(tmp_path_factory):
    """(warnings, flexible_modes attribute) of the rigid and the flexible breaker as bundled (A and J at 0.01 mm)."""
    from clearsim.io.hdf5 import read_result
    from clearsim.runner import prepare, run_to_file

    folder, runs = tmp_path_factory.mktemp("breaker"), {}
    for config in (RIGID, FLEXIBLE):
        loaded = load_mechanism(config)
        report = run_to_file(prepare(loaded), loaded, folder / f"{config.stem}.h5")
        assert report.complete, report.status
        runs[config] = report.warnings, str(read_result(folder / f"{config.stem}.h5")["attrs"].get("flexible_modes", ""))
    return runs


def whirl_orbits(warnings: list[str]) -> int:
    """The orbit count of joint J's whirl warning (0: none)."""
    import re

    found = [re.search(r"(\d+) orbits", w) for w in warnings if "joint J: the journal whirls" in w]
    return sum(int(match.group(1)) for match in found if match)


def test_j_whirls_in_the_rigid_chain_and_less_with_flexible_links(runs_at_10_micrometres):
    """Whether J still whirls with flexible links depends on the arms' discretisation (25 orbits at n = 3, none at
    n = 4, 24 at n = 6: docs/validation.md §7); fewer orbits than the rigid chain's in each."""
    rigid, flexible = (whirl_orbits(runs_at_10_micrometres[config][0]) for config in (RIGID, FLEXIBLE))
    assert rigid > 0  # the rigid chain's journal runs round its bore at J
    assert flexible < rigid


def test_the_whirl_warning_blames_rigid_links_only_in_the_rigid_chain(runs_at_10_micrometres):
    """The flexible chain's journal at J whirls too (25 orbits): its warning names neither rigid links as the cause
    nor the links' compliance as the remedy, which the model already has."""
    rigid, flexible = ([w for w in runs_at_10_micrometres[config][0] if "joint J: the journal whirls" in w]
                       for config in (RIGID, FLEXIBLE))
    assert rigid and flexible
    assert all("rigid links" in w and "model the links' compliance" in w for w in rigid)
    assert not any("rigid links" in w or "model the links' compliance" in w for w in flexible)
    assert all("a gas load" in w for w in flexible)  # the remedies left


def test_the_summary_gives_each_crank_arms_lowest_bending_mode(runs_at_10_micrometres):
    import json

    from clearsim.model.modes import mode_lines

    attribute = runs_at_10_micrometres[FLEXIBLE][1]
    bending = {entry["link"]: entry["bending_mode_hz"] for entry in json.loads(attribute) if "bending_mode_hz" in entry}
    assert set(bending) == set(BEAM_LINKS)
    assert all(50.0 < mode < 5e3 for mode in bending.values())  # a steel crank arm in the chain: 10² Hz to kHz
    pole = next(entry["axial_mode_hz"] for entry in json.loads(attribute) if entry["link"] == "insulating_pole")
    assert pole < POLE_MODE_AXIAL_CHAIN  # the arms' bending compliance can only lower it (Rayleigh)
    assert {f"flexible link {link}: bending mode" for link in BEAM_LINKS} <= \
           {line.split(" mode ")[0] + " mode" for line in mode_lines(attribute)}


def test_the_summary_lists_the_crank_arms_higher_modes_up_to_the_contacts(runs_at_10_micrometres):
    """Each arm's modes of the linearised chain up to √2 × the highest contact frequency, lowest first, at most three:
    the lower turn arm's 559 Hz, 2.1 kHz, 4.6 kHz; the main crank arm's 388 Hz, 3.2 kHz, 6.7 kHz (A's contacts reach
    4.7 kHz)."""
    import json
    import math

    from clearsim.model.modes import MODES_REPORTED, NEAR_FACTOR

    report = {entry["link"]: entry for entry in json.loads(runs_at_10_micrometres[FLEXIBLE][1])}
    ceiling = NEAR_FACTOR * max(high for _, high in report[BEAM_LINKS[0]]["contacts_hz"].values())
    for link in BEAM_LINKS:
        listed = [mode["hz"] for mode in report[link]["modes"]]
        assert 1 < len(listed) <= MODES_REPORTED
        assert listed == sorted(listed) and listed[0] == report[link]["bending_mode_hz"]
        assert all(math.isfinite(mode) and mode <= ceiling for mode in listed)
