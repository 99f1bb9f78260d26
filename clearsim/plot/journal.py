"""Clearance-joint figures: the journal centre's path in the clearance circle (paper Fig. 11),
the contact forces and the penetration against time, coloured or shaded by contact mode.

Contact modes (`/joints/<name>/mode`, docs/model.md §5): 0 free flight, 1 impact, 2 continuous
contact. A path segment takes the mode of the sample it starts from.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Circle

from clearsim.plot.data import RunData, check_joint
from clearsim.plot.scales import TIME, force_scale, length_scale
from clearsim.plot.style import (LEGEND_WIDTH, MODE_COLOURS, axes_or_new, legend_beside, mode_handles, new_figure,
                                 overlay_styles, set_title, title_of)

PATH_GID = "journal-path"  # lets tests and callers find the drawn path
MAX_PATH_PANELS = 4


def _eccentricity_scale(runs: list[RunData], joint: str):
    sizes = [run.clearances.get(joint, 0.0) for run in runs]
    sizes += [float(np.max(np.hypot(*run.series(f"joints/{joint}/eccentricity").T))) for run in runs]
    return length_scale([max(sizes)])


def plot_journal_path(run: RunData, joint: str, ax=None, scale=None):
    """Journal centre − bearing centre, coloured by contact mode, inside the clearance circle."""
    ax = axes_or_new(ax, (5.0, 5.0))
    check_joint(run, joint)
    scale = scale or _eccentricity_scale([run], joint)
    e = scale(run.series(f"joints/{joint}/eccentricity"))
    mode = np.asarray(run.series(f"joints/{joint}/mode"), dtype=int)
    segments = np.stack([e[:-1], e[1:]], axis=1)
    colours = [MODE_COLOURS[m] if 0 <= m < 3 else "grey" for m in mode[:-1]]
    ax.add_collection(LineCollection(segments, colors=colours, linewidths=0.9, gid=PATH_GID))
    ax.plot(*e[0], marker="o", color="black", markersize=4, linestyle="none", label="start")
    clearance = run.clearances.get(joint)
    if clearance is not None:
        ax.add_patch(Circle((0.0, 0.0), scale(clearance), fill=False, linestyle="--", color="black", linewidth=1.0))
    extent = 1.12 * max(float(np.max(np.abs(e))) if e.size else 0.0, scale(clearance or 0.0), 1e-30)
    ax.set_xlim(-extent, extent)
    ax.set_ylim(-extent, extent)
    ax.set_aspect("equal")
    ax.set_xlabel(scale.label("$e_x$"))
    ax.set_ylabel(scale.label("$e_y$"))
    c_text = f"c = {scale(clearance):.3g} {scale.unit}" if clearance is not None else "clearance unknown"
    ax.set_title(c_text if not run.label else run.label if "clearance" in run.label else f"{run.label}: {c_text}")
    return ax


def mode_legend(figure, with_circle: bool = True, shaded: bool = True) -> None:
    """One legend under the figure: mode colours (path segments and shaded bands), start, circle."""
    handles = mode_handles() + [Line2D([], [], marker="o", color="black", linestyle="none", markersize=4,
                                       label="start")]
    if with_circle:
        handles.append(Line2D([], [], color="black", linestyle="--", label="clearance circle"))
    figure.legend(handles=handles, loc="outside lower center", ncol=len(handles), fontsize=8,
                  title="contact mode: path colour" + (" and shaded band" if shaded else ""), title_fontsize=8)


def shade_modes(run: RunData, joint: str, ax) -> None:
    """Background bands by contact mode (impact and contact; free flight stays white)."""
    time = TIME(run.time)
    mode = np.asarray(run.series(f"joints/{joint}/mode"), dtype=int)
    for value in (1, 2):
        ax.fill_between(time, 0.0, 1.0, where=mode == value, transform=ax.get_xaxis_transform(),
                        color=MODE_COLOURS[value], alpha=0.12, linewidth=0.0, step="mid")


def _plot_joint_series(runs: list[RunData], joint: str, name: str, scale, ax):
    series = [run.series(f"joints/{joint}/{name}") for run in runs]
    if name == "penetration":
        series = [np.maximum(values, 0.0) for values in series]
    peaks = [float(np.max(np.abs(values), initial=0.0)) for values in series]
    for run, values, style in zip(runs, series, overlay_styles(runs, peaks)):
        ax.plot(TIME(run.time), scale(values), label=run.label or run.name, **style)
    ax.set_xlabel(TIME.label("time"))
    return ax


def _plot_force(runs: list[RunData], joint: str, dataset: str, label: str, ax):
    ax = axes_or_new(ax)
    scale = force_scale(np.concatenate([run.series(f"joints/{joint}/{dataset}") for run in runs]))
    _plot_joint_series(runs, joint, dataset, scale, ax)
    ax.set_ylabel(scale.label(label))
    return ax


FILM_GID = "film-force"  # lets tests and callers find the drawn film forces


def film_force_magnitude(run: RunData, joint: str) -> np.ndarray:
    """|F| of a lubricated joint's oil film force on the journal (`/joints/<j>/film_force`, 0 while dry)."""
    return np.hypot(*run.series(f"joints/{joint}/film_force").T)


def plot_contact_forces(runs: list[RunData], joint: str, ax=None):
    """Normal force F_n (≥ 0, on the journal along −n) against time; for a lubricated joint also its oil film
    force |F_film| (dotted), which acts while F_n is zero (docs/model-contact.md, lubricated joints)."""
    ax = axes_or_new(ax)
    lubricated = [run for run in runs if run.has(f"joints/{joint}/film_force")]
    films = [film_force_magnitude(run, joint) for run in lubricated]
    scale = force_scale(np.concatenate([run.series(f"joints/{joint}/normal_force") for run in runs] + films))
    _plot_joint_series(runs, joint, "normal_force", scale, ax)
    peaks = [float(np.max(values, initial=0.0)) for values in films]
    for run, values, style in zip(lubricated, films, overlay_styles(lubricated, peaks)):
        ax.plot(TIME(run.time), scale(values), label=f"{run.label or run.name}: oil film", gid=FILM_GID,
                **style | {"linestyle": ":"})
    if lubricated and len(runs) == 1:
        ax.legend(["dry contact $F_n$", "oil film $|F_{film}|$"], fontsize=8, loc="upper right")
    ax.set_ylabel(scale.label("normal force $F_n$" + (", film $|F_{film}|$" if lubricated else "")))
    return ax


def plot_friction_force(runs: list[RunData], joint: str, ax=None):
    """Friction force F_t (signed, on the journal along +t) against time."""
    return _plot_force(runs, joint, "friction_force", "friction force $F_t$", ax)


def plot_penetration(runs: list[RunData], joint: str, ax=None, scale=None):
    """Penetration δ = |e| − c where positive (in contact); 0 in free flight; in `scale` (default: from δ)."""
    ax = axes_or_new(ax)
    values = np.concatenate([np.maximum(run.series(f"joints/{joint}/penetration"), 0.0) for run in runs])
    scale = scale or length_scale([max(float(np.max(values, initial=0.0)), 1e-9)])
    _plot_joint_series(runs, joint, "penetration", scale, ax)
    ax.set_ylabel(scale.label(r"penetration $\delta$"))
    ax.set_ylim(bottom=0.0)
    return ax


def _has_friction(runs: list[RunData], joint: str) -> bool:
    return any(np.any(run.series(f"joints/{joint}/friction_force")) for run in runs)


def _time_panels(runs: list[RunData], joint: str, axes, length) -> None:
    plot_contact_forces(runs, joint, axes[0])
    if len(axes) == 3:
        plot_friction_force(runs, joint, axes[1])
    plot_penetration(runs, joint, axes[-1], length)
    for ax in axes[:-1]:
        ax.set_xlabel("")
        ax.tick_params(labelbottom=False)
    if len(runs) == 1:
        for ax in axes:
            shade_modes(runs[0], joint, ax)
    else:
        legend_beside(axes[0])


def _joint_layout(paths: int, rows: int, interactive: bool):
    """(figure, path axes, time axes): one path beside the time panels, or a row of paths above them (and the
    legend of the runs beside the time panels)."""
    if paths == 1:
        figure = new_figure((10.0, 6.0), interactive)
        grid = figure.add_gridspec(rows, 2, width_ratios=(1.0, 1.25))
        return figure, [figure.add_subplot(grid[:, 0])], [figure.add_subplot(grid[row, 1]) for row in range(rows)]
    figure = new_figure((max(9.0, 3.0 * paths) + LEGEND_WIDTH, 10.0), interactive)
    grid = figure.add_gridspec(rows + 1, paths, height_ratios=(1.6,) + (1.0,) * rows)
    return (figure, [figure.add_subplot(grid[0, k]) for k in range(paths)],
            [figure.add_subplot(grid[row, :]) for row in range(1, rows + 1)])


def joint_figure(runs: list[RunData], joint: str, interactive: bool = False):
    """Path panel(s) and force / penetration histories of one clearance joint."""
    runs = [run for run in runs if joint in run.clearance_joints]
    for run in runs:
        check_joint(run, joint)
    shown = runs[:MAX_PATH_PANELS]
    friction = _has_friction(runs, joint)
    figure, paths, series = _joint_layout(len(shown), 3 if friction else 2, interactive)
    length = _eccentricity_scale(runs, joint)  # one length unit for every panel
    for run, ax in zip(shown, paths):
        plot_journal_path(run, joint, ax, length)
    mode_legend(figure, with_circle=bool(shown[0].clearances.get(joint)), shaded=len(runs) == 1)
    for ax in series[1:]:
        ax.sharex(series[0])
    _time_panels(runs, joint, series, length)
    note = "" if len(runs) <= MAX_PATH_PANELS else f" (paths of the first {MAX_PATH_PANELS} runs)"
    forces = "contact forces" if friction else "normal force (no friction)"
    set_title(figure, f"{title_of(runs[0])}\nclearance joint {joint}: journal centre relative to the bearing, "
                      f"{forces} on the journal, penetration{note}")
    return figure
