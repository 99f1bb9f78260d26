"""benchmarks/step_trace: one row per accepted step of the run itself, its counts the run's, and a stability picture
that knows DOPRI5's stability function."""

import math
from pathlib import Path

import numpy as np
import pytest

from benchmarks.step_trace import band_crossings, breakdown, stability_function, trace
from clearsim.model.loader import load_mechanism
from clearsim.runner import prepare
from clearsim.solver.simulate import simulate

FRICTION = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores_friction.yaml"
SHORT = ["solver.t_end=3ms"]


@pytest.fixture(scope="module")
def traced():
    rows, run, stopped = trace(FRICTION, SHORT, jacobian_every=50)
    assert stopped is None
    return rows, run


def test_the_trace_accounts_for_every_step_and_rejection_of_the_run(traced):
    rows, run = traced
    statistics = simulate(prepare(load_mechanism(FRICTION, SHORT))).statistics
    assert len(rows) == statistics.steps > 0
    assert sum(row["rejected"] for row in rows) == statistics.rejected_steps > 0
    assert np.isclose(sum(row["h"] for row in rows), 3e-3, rtol=0, atol=1e-15)


def test_the_breakdown_names_the_modes_the_limiting_components_and_the_jacobian(traced):
    rows, run = traced
    joint = run.system.clearance_joints[0]
    text = breakdown(rows, run.system.clearance_joints, {joint: (1e-4, 1e-2)})
    assert f"{len(rows)} accepted steps" in text and f"{joint}:contact" in text
    assert "whole-system Jacobian" in text and "dominant error component" in text
    assert all(row["limiting"].split(".")[0] in run.system.body_names for row in rows)
    in_contact = [row for row in rows if row[f"mode_{joint}"] != "free" and row[f"h_lambda_{joint}"] > 0.0]
    assert in_contact and all(0.0 < row[f"h_lambda_{joint}"] < 3.3 for row in in_contact)  # stable steps


def test_the_stability_function_is_dopri5s():
    """R(z) = Σ z^k/k! to order 5, plus z⁶/600 (Hairer–Wanner II.2): DOPRI5's real boundary lies at z ≈ −3.31."""
    for z in (-0.5, 0.3 + 0.2j, -2.0 + 1.0j):
        expected = sum(z**k / math.factorial(k) for k in range(6)) + z**6 / 600.0
        assert stability_function(z) == pytest.approx(expected, rel=1e-12)
    assert abs(stability_function(-3.2)) < 1.0 < abs(stability_function(-3.4))


def test_a_band_crossing_is_a_step_whose_sliding_speed_passes_an_end_of_the_band():
    rows = [{"mode_A": "contact", "sliding_A": 5e-5, "sliding_end_A": 2e-4},
            {"mode_A": "contact", "sliding_A": 2e-4, "sliding_end_A": 3e-4},
            {"mode_A": "stick", "sliding_A": 5e-5, "sliding_end_A": 2e-4}]
    assert band_crossings(rows, {"A": (1e-4, 1e-2)}) == rows[:1]
