"""The benchmark cases of issue #6, timed after a warm-up, each with its accuracy against a run at
100× tighter tolerance; a table on the terminal and a JSON file to compare runs.

    python -m benchmarks                       # every case, 5 repeats → benchmarks/results/latest.json
    python -m benchmarks --quick               # 1 repeat, short cases (a smoke test)
    python -m benchmarks --cases crank-friction,uhv-c0.1 --repeats 3
    python -m benchmarks --compare benchmarks/results/session2.json
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

CONFIGS = Path(__file__).resolve().parents[1] / "clearsim" / "configs"
UHV, CRANK, CRANK_FRICTION = CONFIGS / "uhv_breaker.yaml", CONFIGS / "slider_crank_flores.yaml", CONFIGS / "slider_crank_flores_friction.yaml"
RESULTS = Path(__file__).resolve().parent / "results"
TIGHTER = 100.0


@dataclass(frozen=True)
class Case:
    name: str
    config: Path
    overrides: tuple[str, ...] = ()
    quick_overrides: tuple[str, ...] = ()  # --quick: a shorter version


CASES = [
    Case("uhv-ideal", UHV, ("joints.A.clearance=0", "joints.J.clearance=0")),
    Case("uhv-c0.01", UHV, (), ("solver.t_end=10ms",)),
    Case("uhv-c0.1", UHV, ("joints.A.clearance=0.1mm", "joints.J.clearance=0.1mm"), ("solver.t_end=10ms",)),
    Case("crank-frictionless", CRANK),
    Case("crank-friction", CRANK_FRICTION),
]


@dataclass
class Measurement:
    case: str
    simulated_time_s: float
    wall_median_s: float
    wall_min_s: float
    wall_max_s: float
    integration_median_s: float
    steps: int
    rejected_steps: int
    rhs_evaluations: int
    contact_events: int
    us_per_step: float
    peak_acceleration: float
    max_contact_force: float
    reference_peak_acceleration: float
    reference_max_contact_force: float
    error_peak_acceleration: float  # relative, vs the 100× tighter run
    error_max_contact_force: float
    repeats: int
    extra: dict = field(default_factory=dict)


def _run(config: Path, overrides, folder: Path, name: str):
    """One `clearsim run` (load, assemble, integrate, write HDF5); (wall s, report, summary)."""
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare, run_to_file, summarize

    started = time.perf_counter()
    loaded = load_mechanism(config, list(overrides))
    report = run_to_file(prepare(loaded), loaded, folder / f"{name}.h5")
    wall = time.perf_counter() - started
    if not report.complete:
        raise RuntimeError(f"{name}: {report.status}")
    summary = summarize(report.output)
    (folder / f"{name}.h5").unlink()
    return wall, report, summary


def _figures(summary) -> tuple[float, float]:
    peak = summary.peak_acceleration[1] if summary.peak_acceleration else float("nan")
    force = max(summary.peak_contact_force.values(), default=0.0)
    return peak, force


def _relative(value: float, reference: float) -> float:
    return abs(value - reference) / abs(reference) if reference else abs(value)


def measure(case: Case, repeats: int, quick: bool, folder: Path) -> Measurement:
    from clearsim.model.loader import load_mechanism

    overrides = case.overrides + (case.quick_overrides if quick else ())
    solver = load_mechanism(case.config, list(overrides)).mechanism.solver
    _run(case.config, overrides, folder, "warm-up")  # compiled kernels loaded, caches warm
    walls, integration, last = [], [], None
    for k in range(repeats):
        wall, report, summary = _run(case.config, overrides, folder, f"{case.name}-{k}")
        walls.append(wall)
        integration.append(report.statistics.wall_time)
        last = (report, summary)
    report, summary = last
    tight = overrides + (f"solver.rtol={solver.rtol / TIGHTER!r}", f"solver.atol={solver.atol / TIGHTER!r}")
    _, _, reference = _run(case.config, tight, folder, f"{case.name}-reference")
    peak, force = _figures(summary)
    ref_peak, ref_force = _figures(reference)
    stats = report.statistics
    return Measurement(
        case.name, solver.t_end, statistics.median(walls), min(walls), max(walls), statistics.median(integration),
        stats.steps, stats.rejected_steps, stats.rhs_evaluations, stats.contact_events,
        1e6 * statistics.median(integration) / max(stats.steps, 1), peak, force, ref_peak, ref_force,
        _relative(peak, ref_peak), _relative(force, ref_force), repeats)


def sweep_throughput(workers: int, quick: bool, folder: Path) -> dict:
    """8 slider-crank cases (4 clearances × 2 friction values) on `workers` processes: cases per minute."""
    from clearsim.sweep import LocalPool, SweepRequest, plan_sweep, run_sweep

    overrides = ["solver.t_end=6ms"] if quick else []
    request = SweepRequest(CRANK, [*overrides, "defaults.friction={law: none}"], clearance="0.1,0.2,0.3,0.5,0.6,0.7,0.8,0.9",
                           joints="slider_pin", ideal=False, out=folder / "sweep")
    plan = plan_sweep(request, CRANK)
    started = time.perf_counter()
    result = run_sweep(plan, LocalPool(workers))
    wall = time.perf_counter() - started
    return {"case": "sweep-8", "cases": len(plan.cases), "workers": workers, "wall_s": wall,
            "cases_per_minute": 60.0 * len(plan.cases) / wall, "failed": len(result.failed)}


def table(measurements: list[Measurement], sweep: dict | None, previous: dict | None):
    from rich.table import Table

    old = {m["case"]: m for m in (previous or {}).get("cases", [])}
    out = Table(title="clearsim benchmarks (wall: load + assemble + integrate + write HDF5)")
    for column in ("case", "sim. time", "wall median [min, max]", "integration", "steps (rej.)", "RHS", "events",
                   "µs/step", "err peak acc.", "err max F_n") + (("vs previous",) if previous else ()):
        out.add_column(column, justify="right" if column != "case" else "left")
    for m in measurements:
        row = [m.case, f"{m.simulated_time_s * 1e3:g} ms", f"{m.wall_median_s:.3f} s [{m.wall_min_s:.3f}, {m.wall_max_s:.3f}]",
               f"{m.integration_median_s:.3f} s", f"{m.steps} ({m.rejected_steps})", f"{m.rhs_evaluations}",
               f"{m.contact_events}", f"{m.us_per_step:.1f}", f"{m.error_peak_acceleration:.1e}", f"{m.error_max_contact_force:.1e}"]
        if previous:
            before = old.get(m.case)
            row.append(f"{before['wall_median_s'] / m.wall_median_s:.2f}× faster" if before else "—")
        out.add_row(*row)
    if sweep:
        out.add_row("sweep-8", "", f"{sweep['wall_s']:.1f} s", "", "", "", "", "",
                    f"{sweep['cases_per_minute']:.0f} cases/min", f"{sweep['workers']} workers",
                    *([""] if previous else []))
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description="clearsim benchmarks (issue #6)")
    parser.add_argument("--quick", action="store_true", help="1 repeat, shortened UHV cases, short sweep")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--cases", help="comma-separated case names (default: all); also sweep-8, baseline, compile, memory, scaling")
    parser.add_argument("--json", type=Path, default=RESULTS / "latest.json")
    parser.add_argument("--compare", type=Path, help="an earlier JSON: wall-time ratios per case")
    args = parser.parse_args(argv)
    from rich.console import Console

    from benchmarks import extras

    console = Console()
    chosen = set(args.cases.split(",")) if args.cases else None
    repeats = 1 if args.quick else args.repeats
    previous = json.loads(args.compare.read_text()) if args.compare else None
    document = {"machine": {"python": platform.python_version(), "processor": platform.processor(),
                            "cores": extras.cores()}, "quick": args.quick, "repeats": repeats, "cases": []}
    with tempfile.TemporaryDirectory(prefix="clearsim-bench-") as tmp:
        folder = Path(tmp)
        measurements = []
        for case in CASES:
            if chosen is None or case.name in chosen:
                console.print(f"[dim]{case.name} …[/]")
                measurements.append(measure(case, repeats, args.quick, folder))
        document["cases"] = [asdict(m) for m in measurements]
        sweep = None
        if chosen is None or "sweep-8" in chosen:
            console.print("[dim]sweep-8 …[/]")
            sweep = document["sweep"] = sweep_throughput(2, args.quick, folder)
        for name, function in extras.STUDIES.items():
            if chosen is None or name in chosen:
                console.print(f"[dim]{name} …[/]")
                document[name] = function(quick=args.quick, folder=folder, measurements=measurements)
    console.print(table(measurements, sweep, previous))
    for name in extras.STUDIES:
        if name in document:
            console.print(extras.describe(name, document[name]))
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(document, indent=2, default=_plain) + "\n")
    console.print(f"results: {args.json}")
    return 0


def _plain(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(type(value))
