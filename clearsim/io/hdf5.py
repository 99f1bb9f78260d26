"""Result files in the HDF5 layout of DESIGN.md §6, written as the run goes.

The file is created with `complete = False` and `status = "running"`, every chunk of samples
is appended and flushed, and `finish()` records the final status. A run that is interrupted
or fails therefore leaves a readable file that says it is incomplete and why. An existing
file is never overwritten: it is first renamed to the next free `<stem>.<k>.h5`.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import errno
import shutil
import signal
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from clearsim import __version__
from clearsim.errors import ClearsimError

WRITE_HINT = "check that the folder exists and can be written, or choose another file with -o"


def keep_as_previous(path: Path) -> Path | None:
    """Rename an existing file (a result, a report, a figure) to <stem>.previous<suffix>, or the first free
    <stem>.previous-<k><suffix> (k = 2, 3, …) when earlier ones exist: an older kept file is never overwritten, and
    `clearsim plot` leaves these names out of a folder. Returns the new name (None: nothing was there)."""
    path = Path(path)
    if not path.exists():
        return None
    backup, k = path.with_name(f"{path.stem}.previous{path.suffix}"), 2
    while backup.exists():
        backup, k = path.with_name(f"{path.stem}.previous-{k}{path.suffix}"), k + 1
    path.rename(backup)
    return backup


@contextlib.contextmanager
def interrupts_deferred():
    """Hold Ctrl-C and SIGTERM until the block ends, so a write is never cut in half (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received = []
    previous = {sig: signal.signal(sig, lambda number, frame: received.append(number))
                for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if received:
            raise KeyboardInterrupt


class ResultWriteError(ClearsimError):
    """The result file cannot be written (no such folder, no permission, disk full); says where and why."""

    def __init__(self, path: Path, reason: str, hint: str = WRITE_HINT):
        self.path, self.reason, self.hint = Path(path), reason, hint
        super().__init__(str(self))

    def __str__(self) -> str:
        return f"cannot write the result file {self.path}: {self.reason}. {self.hint}"


def write_failure(path: Path, exc: OSError) -> ResultWriteError:
    """The OSError of a write (Python's or libhdf5's) as a ResultWriteError naming the file."""
    reason = exc.strerror or str(exc)
    if "No space left" in str(exc) or getattr(exc, "errno", None) == errno.ENOSPC:
        return ResultWriteError(path, "the disk is full", "free some space or write elsewhere with -o; the file keeps "
                                "what was written before, flagged incomplete if it could still be closed")
    return ResultWriteError(path, reason)


def check_free_space(path: Path, needed_bytes: float) -> None:
    """Make the folder of `path`; ResultWriteError, before anything is written, when it cannot be made or has less
    free space than needed."""
    folder = Path(path).parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        free = shutil.disk_usage(folder).free
    except OSError as exc:
        raise write_failure(path, exc) from None
    if free < needed_bytes:
        raise ResultWriteError(path, f"the run writes about {needed_bytes / 2**20:.0f} MB and {folder} has "
                               f"{free / 2**20:.0f} MB free",
                               "free some space, write elsewhere with -o, or lower solver.output_rate or solver.t_end")


_WITH_GROUPS = h5py.h5p.create(h5py.h5p.LINK_CREATE)  # a dataset's path creates the groups it names
_WITH_GROUPS.set_create_intermediate_group(True)
_UNIT_TYPE = h5py.h5t.py_create(h5py.string_dtype("utf-8"), logical=True)  # as h5py stores a str attribute


COMPRESSION_LEVEL = 1  # gzip (deflate) after the byte shuffle; docs/model.md §8 measures levels 1, 4, 9 and lzf


def new_dataset(parent: h5py.h5g.GroupID, name: str, values: np.ndarray, unit: str, chunk_rows: int | None = None):
    """What h5py's create_dataset(name, data=values[, chunks, maxshape=(None, …), shuffle=True,
    compression="gzip"]) and attrs["unit"] = unit write, by its low-level API: 3 ms instead of 7.5 ms for the 41
    datasets of a slider-crank run. With chunk_rows, chunked, compressed and growing along the first axis."""
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_obj_track_times(False)  # h5py's default: the same values give the same file
    if chunk_rows is not None:
        dcpl.set_chunk((chunk_rows, *values.shape[1:]))
        dcpl.set_shuffle()
        dcpl.set_deflate(COMPRESSION_LEVEL)
        space = h5py.h5s.create_simple(values.shape, (h5py.h5s.UNLIMITED, *values.shape[1:]))
    else:
        space = h5py.h5s.create_simple(values.shape)
    dataset = h5py.h5d.create(parent, name.encode(), h5py.h5t.py_create(values.dtype, logical=True), space, dcpl=dcpl,
                              lcpl=_WITH_GROUPS)
    if values.size:
        dataset.write(h5py.h5s.ALL, h5py.h5s.ALL, values)
    attribute = h5py.h5a.create(dataset, b"unit", _UNIT_TYPE, h5py.h5s.create(h5py.h5s.SCALAR))
    attribute.write(np.array(unit, dtype=h5py.string_dtype("utf-8")))


class ResultWriter:
    """Append-only writer of one run's result file."""

    def __init__(self, path: Path, config_yaml: str, attributes: dict | None = None):
        self.path = Path(path)
        with interrupts_deferred():  # a Ctrl-C here would leave a file without `complete` and `status`
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self.file = h5py.File(self.path, "w")
            except OSError as exc:
                raise write_failure(self.path, exc) from None
            root = self.file.attrs
            root["clearsim_version"] = __version__
            root["created"] = dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")
            root["config_yaml"] = config_yaml
            root["complete"] = False
            root["status"] = "running"
            for key, value in (attributes or {}).items():
                root[key] = value
            self.file.flush()
        self.rows = 0
        self.created: set[str] = set()

    def _append(self, name: str, values: np.ndarray, unit: str) -> None:
        values = np.ascontiguousarray(values)
        if name not in self.created:  # a set, not `name in self.file`: the lookup by path costs as much as the write
            chunk_rows = max(1, min(1024, 2**20 // max(1, values[0].nbytes if values.ndim > 1 else 8)))
            new_dataset(self.file.id, name, values, unit, chunk_rows)
            self.created.add(name)
            return
        dataset = self.file[name]  # not kept open: an open dataset holds its chunk cache (up to 1 MB) until closed
        start = dataset.shape[0]
        dataset.resize(start + values.shape[0], axis=0)
        dataset[start:] = values

    def append(self, times: np.ndarray, datasets: dict) -> None:
        """Add samples: /time and every `path → (values, unit)`; flushed to disk at once.

        Hold interrupts around the call (`interrupts_deferred`) when a half-written chunk must not happen."""
        self._append("time", times, "s")
        for name, (values, unit) in datasets.items():
            self._append(name, values, unit)
        self.rows += len(times)
        self.file.flush()

    def replace(self, name: str, values: np.ndarray) -> None:
        """Overwrite a whole dataset that was written chunk by chunk (e.g. contact modes once episodes end)."""
        if name in self.file:
            self.file[name][...] = values

    def write_table(self, name: str, columns: dict, attributes: dict | None = None) -> None:
        group = self.file.require_group(name)
        for key, (values, unit) in columns.items():
            if key in group:
                del group[key]
            new_dataset(group.id, key, np.ascontiguousarray(values), unit)
        for key, value in (attributes or {}).items():
            group.attrs[key] = value

    def finish(self, complete: bool, status: str, attributes: dict) -> None:
        root = self.file.attrs
        root["complete"] = bool(complete)
        root["status"] = status
        for key, value in attributes.items():
            root[key] = value
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.file.id.valid:
            try:
                self.file.close()
            except OSError:  # a failed write was already reported (run_to_file); the close fails for the same reason
                pass


class NotAResultFile(ValueError):
    pass


def read_result(path: Path, wanted: Callable[[str], bool] | None = None) -> dict:
    """All datasets (as arrays, floating-point ones as float64) and root attributes of a result file: {'attrs': {...},
    'time': …, 'bodies/x/q': …};
    with `wanted`, only the datasets whose names it accepts (a summary need not hold a long run in memory)."""
    path = Path(path)
    try:
        handle = h5py.File(path, "r")
    except OSError as exc:
        raise NotAResultFile(f"{path} is not a readable HDF5 file ({exc})") from None
    with handle:
        if "clearsim_version" not in handle.attrs:
            raise NotAResultFile(f"{path} is not a clearsim result file (no clearsim_version attribute)")
        out = {"attrs": dict(handle.attrs)}

        def keep(name, node):
            if isinstance(node, h5py.Dataset):
                values = node[()]  # a float32 history is handed on as float64, as older files stored it
                out[name] = values.astype(np.float64) if values.dtype == np.float32 else values

        if wanted is None:
            handle.visititems(keep)
        else:  # by name first: an h5py object for each of the file's groups and datasets costs more than the reading
            handle.visit(lambda name: keep(name, handle[name]) if wanted(name) else None)
        return out


def read_attributes(path: Path) -> dict:
    """The root attributes of a result file, its datasets left unread (NotAResultFile as for read_result)."""
    return read_result(path, lambda name: False)["attrs"]


def group_attribute(path: Path, group: str, name: str, default=None):
    """One attribute of a group of a result file, or `default` when the group or attribute is absent."""
    with h5py.File(path, "r") as handle:
        node = handle.get(group)
        return node.attrs.get(name, default) if node is not None else default


@dataclass
class ResultOverview:
    """What a result file holds, read without its histories: size on disk, samples, rate, what it describes."""

    size_bytes: int
    samples: int
    rate_hz: float | None  # None: fewer than two samples and no `output_rate_hz` attribute (an older file)
    rate_derived: bool  # the rate came from the model's time scales, not from solver.output_rate
    members: dict[str, int]  # group → how many bodies, joints, sensors, … it holds


def result_overview(path: Path) -> ResultOverview:
    """The ResultOverview of a result file (older files without the `output_rate_hz` attribute: the rate from the
    spacing of their first two samples)."""
    path = Path(path)
    with h5py.File(path, "r") as handle:
        time = handle.get("time")
        samples = 0 if time is None else time.shape[0]
        rate = handle.attrs.get("output_rate_hz")
        if rate is None and samples >= 2:
            rate = 1.0 / float(time[1] - time[0])
        members = {group: len(handle[group]) for group in ("bodies", "joints", "sensors") if group in handle}
        derived = handle.attrs.get("output_rate_source") == "derived"
    return ResultOverview(path.stat().st_size, samples, None if rate is None else float(rate), derived, members)
