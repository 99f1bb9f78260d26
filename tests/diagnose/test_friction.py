"""A hidden friction change is named as friction at the right joint and μ_d is fitted within 20 %.

Friction reaches the slider's displacement and velocity through the chaotic journal motion in the clearance
joint, so χ² over μ_d is a comb of narrow minima (teeth ~0.004 wide) over a smooth basin: the lowest run of a
grid is whichever tooth the grid hit (μ_d = 0.071 for a true 0.1 before the smoothed-profile fit). CI-sized:
the study `crank-friction` of docs/diagnose.md with two candidate kinds at the slider pin.
"""

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.candidates import PIN_CLEARANCE, candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.runner import prepare, run_to_file

CONFIG = str(Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores_friction.yaml")
BENCH = ["--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz",
         "--trigger-offset", "0.1ms", "--noise", "0.1%", "--seed", "5"]
TRUE_MU = 0.1  # the model has 0.01


def test_a_hidden_friction_change_is_named_at_its_joint_and_fitted_within_20_percent(tmp_path):
    runner = CliRunner()
    record = tmp_path / "bench.csv"
    result = runner.invoke(app, ["synthesize", CONFIG, "--set", f"joints.slider_pin.friction.mu_d={TRUE_MU}", *BENCH,
                                 "-o", str(record)])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["diagnose", CONFIG, "--measured", str(record), "-o", str(tmp_path / "report"),
                                 "--workers", "2", "--candidates", "friction,restitution"])
    assert result.exit_code == 0, result.output
    found = json.loads((tmp_path / "report" / "diagnosis.json").read_text())
    assert len(found["effects"]) == 1
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("friction", "slider_pin")
    assert effect["parameters"]["mu_d"] == pytest.approx(TRUE_MU, rel=0.2)
    assert found["gap_after"] < 0.6 * found["gap_before"]


def test_pin_friction_candidate_makes_an_ideal_pin_dissipate_as_its_friction_circle(tmp_path):
    """The friction candidate of an ideal pin (crank_pin) makes it a journal in a bearing with a tight fit
    (PIN_CLEARANCE), loaded as the ideal pin was: its friction then dissipates ∫ μ R_J |F| |ω_rod − ω_crank| dt,
    with F the ideal pin's reaction (the friction-circle model of a pin), and the slider moves as with the ideal pin."""
    mu = 0.1
    source = Path(CONFIG).with_name("slider_crank_flores.yaml")
    ideal = load_mechanism(source, ["joints.slider_pin.clearance=0", "solver.t_end=12ms"])
    document = yaml.safe_load(ideal.resolved_yaml)
    pin = next(c for c in candidates_for(ideal.mechanism, document, ["friction"]) if c.target == "crank_pin")
    assert pin.current is None and pin.pin_radius == pytest.approx(0.01 - PIN_CLEARANCE)
    with_pin = load_mechanism_text(document_text(pin.applied(document, mu)), str(source), (), source.parent)

    def run(loaded, name):
        report = run_to_file(prepare(loaded), loaded, tmp_path / name)
        assert report.complete, report.status
        return read_result(tmp_path / name)

    a, b = run(ideal, "ideal.h5"), run(with_pin, "pin.h5")
    time = a["time"]
    slip = np.abs(a["bodies/rod/qd"][:, 2] - a["bodies/crank/qd"][:, 2])
    load = np.hypot(*a["joints/crank_pin/reaction"].T)
    rate = mu * pin.pin_radius * load * slip
    circle = float(np.sum(0.5 * (rate[1:] + rate[:-1]) * np.diff(time)))
    assert b["energy/friction_dissipated"][-1] == pytest.approx(circle, rel=0.01)  # 22.297 J vs 22.322 J
    stroke = np.ptp(a["sensors/slider_displacement"])
    assert np.max(np.abs(b["sensors/slider_displacement"] - a["sensors/slider_displacement"])) < 5e-4 * stroke  # 1.5e-4: the 5 µm fit
