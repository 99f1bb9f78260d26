"""Simulation over measurement: a bench record (CSV) on the same axes as the runs, residual below.

The CSV has a header row; each column is named after a sensor of the result file, with its
unit in brackets (`sealing_rod_displacement [mm]`); the time column is `time` (or the first
column), `time [ms]` by default in seconds. Lines starting with `#` are comments. A column
without a unit is in the sensor's SI unit. The residual is simulation − measurement at the
measured times (the simulation interpolated linearly), where both exist.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from clearsim.plot.data import PlotInputError, RunData
from clearsim.plot.history import pretty
from clearsim.plot.scales import TIME, scale_for
from clearsim.plot.style import axes_or_new, new_figure, run_style, set_title, title_of

HEADER = re.compile(r"^\s*(?P<name>[^\[\(]+?)\s*(?:[\[\(](?P<unit>[^\]\)]*)[\]\)])?\s*$")


@dataclass
class Measurement:
    path: Path
    time: np.ndarray  # s
    columns: dict  # name → (values as written, unit as written or "")


def _rows(path: Path) -> list[list[str]]:
    if not path.exists():
        raise PlotInputError(f"no such file: {path}")
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            return [row for row in csv.reader(handle) if row and not row[0].lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as exc:
        raise PlotInputError(f"cannot read the measurement {path}: {exc}") from None


def _split_header(cell: str) -> tuple[str, str]:
    match = HEADER.match(cell)
    return (match["name"], (match["unit"] or "").strip()) if match else (cell.strip(), "")


def _factor(unit: str, to_unit: str, where: str) -> float:
    from clearsim.units import registry

    if not unit:
        return 1.0
    try:
        return float(registry().Quantity(1.0, unit).to(to_unit).magnitude)
    except Exception as exc:  # pint raises several types for unknown or mismatched units
        raise PlotInputError(f"{where}: cannot convert '{unit}' to {to_unit} ({exc})") from None


def read_measurement(path: Path | str) -> Measurement:
    """Columns of a measurement CSV (see the module docstring), time converted to seconds."""
    path = Path(path)
    rows = _rows(path)
    if len(rows) < 3:
        raise PlotInputError(f"{path}: expected a header row and at least two rows of numbers")
    header = [_split_header(cell) for cell in rows[0]]
    try:
        numbers = np.array([[float(v) for v in row] for row in rows[1:]], dtype=float)
    except ValueError:
        raise PlotInputError(f"{path}: a value below the header is not a number") from None
    names = [name for name, _ in header]
    t_index = names.index("time") if "time" in names else 0
    time = numbers[:, t_index] * _factor(header[t_index][1], "s", f"{path}: column '{names[t_index]}'")
    columns = {name: (numbers[:, k], unit) for k, (name, unit) in enumerate(header) if k != t_index}
    return Measurement(path, time, columns)


def matched_sensors(measurement: Measurement, runs: list[RunData], chosen: list[str]) -> list[str]:
    """Sensors both measured and simulated (restricted to `chosen` when given)."""
    simulated = set(runs[0].sensors())
    names = [n for n in measurement.columns if n in simulated and (not chosen or n in chosen)]
    if not names:
        raise PlotInputError(f"{measurement.path}: no column is named after a sensor of {runs[0].path} "
                             f"(columns: {', '.join(measurement.columns)}; sensors: {', '.join(sorted(simulated))})")
    return names


def measured_si(measurement: Measurement, sensor: str, run: RunData) -> np.ndarray:
    values, unit = measurement.columns[sensor]
    return values * _factor(unit, run.unit(f"sensors/{sensor}"), f"{measurement.path}: column '{sensor}'")


def residual(run: RunData, sensor: str, time: np.ndarray, measured: np.ndarray):
    """(times, simulation − measurement) where the run covers the measured times."""
    inside = (time >= run.time[0]) & (time <= run.time[-1])
    simulated = np.interp(time[inside], run.time, run.series(f"sensors/{sensor}"))
    return time[inside], simulated - measured[inside]


def wrap_label(text: str, width: int = 24) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


def within(measurement: Measurement, window: tuple[float, float] | None) -> Measurement:
    """The samples of the measurement inside a time window (s)."""
    if window is None:
        return measurement
    inside = (measurement.time >= window[0]) & (measurement.time <= window[1])
    columns = {name: (values[inside], unit) for name, (values, unit) in measurement.columns.items()}
    return Measurement(measurement.path, measurement.time[inside], columns)


def plot_measured(runs: list[RunData], measurement: Measurement, sensor: str, ax=None, residual_ax=None):
    """Simulation(s) and measurement on `ax`; the residual(s) on `residual_ax` when given."""
    ax = axes_or_new(ax)
    unit = runs[0].unit(f"sensors/{sensor}")
    measured = measured_si(measurement, sensor, runs[0])
    scale = scale_for(unit, measured)
    ax.plot(TIME(measurement.time), scale(measured), color="black", linewidth=1.6, alpha=0.55, label="measured")
    for run in runs:
        ax.plot(TIME(run.time), scale(run.series(f"sensors/{sensor}")), label=run.label or run.name,
                **run_style(run))
        if residual_ax is not None:
            t, r = residual(run, sensor, measurement.time, measured)
            rms = float(np.sqrt(np.mean(r ** 2))) if r.size else float("nan")
            residual_ax.plot(TIME(t), scale(r), label=f"{run.label or run.name}: RMS {scale(rms):.3g} {scale.unit}",
                             **run_style(run))
    ax.set_ylabel(wrap_label(scale.label(pretty(sensor))))
    ax.legend(loc="best")
    if residual_ax is not None:
        residual_ax.axhline(0.0, color="black", linewidth=0.8)
        residual_ax.set_ylabel(wrap_label(scale.label("sim − meas")))
        residual_ax.set_xlabel(TIME.label("time"))
        residual_ax.legend(loc="best")
    return ax


def measured_figure(runs: list[RunData], measurement: Measurement, sensors: list[str], interactive: bool = False):
    figure = new_figure((8.0, 3.6 * len(sensors) + 0.8), interactive)
    grid = figure.add_gridspec(2 * len(sensors), 1, height_ratios=[2.0, 1.0] * len(sensors))
    for k, sensor in enumerate(sensors):
        top = figure.add_subplot(grid[2 * k])
        bottom = figure.add_subplot(grid[2 * k + 1], sharex=top)
        plot_measured(runs, measurement, sensor, top, bottom)
        top.tick_params(labelbottom=False)
    set_title(figure, f"{title_of(runs[0])}\nsimulation over measurement ({measurement.path.name}), residual below")
    return figure
