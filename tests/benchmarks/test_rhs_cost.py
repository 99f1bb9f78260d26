"""benchmarks/rhs_cost: the run's right-hand sides all accounted for, the parts timed, and the refinement with a kept
factor landing on the factored solve's multipliers."""

import math

import pytest

from benchmarks.rhs_cost import CASES, breakdown, refinement, rhs_accounting, state_at

FRICTION, _ = CASES["crank-friction"]
SHORT = ["solver.t_end=3ms"]


@pytest.fixture(scope="module")
def crank_state():
    return state_at(FRICTION, 2e-3)


def test_the_accounting_splits_every_right_hand_side_of_the_run():
    counts = rhs_accounting(FRICTION, SHORT)
    assert counts["steps"] > 0 and counts["rejected"] > 0
    assert counts["other_rhs"] >= 0
    assert (counts["accepted_tries_rhs"] + counts["rejected_tries_rhs"] + counts["step_end_rhs"] + counts["other_rhs"]
            == counts["rhs"])


def test_every_part_is_timed(crank_state):
    result = breakdown(*crank_state, count=50, repeats=1)
    assert result["t_ms"] == pytest.approx(2.0)
    assert all(math.isfinite(value) and value > 0.0 for value in result["parts_us"].values())
    assert result["rhs_new_q_us"] > 0.0 and result["rhs_same_q_us"] > 0.0


def test_the_refinement_reaches_the_factored_solve(crank_state):
    run, system, _ = crank_state
    rows = refinement(run, system, steps=(1e-6, 1e-5), count=10, repeats=1)
    for row in rows.values():
        assert 1 <= row["iterations"] < 50
        assert row["relative_difference"] < 1e-13
