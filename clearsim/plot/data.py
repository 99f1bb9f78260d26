"""Result files as the figures need them: arrays, units, the mechanism they came from.

Plotting only reads: a file is loaded with `clearsim.io.hdf5.read_result`, its datasets'
`unit` attributes are read alongside, and its stored configuration (`config_yaml`) is parsed
to know the output sensors and each clearance joint's radial clearance. Every problem a user
can fix (a missing file, a file that is not a clearsim result, a dataset a figure needs and
the file lacks) is a `PlotInputError`: one message, exit code 2 in the CLI.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from clearsim.errors import ClearsimError
from clearsim.io.hdf5 import NotAResultFile, read_result

OUTPUT_ROLES = ("displacement", "velocity", "acceleration")
JOINT_DATASETS = ("eccentricity", "mode", "normal_force", "friction_force", "penetration")


class PlotInputError(ClearsimError):
    """A result file, folder or measurement that cannot be plotted; the message says why."""


@dataclass
class RunData:
    """One result file: datasets by HDF5 path (SI), their units, and what its YAML says."""

    path: Path
    attrs: dict
    datasets: dict
    units: dict
    mechanism: object | None  # clearsim.model.schema.Mechanism, None when the stored YAML does not load
    output: dict  # role (displacement/velocity/acceleration) → sensor name
    clearances: dict  # clearance joint → radial clearance c (m)
    label: str = ""
    index: int = 0  # place among overlaid runs: its colour in every figure
    window: slice = field(default_factory=lambda: slice(None))
    notes: list = field(default_factory=list)  # what the user should know about this file (cut short, ...)

    @property
    def name(self) -> str:
        return self.path.stem

    @property
    def time(self) -> np.ndarray:
        return self.series("time")

    @property
    def clearance_joints(self) -> list[str]:
        return [j for j in str(self.attrs.get("clearance_joints", "")).split(",") if j]

    @property
    def complete(self) -> bool:
        return bool(self.attrs.get("complete", False))

    def has(self, key: str) -> bool:
        return key in self.datasets

    def require(self, key: str, purpose: str) -> None:
        if key in self.datasets:
            return
        held = REDUCED_CONTENTS.get(str(self.attrs.get("contents", "all")))
        if held is not None:
            raise PlotInputError(f"{self.path}: holds {held}, no /{key} for {purpose}; run its mechanism with "
                                 "`clearsim run` for every history (the file's config_yaml attribute is the mechanism)")
        raise PlotInputError(f"{self.path}: no dataset /{key} (needed for {purpose}); "
                             "the file may come from an interrupted run or an older clearsim")

    def series(self, key: str, purpose: str = "this figure") -> np.ndarray:
        """A per-sample dataset restricted to the time window."""
        self.require(key, purpose)
        return np.asarray(self.datasets[key])[self.window]

    def unit(self, key: str) -> str:
        return str(self.units.get(key, ""))

    def sensors(self) -> list[str]:
        return [key.split("/", 1)[1] for key in self.datasets if key.startswith("sensors/")]


# what a file with fewer histories than the full layout holds (its `contents` attribute, runner.CONTENTS)
REDUCED_CONTENTS = {
    "summary": "the histories a sweep keeps with --keep summary (no bodies' motion, no ideal joints' reactions)",
    "figures": "the histories a sweep keeps with --keep figures (the sensors, the clearance joints' normal force, "
               "mode and stick flag)",
    "sensors": "the time and the sensors alone (a diagnosis's model run)",
}


def _units(path: Path) -> dict:
    units = {}
    with h5py.File(path, "r") as handle:
        handle.visititems(lambda name, node: units.__setitem__(name, node.attrs.get("unit", ""))
                          if isinstance(node, h5py.Dataset) else None)
    return {key: value.decode() if isinstance(value, bytes) else str(value) for key, value in units.items()}


DAMAGED_HINT = "run it again (`clearsim run`), or plot the other files"


def _read(path: Path) -> tuple[dict, dict]:
    if not path.exists():
        raise PlotInputError(f"no such file: {path}")
    if path.is_dir():
        raise PlotInputError(f"{path} is a folder; give result files or one sweep folder")
    if not h5py.is_hdf5(path):
        raise PlotInputError(f"{path} is not an HDF5 file (clearsim results are written by `clearsim run`)")
    try:
        return read_result(path), _units(path)
    except NotAResultFile as exc:
        hint = (f"it is cut short or damaged: {DAMAGED_HINT}" if "not a readable" in str(exc)
                else "give files written by `clearsim run` or `clearsim sweep`")
        raise PlotInputError(f"{exc}; {hint}") from None
    except (OSError, RuntimeError, KeyError, ValueError) as exc:  # libhdf5 fails on a damaged file as it reads it
        raise PlotInputError(f"{path}: the HDF5 file is damaged and cannot be read ({exc}); {DAMAGED_HINT}") from None


def _per_sample(key: str) -> bool:
    """Datasets with one row per time sample (the tables under joints/<J>/episodes/ have their own length)."""
    parts = key.split("/")
    return parts[0] in ("bodies", "constraints", "drivers", "energy", "sensors") or (parts[0] == "joints" and len(parts) == 3)


def _check_samples(path: Path, attrs: dict, data: dict) -> list[str]:
    """/time is numbers, one per row of every per-sample dataset. A file flagged incomplete (a run cut off between
    two writes) is cut to the rows every dataset has, with a note; a complete file that disagrees is damaged."""
    time = data["time"]
    if not isinstance(time, np.ndarray) or time.ndim != 1 or time.dtype.kind not in "iuf":
        shape = getattr(time, "shape", ())
        raise PlotInputError(f"{path}: dataset /time is not a column of numbers (shape {shape}, "
                             f"type {getattr(time, 'dtype', type(time).__name__)}); the file was not written by clearsim "
                             f"or is damaged: {DAMAGED_HINT}")
    if len(time) < 2:
        raise PlotInputError(f"{path}: dataset /time holds {len(time)} sample(s), too few to plot "
                             f"(status: {attrs.get('status', 'unknown')}); the run stopped before it wrote its "
                             "second sample: run it again")
    lengths = {}
    for key, values in data.items():
        if key == "time" or not _per_sample(key):
            continue
        if not isinstance(values, np.ndarray) or values.ndim == 0 or values.dtype.kind not in "iufb":
            raise PlotInputError(f"{path}: dataset /{key} is not an array of numbers "
                                 f"(type {getattr(values, 'dtype', type(values).__name__)}); the file is damaged: "
                                 f"{DAMAGED_HINT}")
        lengths[key] = len(values)
    shortest = min([len(time), *lengths.values()])
    if shortest == len(time) and all(n == len(time) for n in lengths.values()):
        return []
    key = next((k for k, n in lengths.items() if n != len(time)), "time")
    if bool(attrs.get("complete", False)):
        raise PlotInputError(f"{path}: dataset /{key} has {lengths.get(key, len(time))} samples, /time has "
                             f"{len(time)}; the file says it is complete but is damaged: {DAMAGED_HINT}")
    if shortest < 2:
        raise PlotInputError(f"{path}: dataset /{key} holds {lengths.get(key, len(time))} sample(s), too few to plot; "
                             f"the run was cut off ({attrs.get('status', 'unknown')}): run it again")
    for k in ["time", *lengths]:
        data[k] = data[k][:shortest]
    return [f"{path}: the datasets of this incomplete file end at different samples (/{key} has "
            f"{lengths.get(key, len(time))}, /time {len(time)}): plotted the first {shortest}"]


def _mechanism(config_yaml: str, path: Path):
    """The stored mechanism, or None when this clearsim cannot load it (clearances then unknown)."""
    from clearsim.model.loader import load_stored_mechanism

    try:
        return load_stored_mechanism(config_yaml, name=f"{path} (config_yaml)").mechanism
    except ClearsimError:
        return None


def _clearances(mechanism, joints: list[str]) -> dict:
    from clearsim.model.resolve import ResolveError, resolve_clearance

    if mechanism is None:
        return {}
    clearances = {}
    for joint in mechanism.joints:
        if joint.name not in joints:
            continue
        try:
            parameters = resolve_clearance(joint, mechanism.defaults)
        except ResolveError:
            continue
        if parameters is not None:
            clearances[joint.name] = parameters.clearance
    return clearances


def _output(mechanism, data: dict) -> dict:
    declared = {}
    if mechanism is not None:
        declared = {role: getattr(mechanism.output, role) for role in OUTPUT_ROLES}
    return {role: name for role, name in declared.items() if name and f"sensors/{name}" in data}


def load_run(path: Path | str) -> RunData:
    """Read a result file; PlotInputError when it is missing, not HDF5 or not a clearsim result."""
    path = Path(path)
    data, units = _read(path)
    attrs = data.pop("attrs")
    if "time" not in data:
        raise PlotInputError(f"{path}: no dataset /time; the run wrote no samples")
    notes = _check_samples(path, attrs, data)
    mechanism = _mechanism(str(attrs.get("config_yaml", "")), path)
    if mechanism is None:
        notes.append(f"{path}: its stored mechanism (config_yaml) cannot be read: no output sensors or clearance "
                     "circles are known, all sensors are drawn")
    run = RunData(path, attrs, data, units, mechanism, _output(mechanism, data), {}, notes=notes)
    run.clearances = _clearances(mechanism, run.clearance_joints)
    return run


def parse_time_window(text: str | None) -> tuple[float, float] | None:
    """"a:b" → (a, b) in s; numbers are ms, a unit may be written ("10ms:0.02s"); either end may be empty."""
    if not text:
        return None
    from clearsim.units import UnitError, to_si

    parts = text.split(":")
    if len(parts) != 2:
        raise PlotInputError(f"--time-window {text!r}: expected start:end in ms, e.g. 10:20 or 10ms:20ms")
    bounds = []
    for part, default in zip(parts, (-np.inf, np.inf)):
        part = part.strip()
        try:
            bounds.append(default if not part else float(part) * 1e-3 if _is_number(part) else to_si(part, "time"))
        except UnitError as exc:
            raise PlotInputError(f"--time-window {text!r}: {exc}") from None
    if any(np.isnan(bounds)) or any(np.isinf(b) for b, part in zip(bounds, parts) if part.strip()):
        raise PlotInputError(f"--time-window {text!r}: expected finite times, e.g. 10:20 (ms) or 10ms:20ms; "
                             "leave an end empty for the start or end of the run")
    if bounds[0] >= bounds[1]:
        raise PlotInputError(f"--time-window {text!r}: the start must come before the end")
    return bounds[0], bounds[1]


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def apply_window(run: RunData, window: tuple[float, float] | None) -> None:
    """Restrict every per-sample series of the run to t in [start, end]."""
    if window is None:
        return
    time = np.asarray(run.datasets["time"])
    inside = np.flatnonzero((time >= window[0]) & (time <= window[1]))
    if inside.size < 2:
        raise PlotInputError(f"{run.path}: fewer than two samples in the time window "
                             f"{window[0] * 1e3:g}:{window[1] * 1e3:g} ms (the run covers "
                             f"{time[0] * 1e3:g} to {time[-1] * 1e3:g} ms)")
    run.window = slice(int(inside[0]), int(inside[-1]) + 1)


def signals(run: RunData, chosen: list[str]) -> list[str]:
    """The sensors to draw: the chosen ones (each must exist), else the output sensors, else all (≤ 4)."""
    available = run.sensors()
    for name in chosen:
        if name not in available:
            from clearsim.errors import did_you_mean

            raise PlotInputError(f"{run.path}: no sensor '{name}'{did_you_mean(name, available)} "
                                 f"(sensors in the file: {', '.join(available) or 'none'})")
    if chosen:
        return list(chosen)
    declared = [run.output[role] for role in OUTPUT_ROLES if role in run.output]
    return declared or available[:4]


def check_joint(run: RunData, joint: str) -> None:
    for name in JOINT_DATASETS:
        run.require(f"joints/{joint}/{name}", f"the figures of clearance joint {joint}")
