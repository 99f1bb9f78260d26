"""The reported intervals cover the truth at their stated level (docs/diagnose.md §4, step 4).

A clearance's χ² profile is a comb: the chaotic impacts replay differently at every value, so neighbouring runs scatter
by more than the statistical Δχ² of a profile interval, and the lowest run lies off the truth by more than the span
of the runs within Δ of it. The interval must count that scatter (and σ̂'s own uncertainty): before it did, the
slider-crank's 0.17 mm clearance at 0.1 % noise was reported as 0.164 mm (0.163–0.167).
"""

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.candidates import Candidate
from clearsim.diagnose.search import Point, Scored, interval, profile_threshold

CONFIG = str(Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml")
BENCH = ["--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz",
         "--trigger-offset", "0.1ms", "--noise", "0.1%"]
runner = CliRunner()


def diagnosed_clearance(tmp_path: Path, clearance_mm: float, seed: int) -> dict:
    """The slider pin's clearance hidden in a record of the slider-crank (its model with a rigid slider pin)."""
    record = tmp_path / "bench.csv"
    result = runner.invoke(app, ["synthesize", CONFIG, "--set", f"joints.slider_pin.clearance={clearance_mm}mm", *BENCH,
                                 "--seed", str(seed), "-o", str(record)])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["diagnose", CONFIG, "--set", "joints.slider_pin.clearance=0", "--measured", str(record),
                                 "-o", str(tmp_path / "report"), "--workers", "2", "--candidates", "clearance"])
    assert result.exit_code == 0, result.output
    return json.loads((tmp_path / "report" / "diagnosis.json").read_text())


@pytest.mark.parametrize("clearance_mm, seed", [(0.17, 3), (0.14, 4), (0.2, 7), (0.26, 8)])
def test_a_hidden_clearance_lies_inside_its_reported_interval(tmp_path, clearance_mm, seed):
    found = diagnosed_clearance(tmp_path, clearance_mm, seed)
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("clearance", "slider_pin")
    low, high = effect["interval"]["clearance"]
    assert low <= effect["parameters"]["clearance"] <= high
    assert low <= clearance_mm * 1e-3 <= high


def comb_profile(rng, truth: float, scatter: float) -> Scored:
    """A profile like a clearance's: a parabola in the unit range with its minimum at `truth`, n_eff = 40 on top,
    and a run-to-run scatter (the chaotic impacts) at 13 values about the truth: the scan's and the zooms'."""
    candidate = Candidate("clearance", "J", "clearance", "m", 0.0, 1.0, False, None, lambda document, value: None)
    units = np.sort(np.concatenate([np.linspace(0.05, 0.95, 7), truth + rng.uniform(-0.08, 0.08, 6)]))
    chi = 40.0 + 4000.0 * (units - truth) ** 2 + np.abs(rng.normal(0.0, scatter, len(units)))
    return Scored(candidate, [Point(float(u), SimpleNamespace(chi_square=float(c)), None) for u, c in zip(units, chi)])


def test_the_interval_covers_the_minimum_of_a_scattered_profile_at_its_stated_rate():
    """200 comb profiles whose smooth minimum is known: the interval holds it in ≥ 90 % of them (stated: 95 %). The
    span of the runs within Δ of the lowest one alone held it in about half of them."""
    rng = np.random.default_rng(1)
    record = SimpleNamespace(noise={"x": SimpleNamespace(degrees_of_freedom=60.0)}, effective_samples=40.0)
    covered = []
    for _ in range(200):
        truth = rng.uniform(0.3, 0.7)
        scored = comb_profile(rng, truth, scatter=15.0)
        scored.allowance = profile_threshold(min(p.chi_square for p in scored.points), record)
        low, high = interval(scored, record)
        covered.append(low <= truth <= high)
    assert np.mean(covered) >= 0.9


def test_a_profile_of_few_distinct_values_has_the_interval_of_its_runs():
    """Runs at two values only (a candidate screened, its runs repeated by an ensemble): no parabola to fit (its normal
    equations are singular), the interval is the runs' own."""
    candidate = Candidate("mass", "pole", "mass factor", "", 0.0, 1.0, False, 1.0, lambda document, value: None)
    scored = Scored(candidate, [Point(u, SimpleNamespace(chi_square=c), None)
                                for u, c in [(0.3, 50.0), (0.3, 50.0), (0.3, 50.0), (0.75, 90.0), (0.75, 90.0)]])
    scored.allowance = 4.0
    record = SimpleNamespace(noise={}, effective_samples=40.0)
    assert interval(scored, record) == pytest.approx((0.0, 0.525))
