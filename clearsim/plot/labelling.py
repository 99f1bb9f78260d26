"""Names next to what they name, without overlapping each other or the drawing.

Each label tries a ring of offsets around its anchor (nearest first) and takes the first one
whose box, in display coordinates after layout, is inside the axes and clear of the labels
already placed and of the drawn lines and markers. A label with no free place keeps the
first offset: a crowded drawing is then visible as such rather than silently losing a name.
"""

from __future__ import annotations

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.transforms import Bbox

RINGS = (7.0, 16.0, 28.0)  # points from the anchor
DIRECTIONS = ((1, 1), (1, -1), (-1, 1), (-1, -1), (1, 0), (-1, 0), (0, 1), (0, -1))
OBSTACLE_SPACING = 6.0  # pixels between sampled points of the drawn lines
OBSTACLE_HALF = 2.5  # pixels: half size of an obstacle box
SMALL_PATCH = 0.02  # of the axes area: a filled patch smaller than this keeps labels out of its inside


def _alignment(dx: float, dy: float) -> dict:
    ha = "left" if dx > 0 else "right" if dx < 0 else "center"
    va = "bottom" if dy > 0 else "top" if dy < 0 else "center"
    return {"ha": ha, "va": va}


def _display_vertices(artist) -> np.ndarray:
    if isinstance(artist, Line2D):
        return artist.get_transform().transform(artist.get_xydata())
    return artist.get_transform().transform(artist.get_path().vertices)


def _obstacles(ax, renderer) -> list[Bbox]:
    """Boxes along every drawn line and patch edge; a small filled patch (a slider block) as a whole."""
    boxes = []
    area = ax.get_window_extent(renderer)
    for artist in list(ax.lines) + list(ax.patches):
        if artist in ax.patches and artist.get_fill():
            extent = artist.get_window_extent(renderer)
            if extent.width * extent.height < SMALL_PATCH * area.width * area.height:
                boxes.append(extent)
                continue
        boxes.extend(_sample(_display_vertices(artist)))
    return boxes


def _sample(vertices: np.ndarray) -> list[Bbox]:
    boxes = []
    for a, b in zip(vertices[:-1], vertices[1:]):
        count = max(1, int(np.linalg.norm(b - a) / OBSTACLE_SPACING))
        for t in np.linspace(0.0, 1.0, count + 1):
            p = a + t * (b - a)
            boxes.append(Bbox.from_extents(p[0] - OBSTACLE_HALF, p[1] - OBSTACLE_HALF,
                                           p[0] + OBSTACLE_HALF, p[1] + OBSTACLE_HALF))
    if len(vertices) == 1:
        p = vertices[0]
        boxes.append(Bbox.from_extents(p[0] - 4, p[1] - 4, p[0] + 4, p[1] + 4))
    return boxes


def _free(box: Bbox, area: Bbox, taken: list[Bbox]) -> bool:
    if not (area.contains(box.x0, box.y0) and area.contains(box.x1, box.y1)):
        return False
    return not any(box.overlaps(other) for other in taken)


def _try(ax, item: dict, offset, renderer, area: Bbox, taken: list[Bbox]):
    candidate = ax.annotate(item["text"], tuple(item["at"]), xytext=offset, textcoords="offset points",
                            annotation_clip=False, zorder=10, **_alignment(*offset), **item["style"])
    box = candidate.get_window_extent(renderer).expanded(1.05, 1.1)
    if _free(box, area, taken):
        return candidate, box
    candidate.remove()
    return None, None


def _leader(ax, item: dict, text) -> object:
    """The same label with a thin line to its anchor (for labels placed away from it)."""
    offset = text.xyann
    text.remove()
    return ax.annotate(item["text"], tuple(item["at"]), xytext=offset, textcoords="offset points",
                       annotation_clip=False, zorder=10, **_alignment(*offset), **item["style"],
                       arrowprops={"arrowstyle": "-", "color": "grey", "linewidth": 0.6, "shrinkA": 1, "shrinkB": 3})


def _place(ax, item: dict, renderer, area: Bbox, taken: list[Bbox]):
    for ring, radius in enumerate(RINGS):
        for dx, dy in DIRECTIONS:
            text, box = _try(ax, item, (dx * radius, dy * radius), renderer, area, taken)
            if text is not None:
                return (_leader(ax, item, text) if ring else text), box
    text = ax.annotate(item["text"], tuple(item["at"]), xytext=(RINGS[0], RINGS[0]), textcoords="offset points",
                       zorder=10, **_alignment(1, 1), **item["style"])
    return text, text.get_window_extent(renderer)


def place_labels(ax, items: list[dict]) -> list:
    """Annotate each item ({'text', 'at', 'style'}); returns the text artists."""
    figure = ax.figure
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    area = ax.get_window_extent(renderer)
    taken = _obstacles(ax, renderer)
    texts = []
    for item in items:
        text, box = _place(ax, item, renderer, area, taken)
        text.set_in_layout(False)
        taken.append(box)
        texts.append(text)
    return texts
