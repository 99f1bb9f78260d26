"""Time histories of sensors, their spectra, and the energy / constraint diagnostic page.

Every function takes a list of runs (one run, or several overlaid with their labels) and
`ax=None`, and returns the axes it drew on.
"""

from __future__ import annotations

import numpy as np

from clearsim.plot.data import RunData
from clearsim.plot.scales import FREQUENCY, TIME, scale_for
from clearsim.plot.style import (LEGEND_WIDTH, axes_or_new, legend_beside, new_figure, overlay_styles, set_title,
                                 title_of)

ENERGY_KINDS = ("kinetic", "potential", "driver_work", "applied_work", "contact_dissipated",
                "friction_dissipated", "damping_dissipated", "hydraulic_supply_work", "hydraulic_tank_work",
                "orifice_dissipated", "oil_compression", "dashpot_dissipated", "guide_friction_dissipated")
STORED_SUFFIX = "_stored"  # energy held by a drive element (drive_spring_stored, gas_stored): counted in the potential
VIOLATION_FLOOR = 1e-18  # m: stands for an exact zero on the logarithmic axis
SPECTRUM_RANGE = 1e-8  # amplitudes below the highest peak × this are numerical floor (of an ideal run): not shown
SPECTRUM_FLOOR_PERCENTILE = 1.0  # the amplitude axis starts at a third of this percentile of the clearance runs
ENVELOPE_BINS = 300  # the violation jumps between 0 (just projected) and ~1e-13 m: draw its envelope


def pretty(name: str) -> str:
    return name.replace("_", " ")


def _sensor_scale(runs: list[RunData], sensor: str):
    key = f"sensors/{sensor}"
    values = np.concatenate([run.series(key, f"sensor {sensor}") for run in runs])
    return scale_for(runs[0].unit(key), values)


def plot_signal(runs: list[RunData], sensor: str, ax=None):
    """A sensor against time, one line per run, in engineering units."""
    ax = axes_or_new(ax)
    scale = _sensor_scale(runs, sensor)
    series = [run.series(f"sensors/{sensor}") for run in runs]
    for run, values, style in zip(runs, series, overlay_styles(runs, [_peak_to_peak(v) for v in series])):
        ax.plot(TIME(run.time), scale(values), label=run.label or run.name, **style)
    ax.set_ylabel(scale.label(pretty(sensor)))
    ax.set_xlabel(TIME.label("time"))
    if len(runs) > 1:
        legend_beside(ax)
    return ax


def _peak_to_peak(values) -> float:
    values = np.asarray(values, dtype=float)
    return float(np.ptp(values[np.isfinite(values)])) if np.any(np.isfinite(values)) else float("nan")


def signals_figure(runs: list[RunData], sensors: list[str], interactive: bool = False):
    """One axis per sensor, stacked with a shared time axis (paper Fig. 7/8: x, v, a of the output)."""
    figure = new_figure((8.0 + (LEGEND_WIDTH if len(runs) > 1 else 0.0), 2.3 * len(sensors) + 0.8), interactive)
    axes = figure.subplots(len(sensors), 1, sharex=True, squeeze=False)[:, 0]
    for ax, sensor in zip(axes, sensors):
        plot_signal(runs, sensor, ax)
        if ax is not axes[-1]:
            ax.set_xlabel("")
        if ax is not axes[0] and ax.get_legend():
            ax.get_legend().remove()
    what = "output" if len(runs) == 1 else f"{len(runs)} runs"
    set_title(figure, f"{title_of(runs[0])}\n{what}: " + ", ".join(pretty(s) for s in sensors))
    return figure


def amplitude_spectrum(time: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum (Hann window, mean removed): a sine of amplitude A shows as ≈ A."""
    if len(time) < 4:
        return np.zeros(0), np.zeros(0)
    step = float(np.median(np.diff(time)))
    window = np.hanning(len(values))
    centred = np.asarray(values, float) - np.mean(values)
    amplitude = 2.0 * np.abs(np.fft.rfft(centred * window)) / np.sum(window)
    return np.fft.rfftfreq(len(values), step), amplitude


def plot_spectrum(runs: list[RunData], sensor: str, ax=None):
    """Amplitude spectrum of a sensor, frequency in kHz, logarithmic amplitude."""
    ax = axes_or_new(ax)
    unit = scale_for(runs[0].unit(f"sensors/{sensor}"), [1.0]).unit
    spectra = [amplitude_spectrum(run.time, run.series(f"sensors/{sensor}")) for run in runs]
    spectra = [(frequency[1:], amplitude[1:]) for frequency, amplitude in spectra]
    for run, (frequency, amplitude), style in zip(runs, spectra, overlay_styles(runs, [_top(a) for _, a in spectra])):
        ax.semilogy(FREQUENCY(frequency), amplitude, label=run.label or run.name, **style)
    ax.set_xlabel(FREQUENCY.label("frequency"))
    ax.set_ylabel(f"amplitude of {pretty(sensor)} ({unit})")
    ax.set_xlim(left=0.0)
    limits = spectrum_limits([amplitude for _, amplitude in spectra], [not run.clearance_joints for run in runs])
    if limits is not None:
        ax.set_ylim(*limits)
    if len(runs) > 1:
        legend_beside(ax)
    return ax


def _top(values) -> float:
    finite = np.asarray(values, dtype=float)[np.isfinite(values)]
    return float(np.max(finite)) if finite.size else float("nan")


def spectrum_limits(amplitudes: list[np.ndarray], ideal: list[bool]) -> tuple[float, float] | None:
    """Amplitude axis limits from the informative data: up to twice the highest peak, down to a third of the
    SPECTRUM_FLOOR_PERCENTILE-th percentile of the runs with clearance (of every run when all are ideal), never
    below the peak × SPECTRUM_RANGE — an ideal run's smooth spectrum falls to a numerical floor far below."""
    def positive(values):
        values = np.asarray(values, dtype=float)
        return values[np.isfinite(values) & (values > 0.0)]

    every = [positive(a) for a in amplitudes]
    informative = [a for a, is_ideal in zip(every, ideal) if not is_ideal and a.size] or [a for a in every if a.size]
    if not informative:
        return None
    top = max(float(np.max(a)) for a in every if a.size)
    low = float(np.percentile(np.concatenate(informative), SPECTRUM_FLOOR_PERCENTILE)) / 3.0
    return max(low, top * SPECTRUM_RANGE), top * 2.0


def spectrum_figure(runs: list[RunData], sensors: list[str], interactive: bool = False):
    figure = new_figure((8.0 + (LEGEND_WIDTH if len(runs) > 1 else 0.0), 2.6 * len(sensors) + 0.9), interactive)
    axes = figure.subplots(len(sensors), 1, squeeze=False)[:, 0]
    for ax, sensor in zip(axes, sensors):
        plot_spectrum(runs, sensor, ax)
    start, end = runs[0].time[0], runs[0].time[-1]
    set_title(figure, f"{title_of(runs[0])}\namplitude spectrum, {TIME(start):.4g}–{TIME(end):.4g} ms (Hann window)")
    return figure


def energy_entries(run: RunData) -> list[str]:
    """Every /energy entry of the file but the balance error (drawn on its own): ENERGY_KINDS first, in their order,
    then the others (the stored energies of drive elements, ...) as the file lists them."""
    held = [key.split("/", 1)[1] for key in run.datasets if key.startswith("energy/")]
    known = [kind for kind in ENERGY_KINDS if kind in held]
    return known + [kind for kind in held if kind not in known and kind != "balance_error"]


def energy_label(kind: str, values: np.ndarray) -> str:
    """Legend label of an energy entry: its name; a stored energy (part of the potential, not in the balance again)
    says so; one that stays 0 says so."""
    label = "potential (change)" if kind == "potential" else pretty(kind)
    if kind.endswith(STORED_SUFFIX):
        label += " (part of potential)"
    return label + (" (0 throughout)" if not np.any(values) else "")


def plot_energies(run: RunData, ax=None):
    """Every energy entry of the file (J) against time, each with its label: kinetic energy, change of potential
    energy, works, dissipations and the energies stored in drive elements (energy_entries)."""
    ax = axes_or_new(ax)
    for kind in energy_entries(run):
        values = run.series(f"energy/{kind}")
        label = energy_label(kind, values)
        if kind == "potential":
            values = values - values[0]
        ax.plot(TIME(run.time), values, label=label)
    ax.set_ylabel("energy (J)")
    ax.set_xlabel(TIME.label("time"))
    legend_beside(ax)  # none for a file without energies (an empty panel, not a matplotlib warning)
    return ax


def plot_balance_error(runs: list[RunData], ax=None):
    """The energy balance error E − E(0) − W + D (J): zero for exact integration."""
    ax = axes_or_new(ax)
    errors = [run.series("energy/balance_error", "the energy balance") for run in runs]
    peaks = [float(np.max(np.abs(error))) for error in errors]
    for run, error, peak, style in zip(runs, errors, peaks, overlay_styles(runs, peaks)):
        reference = max(float(np.max(np.abs(run.series("energy/kinetic", "the energy balance")))), 1e-300)
        label = f"{run.label or run.name}: max |error| {peak:.3g} J ({peak / reference:.2g} of peak kinetic energy)"
        ax.plot(TIME(run.time), error, label=label, **style)
    ax.set_ylabel("balance error (J)")
    ax.set_xlabel(TIME.label("time"))
    legend_beside(ax)
    return ax


def envelope(time: np.ndarray, values: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """(bin centres, max of |values| per bin): the upper envelope of a noisy series."""
    if len(values) <= bins:
        return time, np.abs(values)
    edges = np.linspace(0, len(values), bins + 1).astype(int)
    peaks = np.maximum.reduceat(np.abs(values), edges[:-1])
    centres = 0.5 * (time[edges[:-1]] + time[np.minimum(edges[1:], len(time)) - 1])
    return centres, peaks


def plot_violation(runs: list[RunData], ax=None):
    """max |Φ| of the ideal joints (m), logarithmic: its upper envelope over ENVELOPE_BINS bins."""
    ax = axes_or_new(ax)
    violations = [run.series("constraints/violation", "the constraint violation") for run in runs]
    peaks = [float(np.max(violation)) for violation in violations]
    for run, violation, peak, style in zip(runs, violations, peaks, overlay_styles(runs, peaks)):
        time, envelope_peaks = envelope(run.time, violation, ENVELOPE_BINS)
        ax.semilogy(TIME(time), np.maximum(envelope_peaks, VIOLATION_FLOOR), label=f"{run.label or run.name}: max "
                    f"{peak:.2g} m", **style)
    ax.set_ylabel("constraint violation\nmax |Φ| (m)")
    ax.set_xlabel(TIME.label("time"))
    legend_beside(ax)
    return ax


def energy_figure(runs: list[RunData], interactive: bool = False):
    """Diagnostic page: energies (one run), balance error and constraint violation (all runs)."""
    panels = 3 if len(runs) == 1 else 2
    figure = new_figure((8.0 + LEGEND_WIDTH, 2.5 * panels + 0.8), interactive)
    axes = figure.subplots(panels, 1, sharex=True)
    if panels == 3:
        plot_energies(runs[0], axes[0])
    plot_balance_error(runs, axes[-2])
    plot_violation(runs, axes[-1])
    for ax in axes[:-1]:
        ax.set_xlabel("")
    set_title(figure, f"{title_of(runs[0])}\nenergy balance and constraint violation (diagnostics)")
    return figure
