"""What `clearsim sweep` prints: the progress bar over cases, the summary table, the closing lines."""

from __future__ import annotations

import math

from rich.console import Console, Group
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.markup import escape
from rich.table import Table

from clearsim.sweep.execute import SweepResult
from clearsim.sweep.plan import SweepPlan
from clearsim.sweep.summary import JOINT_FIGURES, PERCENTILES, joint_column, percentile_header

MAX_PRINTED_ROWS = 40


def case_progress(console: Console, total: int):
    """(progress bar, update(outcome, finished, total)) counting finished cases."""
    progress = Progress(TextColumn("cases"), BarColumn(), MofNCompleteColumn(), TextColumn("{task.fields[last]}"),
                        TimeElapsedColumn(), console=console, transient=True, disable=not console.is_terminal)
    task = progress.add_task("sweep", total=total, last="")
    return progress, lambda outcome, finished, _: progress.update(task, completed=finished,
                                                                  last=f"{outcome.name}: {outcome.state}")


def case_heartbeat(beat, total: int):
    """update(outcome, finished, total) for a Heartbeat (clearsim/heartbeat.py): cases finished of all, the last."""
    beat.update(f"0 of {total} cases finished", 0, total)
    return lambda outcome, finished, total: beat.update(
        f"{finished} of {total} cases finished (last: {outcome.name}: {outcome.state})", finished, total)


def _number(value, digits: int = 4) -> str:
    if value is None or value == "" or (isinstance(value, float) and math.isnan(value)):
        return "–"
    if isinstance(value, float) and 1e3 <= abs(value) < 1e7:
        return f"{value:.0f}"  # forces and accelerations: whole units are precise enough and shorter
    return f"{value:.{digits}g}" if isinstance(value, float) else str(value)


def _shares(row: dict, joint: str) -> str:
    if math.isnan(row.get(joint_column("free_percent", joint), math.nan)):
        return "–"
    return "/".join(f"{row[joint_column(f, joint)]:.0f}" for f in JOINT_FIGURES[1:])


def _first_columns(plan: SweepPlan, row: dict) -> list[str]:
    """The case's swept values (the ideal case marked), or its name for Monte Carlo samples."""
    if plan.sampled:
        return [row["case"]]
    case = plan.case(row["case"])
    values = [row.get(label) or "–" for label in plan.labels]
    return [f"ideal ({values[0]})" if case.ideal and values[0] != "–" else "ideal", *values[1:]] if case.ideal else values


def rich_table(plan: SweepPlan, header: list[str], rows: list[dict]) -> Table:
    """The printed summary: a row per case (for a long sweep the ideal cases and the first ones)."""
    joints = [key[len("max_contact_force_N["):-1] for key in header if key.startswith("max_contact_force_N[")]
    table = Table(box=None, pad_edge=False, header_style="bold")
    for title in (["case"] if plan.sampled else plan.labels):
        table.add_column(escape(title.removeprefix("joints.")), overflow="fold")
    for title in ["peak |a|\nm/s²", "×\nideal", "delay\nms", "end\nerror %"]:
        table.add_column(title, justify="right", overflow="fold")
    for joint in joints:
        table.add_column(f"F max N\n{escape(joint)}", justify="right", overflow="fold")
        table.add_column(f"free/imp/cont %\n{escape(joint)}", justify="right", overflow="fold")
    table.add_column("steps", justify="right", overflow="fold")
    table.add_column("status", overflow="fold")
    ideal = [r for r in rows if plan.case(r["case"]).ideal]
    shown = rows if len(rows) <= MAX_PRINTED_ROWS else ideal + rows[:MAX_PRINTED_ROWS]
    for row in list({r["case"]: r for r in shown}.values()):
        cells = [_number(row.get(key), 3) for key in ("peak_acceleration_m_s2", "acceleration_ratio",
                                                       "start_delay_ms", "end_error_percent")]
        per_joint = [c for j in joints for c in (_number(row.get(joint_column("max_contact_force_N", j))), _shares(row, j))]
        table.add_row(*(escape(text) for text in _first_columns(plan, row)), *cells, *per_joint, _number(row.get("steps")),
                      "ok" if row["status"] == "complete" else row["status"])
    return table


def percentile_table(entries: list[dict]) -> Table:
    table = Table(box=None, pad_edge=False, header_style="bold")
    for title in percentile_header():
        table.add_column(title)
    for entry in entries:
        table.add_row(escape(entry["figure"]), str(entry["cases"]), *(_number(entry[f"p{p}"]) for p in PERCENTILES))
    return table


def opening_line(plan: SweepPlan, where: str) -> str:
    kept = "" if plan.keep == "all" else f" (each file: the {plan.keep} histories)"
    return f"sweep of {len(plan.cases)} cases of {plan.config.name} on {where} → {plan.folder}{kept}"


def _cases(count: int) -> str:
    return f"{count} case{'' if count == 1 else 's'}"


def closing_lines(result: SweepResult) -> list[str]:
    """What ran, what was reused, where the summary is; for an interrupted sweep, how to resume."""
    total = len(result.plan.cases)
    finished = [o for o in result.outcomes.values() if o.state in ("complete", "failed")]
    ran = sum(1 for o in finished if o.ran)
    lines = [f"{_cases(ran)} run, {len(finished) - ran} reused from earlier runs → {result.summary}"]
    if result.percentiles:
        lines.append(f"percentiles over the samples → {result.summary.with_name('percentiles.csv')}")
    warned = [row["case"] for row in result.rows if row.get("warnings")]
    if warned:
        lines.append(f"warning: {_cases(len(warned))} with results the solver could not vouch for ({', '.join(warned)}): "
                     f"see the warnings column of {result.summary}")
    if result.interrupted:
        lines.append(f"interrupted: {len(finished)} of {total} cases finished; run the same command again to resume")
    return lines


def failure_message(result: SweepResult) -> str:
    failed = result.failed
    listing = "\n".join(f"  {o.name}: {o.error}" for o in failed)
    return (f"{len(failed)} of {len(result.plan.cases)} cases failed (the others finished; see {result.summary}):\n"
            f"{listing}\n  hint: a re-run keeps failed cases; --retry-failed runs them again")


def summary_table(result: SweepResult):
    """The case table, and for a Monte Carlo sweep the percentiles of each figure."""
    table = rich_table(result.plan, result.header, result.rows)
    if not result.percentiles:
        return table
    return Group(table, "", percentile_table(result.percentiles))
