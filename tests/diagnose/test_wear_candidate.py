"""A worn arc of a bore as a diagnosis candidate: `diagnose` names the worn joint, the arc's position and its depth.

The hidden wear is not the candidate's shape (a wrapped Gaussian 60° wide, candidates.worn_arc) but a broader one,
h(θ) = d (1 + cos(θ − φ))²/4, at φ = 20°, between two of the positions tried (every 30°). CI-sized: the slider-crank's
first 12 ms, the slider's displacement and velocity, candidates clearance and wear.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.candidates import WEAR_ARC, WEAR_DEPTH_BOUNDS, candidates_for, worn_arc
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.physics.wear import evaluate_profile, summed_coefficients, tightest_radius
from clearsim.runner import simulate_config

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
CONFIG = str(CONFIGS / "slider_crank_flores.yaml")
UHV = CONFIGS / "uhv_breaker.yaml"
SHORT = ["--set", "solver.t_end=12ms"]
BENCH = ["--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz",
         "--trigger-offset", "0.1ms", "--noise", "0.1%", "--seed", "5"]
TRUE_DEPTH = 0.1e-3  # m, at TRUE_ANGLE
TRUE_ANGLE = math.radians(20.0)
ANGLES = np.linspace(0.0, 2.0 * math.pi, 3600, endpoint=False)


def hidden_wear() -> str:
    """`--set` of the profile d (1 + cos(θ − φ))²/4 = d (3/8 + ½ cos(θ − φ) + ⅛ cos 2(θ − φ))."""
    d, phi = TRUE_DEPTH * 1e3, TRUE_ANGLE
    cos = [3 * d / 8, d / 2 * math.cos(phi), d / 8 * math.cos(2 * phi)]
    sin = [d / 2 * math.sin(phi), d / 8 * math.sin(2 * phi)]
    return (f"joints.slider_pin.wear.profile={{cos: [{', '.join(f'{v!r}mm' for v in cos)}], "
            f"sin: [{', '.join(f'{v!r}mm' for v in sin)}]}}")


def diagnosed(tmp_path: Path, hidden: list[str]) -> dict:
    runner = CliRunner()
    record = tmp_path / "bench.csv"
    result = runner.invoke(app, ["synthesize", CONFIG, *SHORT, *hidden, *BENCH, "-o", str(record)])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["diagnose", CONFIG, *SHORT, "--measured", str(record), "-o", str(tmp_path / "report"),
                                 "--workers", "2", "--candidates", "clearance,wear"])
    assert result.exit_code == 0, result.output
    return json.loads((tmp_path / "report" / "diagnosis.json").read_text())


def angle_apart(a: float, b: float) -> float:
    """|a − b| on the circle (degrees)."""
    return abs((a - b + 180.0) % 360.0 - 180.0)


def test_a_hidden_worn_arc_is_named_at_its_joint_its_angle_and_depth(tmp_path):
    found = diagnosed(tmp_path, ["--set", hidden_wear()])
    assert len(found["effects"]) == 1
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("wear", "slider_pin")
    assert angle_apart(effect["angle_deg"], math.degrees(TRUE_ANGLE)) <= 30.0
    low, high = effect["interval"]["depth"]
    assert low <= TRUE_DEPTH <= high  # 0.108 mm (0.085–0.123) around 0°
    assert effect["finding"].startswith("joint slider_pin worn ") and f"around {effect['angle_deg']:.0f}°" in effect["finding"]
    assert effect["finding"] in (tmp_path / "report" / "report.md").read_text()
    assert found["gap_after"] < 0.3 * found["gap_before"]
    ranking = found["iterations"][0]["ranking"]
    refined = {r["angle_deg"] for r in ranking if r["kind"] == "wear" and round(r["angle_deg"]) % 30}
    assert len(refined) == 2 and all(r["fitted"] for r in ranking if r["kind"] == "wear" and r["angle_deg"] in refined)
    assert [r["fitted"] for r in ranking if r["kind"] == "clearance" and r["target"] == "slider_pin"] == [True]  # the
    # arc is judged against its joint's clearance


def test_a_record_of_the_unworn_model_names_no_wear(tmp_path):
    found = diagnosed(tmp_path, [])
    assert not [e for e in found["effects"] if e["kind"] == "wear"]


def test_the_worn_arc_peaks_at_its_angle_with_its_depth_and_the_volume_of_its_width():
    radius, depth, angle = 0.01, 5e-5, math.radians(120.0)
    profile = evaluate_profile(worn_arc(depth, angle, radius, 0.5e-3), ANGLES)
    assert math.degrees(ANGLES[np.argmax(profile)]) == pytest.approx(120.0, abs=0.1)
    assert profile.max() == pytest.approx(depth, rel=1e-9)
    assert profile.min() > -1e-4 * depth  # wear only removes material (the kernel's ringing aside)
    assert profile.mean() * 2.0 * math.pi == pytest.approx(depth * WEAR_ARC, rel=1e-9)  # worn area / R_B = d · w / R_B


def test_wear_candidates_cover_the_bore_and_add_to_a_present_profile():
    loaded = load_mechanism(CONFIG, [hidden_wear()])
    document = yaml.safe_load(loaded.resolved_yaml)
    candidates = candidates_for(loaded.mechanism, document, ["wear"])
    assert [round(math.degrees(c.angle)) for c in candidates] == list(range(0, 360, 30))
    assert len({c.key for c in candidates}) == 12
    assert all(c.target == "slider_pin" and c.current is None for c in candidates)
    at_120 = candidates[4]
    assert at_120.finding(5e-5) == "joint slider_pin worn 0.05 mm around 120°"
    worn = load_mechanism_text(document_text(at_120.applied(document, 5e-5)), CONFIG, (), Path(CONFIG).parent)
    joint = next(j for j in worn.mechanism.joints if j.name == "slider_pin")
    present = next(j for j in loaded.mechanism.joints if j.name == "slider_pin").wear.profile.coefficients()
    added = evaluate_profile(joint.wear.profile.coefficients(), ANGLES) - evaluate_profile(present, ANGLES)
    assert np.max(np.abs(added - evaluate_profile(worn_arc(5e-5, math.radians(120.0), 0.01, 0.5e-3), ANGLES))) < 1e-15


@pytest.mark.parametrize("depth", [WEAR_DEPTH_BOUNDS[0], 1.05e-5, 1.26e-4, WEAR_DEPTH_BOUNDS[1]])
def test_a_worn_arc_in_a_tight_joint_is_no_tighter_than_its_journal(depth):
    """The UHV breaker's joint A (R_B = 50 mm, c = 0.01 mm): the 60° arc of 0.0105 mm had a radius of curvature of
    49.950 mm at its bottom, tighter than the 49.990 mm journal; the arc is widened until it leaves the journal a tenth
    of the clearance, keeping its depth and its position."""
    radius, clearance, angle = 0.05, 1e-5, math.radians(120.0)
    arc = worn_arc(depth, angle, radius, clearance)
    assert tightest_radius(arc, radius) >= radius - 0.9 * clearance - 1e-3 * clearance
    profile = evaluate_profile(arc, ANGLES)
    assert profile.max() == pytest.approx(depth, rel=1e-9)
    assert math.degrees(ANGLES[np.argmax(profile)]) == pytest.approx(120.0, abs=0.1)


def test_a_worn_arc_added_to_a_present_wear_leaves_their_sum_no_tighter_than_the_journal():
    """Joint A's bore already worn 0.0105 mm at 120° (an arc as the candidate writes it, as loose as allowed): a
    second arc of that depth there, checked alone, is as loose as allowed too, but their sum is a pocket of 49.981 mm
    against the 49.990 mm journal; the arc is widened until the sum leaves it a tenth of the clearance."""
    radius, clearance, angle, depth = 0.05, 1e-5, math.radians(120.0), 1.05e-5
    present = worn_arc(depth, angle, radius, clearance)
    arc = worn_arc(depth, angle, radius, clearance, present)
    assert tightest_radius(summed_coefficients(present, arc), radius) >= radius - 0.9 * clearance - 1e-3 * clearance
    assert evaluate_profile(arc, ANGLES).max() == pytest.approx(depth, rel=1e-9)


def test_a_worn_arc_in_a_tight_joint_takes_the_steps_of_the_unworn_joint(tmp_path):
    """The UHV breaker's first 15 ms with a 0.0105 mm arc at 0° in joint A (0.01 mm), written by its candidate: with a
    pocket tighter than the journal the journal touched its two flanks in turn, the contact's normal flipping between
    them, and the steps fell to 30 ns (from 12 ms on: 97 942 steps in 20 ms); now within twice the unworn run's."""
    loaded = load_mechanism(str(UHV))
    document = yaml.safe_load(loaded.resolved_yaml)
    arc = next(c for c in candidates_for(loaded.mechanism, document, ["wear"]) if c.target == "A" and c.angle == 0.0)
    worn = tmp_path / "worn.yaml"
    worn.write_text(document_text(arc.applied(document, 1.05e-5)))
    short = ["solver.t_end=15ms", "solver.output_rate=10kHz"]
    unworn_steps = simulate_config(UHV, short, tmp_path / "unworn.h5").statistics.steps
    worn_steps = simulate_config(worn, short, tmp_path / "worn.h5").statistics.steps
    assert worn_steps <= 2 * unworn_steps, (worn_steps, unworn_steps)
