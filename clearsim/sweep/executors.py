"""Where the cases run: a local process pool, or an existing Dask distributed cluster.

Both hand each outcome to a callback as its case finishes. Ctrl-C cancels the cases not yet
started; cases already running in the pool are interrupted (their files flagged incomplete) and
their outcomes still collected, so the summary matches the files. A second Ctrl-C leaves at once.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import uuid
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Callable, Sequence

from clearsim.solver import precompile
from clearsim.sweep.grid import SweepOptionError
from clearsim.sweep.worker import FAILED, CaseOutcome, CaseTask, init_pool_worker

Collect = Callable[[CaseOutcome], None]
MAX_WORKERS_PER_CORE = 4  # a case is compiled code using one core: more processes only add memory


def available_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def _lost(task: CaseTask, exc: BaseException) -> CaseOutcome:
    """A case whose worker died (killed, out of memory): recorded like a failure."""
    return CaseOutcome(task.name, FAILED, True, f"worker lost: {type(exc).__name__}: {exc}")


class LocalPool:
    """A pool of `workers` processes (default: all cores), each running many cases."""

    def __init__(self, workers: int | None = None):
        if workers is not None and workers < 1:
            raise SweepOptionError(f"--workers must be at least 1, got {workers}")
        cores = available_cores()
        if workers is not None and workers > MAX_WORKERS_PER_CORE * cores:
            raise SweepOptionError(f"--workers {workers}: this machine gives clearsim {cores} core"
                                   f"{'s' if cores > 1 else ''}; more than {MAX_WORKERS_PER_CORE * cores} processes "
                                   "only share them, and each holds its own copy of the compiled kernels (~200 MB)\n"
                                   f"  hint: --workers {cores}, or leave the option out (one process per core)")
        self.workers = workers or available_cores()
        self._pool, self._stop = None, None

    def describe(self) -> str:
        return f"{self.workers} local worker process{'es' if self.workers > 1 else ''}"

    def connect(self) -> None:
        """Nothing to connect to: the processes start with the first case."""

    def open(self) -> "LocalPool":
        """Keep the worker processes between `run` calls (diagnose runs many small batches) until `close`."""
        if self._pool is None:
            self._pool, self._stop = self._start(self.workers)
        return self

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool, self._stop = None, None

    def __enter__(self) -> "LocalPool":
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()

    @staticmethod
    def _start(workers: int):
        # spawn, not fork: the parent may hold threads (the progress bar) and numba state
        context = multiprocessing.get_context("spawn")
        stop = context.Event()
        pool = ProcessPoolExecutor(workers, mp_context=context, initializer=init_pool_worker, initargs=(stop,))
        return pool, stop

    def run(self, function: Callable, tasks: Sequence[CaseTask], collect: Collect) -> bool:
        """Run every task, passing each outcome to `collect`; True when Ctrl-C stopped the sweep."""
        if not tasks:
            return False
        kept = self._pool is not None
        pool, stop = (self._pool, self._stop) if kept else self._start(min(self.workers, len(tasks)))
        stop.clear()
        # on an empty kernel cache the first case runs alone: its process compiles the kernels (with the
        # compile-ahead helper on the second core) and every other case loads them, instead of each process
        # compiling them at once on shared cores (a 2-worker sweep's first cases: 17 → 13 s)
        held_back = list(tasks[1:]) if len(tasks) > 1 and self.workers > 1 and precompile.cache_is_cold() else []
        futures = {pool.submit(function, task): task for task in tasks[:len(tasks) - len(held_back)]}
        remaining, interrupted = set(futures), False
        try:
            while remaining:
                try:
                    _collect_finished(futures, remaining, collect)
                    if held_back and not interrupted:
                        submitted = {pool.submit(function, task): task for task in held_back}
                        futures.update(submitted)
                        remaining.update(submitted)
                        held_back = []
                except KeyboardInterrupt:
                    if interrupted:
                        raise  # a second Ctrl-C: leave without waiting for the running cases
                    interrupted = True
                    stop.set()  # cases already handed to a process return at once instead of starting
                    _interrupt_workers(pool)
                    remaining = {future for future in remaining if not future.cancel()}
        finally:
            if not kept or interrupted:
                pool.shutdown(wait=True, cancel_futures=True)
                if kept:
                    self._pool, self._stop = None, None
        return interrupted


def _collect_finished(futures: dict, remaining: set, collect: Collect) -> None:
    done, _ = wait(remaining, return_when=FIRST_COMPLETED)
    for future in done:
        remaining.discard(future)
        collect(_result(future, futures[future]))


def _interrupt_workers(pool: ProcessPoolExecutor) -> None:
    """Ask the running cases to stop and flag their files (a SIGTERM reaches only this process)."""
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            os.kill(process.pid, signal.SIGINT)
        except (OSError, AttributeError):
            pass


def _result(future, task: CaseTask) -> CaseOutcome:
    try:
        return future.result()
    except Exception as exc:
        return _lost(task, exc)


CONNECT_TIMEOUT = 10  # seconds: an address that answers nothing is reported, not waited on
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
ADDRESS_HINT = "hint: the scheduler's address as `dask scheduler` prints it, e.g. --scheduler tcp://192.168.1.10:8786"


def check_address(address: str) -> str:
    """The --scheduler address if it can name a scheduler (scheme://host:port); a malformed one is reported at once,
    before the cases are planned and without trying to connect."""
    text = address.strip()
    scheme, separator, rest = text.partition("://")
    if not separator:
        scheme, rest = "tcp", text
    if scheme not in SCHEMES:
        raise SweepOptionError(f"--scheduler {address!r}: unknown scheme {scheme + '://'!r}; expected one of "
                               f"{', '.join(s + '://' for s in SCHEMES)}\n  {ADDRESS_HINT}")
    host, colon, port = rest.rpartition(":")
    bracketed = host.startswith("[") == host.endswith("]")  # an IPv6 host is written [::1]
    if not colon or not host.strip("[]") or not bracketed or "/" in rest:
        raise SweepOptionError(f"--scheduler {address!r}: expected host:port after the scheme\n  {ADDRESS_HINT}")
    if not (port.isascii() and port.isdigit() and 1 <= int(port) <= 65535):
        raise SweepOptionError(f"--scheduler {address!r}: the port {port!r} is not a number from 1 to 65535\n"
                               f"  {ADDRESS_HINT}")
    return text if separator else f"tcp://{text}"


class DaskCluster:
    """An existing dask.distributed cluster at `address` (tcp://host:8786); its workers need clearsim
    installed and the sweep folder on a shared file system at the same path."""

    def __init__(self, address: str, workers: int | None = None):
        if workers is not None:
            raise SweepOptionError("--workers sizes the local pool; a Dask cluster runs as many cases "
                                   "at once as its workers have threads")
        self.address = check_address(address)
        self.client = None

    def describe(self) -> str:
        return f"the Dask cluster at {self.address}"

    def close(self) -> None:
        """Each `run` closes its own client; a client connected but not used is closed here."""
        if self.client is not None:
            self.client.close()
            self.client = None

    def connect(self) -> None:
        """Reach the scheduler before anything is written (an unreachable one is an input error)."""
        if self.client is None:
            self.client = self._client()

    def _client(self):
        try:
            from distributed import Client
        except ImportError:
            raise SweepOptionError("--scheduler needs dask.distributed: pip install 'dask[distributed]'") from None
        try:
            return Client(self.address, timeout=f"{CONNECT_TIMEOUT}s")
        except Exception as exc:  # noqa: BLE001 — OSError, TimeoutError, ValueError, and distributed's own assertions
            raise SweepOptionError(f"--scheduler: cannot reach the Dask scheduler at {self.address} ({exc})\n"
                                   "  hint: start one with `dask scheduler` and workers with `dask worker ADDRESS`") from None

    def run(self, function: Callable, tasks: Sequence[CaseTask], collect: Collect) -> bool:
        """As LocalPool.run; on Ctrl-C the cases not started are cancelled, running ones finish on the cluster."""
        from distributed import as_completed

        self.connect()
        client, self.client = self.client, None
        futures, token = {}, uuid.uuid4().hex[:8]
        try:
            for task in tasks:
                futures[client.submit(function, task, key=f"clearsim-{token}-{task.name}", pure=False)] = task
            for future in as_completed(list(futures)):
                collect(_result(future, futures[future]))
        except KeyboardInterrupt:
            return True
        finally:
            client.cancel(list(futures))
            client.close()
        return False
