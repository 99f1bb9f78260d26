"""Running a plan: cases to the executor, outcomes back, the summary written even when interrupted."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

from clearsim.errors import ClearsimError
from clearsim.sweep.figures import settled
from clearsim.sweep.plan import SweepPlan, check_folder, write_cases
from clearsim.sweep.summary import (PERCENTILES_FILE, SUMMARY_FILE, percentile_header, percentiles,
                                    summary_rows, write_csv)
from clearsim.sweep.worker import (COMPLETE, FAILED, INTERRUPTED, NOT_RUN, CaseOutcome, CaseTask, finished_outcome,
                                   run_case)

Progress = Callable[[CaseOutcome, int, int], None]  # (outcome, finished, total)


@dataclass
class SweepResult:
    plan: SweepPlan
    outcomes: dict[str, CaseOutcome]
    header: list[str]
    rows: list[dict]
    summary: Path
    percentiles: list[dict] = field(default_factory=list)
    interrupted: bool = False

    def count(self, state: str) -> int:
        return sum(1 for o in self.outcomes.values() if o.state == state)

    @property
    def ran(self) -> list[str]:
        """Cases computed by this call (the others were complete already)."""
        return [name for name, o in self.outcomes.items() if o.ran]

    @property
    def failed(self) -> list[CaseOutcome]:
        return [o for o in self.outcomes.values() if o.state == FAILED]


def case_file(plan: SweepPlan, name: str) -> Path:
    return plan.folder / f"{name}.h5"


def tasks_of(plan: SweepPlan, retry_failed: bool = False) -> list[CaseTask]:
    return [CaseTask(case.name, plan.config_text, str(plan.config), str(plan.base_dir), case.overrides,
                     str(case_file(plan, case.name)), retry_failed, plan.keep) for case in plan.cases]


def run_sweep(plan: SweepPlan, executor, progress: Progress | None = None,
              retry_failed: bool = False) -> SweepResult:
    """Run every case not done yet; summary.csv (and percentiles.csv) describe every case.

    Ctrl-C stops the sweep: finished cases stay, the summary lists the others as not run, and
    KeyboardInterrupt is raised again once the files are written.
    """
    check_folder(plan.folder, plan.config, plan.config_text)
    executor.connect()
    plan.folder.mkdir(parents=True, exist_ok=True)
    write_cases(plan)
    outcomes: dict[str, CaseOutcome] = {}
    tasks = tasks_of(plan, retry_failed)
    waiting = dependents(plan)

    def collect(outcome: CaseOutcome) -> None:
        outcomes[outcome.name] = outcome
        outcomes.update(settle(plan, outcomes, outcome.name, waiting))
        if progress is not None:
            progress(outcome, len(outcomes), len(tasks))

    try:
        interrupted = executor.run(run_case, tasks, collect)
    except KeyboardInterrupt:
        interrupted = True
    if interrupted:
        outcomes.update(recovered(tasks, outcomes))
    interrupted = interrupted or any(o.state in (INTERRUPTED, NOT_RUN) for o in outcomes.values())
    result = _summarize(plan, outcomes, interrupted)
    if interrupted:
        raise SweepInterrupted(result)
    return result


def dependents(plan: SweepPlan) -> dict[str, list[str]]:
    """Ideal case → the cases read against it."""
    found: dict[str, list[str]] = {}
    for case in plan.cases:
        if case.reference:
            found.setdefault(case.reference, []).append(case.name)
    return found


def settle(plan: SweepPlan, outcomes: dict[str, CaseOutcome], name: str,
           waiting: dict[str, list[str]]) -> dict[str, CaseOutcome]:
    """The outcomes that can drop their histories now that `name` is in (figures.settled): that case once its
    reference (its ideal case) has completed, or at once without one; when it is an ideal case, the cases in
    `waiting` for it (`dependents`). An ideal case keeps its own (the others are read against them), and so does a
    case whose ideal case did not complete (after Ctrl-C its finished file may still be read back, `recovered`)."""
    names = [name, *(n for n in waiting.get(name, ()) if n in outcomes)]
    changed = {}
    for case in (plan.case(n) for n in names):
        record = outcomes[case.name].record
        reference = outcomes.get(case.reference) if case.reference else None
        ideal = reference.record if reference is not None else None
        if case.ideal or record is None or record.relative is not None:
            continue
        if case.reference is None or (ideal is not None and ideal.complete):
            changed[case.name] = replace(outcomes[case.name], record=settled(record, ideal, plan.delay_fraction))
    return changed


def recovered(tasks: list[CaseTask], outcomes: dict[str, CaseOutcome]) -> dict[str, CaseOutcome]:
    """After Ctrl-C: the cases whose worker finished the file as the interruption came, so that their outcome
    never reached this process (or said interrupted), read back from their complete files."""
    unsettled = [t for t in tasks if t.name not in outcomes or outcomes[t.name].state in (INTERRUPTED, NOT_RUN)]
    return {t.name: outcome for t in unsettled if (outcome := finished_outcome(t)) is not None}


def _summarize(plan: SweepPlan, outcomes: dict[str, CaseOutcome], interrupted: bool) -> SweepResult:
    ordered = {case.name: outcomes[case.name] for case in plan.cases if case.name in outcomes}
    header, rows = summary_rows(plan, ordered)
    summary = write_csv(plan.folder / SUMMARY_FILE, header, rows)
    table = percentiles(plan, header, rows) if plan.sampled else []
    if table:
        write_csv(plan.folder / PERCENTILES_FILE, percentile_header(), table)
    return SweepResult(plan, ordered, header, rows, summary, table, interrupted)


class SweepFailed(ClearsimError):
    """Some cases of a sweep failed (the others finished and are in the summary)."""


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep; `result` holds what had finished (already written to summary.csv)."""

    def __init__(self, result: SweepResult):
        super().__init__()
        self.result = result


__all__ = ["COMPLETE", "FAILED", "SweepFailed", "SweepInterrupted", "SweepResult", "case_file", "run_sweep"]
