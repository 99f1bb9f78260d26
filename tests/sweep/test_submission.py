"""How the local pool hands cases to its processes: a few at a time, in order, every one collected once."""

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

from clearsim.solver import precompile
from clearsim.sweep import LocalPool, executors
from clearsim.sweep.worker import COMPLETE, CaseOutcome


class CountingPool(ThreadPoolExecutor):
    """A pool of threads that notes how many submitted tasks had not finished, at most, and the order of starts."""

    def __init__(self, workers: int):
        super().__init__(workers)
        self.lock, self.in_flight, self.most, self.started = threading.Lock(), 0, 0, []

    def submit(self, function, *args):
        with self.lock:
            self.in_flight += 1
            self.most = max(self.most, self.in_flight)
        future = super().submit(function, *args)
        future.add_done_callback(self._finished)
        return future

    def _finished(self, future) -> None:
        with self.lock:
            self.in_flight -= 1


@pytest.mark.parametrize("cold", [True, False], ids=["empty cache", "filled cache"])
def test_the_pool_holds_a_few_cases_per_worker_not_the_whole_sweep(monkeypatch, cold):
    """Waiting for the first of N pending cases costs O(N): a 10 000-case sweep submits them a few at a time."""
    pools = []

    def counting(workers: int):
        pools.append(CountingPool(workers))
        return executors._Pool(pools[-1], threading.Event())

    def case(task):
        pools[-1].started.append(task)
        time.sleep(0.002)
        return CaseOutcome(task, COMPLETE, True, "")

    monkeypatch.setattr(precompile, "cache_is_cold", lambda: cold)
    monkeypatch.setattr(executors.LocalPool, "_start", staticmethod(counting))
    tasks = [f"case-{k:02d}" for k in range(40)]
    collected = []
    assert not LocalPool(2).run(case, tasks, collected.append)
    assert sorted(outcome.name for outcome in collected) == tasks
    assert pools[0].most <= executors.SUBMITTED_PER_WORKER * 2
    assert pools[0].started[0] == tasks[0] and sorted(pools[0].started) == tasks
