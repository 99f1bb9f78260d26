"""The case list of a sweep: value lists, units, the grid product, ideal references, names, Monte Carlo
draws, and the messages (exit code 2, nothing written) for options a user can get wrong."""

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.errors import InputError
from clearsim.model.loader import load_mechanism_text
from clearsim.sweep import SweepOptionError, SweepRequest, plan_sweep
from clearsim.sweep.grid import clearance_text, safe_name, split_values
from clearsim.sweep.montecarlo import draw
from clearsim.units import to_si

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = CONFIGS / "slider_crank_flores.yaml"
UHV = CONFIGS / "uhv_breaker.yaml"
runner = CliRunner()

TOLERANCES = """
tolerances:
  - {path: joints.slider_pin.clearance, distribution: uniform, low: 0.1 mm, high: 0.5 mm}
  - {path: joints.slider_pin.contact.restitution, distribution: normal, mean: 0.85, std: 0.05, low: 0.5, high: 1}
"""


def plan(**options):
    return plan_sweep(SweepRequest(config=options.pop("config", SLIDER_CRANK), **options), UHV)


def with_tolerances(tmp_path, text=TOLERANCES) -> Path:
    path = tmp_path / "toleranced.yaml"
    path.write_text(SLIDER_CRANK.read_text() + text)
    return path


def test_values_split_on_top_level_commas_only():
    assert split_values("0.01,0.1mm, 50 um") == ["0.01", "0.1mm", "50 um"]
    assert split_values("[0, -9.81],[0, 0]") == ["[0, -9.81]", "[0, 0]"]
    assert split_values("'a,b',{law: coulomb, mu_d: 0.1}") == ["'a,b'", "{law: coulomb, mu_d: 0.1}"]


def test_clearance_values_are_millimetres_unless_a_unit_is_written():
    assert to_si(clearance_text("0.05"), "length") == pytest.approx(5e-5)
    assert to_si(clearance_text("50um"), "length") == pytest.approx(5e-5)
    assert to_si(clearance_text("0"), "length") == 0.0
    with pytest.raises(SweepOptionError, match="expected a length"):
        clearance_text("0.05 s")


def test_grid_is_the_product_of_the_axes_after_the_ideal_case():
    p = plan(overrides=["solver.t_end=1ms", "joints.slider_pin.contact.restitution=0.8,0.9"], clearance="0.1,0.2")
    assert [c.name for c in p.cases] == [
        "ideal", "clearance-0.1_mm__joints.slider_pin.contact.restitution-0.8",
        "clearance-0.1_mm__joints.slider_pin.contact.restitution-0.9",
        "clearance-0.2_mm__joints.slider_pin.contact.restitution-0.8",
        "clearance-0.2_mm__joints.slider_pin.contact.restitution-0.9"]
    assert p.labels == ["clearance", "joints.slider_pin.contact.restitution"]
    ideal, first = p.cases[0], p.cases[1]
    assert ideal.ideal and ideal.overrides == ("solver.t_end=1ms", "joints.slider_pin.clearance=0")
    assert first.reference == "ideal"
    assert first.overrides == ("solver.t_end=1ms", "joints.slider_pin.clearance=0.1 mm",
                               "joints.slider_pin.contact.restitution=0.8")


def test_clearance_applies_to_the_named_joints_and_ideal_zeroes_every_clearance_joint():
    p = plan(config=UHV, clearance="0.01,0.1", joints="A,C")
    swept = p.cases[1]
    assert swept.overrides == ("joints.A.clearance=0.01 mm", "joints.C.clearance=0.01 mm")
    assert set(p.cases[0].overrides) == {"joints.A.clearance=0", "joints.J.clearance=0", "joints.C.clearance=0"}


def test_a_value_that_changes_the_ideal_motion_gets_an_ideal_case_per_value():
    p = plan(clearance="0.1", overrides=["bodies.slider.mass=0.14kg,0.2kg", "defaults.contact.restitution=0.8,0.9"])
    ideals = [c for c in p.cases if c.ideal]
    assert [c.name for c in ideals] == ["ideal__bodies.slider.mass-0.14kg", "ideal__bodies.slider.mass-0.2kg"]
    heavy = next(c for c in p.cases if not c.ideal and c.values["bodies.slider.mass"] == "0.2kg")
    assert heavy.reference == "ideal__bodies.slider.mass-0.2kg"


def test_a_case_equal_to_the_ideal_one_runs_once_as_the_ideal_case():
    p = plan(clearance="0,0.1")
    assert [c.name for c in p.cases] == ["ideal", "clearance-0.1_mm"]
    assert p.cases[0].values == {"clearance": "0 mm"}


def test_no_ideal_leaves_the_reference_out():
    p = plan(clearance="0.1,0.2", ideal=False)
    assert [c.ideal for c in p.cases] == [False, False] and all(c.reference is None for c in p.cases)


def test_names_are_stable_and_file_system_safe():
    assert safe_name("joints.J.friction.mu_d-0.10__clearance-0.01 mm") == "joints.J.friction.mu_d-0.10__clearance-0.01_mm"
    long = safe_name("x" * 300)
    assert len(long) == 100 and long == safe_name("x" * 300) and long != safe_name("x" * 301)


def test_folder_name_hashes_the_file_and_the_case_list():
    first, again, other = plan(clearance="0.1"), plan(clearance="0.1"), plan(clearance="0.2")
    assert first.folder == again.folder != other.folder
    assert first.folder.name.startswith("sweep-slider_crank_flores-")


def test_monte_carlo_draws_are_reproducible_and_within_bounds(tmp_path):
    config = with_tolerances(tmp_path)
    p = plan(config=config, sample=20, seed=3)
    again = plan(config=config, sample=30, seed=3)
    assert [c.name for c in p.cases][:2] == ["ideal", "sample-0001"]
    assert [c.values for c in p.cases] == [c.values for c in again.cases[:21]]  # a larger sample keeps the first ones
    clearances = [to_si(c.values["joints.slider_pin.clearance"], "length") for c in p.cases[1:]]
    restitutions = [float(c.values["joints.slider_pin.contact.restitution"]) for c in p.cases[1:]]
    assert 1e-4 <= min(clearances) and max(clearances) <= 5e-4 and len(set(clearances)) == 20
    assert 0.5 <= min(restitutions) and max(restitutions) <= 1.0
    assert plan(config=config, sample=5, seed=4).cases[1].values != p.cases[1].values


def test_draws_follow_their_distribution():
    tolerance = load_mechanism_text(SLIDER_CRANK.read_text() + TOLERANCES).mechanism.tolerances[1]
    rng = np.random.default_rng(0)
    values = np.array([float(draw(tolerance, rng)) for _ in range(4000)])
    assert values.mean() == pytest.approx(0.85, abs=0.005) and values.std() == pytest.approx(0.05, rel=0.05)


def test_tolerance_declarations_are_validated_at_their_line():
    bad = SLIDER_CRANK.read_text() + "tolerances:\n  - {path: joints.slider_pin.clearance, distribution: uniform, low: 0.5 mm, high: 0.1 mm}\n"
    with pytest.raises(InputError, match="low must be smaller than high") as error:
        load_mechanism_text(bad, "bad.yaml")
    assert "bad.yaml:41:5  tolerances[0]" in str(error.value)


def test_a_tolerance_whose_value_does_not_fit_its_path_is_reported_at_the_tolerance(tmp_path):
    config = with_tolerances(tmp_path, "tolerances:\n  - {path: joints.slider_pin.clearance, distribution: uniform, "
                                       "low: 1 s, high: 2 s}\n  - {path: joints.slider_pn.clearance, "
                                       "distribution: uniform, low: 1 mm, high: 2 mm}\n")
    with pytest.raises(Exception) as error:
        plan(config=config, sample=2)
    text = str(error.value)
    assert "toleranced.yaml:41:12  tolerances[0] → path\n  expected a length (e.g. '0.01 mm'), got '1" in text
    assert "tolerances[1] → path\n  no joint named 'slider_pn'; did you mean 'slider_pin'?" in text
    assert text.count("tolerances[0]") == 1  # one report per tolerance, not one per sample


@pytest.mark.parametrize("options, message", [
    (["--clearance", "0.1,abc"], "error: --clearance: unknown unit in 'abc'"),
    (["--clearance", "0.1,0.2s"], "error: --clearance: expected a length (e.g. '0.01 mm'), got '0.2s' [s]"),
    (["--set", "joints.slider_pn.clearance=0.1mm,0.2mm"],
     "error: in --set joints.slider_pn.clearance=0.1mm\n  no joint named 'slider_pn'; did you mean 'slider_pin'?"),
    (["--set", "joints.slider_pin.clearence=0.1mm,0.2mm"], "unknown key 'clearence' in joints.slider_pin; did you mean 'clearance'?"),
    (["--set", "joints.slider_pin.contact.restitution=0.5,1.5"],
     "in --set joints.slider_pin.contact.restitution=1.5  joints[2] 'slider_pin' → contact → restitution\n  must be at most 1, got 1.5"),
    (["--clearance", "0.1", "--joints", "slider_guide"], "error: --joints: 'slider_guide' is a prismatic joint"),
    (["--clearance", "0.1", "--joints", "slider_pn"], "error: --joints: no revolute joint named 'slider_pn'; did you mean 'slider_pin'?"),
    ([], "error: nothing to sweep"),
    (["--sample", "3"], "declares no `tolerances:`"),
    (["--clearance", "0.1", "--workers", "0"], "error: --workers must be at least 1, got 0"),
    (["--clearance", "0.1", "--delay-fraction", "1.5"], "error: --delay-fraction must be between 0 and 1, got 1.5"),
    (["--sample", "3", "--seed", "-1"], "error: --seed must be 0 or more, got -1"),
])
def test_bad_options_exit_2_with_one_clear_message_and_write_nothing(tmp_path, options, message):
    out = tmp_path / "sweep"
    result = runner.invoke(app, ["sweep", str(SLIDER_CRANK), "-o", str(out), *options])
    assert result.exit_code == 2, result.output
    assert message in result.output and "Traceback" not in result.output
    assert result.output.count("no joint named") <= 1  # one report per distinct problem, not one per case
    assert not out.exists()


def test_a_folder_that_is_not_a_sweep_folder_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("someone else's work")
    result = runner.invoke(app, ["sweep", str(SLIDER_CRANK), "--clearance", "0.1", "-o", str(tmp_path)])
    assert result.exit_code == 2 and "not a sweep folder (it holds other files and no cases.json)" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
