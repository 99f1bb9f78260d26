"""Benchmarks beside the timed cases: compile time on an empty numba cache, peak memory, a diagnosis's throughput;
`describe` prints each study's one-line summary. Each study takes (quick, folder, measurements, repeats), returns a JSON-ready dict.
"""

from __future__ import annotations

import csv
import importlib.util
import os
import shutil
import statistics
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



# --- a diagnosis: runs per minute, and whether it found what was hidden ------------------------------------

DIAGNOSE_STUDY = {False: "uhv-clearance-B", True: "crank-clearance"}  # by --quick; each hides one joints.<J>.clearance


def _diagnose_studies():
    """docs/scripts/diagnose_studies.py, the studies of docs/diagnose.md (one definition of each study)."""
    path = ROOT / "docs" / "scripts" / "diagnose_studies.py"
    spec = importlib.util.spec_from_file_location("diagnose_studies", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up while it loads
    spec.loader.exec_module(module)
    return module


def diagnose_throughput(quick: bool, folder: Path, measurements, repeats: int = 1) -> dict:
    """`clearsim diagnose` of a docs/diagnose.md study (a clearance hidden in a synthetic record; the uhv-clearance-B
    study, with --quick the slider-crank's crank-clearance), each repeat in a new folder (no run file reused), on
    the local pool (one worker per core): wall time of the command, the runs it made, runs per minute, and its
    accuracy (the fitted clearance against the hidden one). At most 3 repeats: one is ~25 s."""
    studies = _diagnose_studies()
    from clearsim.units import to_si

    name = DIAGNOSE_STUDY[quick]
    study = next(s for s in studies.STUDIES if s.name == name)
    (hidden,) = study.hidden  # joints.<joint>.clearance=<length>, the truth as the study sets it
    path, length = hidden.split("=", 1)
    joint, truth = path.split(".")[1], to_si(length, "length")
    found = []
    for repeat in range(min(repeats, 3)):
        root = folder / f"diagnose-{repeat}"
        if repeat:  # the same record: synthesized once
            (root / name).mkdir(parents=True)
            shutil.copy(folder / "diagnose-0" / name / "bench.csv", root / name / "bench.csv")
        found.append(studies.run_study(study, root))
    walls = [f["wall_s"] for f in found]
    effects = [{"kind": e["kind"], "target": e["target"], "value": next(iter(e["parameters"].values())),
                "ties": e["ambiguous_with"]} for e in found[-1]["effects"]]
    hit = next((e for e in effects if e["kind"] == "clearance" and e["target"] == joint), None)
    runs = found[-1]["simulations"]
    return {"study": name, "repeats": len(found), "runs": runs, "wall_median_s": statistics.median(walls),
            "wall_min_s": min(walls), "wall_max_s": max(walls), "runs_per_minute": 60.0 * runs / statistics.median(walls),
            "hidden": {"joint": joint, "clearance_m": truth}, "found": effects,
            "error": abs(hit["value"] / truth - 1.0) if hit else None,
            "gap_before": found[-1]["gap_before"], "gap_after": found[-1]["gap_after"]}

KEEP_CLEARANCES = {False: "0.02,0.04,0.06,0.08,0.1,0.12", True: "0.05,0.1"}  # mm, the UHV at A and J


def sweep_keep(quick: bool, folder: Path, measurements, repeats: int = 1) -> dict:
    """A UHV clearance sweep (6 cases, no ideal case; with --quick 2 cases of 10 ms) on 2 workers with every
    history in each file (`--keep all`, the default) and with the summary histories (`--keep summary`), alternated,
    each repeat in new folders (at most 3 pairs): wall time, cases per minute and MB per case of each, and the
    summary tables compared (they must agree)."""
    import time

    from clearsim.runner import BUNDLED_CONFIG
    from clearsim.sweep import LocalPool, SweepRequest, plan_sweep, run_sweep

    overrides = ["solver.t_end=10ms"] if quick else []
    walls, sizes, summaries = {"all": [], "summary": []}, {}, {}
    for repeat in range(min(repeats, 3)):
        for keep in ("all", "summary") if repeat % 2 == 0 else ("summary", "all"):
            out = folder / f"sweep-keep-{keep}-{repeat}"
            request = SweepRequest(BUNDLED_CONFIG, list(overrides), KEEP_CLEARANCES[quick], "A,J", ideal=False,
                                   out=out, keep=keep)
            plan = plan_sweep(request, BUNDLED_CONFIG)
            started = time.perf_counter()
            run_sweep(plan, LocalPool(2))
            walls[keep].append(time.perf_counter() - started)
            files = sorted(out.glob("*.h5"))
            sizes[keep] = (sum(f.stat().st_size for f in files) / len(files) / 1e6,
                           sum(history_bytes(f) for f in files) / len(files) / 1e6)
            with (out / "summary.csv").open(newline="") as handle:  # the rows without the run-dependent columns
                summaries[keep] = [{k: v for k, v in row.items() if k not in ("wall_time_s", "reused")}
                                   for row in csv.DictReader(handle)]
    cases = len(KEEP_CLEARANCES[quick].split(","))
    result = {"cases": cases, "repeats": len(walls["all"]), "same_summary": summaries["all"] == summaries["summary"]}
    for keep, times in walls.items():
        median = statistics.median(times)
        result[keep] = {"wall_median_s": median, "wall_min_s": min(times), "wall_max_s": max(times),
                        "cases_per_minute": 60.0 * cases / median, "mb_per_case": sizes[keep][0],
                        "history_mb_per_case": sizes[keep][1]}
    return result


def history_bytes(path: Path) -> int:
    """Bytes of a result file's datasets, uncompressed: what `--keep` chooses, without the file's fixed part
    (attributes, episode tables, HDF5 metadata) and without the compression, whose chunks follow the run's flushes."""
    import h5py

    sizes = []
    with h5py.File(path, "r") as file:
        file.visititems(lambda name, item: sizes.append(item.nbytes) if isinstance(item, h5py.Dataset) else None)
    return sum(sizes)


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
    if name == "diagnose":
        named = ", ".join(f"{e['kind']} {e['target']} {e['value']:.4g}" for e in result["found"]) or "nothing"
        hidden = result["hidden"]
        found = (f"found {named} (hidden: clearance {hidden['joint']} {hidden['clearance_m']:.4g}"
                 + (f", error {result['error']:.1%})" if result["error"] is not None else ", not named)"))
        return (f"diagnose {result['study']}: {result['wall_median_s']:.1f} s [{result['wall_min_s']:.1f}, "
                f"{result['wall_max_s']:.1f}] for {result['runs']} runs ({result['runs_per_minute']:.0f} runs/min); "
                f"{found}; gap {result['gap_before']:.3g} → {result['gap_after']:.3g}")
    if name == "sweep-keep":
        full, kept = result["all"], result["summary"]
        return (f"sweep-keep ({result['cases']} UHV cases, 2 workers, {result['repeats']} pairs): --keep all "
                f"{full['wall_median_s']:.1f} s, {full['cases_per_minute']:.0f} cases/min, {full['mb_per_case']:.1f} "
                f"MB/case; --keep summary {kept['wall_median_s']:.1f} s, {kept['cases_per_minute']:.0f} cases/min, "
                f"{kept['mb_per_case']:.1f} MB/case; same summary: {result['same_summary']}")
    if name == "scaling":
        return "scaling (log–log slopes): " + ", ".join(f"{k} {v:.2f}" for k, v in result["orders"].items() if v is not None)
    return str(result)
