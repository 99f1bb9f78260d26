"""The case list of a sweep: value lists, units, the grid product, ideal references, names, Monte Carlo
draws, and the messages (exit code 2, nothing written) for options a user can get wrong."""

import re
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


@pytest.mark.parametrize("value", ["0.01;0.02", "0.01 0.02", "(0.005)", "2*0.001", "0.01 mm 2", "1_0"])
def test_a_clearance_that_is_not_one_number_is_refused_not_read_as_metres_or_a_product(value):
    """pint read '0.01;0.02' and '0.01 0.02' as 0.0002 (metres: 0.2 mm), '(0.005)' as 5 mm, '0.01 mm 2' as 0.02 mm:
    one silent case of the wrong size."""
    with pytest.raises(SweepOptionError, match=r"--clearance: cannot read .* as one clearance .*\n  hint: separate "
                                               "values by commas: --clearance 0.01,0.05"):
        plan(clearance=value, overrides=["solver.t_end=1ms"])


@pytest.mark.parametrize("options, message", [
    (dict(clearance="0.1,100um"), "--clearance: clearance '0.1 mm' and '100um' give the same mechanism"),
    (dict(clearance="0.01,0.010"), "--clearance: clearance '0.01 mm' and '0.010 mm' give the same mechanism"),
    (dict(overrides=["joints.slider_pin.contact.restitution=0.8,0.80"]),
     "--set joints.slider_pin.contact.restitution: joints.slider_pin.contact.restitution '0.8' and '0.80' give the "
     "same mechanism"),
])
def test_two_swept_values_that_are_one_mechanism_are_refused(options, message):
    """Was: run once, under the first value's name; the second value had no row in the summary and no file."""
    with pytest.raises(SweepOptionError, match=re.escape(message) + ".*\n  hint: give each value once"):
        plan(**options)


def test_cases_that_are_the_ideal_mechanism_still_merge_into_it():
    p = plan(clearance="0,0.1", overrides=["joints.slider_pin.contact.restitution=0.8,0.9"])
    assert [c.name for c in p.cases] == ["ideal", "clearance-0.1_mm__joints.slider_pin.contact.restitution-0.8",
                                         "clearance-0.1_mm__joints.slider_pin.contact.restitution-0.9"]


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
    (["--clearance", "0.1,20mm"],  # was: "in --set joints.slider_pin.clearance=20mm", a --set never written
     "error: in --clearance 20mm (joints.slider_pin.clearance)  joints[2] 'slider_pin' → clearance\n  clearance 20 mm"),
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
    (["--clearance", "0.1", "--workers", "100000"], "error: --workers 100000: this machine gives clearsim "),  # was: run
    (["--clearance", "0.1", "--delay-fraction", "1.5"], "error: --delay-fraction must be between 0 and 1, got 1.5"),
    (["--sample", "3", "--seed", "-1"], "error: --seed must be 0 or more, got -1"),
    (["--clearance", "0.1", "--keep", "bodies"], "error: --keep must be all, summary or figures, got 'bodies'"),
])
def test_bad_options_exit_2_with_one_clear_message_and_write_nothing(tmp_path, options, message):
    out = tmp_path / "sweep"
    result = runner.invoke(app, ["sweep", str(SLIDER_CRANK), "-o", str(out), *options])
    assert result.exit_code == 2, result.output
    assert message in result.output and "Traceback" not in result.output
    assert result.output.count("no joint named") <= 1  # one report per distinct problem, not one per case
    assert not out.exists()


@pytest.mark.parametrize("options, message", [
    (["--set", "joints.slider_pin.contact.restitution=0.8,0.9", "--set", "joints.slider_pin.contact.restitution=0.7"],
     "--set joints.slider_pin.contact.restitution=0.7: joints.slider_pin.contact.restitution is also varied by a --set "
     "list, which would override this value in every case\n  hint: give the path once"),
    (["--clearance", "0.1,0.2", "--set", "joints.slider_pin.clearance=0.3mm"],
     "--set joints.slider_pin.clearance: that clearance is already swept by --clearance\n  hint: leave out the --set"),
    (["--sample", "2", "--set", "joints.slider_pin.clearance=0.3mm"],
     "joints.slider_pin.clearance is also varied by the file's tolerances[0], which would override this value in "
     "every case\n  hint: leave out the --set, or that tolerance"),
])
def test_a_single_value_that_the_sweep_would_override_is_refused_not_ignored(tmp_path, options, message):
    """Was: the single --set value was silently overridden in every case (the sweep ran without it)."""
    out = tmp_path / "sweep"
    result = runner.invoke(app, ["sweep", str(with_tolerances(tmp_path)), "--set", "solver.t_end=0.1ms", *options,
                                 "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output and not out.exists()


def test_a_normal_tolerance_whose_bounds_miss_it_is_refused_not_clipped(tmp_path):
    """Was: after 1000 draws outside [low, high] the mean was clipped to a bound: every sample the same value, the
    samples merged into one case, and --sample 3 ran one sample."""
    config = with_tolerances(tmp_path, "\ntolerances:\n  - {path: joints.slider_pin.contact.restitution, "
                                       "distribution: normal, mean: 0.8, std: 0.001, low: 0.1, high: 0.2}\n")
    result = runner.invoke(app, ["sweep", str(config), "--sample", "3", "-o", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    assert ("--sample: tolerances[0] (joints.slider_pin.contact.restitution): mean 0.8 ± std 0.001 almost never falls "
            "within [0.1, 0.2]") in result.output and "hint: check the mean, std, low and high" in result.output
    assert "Traceback" not in result.output and not (tmp_path / "out").exists()


@pytest.mark.parametrize("address, message", [
    ("tcp://localhost:99999", "the port '99999' is not a number from 1 to 65535"),  # was: a 10 s wait (or an AssertionError)
    ("tcp://:8786", "expected host:port after the scheme"),  # was: a 10 s wait
    ("http://localhost:8786", "unknown scheme 'http://'"),
    ("", "expected host:port after the scheme"),  # was: ignored, the sweep ran on the local pool
])
def test_a_malformed_scheduler_address_fails_at_once_without_connecting(tmp_path, address, message):
    import time

    out = tmp_path / "sweep"
    start = time.monotonic()
    result = runner.invoke(app, ["sweep", str(SLIDER_CRANK), "--clearance", "0.1", "--set", "solver.t_end=0.1ms",
                                 "--scheduler", address, "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert f"error: --scheduler {address!r}: {message}" in result.output and "e.g. --scheduler tcp://" in result.output
    assert "Traceback" not in result.output and not out.exists()
    assert time.monotonic() - start < 5


@pytest.mark.parametrize("options, message", [
    (["--sample", "1000000000"], "--sample 1000000000: a sweep has at most 100000 cases"),
    (["--clearance", ",".join(f"{k}um" for k in range(1, 401)), "--set", "bodies.crank.mass=" + ",".join(
        f"{k}kg" for k in range(1, 401))], "the grid has 160000 cases (400 (clearance) × 400 (bodies.crank.mass)); "
     "a sweep has at most 100000\n  hint: give fewer values"),
])
def test_a_sweep_too_large_to_plan_is_refused_at_once(tmp_path, options, message):
    """Was: every case drawn and loaded before anything ran: minutes to hours with no output (and for 1e9 samples the
    memory ran out). The alarm turns that wait into a failure of this test."""
    import signal

    def too_slow(signum, frame):
        raise TimeoutError("still planning after 20 s")

    previous = signal.signal(signal.SIGALRM, too_slow)
    signal.alarm(20)
    try:
        result = runner.invoke(app, ["sweep", str(with_tolerances(tmp_path)), *options, "-o", str(tmp_path / "out")])
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert result.exit_code == 2, result.output
    assert message in result.output and "Traceback" not in result.output and not (tmp_path / "out").exists()


def test_a_folder_that_is_not_a_sweep_folder_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("someone else's work")
    result = runner.invoke(app, ["sweep", str(SLIDER_CRANK), "--clearance", "0.1", "-o", str(tmp_path)])
    assert result.exit_code == 2 and "not a sweep folder (it holds other files and no cases.json)" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
