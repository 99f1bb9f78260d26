"""A worker process of the local pool that dies mid-case (SIGKILL: the out-of-memory killer, an operator) takes
only its own case with it: the pool is started again and the other cases finish; a re-run completes the killed one."""

import csv
import functools
import os
import signal
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import h5py
import pytest

from clearsim.sweep import LocalPool, SweepRequest, executors, plan_sweep, run_sweep
from clearsim.sweep.worker import COMPLETE, FAILED, INTERRUPTED, CaseOutcome, CaseTask

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
SHORT = "solver.t_end=4ms"
CLEARANCES = "0.1,0.2,0.3,0.4"
VICTIM = "clearance-0.2_mm"


def _kill_when_written(path: Path, signum: int) -> None:
    while not list(path.parent.glob(f".{path.name}.*.tmp")):  # the file being written, under its hidden name
        time.sleep(0.001)
    os.kill(os.getpid(), signum)


def _dying(victims: frozenset, signum: int, function, task):
    """In a worker process: the named cases kill their process once their result file is being written."""
    if task.name in victims:
        threading.Thread(target=_kill_when_written, args=(Path(task.output), signum), daemon=True).start()
    return function(task)


class DyingPool(LocalPool):
    """The local pool whose named cases die mid-case with a real signal to their worker process."""

    def __init__(self, workers: int, victims, signum: int = signal.SIGKILL):
        super().__init__(workers)
        self.victims, self.signum = frozenset(victims), signum

    def run(self, function, tasks, collect):
        return super().run(functools.partial(_dying, self.victims, self.signum, function), tasks, collect)


def _plan(out: Path):
    return plan_sweep(SweepRequest(SLIDER_CRANK, [SHORT], CLEARANCES, out=out), SLIDER_CRANK)


def test_a_case_whose_worker_is_killed_fails_alone_and_the_others_finish(tmp_path):
    out = tmp_path / "sweep"
    result = run_sweep(_plan(out), DyingPool(2, [VICTIM]))
    states = {name: outcome.state for name, outcome in result.outcomes.items()}
    assert states == {"ideal": COMPLETE, "clearance-0.1_mm": COMPLETE, VICTIM: FAILED, "clearance-0.3_mm": COMPLETE,
                      "clearance-0.4_mm": COMPLETE}
    assert result.outcomes[VICTIM].error == "worker killed by signal 9 (SIGKILL) while running this case"
    with (out / "summary.csv").open(newline="") as handle:
        rows = {row["case"]: row for row in csv.DictReader(handle)}
    assert rows[VICTIM]["status"] == "failed" and "signal 9" in rows[VICTIM]["error"]
    for name in set(states) - {VICTIM}:
        with h5py.File(out / f"{name}.h5") as handle:  # the cases the pool's break cut short ran again, complete
            assert bool(handle.attrs["complete"]), name
    again = run_sweep(_plan(out), LocalPool(2))
    assert again.ran == [VICTIM] and again.count(COMPLETE) == 5


def test_a_pool_whose_workers_keep_dying_is_started_again_a_bounded_number_of_times(tmp_path, monkeypatch):
    monkeypatch.setattr(executors, "MAX_POOL_REBUILDS", 1)
    plan = _plan(tmp_path / "sweep")
    everyone = [case.name for case in plan.cases]
    result = run_sweep(plan, DyingPool(1, everyone))
    errors = [result.outcomes[name].error for name in everyone]
    assert [o.state for o in result.outcomes.values()] == [FAILED] * 5
    assert errors[:2] == ["worker killed by signal 9 (SIGKILL) while running this case"] * 2
    assert errors[2:] == ["not run: worker processes died 2 times in this sweep, the pool was not started again"] * 3


def _b_ends_in_order_a_is_killed(folder: str, task: CaseTask) -> CaseOutcome:
    """Case b ends in order on SIGTERM, as a case writing its file does (it defers the signal and then returns as
    interrupted, and its process exits with code 0); case a kills its own process while b runs. Both complete
    when run again (a-killed exists)."""
    killed, running = Path(folder) / "a-killed", Path(folder) / "b-running"
    if killed.exists():
        return CaseOutcome(task.name, COMPLETE, True)
    if task.name == "a":
        while not running.exists():
            time.sleep(0.01)
        killed.touch()
        os.kill(os.getpid(), signal.SIGKILL)

    def ended_in_order(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, ended_in_order)
    running.touch()
    try:
        time.sleep(60)
    except KeyboardInterrupt:
        return CaseOutcome(task.name, INTERRUPTED, True, "interrupted")
    return CaseOutcome(task.name, FAILED, True, "never ended by the pool")


def _run_b_then_a(folder: Path, monkeypatch) -> dict[str, CaseOutcome]:
    from clearsim.solver import precompile

    monkeypatch.setattr(precompile, "cache_is_cold", lambda: False)  # a cold cache would hold a back until b ends
    collected = {}
    tasks = [CaseTask(name, "", "", "", (), "") for name in ("b", "a")]
    assert not LocalPool(2).run(functools.partial(_b_ends_in_order_a_is_killed, str(folder)), tasks,
                                lambda outcome: collected.setdefault(outcome.name, outcome))
    return collected


def test_a_case_the_pool_ended_in_order_after_the_death_is_not_blamed_for_it(tmp_path, monkeypatch):
    collected = _run_b_then_a(tmp_path, monkeypatch)
    assert (collected["a"].state, collected["a"].error) == (FAILED, "worker killed by signal 9 (SIGKILL) while "
                                                                     "running this case")
    assert collected["b"].state == COMPLETE, collected["b"].error


def test_the_death_of_a_process_started_after_the_pool_began_waiting_is_seen_at_once(tmp_path, monkeypatch):
    """The pool starts a process per case submitted, after waking its manager thread: a thread that woke before
    the second process started waits on the first alone. Its death must still end b at once (b is not left to
    sleep its 60 s and be collected as `never ended by the pool`)."""
    spawn = ProcessPoolExecutor._spawn_process

    def second_starts_late(executor):
        if executor._processes:
            time.sleep(0.5)  # the manager thread, woken by the submit, is waiting again by then
        spawn(executor)

    monkeypatch.setattr(ProcessPoolExecutor, "_spawn_process", second_starts_late)
    collected = _run_b_then_a(tmp_path, monkeypatch)
    assert collected["a"].error == "worker killed by signal 9 (SIGKILL) while running this case"
    assert collected["b"].state == COMPLETE, collected["b"].error


@pytest.mark.parametrize("exitcode, reason", [(-9, "worker killed by signal 9 (SIGKILL)"),
                                              (-11, "worker killed by signal 11 (SIGSEGV)"),
                                              (1, "worker process exited with code 1")])
def test_the_dead_process_is_blamed_not_the_ones_the_pool_ended_after_it(exitcode, reason):
    class Ended:
        def __init__(self, code):
            self.exitcode = code

    processes = {101: Ended(exitcode), 102: Ended(-signal.SIGTERM), 103: Ended(-signal.SIGTERM)}
    board = [101, 4, 102, 7, 103, executors.IDLE]
    running = executors._running(board)
    assert running == {101: 4, 102: 7}
    assert executors._deaths(processes, running) == {4: reason}
