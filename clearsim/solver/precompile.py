"""Compile ahead: on an empty kernel cache, a second process compiles part of the loop's kernels meanwhile.

numba compiles in one thread per process. A run compiles the assembly's kernels, then `advance`, then, before the
loop's first call, the kernels `advance` takes by address (integrator.addressed_kernels: the mode switch, the
projection, the dynamics, the films' forces), one after the other in their order (compile_addressed), and packs
them for the loop (integrator.loop_kernels). When the cache holds no `advance`, the first
run (`prepare`) starts `python -m clearsim.solver.precompile`, which compiles into the same cache the kernels the
run's typing of `advance` needs early (`AHEAD`) and then those taken by address in the reverse order, the largest
first (`kernels_ahead`): a DOPRI5 run's of a model without oil films (with the stand-ins of the Rosenbrock step, of
the DOP853 step and of the films; a Rosenbrock or DOP853 run compiles its step itself, a lubricated model its dynamics
and films). When the run reaches a kernel
the helper has already written, numba loads it from the cache instead of compiling it (the same machine code: the
cache is keyed by the sources and the signature), so the two processes meet in the middle of that list. Where they
meet, the run waits for the kernel the helper is compiling at that moment (the helper names it in BUSY_NAME) and
loads it, instead of compiling it too (`compile_addressed`); anything else the two reach first is compiled by both,
which costs CPU only.

Only one helper runs per cache (a lock file), only with two or more cores, and never when the variable
CLEARSIM_COMPILE_AHEAD is 0. The helper's output is discarded; if it fails, the run compiles what it needs
itself, as it does without one.
"""

from __future__ import annotations

import atexit
import importlib
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from numba import typeof, types
from numba.core import config

from clearsim.assembly.arrays import KernelArraysType, blas_hidden
from clearsim.assembly.dynamics import dynamics_type, films_type
from clearsim.physics.wear import BORE_POINT_TYPE
from clearsim.solver.integrator import DOPRI5, addressed_kernels, advance

LOCK_NAME = "compile-ahead.lock"
BUSY_NAME = "compile-ahead.busy"  # the kernel the helper is compiling now, for the run to wait for instead
WAIT_POLL = 0.02  # s between two looks at it
WAIT_LIMIT = 120.0  # s at most: a helper that has stopped moving on is not waited for any longer
DISABLE_VARIABLE = "CLEARSIM_COMPILE_AHEAD"

F, I = types.float64, types.int64
V, IV, M = types.float64[::1], types.int64[::1], types.float64[:, ::1]
D = object()  # stands for dynamics_type(system_type()) in AHEAD
FILMS = object()  # stands for films_type(system_type())

# (module, kernel, argument types after the system): what the helper compiles first, in this order: the kernels the
# run's typing of `advance` reaches soon after the assembly's kernels (the event function, the sampling, the event
# search, the peak search). Then come the kernels `advance` takes by address (kernels_ahead).
AHEAD = (
    ("clearsim.solver.integrator", "event_value", (D, I, I, F, V, IV, V, F)),
    ("clearsim.solver.samples", "derive_sample", (D, FILMS, F, V, F, IV, V, V, V, M, V)),
    ("clearsim.solver.integrator", "_value_at", (D, I, I, F, V, M, F, F, IV, V, V)),
    ("clearsim.solver.integrator", "normal_force_at", (I, V, M, F, F, IV, V, V)),
)

# dtype and dimensions of each field of KernelArrays, as build.pack and arrays._workspace make them
# (tests/unit/test_precompile.py compares them with an assembled system's)
FIELD_LAYOUT = {
    "mass": ("f8", 1), "inertia": ("f8", 1), "gravity": ("f8", 1),
    "pin_bodies": ("i8", 2), "pin_points": ("f8", 2),
    "offset_bodies": ("i8", 2), "offset_params": ("f8", 2), "offset_law": ("i8", 1),
    "angle_bodies": ("i8", 2), "angle_value": ("f8", 1), "angle_law": ("i8", 1),
    "law_breaks": ("f8", 1), "law_coefficients": ("f8", 2), "law_first": ("i8", 1), "law_count": ("i8", 1),
    "clearance_bodies": ("i8", 2), "clearance_laws": ("i8", 2), "clearance_params": ("f8", 2),
    "load_bodies": ("i8", 1), "load_params": ("f8", 2), "load_law": ("i8", 1),
    "spring_bodies": ("i8", 2), "spring_params": ("f8", 2),
    "driveline_kinds": ("i8", 2), "driveline_bodies": ("i8", 2), "driveline_params": ("f8", 2),
    "driveline_table": ("f8", 2),
    "torsion_bodies": ("i8", 2), "torsion_params": ("f8", 2),
    "hydraulic_bodies": ("i8", 2), "hydraulic_params": ("f8", 2), "hydraulic_laws": ("i8", 2),
    "wear_harmonics": ("i8", 1), "wear_profile": ("f8", 2), "wear_samples": ("f8", 2), "wear_depth_range": ("f8", 1), "wear_bounds": ("f8", 2), "wear_slots": ("i8", 2), "wear_rates": ("f8", 2),
    "row_place": ("i8", 1),
    "inverse_mass": ("f8", 1), "solve_blocks": ("f8", 3), "solve_bodies": ("i8", 2), "solve_schur": ("f8", 2),
    "solve_lower": ("f8", 2), "solve_envelope": ("i8", 1), "solve_band": ("i8", 1),
    "solve_next_row": ("i8", 1), "solve_body_start": ("i8", 1),
    "solve_entries": ("i8", 2), "solve_body_fill": ("i8", 1), "solve_vector": ("f8", 1),
    "solve_residual": ("f8", 1), "solve_place": ("i8", 1), "solve_placed": ("f8", 1), "factor_key": ("i8", 1), "factor_q": ("f8", 1),
    "frame_trig": ("f8", 2), "bore_memo": ("f8", 2),
}

_helper: subprocess.Popen | None = None


def system_type():
    """The numba type of every system's KernelArrays (one type for all mechanisms: the arrays, and the worn bores'
    nearest point by address, arrays.KERNEL_FIELDS)."""
    return KernelArraysType([(name, typeof(np.zeros((0,) * ndim, dtype))) for name, (dtype, ndim)
                             in FIELD_LAYOUT.items()] + [("bore_point", BORE_POINT_TYPE)])


def kernels_ahead():
    """(dispatcher, full signature) of each kernel the helper compiles, in order: those of AHEAD, then the kernels
    `advance` takes by address in the reverse of the order in which the run compiles them (compile_addressed)
    (so that the two processes meet in the middle), by their function types' signatures (numba compiles, and keys in
    the cache, a kernel called by address by its signature with the return type)."""
    system = system_type()
    stands_for = {id(D): dynamics_type(system), id(FILMS): films_type(system)}
    ahead = [(getattr(importlib.import_module(module), name),
              (system, *(stands_for.get(id(argument), argument) for argument in arguments)))
             for module, name, arguments in AHEAD]
    return ahead + [(kernel, kind.signature) for kernel, kind in reversed(addressed_kernels(system, DOPRI5, False))]


def cache_is_cold() -> bool:
    """No compiled `advance` in the kernel cache (numba's index file for it is missing)."""
    return not_cached(advance)


def not_cached(kernel) -> bool:
    """No compiled `kernel` (a cached numba dispatcher) in the kernel cache that numba would load: its index file is
    missing, or numba reads it as empty (written by another numba version, or for other sources of the kernel: numba
    then compiles it again, as on an empty cache)."""
    cache_file = getattr(getattr(kernel, "_cache", None), "_cache_file", None)
    return cache_file is not None and not cache_file._load_index()


def compilations(kernels) -> int:
    """How many times numba has compiled these kernels (numba dispatchers) in this process: each time it did not find
    the kernel in memory nor load it from the kernel cache (numba's cache misses)."""
    return sum(sum(kernel.stats.cache_misses.values()) for kernel in kernels)


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def start_if_cold() -> None:
    """Start the helper, once per process, when the cache is cold and a second core is there to run it."""
    global _helper
    if _helper is not None or os.environ.get(DISABLE_VARIABLE, "1") == "0" or _cores() < 2:
        return
    try:
        import fcntl  # noqa: F401  (POSIX: the lock that keeps it to one helper per cache)
    except ImportError:
        return
    if not cache_is_cold():
        return
    try:
        _helper = subprocess.Popen([sys.executable, "-m", "clearsim.solver.precompile"], stdin=subprocess.DEVNULL,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    except (OSError, ValueError):  # no interpreter to start (embedded Python): the run compiles alone
        return
    atexit.register(_stop_helper)


def reap_helper() -> None:
    """Collect the helper's exit status once it has finished (else it stays a zombie until this process exits)."""
    if _helper is not None:
        _helper.poll()


def _stop_helper() -> None:
    """At exit: what the helper has written stays in the cache; it is not left running behind the run."""
    if _helper is not None and _helper.poll() is None:
        _helper.terminate()
        _helper.wait()


def compile_ahead() -> list[str]:
    """The helper's work: compile kernels_ahead() into the cache, under the lock; returns the kernels compiled."""
    import fcntl

    if not config.CACHE_DIR:
        return []
    folder = Path(config.CACHE_DIR)
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / LOCK_NAME, "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return []  # another helper is compiling into this cache
        done = []
        busy = folder / BUSY_NAME
        with blas_hidden():
            for kernel, signature in kernels_ahead():
                busy.write_text(_name(kernel))
                kernel.compile(signature)
                done.append(kernel.py_func.__name__)
        busy.unlink(missing_ok=True)
        return done


def _name(kernel) -> str:
    return f"{kernel.py_func.__module__}.{kernel.py_func.__qualname__}"


def _busy_with() -> str:
    """The kernel the helper is compiling now ("" when none, or unreadable)."""
    try:
        return (Path(config.CACHE_DIR) / BUSY_NAME).read_text()
    except (OSError, TypeError):
        return ""


def wait_while_helper_compiles(kernel) -> float:
    """When this process's helper is compiling `kernel` now, wait until it has moved on or ended (at most WAIT_LIMIT):
    the kernel is then in the cache to be loaded instead of compiled a second time here. Returns the seconds waited."""
    if _helper is None or not config.CACHE_DIR:
        return 0.0
    started = time.monotonic()
    while _busy_with() == _name(kernel) and _helper.poll() is None and time.monotonic() - started < WAIT_LIMIT:
        time.sleep(WAIT_POLL)
    return time.monotonic() - started


_addressed_ready: set[tuple] = set()  # the (method, lubricated) whose kernels this process has compiled or loaded


def compile_addressed(kernel_arrays, method: int, lubricated: bool) -> None:
    """Before the loop's first call in a process: each kernel `advance` takes by address compiled here, or loaded from
    the cache, in their order (integrator.addressed_kernels) — except that one the helper is compiling
    at that moment is waited for and loaded, not compiled by both processes (where the two meet in the middle)."""
    if (method, lubricated) in _addressed_ready:
        return
    for kernel, kind in addressed_kernels(typeof(kernel_arrays), method, lubricated):
        wait_while_helper_compiles(kernel)
        kernel.compile(kind.signature)
    _addressed_ready.add((method, lubricated))


if __name__ == "__main__":
    print(" ".join(compile_ahead()))
