"""One case, where it runs (a process of the local pool or a Dask worker).

A worker process imports clearsim once and runs many cases; the compiled kernels come from
numba's on-disk cache, so no case compiles. A case whose file is complete (same resolved YAML)
is not run again: that is how a re-run sweep resumes. Ctrl-C reaches the pool's processes too;
a process ignores it between cases and turns it into an orderly interruption during one (the
result file is closed and flagged `complete = false`, and is run again on resume).
"""

from __future__ import annotations

import signal
import sys
import threading
from dataclasses import dataclass
from pathlib import Path

from clearsim.errors import ClearsimError
from clearsim.io.files import adopt_abandoned
from clearsim.io.hdf5 import NotAResultFile, ResultWriteError, keep_as_previous, read_attributes
from clearsim.model.loader import load_mechanism_text
from clearsim.process import exit_without_final_collection
from clearsim.runner import contents_serve, prepare, run_to_file
from clearsim.sweep.figures import CaseRecord, kept_record, read_record, record_dataset

COMPLETE, FAILED, INTERRUPTED, NOT_RUN = "complete", "failed", "interrupted", "not run"


@dataclass(frozen=True)
class CaseTask:
    """Everything a worker needs: the YAML text (not its path), the overrides, the output file."""

    name: str
    config_text: str
    config_name: str
    base_dir: str
    overrides: tuple[str, ...]
    output: str
    retry_failed: bool = False
    contents: str = "all"  # the histories its file holds (runner.CONTENTS): `--keep summary`, a diagnosis the sensors


@dataclass
class CaseOutcome:
    name: str
    state: str  # complete, failed, interrupted
    ran: bool  # False: an earlier result was reused
    error: str = ""
    record: CaseRecord | None = None
    unwritten: bool = False  # failed as its file could not be written (a full disk): the machine's fault, not the case's


_interrupted = False  # this process's case was interrupted (what it raised then is a consequence)
_stop = None  # set by the main process of a local pool: cases that have not started yet are skipped


def init_pool_worker(stop) -> None:
    """Pool initializer: an idle worker ignores Ctrl-C (the main process decides what stops)."""
    global _stop
    _stop = stop
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    sys.unraisablehook = _quiet_interrupts
    exit_without_final_collection()  # the pool's shutdown waits for its processes to end


def _quiet_interrupts(unraisable) -> None:
    """A Ctrl-C that lands in a finaliser is dropped there (the case then completes): no traceback."""
    if not isinstance(unraisable.exc_value, KeyboardInterrupt):
        sys.__unraisablehook__(unraisable)


def _interrupt(signum, frame):
    global _interrupted
    _interrupted = True
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # one interruption per case: the file is closed undisturbed
    raise KeyboardInterrupt


def run_case(task: CaseTask) -> CaseOutcome:
    """Run (or reuse) one case; failures and interruptions are outcomes, not exceptions."""
    if _stop is not None and _stop.is_set():
        return CaseOutcome(task.name, NOT_RUN, False, "cancelled")
    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, _interrupt) if in_main_thread else None
    try:
        try:
            return _attempt_recorded(task)
        except KeyboardInterrupt:
            return _after_interrupt(task)
        finally:
            if in_main_thread:
                signal.signal(signal.SIGINT, previous)
    except KeyboardInterrupt:  # the case's one interruption came while the handler was being restored
        return _after_interrupt(task)


def _attempt_recorded(task: CaseTask) -> CaseOutcome:
    global _interrupted
    _interrupted = False
    try:
        return _attempt(task)
    except ResultWriteError as exc:
        return CaseOutcome(task.name, FAILED, True, str(exc), unwritten=True)
    except ClearsimError as exc:
        return CaseOutcome(task.name, FAILED, True, str(exc))
    except Exception as exc:  # a bug must not stop the other cases; its text goes to the summary
        text = f"internal error: {type(exc).__name__}: {exc}"
        return CaseOutcome(task.name, INTERRUPTED if _interrupted else FAILED, True, text)


def _attempt(task: CaseTask) -> CaseOutcome:
    loaded = load_case(task)
    output = Path(task.output)
    output_sensors = loaded.mechanism.output
    if (reused := _reused(task, loaded)) is not None:
        return reused
    system = prepare(loaded)
    # the folder was looked at for a killed worker's file just now (_reused); the record's histories kept as written
    report = run_to_file(system, loaded, output, contents=task.contents, keep=record_dataset(output_sensors),
                         adopt=False)
    if isinstance(report.error, KeyboardInterrupt):
        raise KeyboardInterrupt
    if isinstance(report.error, ResultWriteError):
        raise report.error  # a failed case, with the reason; its file may not be readable
    if report.kept is None:  # the file could not be written whole: what it holds is what counts
        return _outcome(task.name, output, output_sensors, ran=True)
    roles = dict(loaded.document.get("output") or {})  # as the file's config_yaml has them
    return _outcome_of(task.name, kept_record(report.kept, roles, output_sensors), ran=True)


def load_case(task: CaseTask):
    """The case's mechanism: the YAML text with its overrides (CSV tables are read from base_dir when it runs)."""
    return load_mechanism_text(task.config_text, task.config_name, task.overrides, Path(task.base_dir))


def reused_outcome(task: CaseTask) -> CaseOutcome | None:
    """The outcome of the case's existing file when it is this case's result (a re-run reuses it), else None with
    the folder made ready for a new file (an unusable one removed, one of another YAML kept as .previous): where
    the sweep folder is, for a case that runs on a machine that does not see it."""
    return _reused(task, load_case(task))


def _reused(task: CaseTask, loaded) -> CaseOutcome | None:
    adopt_abandoned(Path(task.output))  # what a killed worker of this machine was writing, judged like any file
    if _reusable(Path(task.output), loaded.resolved_yaml, task.retry_failed, task.contents):
        return _outcome(task.name, Path(task.output), loaded.mechanism.output, ran=False)
    return None


def _after_interrupt(task: CaseTask) -> CaseOutcome:
    """An interruption that came after the file was complete (reading it back) leaves a complete case."""
    return finished_outcome(task) or CaseOutcome(task.name, INTERRUPTED, True, "interrupted")


def finished_outcome(task: CaseTask) -> CaseOutcome | None:
    """The case's outcome read from its file when that is complete and of this case's YAML, else None."""
    try:
        loaded = load_case(task)
        output = Path(task.output)
        if not output.exists():
            return None
        attrs = read_attributes(output)
        if attrs.get("complete") and _same_case(attrs, loaded.resolved_yaml, task.contents):
            return _outcome(task.name, output, loaded.mechanism.output, ran=True)
    except (ClearsimError, NotAResultFile, OSError):
        pass
    return None


def _outcome(name: str, output: Path, output_sensors, ran: bool) -> CaseOutcome:
    return _outcome_of(name, read_record(output, output_sensors), ran)


def _outcome_of(name: str, record: CaseRecord, ran: bool) -> CaseOutcome:
    if record.complete:
        return CaseOutcome(name, COMPLETE, ran, "", record)
    error = record.status.removeprefix("failed: ")
    return CaseOutcome(name, FAILED, ran, error, record)


def _same_case(attrs, resolved_yaml: str, contents: str) -> bool:
    """A file written from this YAML that holds what the case asks for (a full file serves any case)."""
    return attrs.get("config_yaml") == resolved_yaml and contents_serve(str(attrs.get("contents", "all")), contents)


def _reusable(output: Path, resolved_yaml: str, retry_failed: bool, contents: str = "all") -> bool:
    """Whether an existing file is this case's result; an unusable one is cleared away."""
    if not output.exists():
        return False
    try:
        attrs = read_attributes(output)
    except (NotAResultFile, OSError):
        output.unlink()  # a file cut short by a hard kill
        return False
    same = _same_case(attrs, resolved_yaml, contents)
    status = str(attrs.get("status", ""))
    if same and (bool(attrs.get("complete")) or (status.startswith("failed") and not retry_failed)):
        return True
    if same:
        output.unlink()  # interrupted, or failed and retried: this case's own file, nothing worth keeping
    else:
        keep_as_previous(output)  # from another YAML, or fewer histories than asked: kept, never over an older one
    return False
