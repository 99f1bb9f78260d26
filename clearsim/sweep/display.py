"""What `clearsim sweep` prints: the progress bar over cases, the summary table, the closing lines."""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass

from rich.cells import cell_len
from rich.console import Console, ConsoleOptions, Group
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.markup import escape
from rich.table import Table

from clearsim.sweep.execute import SweepResult
from clearsim.sweep.plan import SweepPlan
from clearsim.sweep.summary import ENVELOPE_COLUMN, JOINT_FIGURES, PERCENTILES, joint_column, percentile_header

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


GAP = 2  # characters between two columns (rich's padding of one on each side, none at the edges)


@dataclass(frozen=True)
class Column:
    title: str  # its lines ("\n") wrapped at their spaces when the cells are narrower
    cells: list[str]  # never split: a number is read whole or not at all
    justify: str = "right"

    @property
    def width(self) -> int:
        return max([cell_len(cell) for cell in self.cells] + [cell_len(word) for word in self.title.split()])


def column_blocks(keys: list[Column], columns: list[Column], width: int) -> list[list[Column]]:
    """The columns in blocks that fit `width` next to the key columns, in order; a column wider than the space left
    still gets a block of its own."""
    key_width = sum(key.width + GAP for key in keys)
    blocks: list[list[Column]] = [[]]
    used = key_width
    for column in columns:
        if blocks[-1] and used + column.width > width:
            blocks.append([])
            used = key_width
        blocks[-1].append(column)
        used += column.width + GAP
    return blocks


class WholeCellTable:
    """A table that never splits a cell: each column as wide as its widest cell, and the columns that do not fit the
    console (80 characters in a pipe) printed in a further block below, the key columns repeated at its left."""

    def __init__(self, keys: list[Column], columns: list[Column]):
        self.keys, self.columns = keys, columns

    def blocks(self, width: int) -> list[Table]:
        return [self._table(self.keys + block) for block in column_blocks(self.keys, self.columns, width)]

    @staticmethod
    def _table(columns: list[Column]) -> Table:
        table = Table(box=None, pad_edge=False, header_style="bold")
        for column in columns:
            title = "\n".join(wrapped for line in column.title.split("\n")
                              for wrapped in textwrap.wrap(line, column.width, break_long_words=False))
            table.add_column(escape(title), justify=column.justify, no_wrap=True, min_width=column.width)
        for row in zip(*(column.cells for column in columns)):
            table.add_row(*(escape(cell) for cell in row))
        return table

    def __rich_console__(self, console: Console, options: ConsoleOptions):
        for number, table in enumerate(self.blocks(options.max_width)):
            if number:
                yield ""
            yield table


def rich_table(plan: SweepPlan, header: list[str], rows: list[dict]) -> WholeCellTable:
    """The printed summary: a row per case (for a long sweep the ideal cases and the first ones)."""
    joints = [key[len("max_contact_force_N["):-1] for key in header if key.startswith("max_contact_force_N[")]
    ideal = [r for r in rows if plan.case(r["case"]).ideal]
    shown = rows if len(rows) <= MAX_PRINTED_ROWS else ideal + rows[:MAX_PRINTED_ROWS]
    shown = list({r["case"]: r for r in shown}.values())
    firsts = [_first_columns(plan, row) for row in shown]
    keys = [Column(title.removeprefix("joints."), [cells[k] for cells in firsts], "left")
            for k, title in enumerate(["case"] if plan.sampled else plan.labels)]
    figures = [("peak |a| m/s²", "peak_acceleration_m_s2"), ("× ideal", "acceleration_ratio"),
               ("delay ms", "start_delay_ms"), ("end error %", "end_error_percent")]
    columns = [Column(title, [_number(row.get(key), 3) for row in shown]) for title, key in figures]
    for joint in joints:
        columns.append(Column(f"F max N\n{joint}",
                              [_number(row.get(joint_column("max_contact_force_N", joint))) for row in shown]))
        columns.append(Column(f"free imp cont %\n{joint}", [_shares(row, joint) for row in shown]))
    if ENVELOPE_COLUMN in header:
        travel = [("closing ms", "operating_time_ms"), ("zone m/s", "zone_speed_m_s"), ("overtravel mm", "overtravel_mm"),
                  ("rebound mm", "rebound_mm")]
        columns += [Column(title, [_number(row.get(key), 4) for row in shown]) for title, key in travel]
        columns.append(Column("in envelope", [row.get(ENVELOPE_COLUMN) or "–" for row in shown], "left"))
    columns.append(Column("steps", [_number(row.get("steps")) for row in shown]))
    columns.append(Column("status", ["ok" if row["status"] == "complete" else row["status"] for row in shown], "left"))
    return WholeCellTable(keys, columns)


def percentile_table(entries: list[dict]) -> WholeCellTable:
    titles = percentile_header()
    keys = [Column(titles[0], [entry["figure"] for entry in entries], "left")]
    columns = [Column(titles[1], [str(entry["cases"]) for entry in entries])]
    columns += [Column(title, [_number(entry[f"p{p}"]) for entry in entries]) for title, p in zip(titles[2:], PERCENTILES)]
    return WholeCellTable(keys, columns)


KEPT = {"all": "", "summary": " (each file: the summary histories)",
        "figures": " (each file: the histories the figures of merit read)"}


def opening_line(plan: SweepPlan, where: str) -> str:
    kept = KEPT[plan.keep]
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
        lines.append(f"warning: {_cases(len(warned))} with warnings ({', '.join(warned)}): "
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
