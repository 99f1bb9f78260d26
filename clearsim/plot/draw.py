"""`clearsim draw`: the mechanism as assembled at t = 0, with the names of bodies and joints.

A mechanism whose joints sit in a few far-apart groups (the UHV breaker: the drive at the
bottom, the contact 2.5 m higher up, joined by a long insulating pole) gets a detail panel per
group next to the whole view, so that the names stay readable.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.patches import Rectangle

from clearsim.io.files import same_file
from clearsim.plot.drawing import draw_mechanism, drawing_size, label_items, legend_handles
from clearsim.plot.geometry import Geometry, extent, mechanism_geometry, to_global
from clearsim.plot.labelling import place_labels
from clearsim.plot.style import DPI, new_figure, set_title, show_all

GROUP_DISTANCE = 0.15  # of the drawing's size: joints closer than this belong to one group
DETAIL_SIZE = 0.4  # a group smaller than this fraction of the drawing gets a detail panel
MAX_DETAILS = 3


def joint_groups(points: np.ndarray, size: float) -> list[np.ndarray]:
    """Single-linkage groups of points closer than GROUP_DISTANCE × size (indices, largest first)."""
    parent = list(range(len(points)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(len(points)):
        for j in range(i + 1, len(points)):
            if np.linalg.norm(points[i] - points[j]) < GROUP_DISTANCE * size:
                parent[root(i)] = root(j)
    groups: dict = {}
    for i in range(len(points)):
        groups.setdefault(root(i), []).append(i)
    return sorted((np.array(g) for g in groups.values()), key=len, reverse=True)


def detail_groups(geometry: Geometry, poses: dict) -> list[list[str]]:
    """Names of the revolute joints of each group that deserves a detail panel (none if one group)."""
    marks = [m for m in geometry.joints if m.kind == "revolute"]
    if len(marks) < 4:
        return []
    points = np.array([to_global(poses, m.body, m.point) for m in marks])
    size = drawing_size(geometry, poses)
    groups = joint_groups(points, size)
    chosen = [g for g in groups if len(g) >= 3 and np.max(np.ptp(points[g], axis=0)) < DETAIL_SIZE * size]
    return [[marks[i].name for i in g] for g in chosen[:MAX_DETAILS]] if len(groups) > 1 else []


def group_box(geometry: Geometry, poses_list: list[dict], names: list[str], size: float):
    """(lower-left, upper-right) around the named joints at every one of the poses, with a margin."""
    marks = [m for m in geometry.joints if m.name in names]
    points = np.array([to_global(poses, m.body, m.point) for poses in poses_list for m in marks])
    low, high = points.min(axis=0), points.max(axis=0)
    margin = 0.25 * max(float(np.max(high - low)), 0.05 * size)
    return low - margin, high + margin


def detail_boxes(geometry: Geometry, poses: dict) -> list[tuple[np.ndarray, np.ndarray, list[str]]]:
    """(lower-left, upper-right, joint names) of each group that deserves a detail panel."""
    size = drawing_size(geometry, poses)
    return [(*group_box(geometry, [poses], names, size), names) for names in detail_groups(geometry, poses)]


def _inside(point, box) -> bool:
    return bool(np.all(point >= box[0]) and np.all(point <= box[1]))


def _zoom(ax, low, high) -> None:
    """Show the box, letting the equal aspect widen one direction (fixed limits would fight it)."""
    ax.dataLim.set_points(np.array([low, high], dtype=float))
    ax.autoscale_view(tight=True)


def _figure(geometry: Geometry, poses: dict, details: list, interactive: bool):
    if not details:
        low, high = extent(geometry, poses)
        aspect = float(np.clip((high[1] - low[1] + 1e-9) / (high[0] - low[0] + 1e-9), 0.45, 1.3))
        figure = new_figure((8.5, 8.5 * aspect + 1.6), interactive)
        return figure, [figure.add_subplot()]
    figure = new_figure((4.2 + 4.0 * len(details), 8.0), interactive)
    axes = figure.subplots(1, 1 + len(details), width_ratios=[0.75] + [1.0] * len(details))
    return figure, list(axes)


def draw_figure(mechanism, body_names: list[str], q0: np.ndarray, subtitle: str = "", interactive: bool = False):
    """The drawing of a mechanism at the state q0 (bodies in the order of `body_names`)."""
    geometry = mechanism_geometry(mechanism)
    q = np.asarray(q0, float).reshape(-1, 3)
    poses = {name: (q[k, :2], float(q[k, 2])) for k, name in enumerate(body_names)}
    details = detail_boxes(geometry, poses)
    figure, axes = _figure(geometry, poses, details, interactive)
    for ax in axes:
        draw_mechanism(ax, geometry, poses, labels=False)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    for k, (low, high, names) in enumerate(details):
        axes[0].add_patch(Rectangle(low, *(high - low), fill=False, linestyle=":", color="grey"))
        _zoom(axes[k + 1], low, high)
        axes[k + 1].set_title(f"detail: joints {', '.join(names)}")
    axes[0].set_title("whole mechanism" if details else "")
    items = label_items(geometry, poses)
    place_labels(axes[0], [i for i in items if not any(_inside(i["at"], box) for box in details)])
    for ax, box in zip(axes[1:], details):
        place_labels(ax, [i for i in items if _inside(i["at"], box)])
    figure.legend(handles=legend_handles(), loc="outside lower center", ncol=5)
    set_title(figure, f"{mechanism.name}\n{subtitle}" if subtitle else mechanism.name)
    return figure


SAME_FORMAT = {"jpg": "jpeg", "tif": "tiff"}  # two names of one format


def writable_formats() -> list[str]:
    """The file formats matplotlib writes here (those of its Agg canvas: png, svg, pdf, jpg, …)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    return sorted(FigureCanvasAgg(Figure()).get_supported_filetypes())


def _check_figure_path(out: Path, config: Path, formats: list[str]) -> None:
    """A drawing replaces an earlier figure, never a folder, the mechanism file or another file that is no figure."""
    from clearsim.plot.data import PlotInputError

    hint = f"hint: give a figure file such as -o {out.with_suffix('.png').name if out.name else 'drawing.png'}"
    if out.is_dir():
        raise PlotInputError(f"-o {out}: is a folder, not a figure file\n  hint: name the file in it, "
                             f"e.g. -o {out / 'drawing.png'}")
    if same_file(out, config):
        raise PlotInputError(f"-o {out}: that is the mechanism file being drawn; the figure would overwrite it\n  {hint}")
    if out.exists() and out.suffix.lstrip(".").lower() not in formats:
        raise PlotInputError(f"-o {out}: an existing file that is not a figure ({', '.join(formats)}); "
                             f"the drawing would overwrite it\n  {hint}")


def figure_format(out: Path | None, fmt: str | None, formats: list[str]) -> str:
    """The format to write: the one `-o` names by its extension (`--format`, if given, must agree), else `--format`,
    else png. An extension matplotlib cannot write, or none, is refused: the file would hold another format."""
    from clearsim.plot.data import PlotInputError

    listing = ", ".join(formats)
    if fmt is not None and fmt.lower() not in formats:
        raise PlotInputError(f"--format {fmt!r}: matplotlib writes {listing}")
    if out is None:
        return (fmt or "png").lower()
    suffix = out.suffix.lstrip(".").lower()
    example = out.with_suffix("." + (fmt or "png").lower())
    if suffix not in formats:
        named = f"its extension .{suffix} is no figure format" if suffix else "it has no extension"
        raise PlotInputError(f"-o {out}: {named}; name the format by the extension, one of {listing}\n"
                             f"  hint: -o {example}")
    if fmt is not None and SAME_FORMAT.get(fmt.lower(), fmt.lower()) != SAME_FORMAT.get(suffix, suffix):
        raise PlotInputError(f"-o {out} names the format {suffix} but --format {fmt}: the file would hold {fmt} under "
                             f"another name\n  hint: -o {example}, or leave out --format")
    return suffix


def draw_config(config: Path, overrides=(), out: Path | None = None, fmt: str | None = None,
                interactive: bool = False) -> tuple[Path, list[str]]:
    """Load, assemble and draw a mechanism file; returns the written figure and notes for the user.

    The format is the one the extension of `out` names, else `fmt`, else png (`figure_format`).
    """
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare

    formats = writable_formats()
    if out is not None:
        _check_figure_path(Path(out), Path(config), formats)
    fmt = figure_format(Path(out) if out is not None else None, fmt, formats)
    loaded = load_mechanism(config, overrides)
    system = prepare(loaded)
    clearance = ", ".join(system.clearance_joints) or "none"
    subtitle = (f"assembled at t = 0: {len(system.body_names)} bodies, {len(system.mechanism.joints)} joints, "
                f"{system.degrees_of_freedom} degrees of freedom (clearance joints: {clearance})")
    figure = draw_figure(system.mechanism, list(system.body_names), system.q0, subtitle, interactive)
    path = Path(out) if out is not None else Path("results") / f"{Path(config).stem}-drawing.{fmt}"
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, format=fmt, dpi=DPI)
    note = show_all() if interactive else None
    return path, [note] if note else []
