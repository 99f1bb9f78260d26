"""The benchmark cases, timed after a warm-up, each with its accuracy against a run at
100× tighter tolerance; a table on the terminal and a JSON file to compare runs.

    python -m benchmarks                       # every case, 5 repeats → benchmarks/results/latest.json
    python -m benchmarks --quick               # 1 repeat, short cases (a smoke test)
    python -m benchmarks --cases crank-friction,uhv-c0.1 --repeats 3
    python -m benchmarks --cases baseline-cartesian --repeats 3   # the issue's solve_ivp baseline
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
from typing import Callable

import numpy as np

CONFIGS = Path(__file__).resolve().parents[1] / "clearsim" / "configs"
UHV, UHV_FLEXIBLE = CONFIGS / "uhv_breaker.yaml", CONFIGS / "uhv_breaker_flexible.yaml"
UHV_HYDRAULIC = CONFIGS / "uhv_breaker_hydraulic.yaml"
CRANK, CRANK_FRICTION = CONFIGS / "slider_crank_flores.yaml", CONFIGS / "slider_crank_flores_friction.yaml"
RESULTS = Path(__file__).resolve().parent / "results"
TIGHTER = 100.0


LUBRICATED = ("defaults.lubrication.viscosity=0.1Pa*s", "defaults.lubrication.length=50mm",
              "joints.A.initial_eccentricity=[0 m, -1 um]", "joints.J.initial_eccentricity=[0 m, -1 um]",
              "solver.min_step=1e-13 s")  # the film's start-up transient (λ ≈ 3e8 1/s) at the reference's rtol 1e-9
METHODS = (("", ()), ("-rosenbrock", ("solver.method=rosenbrock",)))  # a case's name suffix and override per method


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
    Case("uhv-hydraulic", UHV_HYDRAULIC, ("solver.t_end=85ms",), ("solver.t_end=10ms",)),  # uhv-c0.01's stroke, force-driven
    Case("uhv-flex-ideal", UHV_FLEXIBLE, ("joints.A.clearance=0", "joints.J.clearance=0")),
    Case("uhv-flex-c0.01", UHV_FLEXIBLE, (), ("solver.t_end=10ms",)),
    Case("uhv-flex-c0.1", UHV_FLEXIBLE, ("joints.A.clearance=0.1mm", "joints.J.clearance=0.1mm"), ("solver.t_end=10ms",)),
    *[Case(f"uhv-{law}", UHV, (f"defaults.contact.elastic={law}", "defaults.contact.length=50mm",
                               "defaults.contact.stiffness=auto"), ("solver.t_end=10ms",))
      for law in ("johnson", "pereira", "liu")],  # one per elastic-law family: implicit line, power fit, conformal
    # the breaker with greased pins (docs/model-contact.md, "Cost"), its journals started 1 µm off-centre (as the
    # rtol 1e-9 runs of docs/validation.md §6), both methods over the first 1 ms
    *[Case(f"uhv-lubricated{suffix}", UHV, LUBRICATED + ("solver.t_end=1ms",) + method) for suffix, method in METHODS],
    # the same over the whole 85 ms stroke, rosenbrock only (dopri5 would take ~20 min): against uhv-c0.01, dry
    Case("uhv-lubricated-stroke-rosenbrock", UHV, LUBRICATED + METHODS[1][1], ("solver.t_end=10ms",)),
    # the flexible breaker's crank arms at the beam element's default of 10 segments (their highest modes bound
    # dopri5's steps), ideal pins, first 10 ms, both methods
    *[Case(f"uhv-flex-n10-ideal{suffix}", UHV_FLEXIBLE, ("joints.A.clearance=0", "joints.J.clearance=0",
                                                      "bodies.main_crank_arm.flexible.segments=10",
                                                      "bodies.lower_turn_arm.flexible.segments=10", "solver.t_end=10ms")
           + method) for suffix, method in METHODS],
    Case("uhv-flex-c0.1-rosenbrock", UHV_FLEXIBLE, ("joints.A.clearance=0.1mm", "joints.J.clearance=0.1mm",
                                                   "solver.method=rosenbrock"), ("solver.t_end=10ms",)),
    Case("crank-frictionless", CRANK, (), ("solver.t_end=6ms",)),
    Case("crank-friction", CRANK_FRICTION, (), ("solver.t_end=6ms",)),
]
# the dry cases again with the 8th-order explicit method (the reference at rtol/100 with the same settings)
VARIANTS = (("-dop853", ("solver.method=dop853",)),)
CASES += [Case(f"{case.name}{suffix}", case.config, case.overrides + settings, case.quick_overrides)
          for suffix, settings in VARIANTS for case in CASES
          if case.name in ("uhv-c0.01", "uhv-c0.1", "crank-frictionless", "crank-friction")]


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
    peak_memory_mb: float  # traced (numpy included) during the untimed warm-up run
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


def _run_in_memory(config: Path, overrides) -> tuple[float, object]:
    """The same run with its results kept in memory (`clearsim.solver.simulate.simulate`: load, assemble, integrate
    with every output sample and its accelerations, multipliers and contact forces; no HDF5 file): (wall s, History).
    What a peer or a baseline that keeps its outputs in memory does, for an equal-output comparison."""
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare
    from clearsim.solver.simulate import simulate

    started = time.perf_counter()
    history = simulate(prepare(load_mechanism(config, list(overrides))))
    return time.perf_counter() - started, history


def _traced_run(config: Path, overrides, folder: Path) -> float:
    """The warm-up run under tracemalloc: peak traced memory in MB (numpy arrays included)."""
    import tracemalloc

    tracemalloc.start()
    try:
        _run(config, overrides, folder, "warm-up")
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def clearsim_first_impact(config: Path, t_end: float) -> tuple[float, float]:
    """(onset, peak normal force) of clearsim's first contact episode, the run stopped at t_end."""
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare
    from clearsim.solver.simulate import Run

    run = Run(prepare(load_mechanism(config, [f"solver.t_end={t_end!r}s"])))
    for _chunk in run.chunks():
        pass
    return float(run.episode_log().onset[0]), float(run.statistics().peak_normal_force.max())


def profile_split(case: Case, quick: bool, folder: Path) -> dict:
    """Where one run's wall time goes: integration (the compiled loop, which also derives accelerations,
    forces and energies of each sample), output sampling (the outputs by name of each chunk), HDF5 writing, and the rest (load, assemble, episodes): timers wrapped around the
    functions that do each, for one extra run."""
    from clearsim import runner
    from clearsim.io import hdf5

    spent = {"sampling": 0.0, "hdf5": 0.0}

    def timed(owner, name, bucket):
        original = getattr(owner, name)

        def wrapper(*args, **kwargs):
            started = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                spent[bucket] += time.perf_counter() - started
        setattr(owner, name, wrapper)
        return owner, name, original

    patches = [timed(runner, "chunk_outputs", "sampling"),
               timed(runner, "sample_modes", "sampling"), timed(runner, "classify_episodes", "sampling"),
               timed(hdf5.ResultWriter, "__init__", "hdf5"), timed(hdf5.ResultWriter, "__exit__", "hdf5"),
               timed(hdf5.ResultWriter, "append", "hdf5"),
               timed(hdf5.ResultWriter, "replace", "hdf5"), timed(hdf5.ResultWriter, "write_table", "hdf5"),
               timed(hdf5.ResultWriter, "finish", "hdf5")]
    try:
        overrides = case.overrides + (case.quick_overrides if quick else ())
        wall, report, _ = _run(case.config, overrides, folder, f"{case.name}-profile")
    finally:
        for owner, name, original in patches:
            setattr(owner, name, original)
    integration = report.statistics.wall_time
    rest = wall - integration - spent["sampling"] - spent["hdf5"]
    parts = {"integration_s": integration, "sampling_s": spent["sampling"], "hdf5_s": spent["hdf5"], "other_s": rest}
    return {"case": case.name, "wall_s": wall, **parts,
            **{key.replace("_s", "_share"): value / wall for key, value in parts.items()}}


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
    memory = _traced_run(case.config, overrides, folder)  # warm-up: compiled kernels loaded, caches warm
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
        _relative(peak, ref_peak), _relative(force, ref_force), repeats, memory)


def crank_study(compare_case, measurements: list[Measurement], repeats: int, quick: bool, folder: Path) -> dict:
    """compare_case(friction, clearsim's measurement, repeats, quick) for the slider-crank cases of this run

    (both, measured now, if the run has neither)."""
    names = ((False, "crank-frictionless"), (True, "crank-friction"))
    mine = [(friction, m) for friction, name in names for m in measurements if m.case == name]
    if not mine:
        mine = [(friction, measure(next(c for c in CASES if c.name == name), repeats, quick, folder)) for friction, name in names]
    return {"cases": [compare_case(friction, m, repeats, quick) for friction, m in mine]}


CLEARSIM_LADDER = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)  # rtol (atol = rtol/1000), loosest first


def ladder_settings(case: Case, rtol: float) -> tuple[str, ...]:
    """The case's overrides at one rung of CLEARSIM_LADDER (atol = rtol/1000)."""
    return case.overrides + (f"solver.rtol={rtol!r}", f"solver.atol={rtol / 1000.0!r}")


def paired_ratio(theirs: Callable[[], float], case_name: str, rtol: float, repeats: int) -> dict:
    """Median and range of their wall over clearsim's (in memory, at rtol), one of each in turn, `repeats` pairs.

    On a machine whose speed drifts from one minute to the next, the two sides measured in separate blocks (as the
    ladders are) can each catch another phase; a pair runs both within a fraction of a second."""
    case = next(c for c in CASES if c.name == case_name)
    settings = ladder_settings(case, rtol)
    def ours() -> float:
        return _run_in_memory(case.config, settings)[0]

    ratios = []
    for k in range(repeats):
        walls = {side: side() for side in ((theirs, ours) if k % 2 == 0 else (ours, theirs))}
        ratios.append(walls[theirs] / walls[ours])
    return {"pairs": repeats, "median": statistics.median(ratios), "min": min(ratios), "max": max(ratios)}


def clearsim_ladder(case_name: str, repeats: int, folder: Path) -> list[dict]:
    """The case at each rtol of CLEARSIM_LADDER: wall median and errors against the rtol/100 run of the default.

    Lets a peer that cannot reach clearsim's default accuracy be compared at its own accuracy instead.
    """
    case = next(c for c in CASES if c.name == case_name)
    from clearsim.model.loader import load_mechanism

    solver = load_mechanism(case.config, list(case.overrides)).mechanism.solver
    tight = case.overrides + (f"solver.rtol={solver.rtol / TIGHTER!r}", f"solver.atol={solver.atol / TIGHTER!r}")
    ref_peak, ref_force = _figures(_run(case.config, tight, folder, f"{case_name}-ladder-reference")[2])
    rows = []
    for rtol in CLEARSIM_LADDER:
        settings = ladder_settings(case, rtol)
        try:
            runs = [_run(case.config, settings, folder, f"{case_name}-ladder-{rtol:g}-{k}") for k in range(repeats)]
        except RuntimeError as failure:  # a tolerance too loose for the contact: the row says so
            rows.append({"rtol": rtol, "failed": str(failure)})
            continue
        peak, force = _figures(runs[-1][2])
        in_memory = [_run_in_memory(case.config, settings)[0] for _ in range(repeats)]
        rows.append({"rtol": rtol, "wall_s": statistics.median(r[0] for r in runs),
                     "wall_in_memory_s": statistics.median(in_memory),
                     "error_peak_acceleration": _relative(peak, ref_peak),
                     "error_max_contact_force": _relative(force, ref_force)})
    return rows


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


def _wall(m: dict) -> str:
    return f"{m['wall_median_s']:.3f} s [{m['wall_min_s']:.3f}, {m['wall_max_s']:.3f}]"


def table(measurements: list[Measurement], sweep: dict | None, previous: dict | None):
    from rich.table import Table

    old = {m["case"]: m for m in (previous or {}).get("cases", [])}
    out = Table(title="clearsim benchmarks (wall: load + assemble + integrate + write HDF5)")
    for column in ("case", "sim. time", "wall median [min, max]", "integration", "steps (rej.)", "RHS", "events",
                   "µs/step", "peak mem.", "err peak acc.", "err max F_n") + (("vs previous",) if previous else ()):
        out.add_column(column, justify="right" if column != "case" else "left")
    for m in measurements:
        row = [m.case, f"{m.simulated_time_s * 1e3:g} ms", _wall(asdict(m)), f"{m.integration_median_s:.3f} s",
               f"{m.steps} ({m.rejected_steps})", f"{m.rhs_evaluations}", f"{m.contact_events}", f"{m.us_per_step:.1f}",
               f"{m.peak_memory_mb:.0f} MB", f"{m.error_peak_acceleration:.1e}", f"{m.error_max_contact_force:.1e}"]
        if previous:
            before = old.get(m.case)
            row.append(f"{before['wall_median_s'] / m.wall_median_s:.2f}× faster" if before else "—")
        out.add_row(*row)
    if sweep:
        out.add_row("sweep-8", "", f"{sweep['wall_s']:.1f} s", "", "", "", "", "", "",
                    f"{sweep['cases_per_minute']:.1f} cases/min", f"{sweep['workers']} workers", *([""] if previous else []))
    return out


SIDE_BY_SIDE = (  # study key, tool, its setting, the prefix of the clearsim errors it is matched against
    ("peer", "Exudyn (RK44, fixed step)", lambda r: f"h = {r['step_s']:g} s", "clearsim_"),
    ("baseline", "solve_ivp minimal (DOP853, events)", lambda r: f"rtol = {r['rtol']:g}", "clearsim_"),
    ("baseline-cartesian", "solve_ivp Cartesian (Baumgarte, events)", lambda r: f"rtol = {r['rtol']:g}",
     "clearsim_reference_"),
)


def side_by_side(document: dict):
    """Peer and baseline rows at matched accuracy, with clearsim's in the same run."""
    from rich.markup import escape
    from rich.table import Table

    out = Table(title="slider-crank side by side at matched accuracy (errors: Exudyn and solve_ivp minimal vs their own 100× "
                      "tighter run; solve_ivp Cartesian and the clearsim row under it vs the minimal model at rtol 1e-12)")
    for column in ("case", "tool", "setting", "wall median [min, max]", "err peak acc.", "err max F_n", "its wall / clearsim's"):
        out.add_column(column, justify="left" if column in ("case", "tool") else "right")
    for key, tool, setting, prefix in SIDE_BY_SIDE:
        study = document.get(key)
        if study is None:
            continue
        if "skipped" in study:
            out.add_row("—", tool, escape(study["skipped"]), "", "", "", "")
            continue
        for case in study["cases"]:
            matched = case["matched"]
            if matched is None:
                out.add_row(case["case"], tool, "no setting tried reached clearsim's accuracy", "", "", "", "")
                continue
            out.add_row(case["case"], tool, setting(matched), _wall(case), f"{matched['error_peak_acceleration']:.1e}",
                        f"{matched['error_max_contact_force']:.1e}", f"{case['ratio']:.1f}×")
            out.add_row("", "clearsim (this run)", "rtol = 1e-7", f"{case['clearsim_wall_median_s']:.3f} s",
                        f"{case[prefix + 'error_peak_acceleration']:.1e}", f"{case[prefix + 'error_max_contact_force']:.1e}", "")
            settled = case.get("settled") or {}
            if "ratio" in settled:  # a tighter rung from which on every rung is as accurate (errors not monotone)
                out.add_row("", tool, setting(settled) + " and tighter", _wall(settled), f"{settled['error_peak_acceleration']:.1e}",
                            f"{settled['error_max_contact_force']:.1e}", f"{settled['ratio']:.1f}×")
                out.add_row("", "clearsim (this run)", "rtol = 1e-7", f"{settled['clearsim_wall_median_s']:.3f} s", "", "", "")
            for timed, rung, tighter in ((case, matched, ""), (settled, settled, " and tighter")):
                if "ratio_equal_outputs" in timed:  # both keep the same outputs in memory: no HDF5 file on either side
                    out.add_row("", tool + ", equal outputs", setting(rung) + tighter + ", + 100 kHz states and accelerations",
                                f"{timed['equal_outputs_wall_median_s']:.3f} s", "", "", f"{timed['ratio_equal_outputs']:.1f}×")
                    out.add_row("", "clearsim in memory", "rtol = 1e-7, no HDF5 file",
                                f"{timed['clearsim_in_memory_wall_median_s']:.3f} s", "", "", "")
    return out


def cartesian_ladder(document: dict):
    """The Cartesian baseline's rtol ladder: errors against the common reference and against its own rtol/100 run."""
    from rich.table import Table

    out = Table(title="solve_ivp Cartesian ladder (ref. = minimal model at rtol 1e-12; self = own run at rtol/100)")
    for column in ("case", "rtol", "wall (one run)", "steps", "RHS", "contact events", "max F_n", "err acc. / F_n vs ref.",
                   "err acc. / F_n vs self", "max |Φ|"):
        out.add_column(column, justify="left" if column == "case" else "right")
    for case in (document.get("baseline-cartesian") or {}).get("cases", []):
        out.add_row(case["case"], "clearsim 1e-7", "", "", "", "", "",
                    f"{case['clearsim_reference_error_peak_acceleration']:.1e} / {case['clearsim_reference_error_max_contact_force']:.1e}",
                    f"{case['clearsim_error_peak_acceleration']:.1e} / {case['clearsim_error_max_contact_force']:.1e}", "")
        for r in case["rows"]:
            if "failed" in r:
                out.add_row(case["case"], f"{r['rtol']:g}", f"failed: {r['failed'][:70]}", *[""] * 7)
                continue
            out.add_row(case["case"], f"{r['rtol']:g}", f"{r['wall_s']:.3f} s", f"{r['steps']}", f"{r['rhs_evaluations']}",
                        f"{r['contact_events']}", f"{r['max_contact_force']:.1f} N",
                        f"{r['error_peak_acceleration']:.1e} / {r['error_max_contact_force']:.1e}",
                        f"{r['self_error_peak_acceleration']:.1e} / {r['self_error_max_contact_force']:.1e}",
                        f"{r['constraint_drift']:.1e}")
    return out


def at_peer_accuracy(document: dict):
    """Each Exudyn step beside the loosest clearsim rtol that is at least as accurate in both errors."""
    from rich.table import Table

    study = document.get("peer") or {}
    out = Table(title="clearsim at the peer's accuracy: each Exudyn step vs the loosest clearsim rtol as accurate in both errors")
    for column in ("case", "Exudyn step", "Exudyn wall", "err acc. / F_n", "clearsim rtol", "clearsim wall",
                   "err acc. / F_n", "Exudyn / clearsim", "clearsim in memory", "Exudyn / in memory",
                   "paired, in memory: median [min, max]"):
        out.add_column(column, justify="left" if column == "case" else "right")
    for case in study.get("cases", []):
        for row in case.get("at_peer_accuracy", []):
            mine = row["clearsim"]
            out.add_row(case["case"], f"{row['step_s']:g} s", f"{row['wall_s']:.3f} s",
                        f"{row['error_peak_acceleration']:.1e} / {row['error_max_contact_force']:.1e}",
                        f"{mine['rtol']:g}" if mine else "—", f"{mine['wall_s']:.3f} s" if mine else "",
                        f"{mine['error_peak_acceleration']:.1e} / {mine['error_max_contact_force']:.1e}" if mine else "",
                        f"{row['ratio']:.1f}×" if mine else "",
                        f"{mine['wall_in_memory_s']:.3f} s" if mine and "wall_in_memory_s" in mine else "",
                        f"{row['ratio_in_memory']:.1f}×" if row.get("ratio_in_memory") else "",
                        _paired_text(row.get("paired_ratio_in_memory")))
    return out


FLEXIBLE_PAIRS = (("uhv-flex-ideal", "uhv-ideal"), ("uhv-flex-c0.01", "uhv-c0.01"), ("uhv-flex-c0.1", "uhv-c0.1"))


def flexible_pairs(quick: bool, folder: Path, measurements, repeats: int = 1) -> list[dict]:
    """The flexible breaker's wall and integration time over the rigid one's with the same clearances, a run of each
    in turn (`repeats` pairs, the first of each pair alternating): on a shared machine whose speed drifts between
    minutes, cases measured one after another (the table) can each catch another phase; a pair cannot."""
    rows = []
    for flexible_name, rigid_name in FLEXIBLE_PAIRS:
        cases = {name: next(c for c in CASES if c.name == name) for name in (flexible_name, rigid_name)}
        settings = {name: case.overrides + (case.quick_overrides if quick else ()) for name, case in cases.items()}
        for name in cases:  # warm-up: kernels loaded, caches warm
            _run(cases[name].config, settings[name], folder, f"{name}-pair-warm-up")
        walls, integrations = [], []
        for k in range(max(repeats, 1)):
            order = (flexible_name, rigid_name) if k % 2 == 0 else (rigid_name, flexible_name)
            runs = {name: _run(cases[name].config, settings[name], folder, f"{name}-pair-{k}") for name in order}
            walls.append(runs[flexible_name][0] / runs[rigid_name][0])
            integrations.append(runs[flexible_name][1].statistics.wall_time / runs[rigid_name][1].statistics.wall_time)
        rows.append({"flexible": flexible_name, "rigid": rigid_name, "pairs": len(walls),
                     "wall_ratio_median": statistics.median(walls), "wall_ratio_min": min(walls),
                     "wall_ratio_max": max(walls), "integration_ratio_median": statistics.median(integrations),
                     "integration_ratio_min": min(integrations), "integration_ratio_max": max(integrations),
                     "steps": {name: run[1].statistics.steps for name, run in runs.items()}})
    return rows


def describe_flexible_pairs(rows: list[dict]) -> str:
    return "\n".join(f"{r['flexible']} / {r['rigid']} ({r['pairs']} pairs): wall {r['wall_ratio_median']:.2f}× "
                     f"[{r['wall_ratio_min']:.2f}, {r['wall_ratio_max']:.2f}], integration "
                     f"{r['integration_ratio_median']:.2f}× [{r['integration_ratio_min']:.2f}, "
                     f"{r['integration_ratio_max']:.2f}]" for r in rows)


def _paired_text(paired: dict | None) -> str:
    return f"{paired['median']:.2f}× [{paired['min']:.2f}, {paired['max']:.2f}]" if paired else ""


def _studies() -> dict:
    from benchmarks import chain, exudyn_slider_crank, extras, scaling, solve_ivp_cartesian, solve_ivp_slider_crank

    return {"chain": chain.chain, "peer": exudyn_slider_crank.peer, "baseline": solve_ivp_slider_crank.baseline,
            "baseline-cartesian": solve_ivp_cartesian.baseline,
            "compile": extras.compile_time, "memory": extras.memory, "scaling": scaling.scaling,
            "diagnose": extras.diagnose_throughput, "sweep-keep": extras.sweep_keep, "flex-pairs": flexible_pairs}


PROFILED = ("uhv-ideal", "uhv-c0.01", "uhv-c0.1")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description="clearsim benchmarks")
    parser.add_argument("--quick", action="store_true", help="1 repeat, shortened cases, short sweep and studies")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--cases", help="comma-separated names (default: all): " + ", ".join(c.name for c in CASES)
                        + ", sweep-8, profile, peer, baseline, baseline-cartesian, compile, memory, scaling, chain, diagnose, "
                        "sweep-keep, flex-pairs")
    parser.add_argument("--json", type=Path, default=RESULTS / "latest.json")
    parser.add_argument("--compare", type=Path, help="an earlier JSON: wall-time ratios per case")
    args = parser.parse_args(argv)
    from rich.console import Console

    from benchmarks import extras
    from benchmarks.chain import describe as describe_chain
    from benchmarks.scaling import figure

    console = Console(width=220)
    if args.compare and not args.compare.is_file():
        parser.error(f"--compare: no such file: {args.compare}")
    chosen = set(args.cases.split(",")) if args.cases else None
    known = {c.name for c in CASES} | {"sweep-8", "profile", *_studies()}
    if chosen and chosen - known:
        parser.error(f"unknown case(s): {', '.join(sorted(chosen - known))}; known: {', '.join(sorted(known))}")
    repeats = 1 if args.quick else args.repeats
    previous = json.loads(args.compare.read_text()) if args.compare else None
    document = {"machine": {"python": platform.python_version(), "processor": platform.processor(),
                            "cores": extras.cores()}, "quick": args.quick, "repeats": repeats, "cases": []}
    wanted = lambda name: chosen is None or name in chosen  # noqa: E731
    with tempfile.TemporaryDirectory(prefix="clearsim-bench-") as tmp:
        folder = Path(tmp)
        measurements = []
        for case in CASES:
            if wanted(case.name):
                console.print(f"[dim]{case.name} …[/]")
                measurements.append(measure(case, repeats, args.quick, folder))
        document["cases"] = [asdict(m) for m in measurements]
        sweep = None
        if wanted("sweep-8"):
            console.print("[dim]sweep-8 …[/]")
            sweep = document["sweep"] = sweep_throughput(2, args.quick, folder)
        if wanted("profile"):
            console.print("[dim]profile …[/]")
            document["profile"] = [profile_split(c, args.quick, folder) for c in CASES if c.name in PROFILED]
        for name, function in _studies().items():
            if wanted(name):
                console.print(f"[dim]{name} …[/]")
                document[name] = function(quick=args.quick, folder=folder, measurements=measurements, repeats=repeats)
    if "scaling" in document and not args.quick:
        figure(document["scaling"])
    console.print(table(measurements, sweep, previous))
    if any(key in document for key, *_ in SIDE_BY_SIDE):
        console.print(side_by_side(document))
    if "peer" in document:
        console.print(at_peer_accuracy(document))
    if "baseline-cartesian" in document:
        console.print(cartesian_ladder(document))
    for name in ("profile", "compile", "memory", "scaling", "diagnose", "sweep-keep"):
        if name in document:
            console.print(extras.describe(name, document[name]))
    if "chain" in document:
        console.print(describe_chain(document["chain"]))
    if "flex-pairs" in document:
        console.print(describe_flexible_pairs(document["flex-pairs"]))
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
