"""Benchmarks beside the timed cases: compile time on an empty numba cache, peak memory; `describe` prints
each study's one-line summary. Each study takes (quick, folder, measurements, repeats), returns a JSON-ready dict.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]


def cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


# --- compile time on an empty numba cache, and peak memory -----------------------------------------

# Peak memory is the process's VmHWM (peak resident set of its own address space), not getrusage's ru_maxrss:
# Linux carries the parent's peak into a child's ru_maxrss at exec, so a child of a benchmark process that had
# run other cases read 250–870 MB whatever it did itself.
SNIPPET = textwrap.dedent("""
    import sys, time
    started = time.perf_counter()
    from clearsim.runner import simulate_config
    report = simulate_config(sys.argv[1], sys.argv[3:], sys.argv[2])
    try:
        with open("/proc/self/status") as status:
            peak_kb = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
    except OSError:  # not Linux: ru_maxrss (bytes on macOS), with the parent's peak in it where the OS carries it
        import resource
        peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / (1024.0 if sys.platform == "darwin" else 1.0)
    print(time.perf_counter() - started, peak_kb / 1024.0, report.statistics.wall_time)
""")


def _subprocess(config: Path, overrides: list[str], output: Path, cache: str | None,
                variables: dict | None = None) -> tuple[float, float, float]:
    environment = dict(os.environ, **(variables or {}))
    if cache is not None:
        environment["NUMBA_CACHE_DIR"] = cache
    done = subprocess.run([sys.executable, "-c", SNIPPET, str(config), str(output), *overrides], env=environment,
                          capture_output=True, text=True, check=True)
    total, megabytes, integration = map(float, done.stdout.split()[-3:])
    return total, megabytes, integration


def compile_time(quick: bool, folder: Path, measurements, repeats: int = 1) -> dict:
    """A 1-ms slider-crank run in a fresh process with an empty cache, then again with that cache:
    the difference is the compile time, paid once (later runs and sweep workers load the cache). Measured as a
    first run does it (with the compile-ahead helper on a second core, clearsim/solver/precompile.py) and in
    one process (CLEARSIM_COMPILE_AHEAD=0, e.g. a one-core machine)."""
    from benchmarks.suite import CRANK
    from clearsim.solver.precompile import DISABLE_VARIABLE

    result = {}
    for label, helper in (("", "1"), ("single_process_", "0")):
        cache = folder / f"numba-cache-{label or 'helper'}"
        environment = {DISABLE_VARIABLE: helper}
        cold, _, _ = _subprocess(CRANK, ["solver.t_end=1ms"], folder / "cold.h5", str(cache), environment)
        warm, _, _ = _subprocess(CRANK, ["solver.t_end=1ms"], folder / "warm.h5", str(cache), environment)
        result.update({f"{label}cold_s": cold, f"{label}warm_s": warm, f"{label}compile_s": cold - warm})
    return result


def memory(quick: bool, folder: Path, measurements, repeats: int = 1) -> dict:
    """Peak resident memory of a process running 1 s simulated (slider-crank, ~42 revolutions) at 10 kHz output."""
    from benchmarks.suite import CRANK

    t_end = "0.1s" if quick else "1s"
    # a short run first, in a fresh process too: the measured one must find every kernel in the cache
    # (a process that compiles peaks at 500+ MB; a run after the others read 250–870 MB without it)
    _subprocess(CRANK, ["solver.t_end=1ms"], folder / "memory-warm-up.h5", None)
    total, megabytes, integration = _subprocess(CRANK, [f"solver.t_end={t_end}", "solver.output_rate=10kHz"],
                                                folder / "memory.h5", None)
    return {"t_end": t_end, "output_rate_hz": 1e4, "peak_rss_mb": megabytes, "wall_s": total}


def describe(name: str, result) -> str:
    if name == "profile":
        return "\n".join(f"profile {r['case']}: wall {r['wall_s']:.2f} s = integration {r['integration_share']:.0%}, "
                         f"output sampling {r['sampling_share']:.0%}, HDF5 writing {r['hdf5_share']:.0%}, "
                         f"other (load, assemble) {r['other_share']:.0%}" for r in result)
    if name == "compile":
        single = (f"; in one process {result['single_process_compile_s']:.1f} s"
                  if "single_process_compile_s" in result else "")
        return (f"compile time (empty numba cache): {result['compile_s']:.1f} s (cold process {result['cold_s']:.1f} s, "
                f"warm {result['warm_s']:.1f} s; with the compile-ahead helper){single}")
    if name == "memory":
        return f"peak memory (VmHWM), {result['t_end']} simulated at 10 kHz output: {result['peak_rss_mb']:.0f} MB"
    if name == "scaling":
        return "scaling (log–log slopes): " + ", ".join(f"{k} {v:.2f}" for k, v in result["orders"].items() if v is not None)
    return str(result)
