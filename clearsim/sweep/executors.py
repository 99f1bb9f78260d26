"""Where the cases run: a local process pool, or an existing Dask distributed cluster.

Both hand each outcome to a callback as its case finishes. Ctrl-C cancels the cases not yet
started; cases already running in the pool are interrupted (their files flagged incomplete) and
their outcomes still collected, so the summary matches the files. A second Ctrl-C leaves at once.
A process of the local pool that dies fails only the case it was running (the pool is started again for the
others); a Dask cluster's workers need no shared file system (the case files come back to this machine).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import tempfile
import uuid
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Sequence

from clearsim.errors import ClearsimError
from clearsim.io.files import partial_name, publish
from clearsim.solver import precompile
from clearsim.sweep.grid import SweepOptionError
from clearsim.sweep.worker import (FAILED, INTERRUPTED, CaseOutcome, CaseTask, init_pool_worker, load_case,
                                   reused_outcome)

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


MAX_POOL_REBUILDS = 5  # pools started again in one run after a worker died; at the next death the rest fails
SUBMITTED_PER_WORKER = 2  # tasks handed to the pool at a time per worker process (_Batch); the rest wait in order
IDLE = -1  # a worker slot's task index between cases
_board, _slot = None, -1  # in a pool process: the pool's board of (pid, running task index) and this process's slot


@dataclass
class _Pool:
    """A process pool, its stop flag, and its board: per worker process, its pid and the index of the task it runs
    (shared memory, so that when a process dies the case it was running is known: a broken pool fails every
    pending future alike)."""

    executor: ProcessPoolExecutor
    stop: object
    board: object = None


def _init_worker(stop, board, next_slot) -> None:
    """Pool initializer: the case worker's, then this process's slot on the board."""
    global _board, _slot
    init_pool_worker(stop)
    with next_slot.get_lock():
        _slot, next_slot.value = next_slot.value, next_slot.value + 1
    if 2 * _slot + 1 < len(board):
        _board = board
        _board[2 * _slot], _board[2 * _slot + 1] = os.getpid(), IDLE


def _tracked(function: Callable, index: int, task):
    """Run one task, its index on the board while it runs (a process killed mid-case leaves it there)."""
    if _board is not None:
        _board[2 * _slot + 1] = index
    try:
        return function(task)
    finally:
        if _board is not None:
            _board[2 * _slot + 1] = IDLE


def _death(exitcode: int) -> str:
    if exitcode < 0:
        try:
            return f"worker killed by signal {-exitcode} ({signal.Signals(-exitcode).name})"
        except ValueError:
            return f"worker killed by signal {-exitcode}"
    return f"worker process exited with code {exitcode}"


def _running(board) -> dict[int, int]:
    """pid → index of the task it was running, for the board's busy slots."""
    if board is None:
        return {}
    pairs = zip(board[0::2], board[1::2])
    return {pid: index for pid, index in pairs if pid > 0 and index != IDLE}


def _deaths(processes: dict, running: dict[int, int]) -> dict[int, str]:
    """Task index → why its worker died, for the processes that died by themselves while running a case (once one
    dies, the pool ends the others with SIGTERM)."""
    codes = {pid: process.exitcode for pid, process in processes.items()}
    return {index: _death(codes[pid]) for pid, index in running.items()
            if codes.get(pid) is not None and codes[pid] != -signal.SIGTERM}


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
        self._pool: _Pool | None = None

    def describe(self) -> str:
        return f"{self.workers} local worker process{'es' if self.workers > 1 else ''}"

    def connect(self) -> None:
        """Nothing to connect to: the processes start with the first case."""

    def open(self) -> "LocalPool":
        """Keep the worker processes between `run` calls (diagnose runs many small batches) until `close`."""
        if self._pool is None:
            self._pool = self._start(self.workers)
        return self

    def close(self) -> None:
        if self._pool is not None:
            self._pool.executor.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def __enter__(self) -> "LocalPool":
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()

    @staticmethod
    def _start(workers: int) -> _Pool:
        # spawn, not fork: the parent may hold threads (the progress bar) and numba state
        context = multiprocessing.get_context("spawn")
        stop, board, next_slot = context.Event(), context.Array("q", 2 * workers, lock=False), context.Value("i", 0)
        executor = ProcessPoolExecutor(workers, mp_context=context, initializer=_init_worker,
                                       initargs=(stop, board, next_slot))
        return _Pool(executor, stop, board)

    def run(self, function: Callable, tasks: Sequence[CaseTask], collect: Collect) -> bool:
        """Run every task, passing each outcome to `collect`; True when Ctrl-C stopped the sweep.

        A worker process that dies (killed, out of memory) breaks the pool: its case is recorded as failed with the
        reason, the pool is started again and the cases that were queued or running on the other processes are
        submitted again (at most MAX_POOL_REBUILDS times)."""
        if not tasks:
            return False
        kept = self._pool is not None
        size = self.workers if kept else min(self.workers, len(tasks))
        batch = _Batch(self._pool if kept else self._start(size), function, tasks, collect, lambda: self._start(size))
        batch.pool.stop.clear()
        # on an empty kernel cache the first case runs alone: its process compiles the kernels (with the
        # compile-ahead helper on the second core) and every other case loads them, instead of each process
        # compiling them at once on shared cores (a 2-worker sweep's first cases: 17 → 13 s)
        compile_first = len(tasks) > 1 and self.workers > 1 and precompile.cache_is_cold()
        window = SUBMITTED_PER_WORKER * size
        batch.window = 1 if compile_first else window
        batch.submit(range(len(tasks)))
        interrupted = False
        try:
            while batch.futures or batch.queued:
                try:
                    batch.collect_finished(interrupted)
                    if batch.window < window and not interrupted:
                        batch.window = window
                        batch.top_up()
                except KeyboardInterrupt:
                    if interrupted:
                        raise  # a second Ctrl-C: leave without waiting for the running cases
                    interrupted = True
                    batch.queued.clear()  # not submitted: not run
                    batch.pool.stop.set()  # cases already handed to a process return at once instead of starting
                    _interrupt_workers(batch.pool.executor)
                    batch.futures = {future: i for future, i in batch.futures.items() if not future.cancel()}
        finally:
            if not kept or interrupted:
                batch.pool.executor.shutdown(wait=True, cancel_futures=True)
            if kept:
                self._pool = None if interrupted else batch.pool
        return interrupted


class _Batch:
    """The tasks of one `LocalPool.run` in flight on a pool, and the pool rebuilt when one of its workers dies.

    At most `window` tasks are submitted at a time, the others queued here: waiting for the first of N pending
    futures costs O(N) at each case's end (10 000 cases of 4 ms on 2 workers: 17.3 s of the sweep's process's CPU
    time, on the cores its workers need, 2.3 s with the window; wall time 39 → 28 s)."""

    def __init__(self, pool: _Pool, function: Callable, tasks: Sequence[CaseTask], collect: Collect,
                 new_pool: Callable[[], _Pool]):
        self.pool, self.function, self.tasks, self.collect, self.new_pool = pool, function, tasks, collect, new_pool
        self.futures: dict = {}  # future → task index
        self.queued: deque[int] = deque()  # task indices not submitted yet, in order
        self.window = 1
        self.rebuilds = 0

    def submit(self, indices) -> None:
        self.queued.extend(indices)
        self.top_up()

    def top_up(self) -> None:
        """Submit queued tasks until `window` are in flight."""
        while self.queued and len(self.futures) < self.window:
            index = self.queued.popleft()
            self.futures[self.pool.executor.submit(_tracked, self.function, index, self.tasks[index])] = index
        _watch_every_process(self.pool.executor)

    def collect_finished(self, interrupted: bool) -> None:
        done, _ = wait(self.futures, return_when=FIRST_COMPLETED)
        if any(isinstance(future.exception(), BrokenProcessPool) for future in done):
            self._recover(interrupted)
            return
        for future in done:
            self.collect(_result(future, self.tasks[self.futures.pop(future)]))
        self.top_up()

    def _recover(self, interrupted: bool) -> None:
        """A worker died: every pending future failed alike. The case the dead process was running fails with the
        reason; the others run again on a new pool. A process ended by SIGTERM looks like the ones the pool ends
        itself: then no case is blamed and every one runs again (MAX_POOL_REBUILDS bounds the repeats)."""
        processes = dict(self.pool.executor._processes or {})
        self.pool.executor.shutdown(wait=True)  # the pool has ended its processes: their exit codes are known
        # read once they have ended: a process that the pool's SIGTERM reached while writing its file ends its
        # case in order (clearing its slot) and exits with code 0
        deaths = _deaths(processes, _running(self.pool.board))
        self.rebuilds += 1
        again = []
        for future, index in sorted(self.futures.items(), key=lambda item: item[1]):
            task, exc = self.tasks[index], future.exception()
            if not isinstance(exc, BrokenProcessPool):
                self.collect(_result(future, task))
            elif index in deaths:
                self.collect(CaseOutcome(task.name, FAILED, True, f"{deaths[index]} while running this case"))
            elif interrupted:
                self.collect(CaseOutcome(task.name, INTERRUPTED, True, "interrupted"))
            elif self.rebuilds > MAX_POOL_REBUILDS:
                self.collect(self._not_run(task))
            else:
                again.append(index)
        if self.rebuilds > MAX_POOL_REBUILDS:
            for index in self.queued:
                self.collect(self._not_run(self.tasks[index]))
            self.queued.clear()
        self.futures, self.pool = {}, self.new_pool()  # its processes start with the first case submitted
        self.queued.extendleft(reversed(again))  # before the ones never submitted, in their order
        self.top_up()

    def _not_run(self, task: CaseTask) -> CaseOutcome:
        return CaseOutcome(task.name, FAILED, True, f"not run: worker processes died {self.rebuilds} times in this "
                           "sweep, the pool was not started again")


def _watch_every_process(pool: ProcessPoolExecutor) -> None:
    """Have the pool's manager thread watch every process it has now. `submit` wakes that thread before it starts
    a process: a thread that woke first waits on the processes it knew then and does not see a later one die
    until some case's result arrives, while the case of the dead process stays pending. Woken here as `submit`
    does, under the pool's lock (a broken pool closes the wakeup under it)."""
    if not isinstance(pool, ProcessPoolExecutor):
        return  # a pool of threads: no processes to watch
    with pool._shutdown_lock:
        wakeup = getattr(pool, "_executor_manager_thread_wakeup", None)  # None once the pool is shut down
        if wakeup is not None:
            wakeup.wakeup()


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
    """An existing dask.distributed cluster at `address` (tcp://host:8786); its workers need clearsim installed,
    not the sweep folder: the CSV tables go with each case, the result files come back to this machine."""

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
        """As LocalPool.run, without a shared file system: whether a case's file is there to reuse is decided
        here, each case runs in a scratch folder of its worker, and its file comes back with its outcome and is
        written into the sweep folder here. On Ctrl-C the cases not started are cancelled; the results of
        running ones are not waited for (those cases run again on resume)."""
        from distributed import as_completed

        self.connect()
        client, self.client = self.client, None
        futures, token, read = {}, uuid.uuid4().hex[:8], {}
        try:
            for task in tasks:
                if (reused := _reused_here(task)) is not None:
                    collect(reused)
                    continue
                shipped = replace(task, output=Path(task.output).name)  # the worker's scratch folder holds it
                futures[client.submit(run_shipped, function, shipped, _tables(task, read),
                                      key=f"clearsim-{token}-{task.name}", pure=False)] = task
            for future in as_completed(list(futures)):
                task = futures.pop(future)
                collect(_received(task, future))
        except KeyboardInterrupt:
            return True
        finally:
            client.cancel(list(futures))
            client.close()
        return False


def _reused_here(task: CaseTask) -> CaseOutcome | None:
    """The case's outcome when the sweep folder holds its result already (the folder made ready otherwise)."""
    try:
        return reused_outcome(task)
    except ClearsimError as exc:
        return CaseOutcome(task.name, FAILED, True, str(exc))


def _tables(task: CaseTask, read: dict[Path, bytes]) -> dict[str, bytes]:
    """The CSV tables the case reads (every `file:` of its mechanism, relative to the YAML file), to go with it to
    a worker that does not see them; none when one is missing here (the worker then reports it at its path here).
    `read` keeps the bytes of those read already."""
    base = Path(task.base_dir)
    names = {name for name in _file_keys(load_case(task).mechanism.model_dump()) if not Path(name).is_absolute()}
    for path in {base / name for name in names} - set(read):
        read[path] = path.read_bytes() if path.is_file() else None
    tables = {name: read[base / name] for name in sorted(names)}
    return tables if None not in tables.values() else {}


def _file_keys(value) -> list[str]:
    if isinstance(value, dict):
        return [item for key, inner in value.items()
                for item in ([inner] if key == "file" and isinstance(inner, str) else _file_keys(inner))]
    if isinstance(value, list):
        return [item for inner in value for item in _file_keys(inner)]
    return []


def run_shipped(function: Callable, task: CaseTask, tables: dict[str, bytes]) -> tuple[CaseOutcome, bytes | None]:
    """On a worker: the case with its file in a scratch folder of this machine, and its CSV tables there beside a
    stand-in for the YAML file's folder (all of them, or none when a name climbs out of the scratch folder: then
    they are read at the YAML file's folder); its outcome and the file's bytes (None when it wrote none) go back
    to the machine that holds the sweep folder."""
    with tempfile.TemporaryDirectory(prefix="clearsim-case-") as scratch:
        output, base = Path(scratch) / task.output, Path(scratch) / "config"
        placed = {(base / name).resolve(): data for name, data in tables.items()}
        sent = bool(placed) and all(path.is_relative_to(Path(scratch).resolve()) for path in placed)
        for path, data in placed.items() if sent else ():
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        outcome = function(replace(task, output=str(output), base_dir=str(base) if sent else task.base_dir))
        return outcome, output.read_bytes() if output.exists() else None


def _received(task: CaseTask, future) -> CaseOutcome:
    """A case's outcome from the cluster, its file written into the sweep folder (a file already there is kept as
    .previous, never overwritten); a file that cannot be written fails the case with the reason."""
    try:
        outcome, data = future.result()
    except Exception as exc:
        return _lost(task, exc)
    if data is None:
        return outcome
    output = Path(task.output)
    partial = partial_name(output)
    try:
        partial.write_bytes(data)
        publish(partial, output)
    except OSError as exc:
        partial.unlink(missing_ok=True)
        return CaseOutcome(task.name, FAILED, True, f"its result file ({len(data) / 1e6:.1f} MB) came back from "
                                                    f"the cluster but cannot be written to {output}: {exc}")
    return outcome
