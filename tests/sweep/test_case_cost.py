"""What a sweep's worker does around a case's integration: its record comes from what the run kept in memory of the
file it wrote (not from reading the file back), equal to the record read from the file, for complete and failed
cases; the folder is looked at once per case for a killed worker's file."""

from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from clearsim.sweep import SweepRequest, plan_sweep, worker
from clearsim.sweep.execute import tasks_of
from clearsim.sweep.figures import read_record
from tests.sweep.test_grid import SLIDER_CRANK

SHORT = "solver.t_end=4ms"


def plan(tmp_path: Path, keep: str, *overrides: str):
    return plan_sweep(SweepRequest(SLIDER_CRANK, [SHORT, *overrides], "0.5", keep=keep, out=tmp_path / "sweep"),
                      SLIDER_CRANK)


def assert_same_record(kept, read) -> None:
    for field in fields(read):
        ours, theirs = getattr(kept, field.name), getattr(read, field.name)
        if isinstance(theirs, np.ndarray):
            assert ours.dtype == theirs.dtype and np.array_equal(ours, theirs), field.name
        else:
            assert ours == theirs, field.name  # bit for bit: floats compared with ==


@pytest.mark.parametrize("keep, overrides", [("all", ()), ("figures", ()), ("summary", ("solver.min_step=5e-5s",))])
def test_a_case_record_is_the_file_s_without_reading_it_back(tmp_path, monkeypatch, keep, overrides):
    sweep = plan(tmp_path, keep, *overrides)
    task = next(t for t in tasks_of(sweep) if t.name != "ideal")
    monkeypatch.setattr(worker, "read_record", lambda *args: pytest.fail("the file just written was read back"))
    outcome = worker.run_case(task)
    assert outcome.state == ("failed" if overrides else "complete") and outcome.ran
    monkeypatch.undo()
    loaded = worker.load_case(task)
    assert_same_record(outcome.record, read_record(Path(task.output), loaded.mechanism.output))
    assert outcome.record.contact["slider_pin"][0] > 0.0 or overrides


def test_a_case_looks_for_a_killed_worker_s_file_once(tmp_path, monkeypatch):
    sweep = plan(tmp_path, "figures")
    looked = []
    original = worker.adopt_abandoned
    monkeypatch.setattr(worker, "adopt_abandoned", lambda path: (looked.append(path), original(path)))
    import clearsim.runner as runner
    monkeypatch.setattr(runner, "adopt_abandoned", lambda path: (looked.append(path), original(path)))
    task = next(t for t in tasks_of(sweep) if t.name != "ideal")
    assert worker.run_case(task).state == "complete"
    assert looked == [Path(task.output)]


def turns_sample_by_sample(angle):
    """full_turns' definition, one sample at a time: (ends, directions)."""
    ends, directions, level = [], [], float(angle[0]) if len(angle) else 0.0
    for i, value in enumerate(np.asarray(angle, dtype=float).tolist()):
        while abs(value - level) >= 2 * np.pi:
            direction = 1 if value > level else -1
            level += direction * 2 * np.pi
            ends.append(i)
            directions.append(direction)
    return ends, directions


def test_the_turns_of_a_journal_path_are_those_of_a_sample_by_sample_count():
    from clearsim.whirl import full_turns

    rng = np.random.default_rng(7)
    paths = [np.cumsum(rng.normal(0.0, 0.6, 3000)), np.cumsum(rng.normal(0.1, 0.05, 5000)),
             np.round(np.cumsum(rng.normal(0.0, 1.0, 2000)) / np.pi) * np.pi,  # levels met exactly
             (2 * np.pi / 37 * np.arange(4000)).astype(np.float32), np.zeros(0), np.array([1.0])]
    for angle in paths:
        turns = full_turns(angle)
        ends, directions = turns_sample_by_sample(angle)
        assert turns.ends.tolist() == ends and turns.directions.tolist() == directions
    assert len(full_turns(paths[1]).ends) > 50
