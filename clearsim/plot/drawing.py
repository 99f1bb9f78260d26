"""Drawing a mechanism at a state: bodies, slider blocks, guides, pivots, joints and names.

Colours follow the order of the bodies in the file. Clearance joints are drawn with a red
ring. `gauges` adds, at each clearance joint, the clearance circle magnified to a visible
size with the journal centre inside it at the same magnification (the true offsets of a
0.01 mm clearance are far below a pixel).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.colors import to_rgba
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Polygon

from clearsim.plot.geometry import GROUND, Geometry, extent, to_global
from clearsim.plot.labelling import place_labels
from clearsim.plot.style import MODE_COLOURS, RUN_COLOURS

GUIDE_HALF_LENGTH = 0.12  # of the drawing's size, each side of the guide point
BLOCK_SIZE = (0.25, 0.15)  # slider block, length along the guide × width, of the median link length
CLEARANCE_COLOUR = "tab:red"


@dataclass(frozen=True)
class Gauge:
    """A clearance joint's magnified view: eccentricity e (m) and contact mode at this instant."""

    eccentricity: tuple[float, float]
    mode: int
    magnification: float


def body_colour(geometry: Geometry, body: str) -> str:
    return RUN_COLOURS[geometry.bodies.index(body) % len(RUN_COLOURS)]


def drawing_size(geometry: Geometry, poses: dict) -> float:
    low, high = extent(geometry, poses)
    return float(max(np.max(high - low), 1e-6))


def link_length(geometry: Geometry) -> float:
    """Median largest dimension of the bodies' outlines: the scale of slider blocks."""
    sizes = [float(np.max(np.ptp(o, axis=0))) for o in geometry.outlines.values() if len(o) >= 2]
    return float(np.median(sizes)) if sizes else 1.0


def _draw_body(ax, geometry: Geometry, poses: dict, body: str) -> None:
    colour = body_colour(geometry, body)
    outline = to_global(poses, body, geometry.outlines[body])
    if len(outline) >= 3:
        ax.add_patch(Polygon(outline, closed=True, facecolor=to_rgba(colour, 0.22), edgecolor=colour, linewidth=2.5,
                             joinstyle="round", zorder=2))
    elif len(outline) == 2:
        ax.plot(*outline.T, color=colour, linewidth=4.5, solid_capstyle="round", zorder=2)
    if body in geometry.blocks:
        point, axis = geometry.blocks[body]
        centre = to_global(poses, body, point)
        along = to_global(poses, body, np.asarray(point) + axis) - centre
        across = np.array([-along[1], along[0]])
        half = np.array(BLOCK_SIZE) * link_length(geometry) / 2
        corners = [centre + sa * half[0] * along + sb * half[1] * across
                   for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        ax.add_patch(Polygon(corners, closed=True, facecolor=colour, edgecolor="black", linewidth=0.8, zorder=3))
    r, _ = poses[body]
    ax.plot(*r, marker="+", color="black", markersize=6, zorder=5)


def _draw_joint(ax, geometry: Geometry, poses: dict, mark, size: float) -> None:
    location = to_global(poses, mark.body, mark.point)
    if mark.kind == "prismatic":
        frame = poses[mark.body][1] if mark.body != GROUND else 0.0
        c, s = np.cos(frame), np.sin(frame)
        axis = np.array([c * mark.axis[0] - s * mark.axis[1], s * mark.axis[0] + c * mark.axis[1]])
        ends = location + np.outer([-1.0, 1.0], axis) * GUIDE_HALF_LENGTH * size
        ax.plot(*ends.T, color="grey", linestyle="--", linewidth=1.0, zorder=1)
        return
    if mark.grounded:
        ax.plot(*location, marker="^", color="black", markersize=11, markerfacecolor="none", zorder=3)
    edge = CLEARANCE_COLOUR if mark.clearance else "black"
    ax.plot(*location, marker="o", markersize=7 if mark.clearance else 6, markerfacecolor="white",
            markeredgecolor=edge, markeredgewidth=2.0 if mark.clearance else 1.2, zorder=6)


def _draw_gauge(ax, centre, clearance: float, gauge: Gauge) -> None:
    radius = clearance * gauge.magnification
    ax.add_patch(Circle(centre, radius, facecolor=(1.0, 1.0, 1.0, 0.5), edgecolor=CLEARANCE_COLOUR, linestyle="--",
                        linewidth=1.0, zorder=7))
    journal = centre + np.asarray(gauge.eccentricity) * gauge.magnification
    colour = MODE_COLOURS[gauge.mode] if 0 <= gauge.mode < 3 else "grey"
    ax.plot(*journal, marker="o", color=colour, markersize=5, zorder=8)


def draw_mechanism(ax, geometry: Geometry, poses: dict, labels: bool = True, gauges: dict | None = None):
    """Draw the mechanism at `poses` ({body: (r, θ)}); returns the axes."""
    size = drawing_size(geometry, poses)
    for body in geometry.bodies:
        _draw_body(ax, geometry, poses, body)
    for mark in geometry.joints:
        _draw_joint(ax, geometry, poses, mark, size)
        if gauges and mark.name in gauges and mark.clearance:
            _draw_gauge(ax, to_global(poses, mark.body, mark.point), mark.clearance, gauges[mark.name])
    ax.set_aspect("equal", adjustable="datalim")
    if labels:
        place_labels(ax, label_items(geometry, poses))
    return ax


def label_items(geometry: Geometry, poses: dict) -> list[dict]:
    """Text, anchor and style of every joint name and body name."""
    items = []
    for mark in geometry.joints:
        if mark.kind == "revolute":
            items.append({"text": mark.name, "at": to_global(poses, mark.body, mark.point),
                          "style": {"fontweight": "bold", "fontsize": 8}})
    for body in geometry.bodies:
        outline = to_global(poses, body, geometry.outlines[body])
        at = outline.mean(axis=0)
        if body in geometry.blocks:
            at = to_global(poses, body, geometry.blocks[body][0])
        items.append({"text": body.replace("_", " "), "at": at,
                      "style": {"fontsize": 7.5, "fontstyle": "italic", "color": body_colour(geometry, body)}})
    return items


def legend_handles() -> list:
    return [Line2D([], [], marker="o", color="black", markerfacecolor="white", linestyle="none", label="ideal joint"),
            Line2D([], [], marker="o", color=CLEARANCE_COLOUR, markerfacecolor="white", markeredgewidth=2.0,
                   linestyle="none", label="clearance joint"),
            Line2D([], [], marker="^", color="black", markerfacecolor="none", linestyle="none", label="ground pivot"),
            Line2D([], [], color="grey", linestyle="--", label="prismatic guide"),
            Line2D([], [], marker="+", color="black", linestyle="none", label="centre of mass")]
