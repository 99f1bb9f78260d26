"""Small facts about files on disk that the output checks share."""

from __future__ import annotations

from pathlib import Path


def same_file(one: Path, other: Path) -> bool:
    """The same file on disk (through a symlink or a hard link too); False when either does not exist."""
    try:
        return Path(one).samefile(other)
    except OSError:
        return False
