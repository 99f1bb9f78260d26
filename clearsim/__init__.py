"""clearsim: planar mechanisms with clearance joints."""

import hashlib
import os
import sys
from pathlib import Path

__version__ = "0.1.0"
COMPILED_PACKAGES = ("assembly", "physics", "solver")  # the modules with numba kernels


def cache_home() -> Path:
    """clearsim's cache folder: $XDG_CACHE_HOME/clearsim, or ~/.cache/clearsim where the variable is unset, empty or
    relative (the XDG base directory specification: a relative path is invalid and is ignored)."""
    configured = os.environ.get("XDG_CACHE_HOME", "")
    base = Path(configured) if configured and Path(configured).is_absolute() else Path.home() / ".cache"
    return base / "clearsim"


def _kernel_cache_dir() -> str:
    """A numba cache folder keyed by the source of every compiled module.

    numba's own cache notices a change only in the file that defines a function, not in the
    functions it calls from other modules; keying the folder by all sources makes any change
    recompile everything once (12–26 s on two idle cores, docs/performance.md) instead of running stale machine code.
    """
    digest = hashlib.sha256()
    package = Path(__file__).parent
    for folder in COMPILED_PACKAGES:
        for source in sorted((package / folder).glob("*.py")):
            digest.update(source.read_bytes())
    return str(cache_home() / "numba" / digest.hexdigest()[:16])


os.environ.setdefault("NUMBA_CACHE_DIR", _kernel_cache_dir())
# One OpenBLAS thread (read when numpy loads, so only where clearsim is imported first: the CLI, the benchmarks): the
# assembly's and the mode report's linear algebra is on matrices of tens of rows, whose threads, woken for each call,
# spin against the kernels on a busy machine (a 43 × 57 SVD: 0.16 s with two threads at load 8, 0.3 ms with one;
# results bitwise the same, docs/performance.md "Stiff models").
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
if "numba.core.config" in sys.modules:
    # numba, imported first (a notebook, a test module), read the variable before it was set, and chooses each
    # kernel's cache folder when the kernel is defined: without this, ours would go next to the sources, keyed by
    # each file alone
    sys.modules["numba.core.config"].CACHE_DIR = os.environ["NUMBA_CACHE_DIR"]
