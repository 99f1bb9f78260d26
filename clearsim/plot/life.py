"""The pages of a life file (`clearsim life`; docs/life.md "Figures"): the worn bores in polar form, the clearance
growth against operations, and the drift of the travel figures and peaks."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np

from clearsim.plot.style import RUN_COLOURS, new_figure
from clearsim.travel import FIGURE_ROWS

PROFILES_SHOWN = 5  # rows drawn per joint: the first, the last and three between, evenly in operations
FIGURE_LABELS = {"peak_acceleration_m_s2": ("peak |output acceleration|", 1.0, "m/s²")}


def shown_rows(operations: np.ndarray, count: int = PROFILES_SHOWN) -> list[int]:
    """Row indices whose operations lie nearest to `count` evenly spaced values from the first to the last."""
    targets = np.linspace(operations[0], operations[-1], count)
    return sorted({int(np.argmin(np.abs(operations - target))) for target in targets})


def _figure_label(name: str) -> tuple[str, float, str]:
    if name in FIGURE_LABELS:
        return FIGURE_LABELS[name]
    if name in FIGURE_ROWS:
        return FIGURE_ROWS[name]
    if name.startswith("peak_contact_force_"):
        return f"joint {name.removeprefix('peak_contact_force_').removesuffix('_N')}: max contact force", 1e-3, "kN"
    return name, 1.0, ""


def wear_figure(file: h5py.File, interactive: bool = False):
    """Each wearing joint's worn depth over the bore (polar, µm, angle in the bearing body's frame)."""
    joints = list(json.loads(file.attrs["clearances_m"]))
    figure = new_figure((4.2 * len(joints), 4.4), interactive)
    operations = file["operations"][()]
    angles = file["angle"][()]
    closed = np.append(angles, angles[0])
    for index, joint in enumerate(joints):
        ax = figure.add_subplot(1, len(joints), index + 1, projection="polar")
        depth = file[f"joints/{joint}/depth"][()]
        for colour, row in zip(RUN_COLOURS, shown_rows(operations)):
            ax.plot(closed, np.append(depth[row], depth[row][0]) * 1e6, color=colour,
                    label=f"{operations[row]:,} operations")
        ax.set_title(f"joint {joint}: worn depth (µm)")
        ax.legend(loc="lower left", bbox_to_anchor=(-0.1, -0.25), fontsize=7)
    return figure


def clearance_figure(file: h5py.File, interactive: bool = False):
    """The largest local clearance of each wearing joint against operations (a marker per kept block)."""
    figure = new_figure((6.4, 3.8), interactive)
    ax = figure.add_subplot(1, 1, 1)
    operations = file["operations"][()]
    for colour, joint in zip(RUN_COLOURS, json.loads(file.attrs["clearances_m"])):
        ax.plot(operations, file[f"joints/{joint}/clearance"][()] * 1e3, marker="o", markersize=3, color=colour,
                label=f"joint {joint}")
    ax.set_xlabel("operations")
    ax.set_ylabel("largest clearance (mm)")
    ax.set_title("clearance growth")
    ax.legend()
    return figure


def drift_figure(file: h5py.File, interactive: bool = False):
    """Each recorded figure of the operation at every kept block against operations."""
    names = [name for name in file.get("figures", {}) if np.isfinite(file[f"figures/{name}"][()]).any()]
    columns = 2
    rows = max(1, -(-len(names) // columns))
    figure = new_figure((5.0 * columns, 2.4 * rows), interactive)
    operations = file["operations"][()]
    for index, name in enumerate(names):
        label, scale, unit = _figure_label(name)
        ax = figure.add_subplot(rows, columns, index + 1)
        ax.plot(operations, file[f"figures/{name}"][()] * scale, marker="o", markersize=3)
        ax.set_title(label)
        ax.set_ylabel(unit)
        ax.set_xlabel("operations")
    return figure


def life_figures(path: Path, interactive: bool = False) -> dict:
    """{page name: figure} of a life file."""
    with h5py.File(path, "r") as file:
        return {"wear": wear_figure(file, interactive), "clearance": clearance_figure(file, interactive),
                "drift": drift_figure(file, interactive)}
