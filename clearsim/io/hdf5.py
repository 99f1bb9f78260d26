"""Result files in the HDF5 layout of README (docs/reference.md), written as the run goes.

The file is created with `complete = False` and `status = "running"`, every chunk of samples
is appended and flushed, and `finish()` records the final status. A run that is interrupted
or fails therefore leaves a readable file that says it is incomplete and why. Before each append the
writer checks that the disk (and `ulimit -f`) leaves room for it: a write that would fill the disk
stops the run instead, and the file is closed and flagged while there is still room to do so.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import errno
import math
import re
import signal
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from clearsim import __version__
from clearsim.errors import ClearsimError
from clearsim.io.files import Room, keep_as_previous, megabytes, room_for  # noqa: F401 (keep_as_previous: re-exported)

WRITE_HINT = "check that the folder exists and can be written, or choose another file with -o"


_deferring = threading.Event()  # set while a block of the main thread holds interrupts


@contextlib.contextmanager
def interrupts_deferred():
    """Hold Ctrl-C and SIGTERM until the block ends, so a write is never cut in half (main thread only). A block
    inside another one leaves them held until the outer one ends."""
    if threading.current_thread() is not threading.main_thread() or _deferring.is_set():
        yield
        return
    received = []
    previous = {sig: signal.signal(sig, lambda number, frame: received.append(number))
                for sig in (signal.SIGINT, signal.SIGTERM)}
    _deferring.set()
    try:
        yield
    finally:
        _deferring.clear()
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


class NoRoom(OSError):
    """A write refused before it started: the file would outgrow the room left for it (room_for)."""

    def __init__(self, needed: float, room: Room):
        super().__init__(errno.ENOSPC, f"{room.limit}: the next write needs {megabytes(needed)} and {room.left}")


class WriteFailed(OSError):
    """libhdf5 failed to write (its OSError or RuntimeError); the file is left as far as it got."""


FULL_ERRNOS = (errno.ENOSPC, errno.EFBIG, errno.EDQUOT)
FULL_HINT = "free some space (or raise `ulimit -f`), write elsewhere with -o, or lower solver.output_rate or solver.t_end"


def error_number(exc: Exception) -> int | None:
    """The errno of a failed write: Python's, or the one libhdf5 writes into its message ("errno = 28")."""
    if getattr(exc, "errno", None):
        return exc.errno
    found = re.search(r"errno = (\d+)", str(exc))
    return int(found.group(1)) if found else None


def write_failure(path: Path, exc: OSError, needed_bytes: float | None = None) -> ResultWriteError:
    """The OSError of a write (Python's or libhdf5's) as a ResultWriteError naming the file; for a full disk (or a
    file size limit), with the room left and the room the whole run needs (`needed_bytes`)."""
    if isinstance(exc, NoRoom):
        reason = exc.strerror
    elif error_number(exc) in FULL_ERRNOS:
        room = room_for(path)
        reason = f"{room.limit}: {room.left}"
    else:
        return ResultWriteError(path, exc.strerror or str(exc))
    if needed_bytes is not None:
        reason += f" (the whole run needs about {megabytes(needed_bytes)})"
    return ResultWriteError(path, reason, FULL_HINT)


# the most the histories shrink when compressed: 4.2× measured (a 2 ms slider-crank run: 2.21 MB of whole chunks
# uncompressed, a 0.53 MB file), 1.5× on the UHV run's full file; a room below uncompressed / 5 cannot hold the file
BEST_COMPRESSION = 5.0


def check_free_space(path: Path, needed_bytes: float) -> None:
    """Make the folder of `path`; ResultWriteError, before anything is written, when it cannot be made or leaves
    less room than the run's file takes however well it compresses (needed_bytes, uncompressed, over
    BEST_COMPRESSION), in its file system's free space or under the file size limit of `ulimit -f`. A room between
    that and needed_bytes is left to the check before every write (ResultWriter), which keeps what was written."""
    folder = Path(path).parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        room = room_for(path)
    except OSError as exc:
        raise write_failure(path, exc) from None
    if room.bytes < needed_bytes / BEST_COMPRESSION:
        raise ResultWriteError(path, f"the run writes about {megabytes(needed_bytes / BEST_COMPRESSION)} at the "
                               f"least ({megabytes(needed_bytes)} uncompressed) and {room.left}", FULL_HINT)


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


FINISH_BYTES = 2**18  # kept free by every append: what closing a file takes (its status, episode tables, metadata)


CHUNK_ROWS = 1024  # rows per chunk of a growing dataset whose rows are small


def chunk_rows_of(values: np.ndarray) -> int:
    """Rows per chunk of a growing dataset: CHUNK_ROWS, fewer when that would pass ~1 MB a chunk."""
    return max(1, min(CHUNK_ROWS, 2**20 // max(1, values[0].nbytes if values.ndim > 1 else 8)))


def append_bytes(rows_before: int, values: np.ndarray) -> int:
    """The bytes an append of `values` to a chunked dataset of `rows_before` rows allocates: the chunks it starts
    (whole chunks, at the uncompressed size), and an object header when it creates the dataset."""
    chunk_rows = chunk_rows_of(values)
    row_bytes = values[0].nbytes if values.ndim > 1 else values.dtype.itemsize
    new_chunks = math.ceil((rows_before + len(values)) / chunk_rows) - math.ceil(rows_before / chunk_rows)
    return new_chunks * chunk_rows * row_bytes + (4096 if rows_before == 0 else 0)


class ResultWriter:
    """Append-only writer of one run's result file.

    No chunk cache (rdcc_nbytes=0): a failed write raises at the write, not later when libhdf5 evicts or frees a
    dataset (where it could not be caught, and could crash the process). After a failed write (`broken`), the file
    is closed without further writes and `finish` flags it from a fresh handle, if it can still be read."""

    def __init__(self, path: Path, config_yaml: str, attributes: dict | None = None):
        self.path = Path(path)
        self.attributes: dict = {}  # the root attributes written so far, as written
        self.rows = 0
        self.created: set[str] = set()
        self.broken = False
        self.file = None
        with interrupts_deferred():  # a Ctrl-C here would leave a file without `complete` and `status`
            self.path.parent.mkdir(parents=True, exist_ok=True)
            try:
                with self._writing():
                    self.file = h5py.File(self.path, "w", rdcc_nbytes=0)
                    self._set_attributes({
                        "clearsim_version": __version__,
                        "created": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
                        "config_yaml": config_yaml, "complete": False, "status": "running"} | (attributes or {}))
                    self.file.flush()
            except WriteFailed:
                self._close_quietly()
                raise

    @contextlib.contextmanager
    def _writing(self):
        """libhdf5's failures (OSError, RuntimeError) as WriteFailed; the writer writes nothing more after one."""
        if self.broken:
            raise WriteFailed(errno.EIO, "an earlier write to this file failed")
        try:
            yield
        except (OSError, RuntimeError) as exc:
            if isinstance(exc, NoRoom):
                raise
            self.broken = True
            raise WriteFailed(error_number(exc) or errno.EIO, str(exc)) from None

    def _make_room(self, needed: float) -> None:
        room = room_for(self.path)
        if room.bytes < needed + FINISH_BYTES:
            raise NoRoom(needed + FINISH_BYTES, room)

    def _append(self, name: str, values: np.ndarray, unit: str) -> None:
        if name not in self.created:  # a set, not `name in self.file`: the lookup by path costs as much as the write
            new_dataset(self.file.id, name, values, unit, chunk_rows_of(values))
            self.created.add(name)
            return
        dataset = self.file[name]  # not kept open: an open dataset holds its chunk cache (up to 1 MB) until closed
        start = dataset.shape[0]
        dataset.resize(start + values.shape[0], axis=0)
        dataset[start:] = values

    def append(self, times: np.ndarray, datasets: dict) -> None:
        """Add samples: /time and every `path → (values, unit)`; flushed to disk at once. NoRoom, before anything
        is written, when the disk would not keep room to finish the file afterwards.

        Hold interrupts around the call (`interrupts_deferred`) when a half-written chunk must not happen."""
        arrays = {"time": (np.ascontiguousarray(times), "s")} | {
            name: (np.ascontiguousarray(values), unit) for name, (values, unit) in datasets.items()}
        self._make_room(sum(append_bytes(self.rows, values) for values, _ in arrays.values()))
        with self._writing():
            for name, (values, unit) in arrays.items():
                self._append(name, values, unit)
            self.rows += len(times)
            self.file.flush()

    def replace(self, name: str, values: np.ndarray) -> None:
        """Overwrite a whole dataset that was written chunk by chunk (e.g. contact modes once episodes end)."""
        with self._writing():
            if name in self.file:
                self.file[name][...] = values

    def write_table(self, name: str, columns: dict, attributes: dict | None = None) -> None:
        """A group of equally long columns written whole (NoRoom before anything is written, as for `append`)."""
        columns = {key: (np.ascontiguousarray(values), unit) for key, (values, unit) in columns.items()}
        self._make_room(sum(values.nbytes + 4096 for values, _ in columns.values()))
        with self._writing():
            group = self.file.require_group(name)
            for key, (values, unit) in columns.items():
                if key in group:
                    del group[key]
                new_dataset(group.id, key, values, unit)
            for key, value in (attributes or {}).items():
                group.attrs[key] = value

    def finish(self, complete: bool, status: str, attributes: dict) -> bool:
        """Record the final status and close; after a failed write, from a fresh handle. False: the file could not
        be flagged and cannot be read (nothing valid in it)."""
        final = {"complete": bool(complete), "status": status} | attributes
        if not self.broken:
            try:
                with self._writing():
                    self._set_attributes(final)
                    self.file.close()
                return True
            except WriteFailed:
                pass
        self._close_quietly()
        return flag_after_failure(self.path, final)

    def _set_attributes(self, attributes: dict) -> None:
        self.file.attrs.update(attributes)
        self.attributes |= attributes

    def _close_quietly(self) -> None:
        if self.file is not None and self.file.id.valid:
            try:
                self.file.close()
            except (OSError, RuntimeError):  # the close fails for the reason the write did
                pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._close_quietly()


def flag_after_failure(path: Path, attributes: dict) -> bool:
    """Write a failed file's final attributes from a new handle; whether the file can be read (flagged or not: a
    file that still says `running` is incomplete all the same)."""
    try:
        with h5py.File(path, "r+") as handle:
            handle.attrs.update(attributes)
        return True
    except (OSError, RuntimeError):
        pass
    try:
        read_attributes(path)
        return True
    except (NotAResultFile, OSError, RuntimeError):
        return False


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
                out[name] = as_read(node[()])

        if wanted is None:
            handle.visititems(keep)
        else:  # by name first: an h5py object for each of the file's groups and datasets costs more than the reading
            handle.visit(lambda name: keep(name, handle[name]) if wanted(name) else None)
        return out


def as_read(values: np.ndarray) -> np.ndarray:
    """A dataset's stored values as read_result hands them on: a float32 history as float64, as older files stored
    it."""
    return values.astype(np.float64) if values.dtype == np.float32 else values


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
