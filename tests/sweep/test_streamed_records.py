"""What the sweep keeps of each finished case while it runs: the figures, not the histories (a 10 000-case Monte Carlo
would hold 2 GB of them), with the same summary as from the whole records. No case is simulated here."""

from dataclasses import replace

import numpy as np

from clearsim.sweep import SweepRequest, plan_sweep, run_sweep
from clearsim.sweep.summary import summary_rows
from clearsim.sweep.worker import COMPLETE, FAILED, CaseOutcome
from clearsim.sweep.figures import CaseRecord
from tests.sweep.test_grid import SLIDER_CRANK, with_tolerances

TIME = np.linspace(0.0, 4e-3, 401)


def record(scale: float, complete: bool = True) -> CaseRecord:
    velocity = scale * np.sin(TIME * 500.0)
    return CaseRecord(complete, "complete" if complete else "failed: x", TIME, velocity, np.cumsum(velocity) * 1e-5,
                      100.0 * scale, {"slider_pin": (1e3 * scale, 0.2, 0.3, 0.5)}, steps=10)


class Replay:
    """An executor that hands over prepared outcomes in a given order."""

    def __init__(self, outcomes: list[CaseOutcome]):
        self.outcomes = outcomes

    def connect(self) -> None:
        pass

    def run(self, function, tasks, collect) -> bool:
        for outcome in self.outcomes:
            collect(outcome)
        return False


def monte_carlo(tmp_path, samples: int = 3):
    return plan_sweep(SweepRequest(with_tolerances(tmp_path), sample=samples, out=tmp_path / "sweep"), SLIDER_CRANK)


def test_cases_keep_their_figures_not_their_histories_whichever_finishes_first(tmp_path):
    plan = monte_carlo(tmp_path)
    samples = [c.name for c in plan.cases if not c.ideal]
    whole = {"ideal": CaseOutcome("ideal", COMPLETE, True, "", record(1.0))}
    whole |= {name: CaseOutcome(name, COMPLETE, True, "", record(1.0 + 0.1 * k)) for k, name in enumerate(samples)}
    order = [whole[samples[0]], whole["ideal"], *(whole[name] for name in samples[1:])]  # one before its ideal case
    result = run_sweep(plan, Replay(order))
    for name in samples:
        kept = result.outcomes[name].record
        assert kept.velocity is None and kept.displacement is None and not len(kept.time) and kept.relative
    assert result.outcomes["ideal"].record.velocity is not None  # the others are read against it
    expected = summary_rows(plan, whole)
    assert (result.header, result.rows) == expected
    assert [row["acceleration_ratio"] for row in result.rows[1:]] == [1.0, 1.1, 1.2]


def test_a_case_whose_ideal_case_failed_keeps_its_histories(tmp_path):
    plan = monte_carlo(tmp_path, samples=1)
    failed = CaseOutcome("ideal", FAILED, True, "x", record(1.0, complete=False))
    sample = CaseOutcome("sample-0001", COMPLETE, True, "", record(2.0))
    result = run_sweep(plan, Replay([failed, sample]))
    assert result.outcomes["sample-0001"].record.velocity is not None
    assert np.isnan(result.rows[1]["acceleration_ratio"])
