"""The mechanism moving: a GIF (matplotlib's PillowWriter, no ffmpeg) of a result file.

Body poses come from /bodies/<b>/q, the drawing from the mechanism stored in the file. Journal
offsets are at true scale unless magnified (`exaggerate`): each clearance joint then shows its
clearance circle and the journal centre, both scaled by the same factor, coloured by contact
mode. "auto" scales the largest journal offset of the run (the clearance, or more: under load the
journal penetrates the bearing wall) to 2.5 % of the drawing's size.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from clearsim.plot.data import PlotInputError, RunData
from clearsim.plot.draw import detail_groups, group_box
from clearsim.plot.drawing import Gauge, draw_mechanism, drawing_size
from clearsim.plot.geometry import Geometry, extent, mechanism_geometry, to_global
from clearsim.plot.scales import TIME
from clearsim.plot.style import new_figure

FRAMES = 48  # few frames: a GIF is written in seconds and stays small
FRAMES_PER_SECOND = 12
AUTO_GAUGE = 0.025  # magnified largest journal offset, of the drawing's size
DPI = 72
PANEL_HEIGHT = 4.6  # inches, when there are detail panels
SINGLE_WIDTH = 6.5  # inches of drawing for a mechanism without detail panels
PANEL_MARGIN = 0.35  # inches between panels


def _poses(run: RunData, geometry: Geometry, sample: int) -> dict:
    poses = {}
    for body in geometry.bodies:
        q = run.series(f"bodies/{body}/q", "the animation")[sample]
        poses[body] = (q[:2], float(q[2]))
    return poses


def parse_exaggerate(text) -> str | float | None:
    """--exaggerate: None, "auto", or a positive factor."""
    if text is None:
        return None
    if str(text).strip().lower() == "auto":
        return "auto"
    try:
        factor = float(text)
    except ValueError:
        raise PlotInputError(f"--exaggerate {text!r}: expected a factor (e.g. 1000) or 'auto'") from None
    if not math.isfinite(factor) or factor <= 0.0:
        raise PlotInputError(f"--exaggerate {text!r}: the factor must be positive")
    return factor


def largest_offset(run: RunData) -> float:
    """max over the clearance joints of max(c, max |e|) in the run (m); 0 without clearance joints."""
    offsets = [0.0]
    for joint in run.clearance_joints:
        e = run.series(f"joints/{joint}/eccentricity", "the animation")
        offsets += [run.clearances.get(joint, 0.0), float(np.max(np.hypot(*e.T), initial=0.0))]
    return max(offsets)


def magnification(geometry: Geometry, poses: dict, exaggerate, offset: float) -> float | None:
    """The gauge scale factor (from parse_exaggerate's value), or None for no gauges."""
    exaggerate = parse_exaggerate(exaggerate)
    if exaggerate is None or offset <= 0.0:
        return None
    if exaggerate == "auto":
        return AUTO_GAUGE * drawing_size(geometry, poses) / offset
    return float(exaggerate)


def _gauges(run: RunData, geometry: Geometry, sample: int, factor: float | None) -> dict:
    if factor is None:
        return {}
    gauges = {}
    for mark in geometry.joints:
        if mark.clearance and mark.name in run.clearance_joints:
            e = run.series(f"joints/{mark.name}/eccentricity", "the animation")[sample]
            mode = int(run.series(f"joints/{mark.name}/mode", "the animation")[sample])
            gauges[mark.name] = Gauge(tuple(e), mode, factor)
    return gauges


def _panels(run: RunData, geometry: Geometry, samples: np.ndarray) -> list[tuple]:
    """(lower-left, upper-right, title) of the whole view and of each detail group, over all frames."""
    poses_list = [_poses(run, geometry, k) for k in samples]
    corners = np.array([extent(geometry, poses) for poses in poses_list])
    low, high = corners[:, 0].min(axis=0), corners[:, 1].max(axis=0)
    margin = 0.08 * np.max(high - low)
    size = drawing_size(geometry, poses_list[0])
    panels = [(low - margin, high + margin, "")]
    for names in detail_groups(geometry, poses_list[0]):
        panels.append((*group_box(geometry, poses_list, names, size), f"joints {', '.join(names)}"))
    return panels


def _figure(panels: list[tuple]):
    """Panels side by side at a common height, each as wide as its box's aspect needs."""
    ratios = [float(np.clip((high[0] - low[0]) / (high[1] - low[1]), 0.25, 3.0)) for low, high, _ in panels]
    height = PANEL_HEIGHT if len(panels) > 1 else float(np.clip(SINGLE_WIDTH / ratios[0], 2.5, 7.0))
    width = height * sum(ratios) + PANEL_MARGIN * len(panels)
    figure = new_figure((width, height + 1.1), layout=None)  # a fixed layout: frames must not jitter
    figure.subplots_adjust(left=0.9 / width, right=1 - 0.15 / width, bottom=0.55 / (height + 1.1),
                           top=1 - 0.55 / (height + 1.1), wspace=PANEL_MARGIN * len(panels) / width)
    axes = figure.subplots(1, len(panels), width_ratios=ratios, squeeze=False)[0]
    return figure, list(axes)


def _joint_names(ax, geometry: Geometry, poses: dict, low, high) -> None:
    """Joint names up-right of the joint, up-left near the right edge (so they stay inside)."""
    for mark in geometry.joints:
        if mark.kind != "revolute":
            continue
        at = to_global(poses, mark.body, mark.point)
        right = at[0] > low[0] + 0.8 * (high[0] - low[0])
        ax.annotate(mark.name, tuple(at), xytext=(-5 if right else 5, 4), textcoords="offset points",
                    ha="right" if right else "left", fontsize=7, fontweight="bold", zorder=10, annotation_clip=True)


def _frame(axes, run: RunData, geometry: Geometry, sample: int, factor, panels) -> None:
    poses = _poses(run, geometry, sample)
    gauges = _gauges(run, geometry, sample, factor)
    for ax, (low, high, title) in zip(axes, panels):
        ax.cla()
        draw_mechanism(ax, geometry, poses, labels=False, gauges=gauges)
        _joint_names(ax, geometry, poses, low, high)
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x (m)")
        ax.set_title(title, fontsize=8)
    axes[0].set_ylabel("y (m)")
    note = f", journal offsets magnified ×{factor:,.0f}" if factor else ""
    axes[0].figure.suptitle(f"{geometry.name}\nt = {TIME(run.time[sample]):6.2f} ms{note}", fontsize=9)


def check_animation(run: RunData) -> None:
    """PlotInputError unless the run has what its animation needs: its mechanism and every body's q."""
    if run.mechanism is None:
        raise PlotInputError(f"{run.path}: the mechanism stored in the file cannot be loaded, so it cannot be drawn")
    for body in run.mechanism.bodies:
        run.require(f"bodies/{body.name}/q", "the animation")


def animate_run(run: RunData, path: Path, exaggerate=None) -> Path:
    """Write the run's animation to `path` (GIF); the file appears only once complete."""
    from matplotlib.animation import PillowWriter

    check_animation(run)
    geometry = mechanism_geometry(run.mechanism)
    samples = np.unique(np.linspace(0, len(run.time) - 1, FRAMES).round().astype(int))
    panels = _panels(run, geometry, samples)
    factor = magnification(geometry, _poses(run, geometry, 0), exaggerate, largest_offset(run))
    figure, axes = _figure(panels)
    partial = path.with_name(f"{path.stem}.partial{path.suffix}")
    writer = PillowWriter(fps=FRAMES_PER_SECOND)
    try:
        with writer.saving(figure, str(partial), dpi=DPI):
            for sample in samples:
                _frame(axes, run, geometry, int(sample), factor, panels)
                writer.grab_frame()
        partial.replace(path)
    finally:
        partial.unlink(missing_ok=True)
    return path
