"""Simulation over measurement: a bench record (CSV) on the same axes as the runs, residual below.

The record is read by the one parser of measured data, `clearsim.diagnose.measured.read_measured`
(docs/diagnose.md, "Measured data"), with every check of `clearsim diagnose`: the header row names
each column after a sensor of the result file, with its unit in brackets or parentheses
(`sealing_rod_displacement [mm]`); the time column is `time` (or the first column). Lines starting
with `#` are comments; the separator may be `,`, `;` or a tab. A column without a unit is in the
sensor's SI unit. The residual is simulation − measurement at the measured times (the simulation
interpolated linearly), where both exist.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Mapping

import numpy as np

from clearsim.diagnose.measured import MeasuredData, read_measured
from clearsim.plot.data import PlotInputError, RunData
from clearsim.plot.history import pretty
from clearsim.plot.scales import TIME, scale_for
from clearsim.plot.style import (LEGEND_WIDTH, axes_or_new, legend_beside, new_figure, run_style, set_title, title_of,
                                 wrap_label)

MIN_SAMPLES = 2  # a plot needs a line, not a noise estimate
Measurement = MeasuredData


def read_measurement(path: Path | str, sensor_units: Mapping[str, str] | None = None,
                     sensors_of: str | None = None) -> MeasuredData:
    """A measurement CSV (see the module docstring) in SI; with `sensor_units` (sensor → SI unit of the result
    file) only the columns named after those sensors are read and checked, the others are left out."""
    return read_measured(path, sensor_units, first_column_time=True, mappable=False, min_samples=MIN_SAMPLES,
                         sensors_of=sensors_of)


def run_sensor_units(run: RunData) -> dict:
    """Sensor → unit (SI) of a result file's sensors, as the record's columns are checked against."""
    return {name: run.unit(f"sensors/{name}") for name in run.sensors()}


def matched_sensors(measurement: MeasuredData, runs: list[RunData], chosen: list[str]) -> list[str]:
    """Sensors both measured and simulated (restricted to `chosen` when given)."""
    simulated = set(runs[0].sensors())
    names = [n for n in measurement.values if n in simulated and (not chosen or n in chosen)]
    if not names:
        raise PlotInputError(f"{measurement.path}: no column is named after a sensor of {runs[0].path} "
                             f"(columns: {', '.join(measurement.values)}; sensors: {', '.join(sorted(simulated))})")
    return names


def measured_si(measurement: MeasuredData, sensor: str, run: RunData) -> np.ndarray:
    return measurement.values[sensor]


def residual(run: RunData, sensor: str, time: np.ndarray, measured: np.ndarray):
    """(times, simulation − measurement) where the run covers the measured times."""
    inside = (time >= run.time[0]) & (time <= run.time[-1])
    simulated = np.interp(time[inside], run.time, run.series(f"sensors/{sensor}"))
    return time[inside], simulated - measured[inside]


def within(measurement: MeasuredData, window: tuple[float, float] | None) -> MeasuredData:
    """The samples of the measurement inside a time window (s)."""
    if window is None:
        return measurement
    inside = (measurement.time >= window[0]) & (measurement.time <= window[1])
    if np.count_nonzero(inside) < MIN_SAMPLES:
        raise PlotInputError(f"{measurement.path}: fewer than {MIN_SAMPLES} samples in the time window "
                             f"{window[0] * 1e3:g}:{window[1] * 1e3:g} ms (the record covers "
                             f"{measurement.time[0] * 1e3:g} to {measurement.time[-1] * 1e3:g} ms); widen --time-window")
    values = {name: v[inside] for name, v in measurement.values.items()}
    return replace(measurement, time=measurement.time[inside], values=values)


def plot_measured(runs: list[RunData], measurement: MeasuredData, sensor: str, ax=None, residual_ax=None):
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
    legend_beside(ax)
    if residual_ax is not None:
        residual_ax.axhline(0.0, color="black", linewidth=0.8)
        residual_ax.set_ylabel(wrap_label(scale.label("sim − meas")))
        residual_ax.set_xlabel(TIME.label("time"))
        legend_beside(residual_ax)
    return ax


def measured_figure(runs: list[RunData], measurement: MeasuredData, sensors: list[str], interactive: bool = False):
    figure = new_figure((8.0 + LEGEND_WIDTH, 3.6 * len(sensors) + 0.8), interactive)
    grid = figure.add_gridspec(2 * len(sensors), 1, height_ratios=[2.0, 1.0] * len(sensors))
    for k, sensor in enumerate(sensors):
        top = figure.add_subplot(grid[2 * k])
        bottom = figure.add_subplot(grid[2 * k + 1], sharex=top)
        plot_measured(runs, measurement, sensor, top, bottom)
        top.tick_params(labelbottom=False)
    set_title(figure, f"{title_of(runs[0])}\nsimulation over measurement ({measurement.path.name}), residual below")
    return figure
