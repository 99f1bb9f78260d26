"""How the best candidates are ranked and judged (docs/diagnose.md §4 steps 3 and 5): each by the run it reports, and the
check below the chaotic detail only where a run can replay impacts by chance (a clearance joint). A CLI record of the
rigid slider-crank (24 ms) and a made-up ranking."""

import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.align import Fit, prepare_record
from clearsim.diagnose.candidates import Candidate
from clearsim.diagnose.search import Point, Scored, judge

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
RIGID = ["--set", "joints.slider_pin.clearance=0"]
runner = CliRunner()


def test_a_drive_lag_of_a_mechanism_without_clearance_is_named(tmp_path):
    """The benchmark's crank-lag-mid: the crank of the rigid slider-crank driven through a 0.7 ms lag (slider
    displacement and velocity, 0.5 % noise). The lag differs from a trigger offset only in its start-up transient,
    e^(−t/τ), over in a few τ: seen in the comparison band (500 Hz, samples from 2 ms on), gap 3.77 → 0.92, ΔBIC −479,
    but not in the screening band (200 Hz, samples from 5 ms on: χ² 4.5 against the model's 8.6, under the margin of
    §4 step 3). No joint rattles, so no run replays impacts by luck and that check does not apply: the lag is named."""
    record = tmp_path / "bench.csv"
    made = runner.invoke(app, ["synthesize", str(SLIDER_CRANK), *RIGID, "--set", "drivers.crank_drive.lag=0.7ms",
                               "--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz",
                               "--trigger-offset", "0.1ms", "--noise", "0.5%", "--seed", "3", "-o", str(record)])
    assert made.exit_code == 0, made.output
    result = runner.invoke(app, ["diagnose", str(SLIDER_CRANK), *RIGID, "--measured", str(record), "--candidates", "drive",
                                 "--workers", "2", "-o", str(tmp_path / "report")])
    assert result.exit_code == 0, result.output
    found = json.loads((tmp_path / "report" / "diagnosis.json").read_text())
    assert [(e["kind"], e["target"]) for e in found["effects"]] == [("drive", "crank_drive")], result.output
    low, high = found["effects"][0]["interval"]["lag"]
    assert low <= 0.7e-3 <= high and found["gap_after"] < 0.5 * found["gap_before"], found["effects"][0]


def test_a_rough_candidate_is_ranked_by_the_run_it_reports_not_by_its_luckiest_tooth():
    """The benchmark's crank-restitution-low (model χ² 3506): friction at the crank pin, a rough candidate, has a comb
    whose lowest tooth (μ_d 0.1878, χ² 880) sits among runs of 1195–2749; its estimate, the run at the smoothed minimum
    (0.187), has χ² 1741. The hidden restitution's lowest run, 0.4976, has 1080 in a basin (1080–1159 within ±0.005).
    Ranked by what each reports, the restitution comes first (by the friction's tooth it came second)."""
    measured = record_for_judging()
    comb = {0.1799: 1195.0, 0.1858: 2749.0, 0.187: 1741.0, 0.1878: 880.0, 0.1897: 2386.0, 0.1938: 2813.0}
    friction = Candidate("friction", "crank_pin", "mu_d", "", 0.0, 0.5, False, None, lambda doc, value: None, rough=True)
    rough = Scored(friction, [Point(v, Fit(0.0, chi, {}, 1.0), None) for v, chi in comb.items()], fitted=True)
    rough.profiles = {False: (float(friction.to_unit(0.187)), 0.05)}
    basin = {0.4833: 1980.0, 0.4917: 1444.0, 0.4976: 1080.0, 0.5: 1085.0, 0.5017: 1118.0, 0.5033: 1159.0, 0.51: 1877.0}
    restitution = Candidate("restitution", "slider_pin", "restitution", "", 0.3, 1.0, False, 0.9, lambda doc, value: None)
    smooth = Scored(restitution, [Point(v, Fit(0.0, chi, {}, 1.0), None) for v, chi in basin.items()], fitted=True)
    ranked = judge([rough, smooth], Fit(0.0, 3506.0, {}, 1.0), measured)
    assert [s.candidate.kind for s in ranked] == ["restitution", "friction"], [(s.candidate.kind, s.bic) for s in ranked]
    assert rough.estimate.value == 0.187 and rough.bic - smooth.bic > 600.0


def record_for_judging():
    """A noise-only record (two sensors, 500 Hz band) whose n_eff and σ̂'s degrees of freedom the ranking uses."""
    time = np.arange(0.0, 0.024, 2e-5)
    rng = np.random.default_rng(1)
    return prepare_record(time, {s: np.sin(300.0 * time) + rng.normal(0.0, 1e-3, time.size) for s in ("x", "v")}, 500.0)
