"""The diagnosis's evaluator: predictions in the documents' order, each handed to `then` as soon as its run ends.

An executor stand-in finishes the runs in reverse order and writes each file as a sweep worker would (the
document's `value` as a constant sensor), so the evaluator's bookkeeping is tested without simulating.
"""

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from clearsim.diagnose.evaluate import Evaluator
from clearsim.sweep.worker import COMPLETE, FAILED, CaseOutcome


class ReversedExecutor:
    """Runs the tasks last first; a document whose value is negative fails. Logs what happened, in order."""

    def __init__(self):
        self.log: list[tuple] = []

    def run(self, function, tasks, collect) -> bool:
        for task in reversed(tasks):
            value = yaml.safe_load(task.config_text)["value"]
            self.log.append(("ran", value))
            if value < 0:
                collect(CaseOutcome(task.name, FAILED, True, "diverged"))
                continue
            with h5py.File(task.output, "w") as handle:
                handle["time"] = np.linspace(0.0, 1.0, 5)
                handle["sensors/x"] = np.full(5, float(value))
            collect(CaseOutcome(task.name, COMPLETE, True))
        return False


def documents(*values):
    return [{"value": v, "solver": {"output_rate": 1000.0}} for v in values]


@pytest.fixture
def evaluator(tmp_path: Path):
    return Evaluator(tmp_path / "runs", "model.yaml", tmp_path, ReversedExecutor(), output_rate=100.0)


def test_results_in_document_order_each_computed_when_its_run_ends(evaluator):
    def then(i, prediction):
        evaluator.executor.log.append(("scored", i))
        return (i, float(prediction.sensors["x"][0]))

    results = evaluator.evaluate(documents(1.0, 2.0, 3.0), then)
    assert results == [(0, 1.0), (1, 2.0), (2, 3.0)]
    # each prediction scored right after its own run, before the next run: the parent's work overlaps the runs
    assert evaluator.executor.log == [("ran", 3.0), ("scored", 2), ("ran", 2.0), ("scored", 1), ("ran", 1.0),
                                      ("scored", 0)]
    assert evaluator.simulations == 3


def test_a_repeated_document_runs_once_and_a_known_one_not_at_all(evaluator):
    evaluator.evaluate(documents(1.0))
    evaluator.executor.log.clear()
    seen = []
    results = evaluator.evaluate(documents(1.0, 2.0, 2.0), lambda i, p: seen.append(i) or float(p.sensors["x"][0]))
    assert results == [1.0, 2.0, 2.0]
    assert [entry for entry in evaluator.executor.log if entry[0] == "ran"] == [("ran", 2.0)]
    assert sorted(seen) == [0, 1, 2] and seen[0] == 0  # the known prediction first, without waiting for a run
    assert evaluator.simulations == 2


def test_without_then_the_predictions_come_back_and_a_failed_run_carries_its_error(evaluator):
    good, failed = evaluator.evaluate(documents(4.0, -1.0))
    assert good.ok and np.all(good.sensors["x"] == 4.0) and len(good.time) == 5
    assert not failed.ok and failed.error == "diverged" and len(failed.time) == 0
