"""The travel page: a breaker's travel curve as a travel analyser shows it (docs/plotting.md "Travel curve").

The `travel:` sensor's travel against time, one line per run, inside the tolerance envelope (shaded) when the file
gives one; the contact-touch and speed-zone positions as horizontal marks, the contact-touch time of each run as a
dot; the figures of the result file's `travel_figures` attribute in a text box (their ranges for many runs).
"""

from __future__ import annotations

import json

import numpy as np

from clearsim.plot.data import RunData
from clearsim.plot.scales import TIME, length_scale
from clearsim.plot.style import LEGEND_WIDTH, legend_beside, new_figure, run_style, set_title, title_of
from clearsim.travel import FIGURE_ROWS, figure_rows, limit_band

ENVELOPE_COLOUR = "tab:green"
MARK_COLOUR = "dimgray"
LISTED_RUNS = 3  # overlaid runs whose figures the text box lists one by one; more are summarised as ranges


def travel_figures_of(run: RunData) -> dict:
    """The run's `travel_figures` attribute ({} when its mechanism has no `travel:` block)."""
    return json.loads(str(run.attrs.get("travel_figures", "{}")))


def travel_runs(runs: list[RunData]) -> list[RunData]:
    """The runs with travel figures, their stored `travel:` block and the sensor's history."""
    return [run for run in runs if travel_figures_of(run) and run.mechanism is not None
            and run.mechanism.travel is not None and run.has(f"sensors/{run.mechanism.travel.sensor}")]


def _ranges_text(runs: list[RunData]) -> str:
    """Each figure's range over the runs (those that reach it), and how many runs kept to the envelope."""
    records = [travel_figures_of(run) for run in runs]
    lines = [f"{len(runs)} runs"]
    for key, (label, scale, unit) in FIGURE_ROWS.items():
        values = [record[key] * scale for record in records if record.get(key) is not None]
        if values:
            lines.append(f"{label}: {min(values):.4g} to {max(values):.4g} {unit}")
    checked = [record["inside_envelope"] for record in records if record.get("inside_envelope") is not None]
    if checked:
        lines.append(f"within the envelope: {sum(checked)} of {len(checked)}")
    return "\n".join(lines)


def _figures_text(runs: list[RunData]) -> str:
    """The summary's travel rows of each run, or for more than LISTED_RUNS runs their ranges."""
    if len(runs) > LISTED_RUNS:
        return _ranges_text(runs)
    blocks = []
    for run in runs:
        rows = [f"{label}: {value}" for label, value in figure_rows(travel_figures_of(run))]
        blocks.append("\n".join(([run.label or run.name] if len(runs) > 1 else []) + rows))
    return "\n\n".join(blocks)


def _marks(ax, spec, scale) -> None:
    ax.axhline(scale(spec.contact_touch), color=MARK_COLOUR, linestyle="--", linewidth=0.9, label="contact touch")
    for position in spec.speed_zone:
        ax.axhline(scale(position), color=MARK_COLOUR, linestyle=":", linewidth=0.9)
    ax.lines[-1].set_label("speed zone")


def plot_travel(runs: list[RunData], ax) -> None:
    """Each run's travel against time over the first run's envelope and marks, in mm and ms."""
    spec = runs[0].mechanism.travel
    curves = [run.series(f"sensors/{run.mechanism.travel.sensor}") for run in runs]
    band = None if spec.envelope is None else limit_band(spec.envelope.lower, spec.envelope.upper)
    scale = length_scale(np.concatenate(curves + ([] if band is None else list(band[1:]))))
    if band is not None:
        time, lower, upper = band
        ax.fill_between(TIME(time), scale(lower), scale(upper), color=ENVELOPE_COLOUR, alpha=0.2, linewidth=0,
                        label="tolerance envelope")
    _marks(ax, spec, scale)
    for run, travel in zip(runs, curves):
        style = run_style(run)
        ax.plot(TIME(run.time), scale(travel), label=run.label or run.name, **style)
        touch = travel_figures_of(run).get("operating_time_s")
        if touch is not None:
            at = touch + run.mechanism.travel.command_time
            ax.plot(TIME(at), scale(spec.contact_touch), "o", color=style["color"], markersize=4)
    ax.set_xlabel(TIME.label("time"))
    ax.set_ylabel(scale.label(f"travel of {spec.sensor.replace('_', ' ')}"))
    ax.text(0.02, 0.97, _figures_text(runs), transform=ax.transAxes, va="top", ha="left", fontsize=7,
            bbox={"boxstyle": "round", "facecolor": "white", "alpha": 0.85}, gid="travel-figures")
    legend_beside(ax)


def travel_figure(runs: list[RunData], interactive: bool = False):
    """The travel page of the runs that have travel figures (build_figures asks only when there are some)."""
    shown = travel_runs(runs)
    figure = new_figure((8.0 + LEGEND_WIDTH, 4.8), interactive)
    plot_travel(shown, figure.subplots())
    set_title(figure, f"{title_of(shown[0])}\ntravel curve")
    return figure
