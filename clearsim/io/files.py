"""Small facts about files on disk that the output checks share, and how a finished file takes its name."""

from __future__ import annotations

import contextlib
import glob
import os
import secrets
import shutil
import socket
from pathlib import Path
from typing import NamedTuple

try:
    import fcntl
    import resource
except ImportError:  # not on POSIX: the rename below is still atomic, the keep-as-previous step unlocked; no ulimit
    fcntl = resource = None

PARTIAL_SUFFIX = ".tmp"  # a file being written: no reader takes it for a result (they read *.h5)


def same_file(one: Path, other: Path) -> bool:
    """The same file on disk (through a symlink or a hard link too); False when either does not exist."""
    try:
        return Path(one).samefile(other)
    except OSError:
        return False


def keep_as_previous(path: Path) -> Path | None:
    """Rename an existing file (a result, a report, a figure) to <stem>.previous<suffix>, or the first free
    <stem>.previous-<k><suffix> (k = 2, 3, …) when earlier ones exist: an older kept file is never overwritten, and
    `clearsim plot` leaves these names out of a folder. Returns the new name (None: nothing was there)."""
    path = Path(path)
    if not path.exists():
        return None
    backup = next(candidate for candidate in previous_names(path) if not candidate.exists())
    path.rename(backup)
    return backup


def previous_names(path: Path):
    """<stem>.previous<suffix>, <stem>.previous-2<suffix>, … : where keep_as_previous puts earlier files."""
    yield path.with_name(f"{path.stem}.previous{path.suffix}")
    k = 2
    while True:
        yield path.with_name(f"{path.stem}.previous-{k}{path.suffix}")
        k += 1


def partial_name(path: Path) -> Path:
    """A name of its own, in the same folder, for `path` while it is being written:
    `.<name>.<host>.<pid>.<random>.tmp` (hidden, and no reader of results takes it), so that runs writing to one -o
    never touch each other's file."""
    path = Path(path)
    return path.with_name(f".{path.name}.{socket.gethostname()}.{os.getpid()}.{secrets.token_hex(4)}{PARTIAL_SUFFIX}")


def abandoned_partials(path: Path) -> list[Path]:
    """The files being written as `path` by processes of this machine that no longer exist (killed outright)."""
    path = Path(path)
    prefix = f".{path.name}.{socket.gethostname()}."
    found = []
    for candidate in sorted(path.parent.glob(f".{glob.escape(path.name)}.*{PARTIAL_SUFFIX}")):
        pid = candidate.name[len(prefix):].split(".")[0] if candidate.name.startswith(prefix) else ""
        if pid.isdigit() and not _alive(int(pid)):
            found.append(candidate)
    return found


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's
        return True
    return True


def adopt_abandoned(path: Path) -> None:
    """Give the files a killed run left being written as `path` that name, as the run itself would have (an earlier
    file kept as previous): what they hold is flagged `status = running`, and is never left hidden."""
    for partial in abandoned_partials(path):
        publish(partial, path)


@contextlib.contextmanager
def folder_lock(folder: Path):
    """An exclusive lock on a folder (flock of the folder itself: no lock file left behind), held by one process at
    a time, for the step that moves an earlier file aside and gives a new one its name. Where the file system
    refuses it (some network file systems), the step runs unlocked: the rename itself is still atomic."""
    if fcntl is None:
        yield
        return
    handle = os.open(folder, os.O_RDONLY)
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX)
        except OSError:
            pass
        yield
    finally:
        os.close(handle)  # releases the lock


def publish(partial: Path, path: Path) -> Path | None:
    """Give a finished file `partial` the name `path`, an earlier file of that name kept as <stem>.previous<suffix>
    (keep_as_previous), both under the folder's lock: runs finishing together each keep their result. Returns where
    the earlier file went (None: there was none)."""
    path = Path(path)
    with folder_lock(path.parent):
        backup = keep_as_previous(path)
        os.rename(partial, path)
    return backup


def locate(path: Path, identity: os.stat_result) -> Path:
    """Where the file that was published as `path` is now: `path`, or the <stem>.previous… name a later run that
    finished with the same name moved it to; `path` when it is in neither."""
    for candidate in (path, *_existing_previous(path)):
        try:
            found = candidate.stat()
        except OSError:
            continue
        if (found.st_dev, found.st_ino) == (identity.st_dev, identity.st_ino):
            return candidate
    return path


def _existing_previous(path: Path):
    for candidate in previous_names(path):
        if not candidate.exists():
            return
        yield candidate


class Room(NamedTuple):
    """How many more bytes a file can take, what limits it ("the disk is full" when that runs out), and how much of
    it there is ("results has 12 MB free")."""

    bytes: float
    limit: str
    left: str


def room_for(path: Path) -> Room:
    """The room left for `path`: the free space of its folder's file system or the file size limit of this process
    (`ulimit -f`), whichever is smaller."""
    folder = Path(path).parent
    free = shutil.disk_usage(folder).free
    disk = Room(float(free), "the disk is full", f"{folder} has {megabytes(free)} free")
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0] if resource is not None else None
    if limit is None or limit == resource.RLIM_INFINITY:
        return disk
    try:
        size = Path(path).stat().st_size
    except FileNotFoundError:
        size = 0
    if limit - size >= free:
        return disk
    return Room(float(max(0, limit - size)), "the file size limit is reached",
                f"the file size limit of this process (ulimit -f) is {megabytes(limit)}")


def megabytes(size: float) -> str:
    """A size in MB with enough digits to compare two of them near a few MB."""
    return f"{size / 2**20:.3g} MB"
