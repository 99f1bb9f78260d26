"""The breaker with axially flexible links (configs/uhv_breaker_flexible.yaml): the bundled breaker with its pole a
GFRP tube and its two-joint steel links stretching. Its links keep the rigid file's mass, centre of mass and
inertia, its ideal stroke is the rigid one's within 1 %, its energy balance closes, and no whirl at J."""

from pathlib import Path

import numpy as np
import pytest

from clearsim.model.loader import load_mechanism

ROOT = Path(__file__).resolve().parents[2]
RIGID, FLEXIBLE = ROOT / "configs" / "uhv_breaker.yaml", ROOT / "configs" / "uhv_breaker_flexible.yaml"
FLEXIBLE_LINKS = ("lower_linkage", "lower_linking_board", "insulating_pole", "upper_linking_board")
IDEAL = ("joints.A.clearance=0", "joints.J.clearance=0")
MID_STROKE = 42.5e-3  # s: half the 85 ms stroke


def link_parts(mechanism, name: str) -> list:
    """The bodies a link of the file became: itself, and its second half when it is flexible."""
    return [body for body in mechanism.bodies if body.name == name or body.name.startswith(f"{name}_") and
            body.name.endswith("_half")]


@pytest.fixture(scope="module")
def models():
    return load_mechanism(RIGID).mechanism, load_mechanism(FLEXIBLE).mechanism


@pytest.mark.parametrize("link", FLEXIBLE_LINKS)
def test_each_flexible_link_keeps_the_rigid_links_mass_centre_of_mass_and_inertia(models, link):
    rigid, flexible = models
    parts, (whole,) = link_parts(flexible, link), link_parts(rigid, link)
    assert len(parts) == 2  # the link is flexible: split in two halves
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


def output_at(result: dict, time: float) -> float:
    return float(np.interp(time, result["time"], result["sensors/contact_displacement"]))


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


def test_no_whirl_at_j_with_flexible_links_where_the_rigid_chain_whirls(tmp_path):
    from clearsim.runner import prepare, run_to_file

    def warnings(config: Path) -> list[str]:
        loaded = load_mechanism(config)
        report = run_to_file(prepare(loaded), loaded, tmp_path / f"{config.stem}.h5")
        assert report.complete, report.status
        return report.warnings

    assert any("joint J: the journal whirls" in w for w in warnings(RIGID))
    assert not any("whirls" in w for w in warnings(FLEXIBLE))
