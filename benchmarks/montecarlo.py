"""Monte Carlo throughput: a UHV tolerance study (`clearsim sweep --sample N`) on the local pool.

    python -m benchmarks.montecarlo --samples 200 --keep figures --json benchmarks/results/montecarlo.json
    python -m benchmarks.montecarlo --parts 24 --keep summary     # where a case's CPU time goes, part by part

Measured in one run: the planning (every case loaded and checked), the sweep's wall time and cases per minute, the
integration time of its cases (the `wall_time_s` column), the overhead (what the wall time has beyond the
integration shared by the workers), the CPU time per case (the workers' and the sweep's own process's, the workers'
start included: what other work on the machine does not inflate, unlike the wall time), the disk per case, the peak
resident memory of each worker process (VmHWM), and a single `clearsim run` of the bundled model in a fresh process
beside it (its total and integration wall time), so that the ratios hold on a machine whose speed varies.

`--parts N` instead runs N cases of the study in this process as a pool worker runs them (two more first, untimed)
and gives the median CPU time of each part of a case (timers around the functions that do each part), and what the
output samples cost: the compiled loop at the config's 100 kHz against 1 kHz, which takes the same steps.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
UHV = ROOT / "clearsim" / "configs" / "uhv_breaker.yaml"
TOLERANCES = """
tolerances:
  - {path: joints.A.clearance, distribution: uniform, low: 0.01 mm, high: 0.05 mm}
  - {path: joints.J.clearance, distribution: uniform, low: 0.01 mm, high: 0.05 mm}
"""
SINGLE_RUN = """
import sys, time
started = time.perf_counter()
from clearsim.runner import simulate_config
report = simulate_config(sys.argv[1], ["joints.A.clearance=0.03mm", "joints.J.clearance=0.03mm"], sys.argv[2])
print(time.perf_counter() - started, report.statistics.wall_time)
"""


def toleranced_config(folder: Path) -> Path:
    """The bundled UHV model with its A and J clearances drawn between 0.01 and 0.05 mm (beside it: no CSV tables)."""
    path = folder / "uhv_tolerances.yaml"
    path.write_text(UHV.read_text(encoding="utf-8") + TOLERANCES, encoding="utf-8")
    return path


def peak_memory_mb(pid: int) -> float | None:
    """VmHWM of a live process (Linux); None elsewhere or when it has ended."""
    try:
        with open(f"/proc/{pid}/status") as status:
            return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024.0
    except (OSError, StopIteration):
        return None


def cpu_seconds(pid: int) -> float | None:
    """User + system CPU time of a live process so far (Linux /proc/PID/stat); None elsewhere or when it has ended."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


def single_run(folder: Path) -> tuple[float, float]:
    """(total, integration) seconds of one `clearsim run` of the UHV model at 0.03 mm in A and J, a fresh process."""
    done = subprocess.run([sys.executable, "-c", SINGLE_RUN, str(UHV), str(folder / "single.h5")],
                          capture_output=True, text=True, check=True, cwd=ROOT)
    total, integration = map(float, done.stdout.split()[-2:])
    return total, integration


def monte_carlo(samples: int, workers: int, keep: str, folder: Path, seed: int = 1) -> dict:
    from clearsim.runner import BUNDLED_CONFIG
    from clearsim.sweep import LocalPool, SweepRequest, plan_sweep, run_sweep

    config = toleranced_config(folder)
    started = time.perf_counter()
    plan = plan_sweep(SweepRequest(config, sample=samples, seed=seed, keep=keep, out=folder / "sweep"), BUNDLED_CONFIG)
    planned, own_cpu = time.perf_counter(), time.process_time()
    with LocalPool(workers) as pool:
        result = run_sweep(plan, pool)
        own_cpu = time.process_time() - own_cpu
        pids = list(pool._pool.executor._processes or {})
        memory, worker_cpu = [peak_memory_mb(pid) for pid in pids], [cpu_seconds(pid) for pid in pids]
    finished = time.perf_counter()
    with (plan.folder / "summary.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    integration = [float(row["wall_time_s"]) for row in rows if row["wall_time_s"]]
    files = [path.stat().st_size for path in plan.folder.iterdir() if path.suffix == ".h5"]
    on_disk = sum(path.stat().st_size for path in plan.folder.iterdir())
    cases, sweep_s = len(plan.cases), finished - planned
    return {"samples": samples, "cases": cases, "workers": workers, "keep": keep, "seed": seed,
            "complete": result.count("complete"), "plan_s": planned - started, "sweep_s": sweep_s,
            "cases_per_minute": 60.0 * cases / sweep_s, "cases_per_minute_with_plan": 60.0 * cases / (finished - started),
            "integration_total_s": sum(integration), "integration_median_s": statistics.median(integration),
            "integration_bound_cases_per_minute": 60.0 * workers * len(integration) / sum(integration),
            "overhead_share": 1.0 - sum(integration) / workers / sweep_s,
            "worker_cpu_s": [c for c in worker_cpu if c is not None], "sweep_process_cpu_s": own_cpu,
            "cpu_s_per_case": (sum(c for c in worker_cpu if c is not None) + own_cpu) / cases,
            "mb_per_case_file": statistics.mean(files) / 1e6 if files else 0.0,
            "mb_per_case_on_disk": on_disk / 1e6 / cases,
            "worker_peak_rss_mb": [m for m in memory if m is not None]}


# part of a case → the functions that do it (module, function or Class.method), none of them calling another's
PARTS = {
    "load (YAML text, overrides, schema, units)": [("clearsim.sweep.worker", "load_case")],
    "look for an earlier or abandoned file": [("clearsim.sweep.worker", "_reused")],
    "prepare (assembly, consistent start)": [("clearsim.sweep.worker", "prepare")],
    "compiled loop (integration and samples)": [("clearsim.solver.simulate", "Run._advance")],
    "outputs by name, contact modes": [("clearsim.runner", name) for name in
                                       ("chunk_outputs", "stored_outputs", "classify_episodes", "sample_modes",
                                        "journal_paths")],
    "HDF5: histories (shuffle + gzip 1)": [("clearsim.io.hdf5", "ResultWriter.append")],
    "HDF5: open, episode tables, attributes, close": [("clearsim.io.hdf5", f"ResultWriter.{name}") for name in
                                                      ("__init__", "replace", "write_table", "finish")],
    "whirl and law-range warnings": [("clearsim.runner", "_PendingChunks.whirls"),
                                     ("clearsim.runner", "_PendingChunks.law_range_warnings")],
    "the case's record for the summary": [("clearsim.sweep.worker", "read_record"),
                                          ("clearsim.sweep.worker", "kept_record")],
}


def _timed(spent: dict, part: str, module: str, attribute: str):
    """Wrap module.attribute (a function, or Class.method) so that its CPU time adds to spent[part]; returns how to
    undo it (None when the code measured has no such function)."""
    import importlib

    owner = importlib.import_module(module)
    *classes, name = attribute.split(".")
    for cls in classes:
        owner = getattr(owner, cls)
    original = getattr(owner, name, None)
    if original is None:
        return None

    def wrapper(*args, **kwargs):
        started = time.process_time()
        try:
            return original(*args, **kwargs)
        finally:
            spent[part] = spent.get(part, 0.0) + time.process_time() - started
    setattr(owner, name, wrapper)
    return owner, name, original


def case_parts(cases: int, keep: str, folder: Path, seed: int = 1) -> dict:
    """Median CPU seconds of each part of a Monte Carlo case run as a pool worker runs it (PARTS; `other`: the rest of
    the case), over `cases` cases after two untimed ones."""
    from clearsim.runner import BUNDLED_CONFIG
    from clearsim.sweep import SweepRequest, plan_sweep
    from clearsim.sweep.execute import tasks_of
    from clearsim.sweep.worker import run_case

    plan = plan_sweep(SweepRequest(toleranced_config(folder), sample=cases + 2, seed=seed, keep=keep,
                                   out=folder / "parts"), BUNDLED_CONFIG)
    plan.folder.mkdir(parents=True, exist_ok=True)
    tasks = [task for task in tasks_of(plan) if task.name != "ideal"]
    spent: dict[str, float] = {}
    patches = [_timed(spent, part, module, attribute) for part, functions in PARTS.items()
               for module, attribute in functions]
    measured = []
    try:
        for index, task in enumerate(tasks):
            spent.clear()
            started = time.process_time()
            run_case(task)
            if index >= 2:
                total = time.process_time() - started
                measured.append(spent | {"other": total - sum(spent.values()), "total": total})
    finally:
        for owner, name, original in (patch for patch in reversed(patches) if patch is not None):
            setattr(owner, name, original)
    return {part: statistics.median(case.get(part, 0.0) for case in measured) for part in [*PARTS, "other", "total"]}


def sample_cost(rates=(1e5, 1e3), repeats: int = 5) -> dict:
    """Median CPU seconds of the compiled loop of the study's middle case (A and J at 0.03 mm) at each output rate,
    the rates alternated, and its steps (the same at every rate)."""
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare
    from clearsim.solver.simulate import Run

    def loop_cpu(rate: float) -> tuple[float, int]:
        overrides = ["joints.A.clearance=0.03mm", "joints.J.clearance=0.03mm", f"solver.output_rate={rate:g} Hz"]
        run = Run(prepare(load_mechanism(UHV, overrides)))
        started = time.process_time()
        for _chunk in run.chunks():
            pass
        return time.process_time() - started, run.statistics().steps

    loop_cpu(rates[0])
    timings = [{rate: loop_cpu(rate) for rate in rates} for _ in range(repeats)]
    return {f"{rate:g} Hz": {"loop_cpu_s": statistics.median(t[rate][0] for t in timings), "steps": timings[0][rate][1]}
            for rate in rates}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.montecarlo", description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--keep", default="figures", help="all, summary or figures (clearsim sweep --keep)")
    parser.add_argument("--json", type=Path, help="write the result here (e.g. benchmarks/results/montecarlo.json)")
    parser.add_argument("--parts", type=int, metavar="N",
                        help="instead: the CPU time of each part of a case, over N cases run in this process")
    options = parser.parse_args(argv)
    folder = Path(tempfile.mkdtemp(prefix="clearsim-montecarlo-"))
    machine = {"python": platform.python_version(), "cores": len(os.sched_getaffinity(0))}
    if options.parts:
        try:
            parts = {"cases": options.parts, "keep": options.keep,
                     "cpu_s": case_parts(options.parts, options.keep, folder), "samples": sample_cost()}
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        return _report({"machine": machine | {"load_average": os.getloadavg()}, "parts": parts}, options.json)
    try:
        single_run(folder)  # the kernels loaded once into the cache before anything is timed
        result = monte_carlo(options.samples, options.workers, options.keep, folder)
        single_total, single_integration = single_run(folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    result |= {"single_run_s": single_total, "single_run_integration_s": single_integration,
               "sweep_s_per_case_and_worker_over_single_run": result["sweep_s"] * result["workers"]
               / result["cases"] / single_total}
    return _report({"machine": machine | {"load_average": os.getloadavg()}, "montecarlo": result}, options.json)


def _report(document: dict, path: Path | None) -> int:
    text = json.dumps(document, indent=2)
    if path is not None:
        path.write_text(text + "\n", encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
