"""The life file of `clearsim life` (HDF5; docs/life.md "The life file"): a row per kept block, resumable.

    attrs: kind = "clearsim life", config_yaml (the mechanism as run, before wear), operations (the target),
           tolerance, complete, status, next_block_size, joints (the wearing joints), clearances_m (JSON)
    /operations (rows,)          operations done at the row (row 0: the machine new)
    /block_size, /error_ratio, /refused (rows,)   the block that ended at the row
    /angle (720,)                rad, the bore's angle in the bearing body's frame
    /joints/<J>/coefficients (rows, 2M+1)        m, the wear accumulated over the life [a_0, a_1, b_1, …]
    /joints/<J>/wear_per_operation (rows, 2M+1)  m, the wear of the operation simulated at the row
    /joints/<J>/depth (rows, 720)                m, the bore's worn depth at the row (the file's profile + the life's)
    /joints/<J>/clearance (rows,)                m, the largest local clearance: c + max depth
    /figures/<name> (rows,)       the operation's figures at the row: travel figures (SI), peaks
A row is written and flushed as its block is kept; a life stopped (Ctrl-C, a run that cannot continue) keeps its
rows, flagged complete = false with its status, and continues from the last row when started again.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import h5py
import numpy as np

from clearsim.life.blocks import PROFILE_ANGLES, Block, Operation
from clearsim.physics.wear import evaluate_profile

KIND = "clearsim life"
ANGLES = np.linspace(0.0, 2.0 * math.pi, PROFILE_ANGLES, endpoint=False)


def is_life_file(path: Path) -> bool:
    try:
        with h5py.File(path, "r") as file:
            return file.attrs.get("kind") == KIND
    except (OSError, ValueError):
        return False


class LifeFile:
    """Rows appended to an open life file."""

    def __init__(self, path: Path, file: h5py.File):
        self.path, self.file = path, file

    @classmethod
    def create(cls, path: Path, attributes: dict, joints: dict[str, float], harmonics: dict[str, int]) -> "LifeFile":
        file = h5py.File(path, "w")
        file.attrs.update({"kind": KIND, "complete": False, "status": "running", "joints": ",".join(joints),
                           "clearances_m": json.dumps(joints)} | attributes)
        for name in ("operations", "block_size", "refused"):
            file.create_dataset(name, (0,), maxshape=(None,), dtype="i8")
        file.create_dataset("error_ratio", (0,), maxshape=(None,), dtype="f8")
        file.create_dataset("angle", data=ANGLES).attrs["unit"] = "rad"
        for joint in joints:
            width = 2 * harmonics[joint] + 1
            for name in ("coefficients", "wear_per_operation"):
                file.create_dataset(f"joints/{joint}/{name}", (0, width), maxshape=(None, width), dtype="f8").attrs["unit"] = "m"
            file.create_dataset(f"joints/{joint}/depth", (0, PROFILE_ANGLES), maxshape=(None, PROFILE_ANGLES),
                                dtype="f8").attrs["unit"] = "m"
            file.create_dataset(f"joints/{joint}/clearance", (0,), maxshape=(None,), dtype="f8").attrs["unit"] = "m"
        return cls(path, file)

    @classmethod
    def reopen(cls, path: Path) -> "LifeFile":
        return cls(path, h5py.File(path, "r+"))

    def append(self, block: Block, next_block_size: int, initial_depth: dict[str, np.ndarray]) -> None:
        """The kept block as a new row, flushed."""
        file = self.file
        _append(file["operations"], block.operations)
        _append(file["block_size"], block.size)
        _append(file["refused"], block.refused)
        _append(file["error_ratio"], block.error_ratio)
        clearances = json.loads(file.attrs["clearances_m"])
        for joint, clearance in clearances.items():
            depth = initial_depth[joint] + evaluate_profile(block.state[joint], ANGLES)
            _append(file[f"joints/{joint}/coefficients"], block.state[joint])
            _append(file[f"joints/{joint}/wear_per_operation"], block.operation.wear[joint])
            _append(file[f"joints/{joint}/depth"], depth)
            _append(file[f"joints/{joint}/clearance"], clearance + float(depth.max()))
        rows = file["operations"].shape[0]
        for name, value in block.operation.figures.items():
            if f"figures/{name}" not in file:
                file.create_dataset(f"figures/{name}", data=np.full(rows - 1, np.nan), maxshape=(None,), dtype="f8")
            _append(file[f"figures/{name}"], np.nan if value is None else value)
        for name in file["figures"] if "figures" in file else []:
            if file[f"figures/{name}"].shape[0] < rows:
                _append(file[f"figures/{name}"], np.nan)
        file.attrs["next_block_size"] = next_block_size
        file.flush()

    def last_block(self) -> tuple[Block, int] | None:
        """The last row as a block to continue from, and the next block's size (None: no row)."""
        file = self.file
        rows = file["operations"].shape[0]
        if rows == 0:
            return None
        joints = json.loads(file.attrs["clearances_m"])
        state = {joint: file[f"joints/{joint}/coefficients"][rows - 1] for joint in joints}
        wear = {joint: file[f"joints/{joint}/wear_per_operation"][rows - 1] for joint in joints}
        figures = {name: float(file[f"figures/{name}"][rows - 1]) for name in file.get("figures", {})}
        block = Block(int(file["operations"][rows - 1]), int(file["block_size"][rows - 1]), state,
                      Operation(wear, figures), float(file["error_ratio"][rows - 1]), int(file["refused"][rows - 1]))
        return block, int(file.attrs["next_block_size"])

    def finish(self, complete: bool, status: str) -> None:
        self.file.attrs.update({"complete": complete, "status": status})
        self.file.flush()

    def close(self) -> None:
        self.file.close()


def _append(dataset: h5py.Dataset, value) -> None:
    dataset.resize(dataset.shape[0] + 1, axis=0)
    dataset[-1] = value


def life_rows(path: Path) -> list[tuple[str, str]]:
    """(label, value) of a life file's summary: each wearing joint's clearance and deepest wear, new and at the end,
    and the figures' drift (first row → last row)."""
    rows = []
    with h5py.File(path, "r") as file:
        operations = file["operations"][()]
        rows.append(("operations", f"{operations[-1]:,} in {len(operations) - 1} blocks"))
        for joint in json.loads(file.attrs["clearances_m"]):
            clearance = file[f"joints/{joint}/clearance"][()]
            depth = file[f"joints/{joint}/depth"][-1]
            deepest = int(np.argmax(depth))
            rows.append((f"joint {joint}: largest clearance", f"{clearance[0] * 1e3:.4g} → {clearance[-1] * 1e3:.4g} mm"))
            rows.append((f"joint {joint}: deepest wear", f"{depth[deepest] * 1e3:.4g} mm at {np.degrees(ANGLES[deepest]):.0f}° "
                         "(bearing frame)"))
        for name in file.get("figures", {}):
            values = file[f"figures/{name}"][()]
            if np.isfinite(values[0]) and np.isfinite(values[-1]):
                rows.append((name, f"{values[0]:.5g} → {values[-1]:.5g}"))
    return rows
