"""The worn arcs of a joint take one place to fit, so a hidden clearance elsewhere is fitted (docs/diagnose.md §4 step 2).

The slider-crank's first 12 ms with a 0.01 mm crank pin (its worn arcs are candidates) and an ideal slider pin; the
record has a 0.08 mm clearance at the slider pin. Arcs at the crank pin mimic play anywhere along the rod: seven of
them screen better than the slider pin's clearance. Counted as twelve candidates, five arcs and the crank pin's
clearance took every place to fit and the slider pin's clearance was never fitted; as one effect, one arc takes a
place, and the slider pin is fitted (0.0794 mm) and named or tied with the winner (the two pins move the slider alike:
the report names the sensor that tells them apart).
"""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.candidates import CLEARANCE_BOUNDS, WEAR_DEPTH_BOUNDS
from clearsim.diagnose.search import SCREEN_POINTS

CONFIG = str(Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml")
MODEL = ["--set", "solver.t_end=12ms", "--set", "joints.crank_pin.clearance=0.01mm",
         "--set", "joints.crank_pin.bearing_radius=10mm", "--set", "joints.slider_pin.clearance=0"]
HIDDEN = 0.08e-3  # m, the slider pin's clearance in the record (0.08 mm)
BENCH = ["--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz",
         "--trigger-offset", "0.1ms", "--noise", "0.1%", "--seed", "5"]


def screened(entry: dict) -> float:
    """The lowest χ² of a ranking entry's screening runs (a clearance's or a worn arc's, at SCREEN_POINTS of its range)."""
    low, high = WEAR_DEPTH_BOUNDS if entry["kind"] == "wear" else CLEARANCE_BOUNDS
    values = [low * (high / low) ** u for u in SCREEN_POINTS]
    return min(chi for value, chi, _ in entry["profile"] if any(abs(value / v - 1.0) < 1e-9 for v in values))


def test_a_hidden_clearance_is_fitted_though_the_worn_arcs_of_another_joint_screen_better(tmp_path):
    runner = CliRunner()
    record = tmp_path / "bench.csv"
    result = runner.invoke(app, ["synthesize", CONFIG, *MODEL, "--set", "joints.slider_pin.clearance=0.08mm",
                                 *BENCH, "-o", str(record)])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["diagnose", CONFIG, *MODEL, "--measured", str(record), "-o", str(tmp_path / "report"),
                                 "--workers", "2", "--candidates", "clearance,wear"])
    assert result.exit_code == 0, result.output
    found = json.loads((tmp_path / "report" / "diagnosis.json").read_text())
    ranking = found["iterations"][0]["ranking"]

    slider_pin = next(r for r in ranking if (r["kind"], r["target"]) == ("clearance", "slider_pin"))
    arcs = [r for r in ranking if r["kind"] == "wear"]
    assert slider_pin["fitted"]
    assert slider_pin["value"] == pytest.approx(HIDDEN, rel=0.1)
    assert len([r for r in arcs if r["fitted"] and round(r["angle_deg"]) % 30 == 0]) == 1  # (an arc that won would
    # have its neighbours at ± 15° fitted too)
    assert sum(screened(r) < screened(slider_pin) for r in arcs) >= 5  # the arcs outrank it: the case is the one meant
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("clearance", "slider_pin") or \
        "clearance in joint slider_pin" in effect["ambiguous_with"]
