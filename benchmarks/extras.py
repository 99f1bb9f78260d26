"""Benchmarks beside the timed cases: the solve_ivp baseline, compile time, memory, scaling.

Each takes (quick, folder, measurements) and returns a JSON-ready dict; `describe` prints it.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


# --- baseline: scipy.integrate.solve_ivp on the minimal-coordinate slider-crank -------------------

def baseline(quick: bool, folder: Path, measurements) -> dict:
    """The slider-crank as a researcher writes it (tests/support/slider_crank_minimal.py: solve_ivp,
    events for contact onset/loss), at the loosest rtol whose peak contact force is as accurate as
    clearsim's default run, both against their own 100× tighter reference; wall-time ratio."""
    sys.path.insert(0, str(ROOT))
    from tests.support.slider_crank_minimal import FRICTIONLESS, simulate

    t_end = 0.006 if quick else 0.024
    clearsim = next((m for m in measurements if m.case == "crank-frictionless"), None)
    target = clearsim.error_max_contact_force if clearsim else 1e-3

    def run(rtol: float) -> tuple[float, float, int]:
        started = time.perf_counter()
        result = simulate(FRICTIONLESS, t_end=t_end, rtol=rtol)
        wall = time.perf_counter() - started
        times = np.linspace(0.0, t_end, 20001)
        return wall, float(np.max(result.histories(times)["normal_force"])), result.steps

    rows = []
    for rtol in ([1e-10] if quick else [1e-8, 1e-9, 1e-10, 1e-11]):
        try:
            wall, force, steps = run(rtol)
            _, reference, _ = run(rtol / 100.0)
        except RuntimeError as exc:  # a step jumped through the clearance: the hand-written model gives up
            rows.append({"rtol": rtol, "failed": str(exc)[:120]})
            continue
        rows.append({"rtol": rtol, "wall_s": wall, "steps": steps, "max_contact_force": force,
                     "error_max_contact_force": abs(force - reference) / reference})
    finished = [r for r in rows if "failed" not in r]
    matched = next((r for r in finished if r["error_max_contact_force"] <= max(target, 1e-12)),
                   finished[-1] if finished else None)
    out = {"t_end_s": t_end, "rows": rows, "matched": matched, "clearsim_error": target}
    if matched is None:
        return out
    if clearsim is not None and not quick:
        out["clearsim_wall_s"] = clearsim.wall_median_s
        out["ratio"] = matched["wall_s"] / clearsim.wall_median_s
    return out


# --- compile time on an empty numba cache, and peak memory -----------------------------------------

SNIPPET = textwrap.dedent("""
    import resource, sys, time
    started = time.perf_counter()
    from clearsim.runner import simulate_config
    report = simulate_config(sys.argv[1], sys.argv[3:], sys.argv[2])
    print(time.perf_counter() - started, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, report.statistics.wall_time)
""")


def _subprocess(config: Path, overrides: list[str], output: Path, cache: str | None) -> tuple[float, float, float]:
    environment = dict(os.environ)
    if cache is not None:
        environment["NUMBA_CACHE_DIR"] = cache
    done = subprocess.run([sys.executable, "-c", SNIPPET, str(config), str(output), *overrides], env=environment,
                          capture_output=True, text=True, check=True)
    total, megabytes, integration = map(float, done.stdout.split()[-3:])
    return total, megabytes, integration


def compile_time(quick: bool, folder: Path, measurements) -> dict:
    """A 1-ms slider-crank run in a fresh process with an empty cache, then again with that cache:
    the difference is the compile time, paid once (later runs and sweep workers load the cache)."""
    from benchmarks.suite import CRANK

    cache = folder / "numba-cache"
    cold, _, _ = _subprocess(CRANK, ["solver.t_end=1ms"], folder / "cold.h5", str(cache))
    warm, _, _ = _subprocess(CRANK, ["solver.t_end=1ms"], folder / "warm.h5", str(cache))
    return {"cold_s": cold, "warm_s": warm, "compile_s": cold - warm}


def memory(quick: bool, folder: Path, measurements) -> dict:
    """Peak resident memory of a process running 1 s simulated (slider-crank, ~42 revolutions) at 10 kHz output."""
    from benchmarks.suite import CRANK

    t_end = "0.1s" if quick else "1s"
    total, megabytes, integration = _subprocess(CRANK, [f"solver.t_end={t_end}", "solver.output_rate=10kHz"],
                                                folder / "memory.h5", None)
    return {"t_end": t_end, "output_rate_hz": 1e4, "peak_rss_mb": megabytes, "wall_s": total}


# --- scaling: a chain of N four-bars with K clearance joints ----------------------------------------

NEXT_ARM = 0.057  # m


def four_bar_chain(bars: int, clearance_joints: int, t_end: float = 0.02) -> str:
    """YAML of N four-bars in a row: each bar's rocker is a bell crank that drives the next bar.

    Bar i (pivots at x = 0.1 i and 0.1 (i+1)): input arm (0.03 m for the crank, 0.057 m after),
    coupler 0.1 m, rocker arm 0.06 m; the rocker's second arm, opposite, is the next bar's input. The first input is a
    crank at 10 rev/s. The last K coupler–rocker pins have clearance 0.1 mm (frictionless).
    """
    import math

    def angle_of(dx, dy):
        return math.degrees(math.atan2(dy, dx))

    lines = ["name: four-bar chain", "gravity: [0, 0]",
             "defaults: {bearing_radius: 5 mm, contact: {law: lankarani_nikravesh, restitution: 0.9, stiffness: auto}, "
             "friction: {law: none}}", "bodies:"]
    joints, inputs = [], []
    tip = (0.0, 0.03)  # the first input arm points up from the origin
    for i in range(bars):
        pivot, next_pivot = (0.1 * i, 0.0), (0.1 * (i + 1), 0.0)
        # rocker end R: 0.06 from next_pivot, 0.1 from tip (the upper intersection of two circles)
        dx, dy = next_pivot[0] - tip[0], next_pivot[1] - tip[1]
        d = math.hypot(dx, dy)
        a = (0.1 ** 2 - 0.06 ** 2 + d ** 2) / (2 * d)
        h = math.sqrt(max(0.1 ** 2 - a ** 2, 0.0))
        mx, my = tip[0] + a * dx / d, tip[1] + a * dy / d
        rocker_end = (mx - h * dy / d, my + h * dx / d)
        if rocker_end[1] < next_pivot[1]:
            rocker_end = (mx + h * dy / d, my - h * dx / d)
        input_body = "crank" if i == 0 else f"rocker{i - 1}"
        if i == 0:
            lines.append(f"  - {{name: crank, mass: 0.1, inertia: 1e-5, position: [{tip[0] / 2}, {tip[1] / 2}], angle: 90 deg}}")
            joints.append(f"  - {{name: O0, type: revolute, bodies: [ground, crank], at: [0, 0]}}")
        centre = ((tip[0] + rocker_end[0]) / 2, (tip[1] + rocker_end[1]) / 2)
        lines.append(f"  - {{name: coupler{i}, mass: 0.2, inertia: 2e-4, position: [{centre[0]}, {centre[1]}], "
                     f"angle: {angle_of(rocker_end[0] - tip[0], rocker_end[1] - tip[1])} deg}}")
        lines.append(f"  - {{name: rocker{i}, mass: 0.15, inertia: 6e-5, position: [{next_pivot[0]}, {next_pivot[1]}]}}")
        joints.append(f"  - {{name: A{i}, type: revolute, bodies: [{input_body}, coupler{i}], at: [{tip[0]}, {tip[1]}]}}")
        clearance = ", clearance: 0.1 mm" if i >= bars - clearance_joints else ""
        joints.append(f"  - {{name: B{i}, type: revolute, bodies: [rocker{i}, coupler{i}], at: [{rocker_end[0]}, {rocker_end[1]}]{clearance}}}")
        joints.append(f"  - {{name: O{i + 1}, type: revolute, bodies: [ground, rocker{i}], at: [{next_pivot[0]}, {next_pivot[1]}]}}")
        # the next input arm: on the rocker, opposite its coupler arm, NEXT_ARM long (the swing
        # passes on nearly undiminished: a near-parallelogram)
        ux, uy = (rocker_end[0] - next_pivot[0]) / 0.06, (rocker_end[1] - next_pivot[1]) / 0.06
        tip = (next_pivot[0] - NEXT_ARM * ux, next_pivot[1] - NEXT_ARM * uy)
        inputs.append(input_body)
    lines += ["joints:", *joints,
              "drivers:", "  - {name: motor, joint: O0, motion: {law: constant_speed, speed: 600 rpm}}",
              "sensors:", f"  - {{name: last_rocker, type: body_angular_velocity, body: rocker{bars - 1}}}",
              f"solver: {{t_end: {t_end}, output_rate: 10 kHz}}"]
    return "\n".join(lines) + "\n"


def scaling(quick: bool, folder: Path, measurements) -> dict:
    """Integration time per simulated second vs N (K = 0 and K = 1), the fitted log–log order."""
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare, run_to_file

    sizes = [1, 2, 5] if quick else [1, 2, 5, 10, 20, 50]
    rows = []
    for clearances in (0, 1):
        for bars in sizes:
            text = four_bar_chain(bars, clearances, t_end=0.005 if quick else 0.02)
            loaded = load_mechanism_text(text, f"chain-{bars}-{clearances}.yaml", (), folder)
            system = prepare(loaded)
            run_to_file(system, loaded, folder / "warm.h5")  # kernels compiled for this size class
            report = run_to_file(system, loaded, folder / f"chain-{bars}-{clearances}.h5")
            stats = report.statistics
            rows.append({"bars": bars, "bodies": 2 * bars + 1, "clearance_joints": clearances, "steps": stats.steps,
                         "integration_s": stats.wall_time, "us_per_step": 1e6 * stats.wall_time / max(stats.steps, 1),
                         "complete": report.complete})
    orders = {}
    for clearances in (0, 1):
        mine = [r for r in rows if r["clearance_joints"] == clearances and r["complete"]]
        if len(mine) >= 2:
            slope = np.polyfit(np.log([r["bodies"] for r in mine]), np.log([r["us_per_step"] for r in mine]), 1)[0]
            orders[f"K={clearances}"] = float(slope)
    return {"rows": rows, "order_us_per_step_vs_bodies": orders}


STUDIES = {"baseline": baseline, "compile": compile_time, "memory": memory, "scaling": scaling}


def describe(name: str, result: dict) -> str:
    if name == "baseline":
        m = result["matched"]
        if m is None:
            return "baseline solve_ivp slider-crank: no tolerance tried ran through (see the JSON rows)"
        ratio = f"; clearsim is {result['ratio']:.1f}× faster" if "ratio" in result else ""
        return (f"baseline solve_ivp slider-crank ({result['t_end_s'] * 1e3:g} ms): matched accuracy at rtol {m['rtol']:g} "
                f"(error {m['error_max_contact_force']:.1e} vs clearsim's {result['clearsim_error']:.1e}), "
                f"{m['wall_s']:.2f} s, {m['steps']} steps{ratio}")
    if name == "compile":
        return f"compile time (empty cache): {result['compile_s']:.1f} s (cold process {result['cold_s']:.1f} s, warm {result['warm_s']:.1f} s)"
    if name == "memory":
        return f"peak memory, {result['t_end']} simulated at 10 kHz output: {result['peak_rss_mb']:.0f} MB"
    if name == "scaling":
        return "scaling, µs per step vs bodies: " + ", ".join(f"{k}: order {v:.2f}" for k, v in
                                                           result["order_us_per_step_vs_bodies"].items())
    return str(result)
