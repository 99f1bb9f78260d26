"""A sweep folder: every `*.h5` of it overlaid, and the figures of merit of `summary.csv`
(one row per case: the swept quantities as written, e.g. "0.05 mm", then the figures of merit,
docs/sweeps.md §3) against the swept quantity.
"""

from __future__ import annotations

import csv
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from clearsim.plot.data import PlotInputError
from clearsim.plot.style import IDEAL_STYLE, RUN_COLOURS, axes_or_new, figure_legend, legend_beside, new_figure, set_title

SUMMARY = "summary.csv"
CASES = "cases.json"  # written by `clearsim sweep` into its folder: the cases it runs (docs/sweeps.md)
BACKUP = re.compile(r"\.previous(-\d+)?\.h5$")  # a case's earlier result, kept by a re-run (docs/sweeps.md §4)
BOOKKEEPING = {"case", "reference", "status", "error", "warnings", "reused", "steps", "rejected_steps", "wall_time_s"}
MERITS = {  # column → (axis label, factor from the CSV's unit to the axis unit)
    "peak_acceleration_m_s2": ("peak |output acceleration| (m/s²)", 1.0),
    "start_delay_ms": ("start delay of the output (ms)", 1.0),
    "end_error_percent": ("end-position error (% of stroke)", 1.0),
    "max_contact_force_N": ("max contact force (kN)", 1e-3),
}
MAX_GROUPS = 8  # more combinations of the other swept quantities: points without lines


def result_files(folder: Path) -> list[Path]:
    """The folder's result files, the ideal case first, then by name."""
    files = sorted(folder.glob("*.h5"), key=lambda p: (not p.stem.startswith("ideal"), p.name))
    files = [f for f in files if not BACKUP.search(f.name)]
    if not files:
        raise PlotInputError(f"{folder} contains no result files (*.h5)")
    return files


def case_names(folder: Path) -> set[str] | None:
    """The names of the cases of the sweep that made `folder` (its cases.json); None when no sweep did (or its
    cases.json cannot be read)."""
    try:
        return {str(case["name"]) for case in json.loads((folder / CASES).read_text(encoding="utf-8"))["cases"]}
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError):
        return None


@dataclass
class Summary:
    parameters: list[str]  # swept quantities, in column order
    units: dict  # parameter → unit of its values ("" for plain numbers)
    rows: list[dict]  # complete cases: parameter → float (NaN for an ideal case), merit column → float


def _number(text: str, unit: str | None) -> tuple[float, str | None]:
    """A swept value as written ("0.05 mm", "0.16") → (number in `unit`, unit); the first value sets the unit."""
    from clearsim.units import UnitError, parse_quantity

    if not text.strip():
        return math.nan, unit
    try:
        quantity = parse_quantity(text)
        unit = unit if unit is not None else f"{quantity.units:~P}"
        return float(quantity.to(unit).magnitude if unit else quantity.magnitude), unit
    except (UnitError, ValueError, TypeError, AttributeError):  # not a number: not a swept quantity we can draw
        return math.nan, unit


def _float(text: str) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read_summary(path: Path) -> Summary:
    with path.open(newline="", encoding="utf-8") as handle:
        table = list(csv.DictReader(handle))
    header = list(table[0].keys()) if table else []
    merit_columns = [c for c in header if c.split("[")[0] in MERITS]
    parameters = [c for c in header if c not in BOOKKEEPING and c not in merit_columns and "[" not in c
                  and c not in ("acceleration_ratio",)]
    units: dict = {p: None for p in parameters}
    rows = []
    for record in table:
        if record.get("status", "complete") != "complete":
            continue
        row = {c: _float(record.get(c, "")) for c in merit_columns}
        for p in parameters:
            row[p], units[p] = _number(record.get(p, ""), units[p])
        rows.append(row)
    swept = [p for p in parameters if any(not math.isnan(row[p]) for row in rows)]  # a column of no quantity: not swept
    return Summary(swept, {p: units[p] or "" for p in swept}, rows)


def _groups(summary: Summary) -> dict:
    """Rows grouped by the values of every swept quantity but the first."""
    groups: dict = {}
    for row in summary.rows:
        if math.isnan(row[summary.parameters[0]]):
            continue
        key = tuple(row[p] for p in summary.parameters[1:])
        groups.setdefault(key, []).append(row)
    return groups


def _group_label(summary: Summary, key: tuple) -> str:
    return ", ".join(f"{p} {v:g} {summary.units[p]}".strip() for p, v in zip(summary.parameters[1:], key))


def plot_merit(summary: Summary, column: str, ax=None, legend: bool = True):
    """A figure of merit against the first swept quantity (one line per combination of the others); the legend
    beside the axes unless `legend` is False (a figure of several panels has one for all)."""
    ax = axes_or_new(ax)
    label, factor = MERITS[column.split("[")[0]]
    x_name = summary.parameters[0]
    groups = _groups(summary)
    style = "o-" if len(groups) <= MAX_GROUPS else "o"
    for k, (key, rows) in enumerate(sorted(groups.items())):
        rows = sorted(rows, key=lambda r: r[x_name])
        x = [r[x_name] for r in rows]
        y = [r.get(column, math.nan) * factor for r in rows]
        ax.plot(x, y, style, color=RUN_COLOURS[k % len(RUN_COLOURS)], markersize=4,
                label=_group_label(summary, key) or None)
    ideal = [r for r in summary.rows if all(math.isnan(r[p]) for p in summary.parameters)]
    if ideal and column == "peak_acceleration_m_s2":
        ax.axhline(ideal[0][column] * factor, label="ideal", **IDEAL_STYLE)
    joint = column[column.index("[") + 1:-1] if "[" in column else ""
    ax.set_ylabel(label + (f", joint {joint}" if joint else ""))
    unit = summary.units[x_name]
    ax.set_xlabel(f"{x_name} ({unit})" if unit else x_name)
    if legend:
        legend_beside(ax)
    return ax


def merit_figure(summary: Summary, title: str, interactive: bool = False):
    """Peak acceleration, start delay, end error and contact forces against the swept quantity."""
    columns = [c for c in ("peak_acceleration_m_s2", "start_delay_ms", "end_error_percent")
               if any(not math.isnan(r.get(c, math.nan)) for r in summary.rows)]
    columns += [c for c in (summary.rows[0] if summary.rows else {}) if c.startswith("max_contact_force_N[")]
    rows = math.ceil(len(columns) / 2)
    figure = new_figure((9.0, 3.0 * rows + 0.8), interactive)
    axes = np.atleast_1d(figure.subplots(rows, 2, squeeze=False).ravel())
    for ax, column in zip(axes, columns):
        plot_merit(summary, column, ax, legend=False)
    figure_legend(figure, axes[:len(columns)])
    for ax in axes[len(columns):]:
        ax.set_visible(False)
    set_title(figure, f"{title}\nfigures of merit against {summary.parameters[0]} (from summary.csv)")
    return figure


def summary_of(folder: Path, notes: list | None = None) -> Summary | None:
    """The folder's summary when it has one with a numeric swept quantity and complete cases; one that cannot be
    read gives no merit figure and a note (the runs are still plotted)."""
    path = folder / SUMMARY
    if not path.exists():
        return None
    try:
        summary = read_summary(path)
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        if notes is not None:
            notes.append(f"{path} cannot be read ({exc}): no figure of merit; run the sweep again to rewrite it")
        return None
    if not summary.parameters or not any(not math.isnan(r[summary.parameters[0]]) for r in summary.rows):
        return None
    return summary
