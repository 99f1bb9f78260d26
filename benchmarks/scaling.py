"""Scaling: a chain of N four-bars with K clearance joints, cost against N and K, fitted log–log order.

    python -m benchmarks --cases scaling      # also writes docs/figures/performance-scaling.png
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np

NEXT_ARM = 0.057  # m
COUPLER, ROCKER, SPACING = 0.1, 0.06, 0.1  # m
FIGURE = Path(__file__).resolve().parents[1] / "docs" / "figures" / "performance-scaling.png"


def _rocker_end(tip: tuple[float, float], pivot: tuple[float, float]) -> tuple[float, float]:
    """The upper intersection of the circles |R − tip| = COUPLER and |R − pivot| = ROCKER."""
    dx, dy = pivot[0] - tip[0], pivot[1] - tip[1]
    d = math.hypot(dx, dy)
    a = (COUPLER**2 - ROCKER**2 + d**2) / (2 * d)
    h = math.sqrt(max(COUPLER**2 - a**2, 0.0))
    mx, my = tip[0] + a * dx / d, tip[1] + a * dy / d
    end = (mx - h * dy / d, my + h * dx / d)
    return end if end[1] >= pivot[1] else (mx + h * dy / d, my - h * dx / d)


def four_bar_chain(bars: int, clearance_joints: int, t_end: float = 0.02) -> str:
    """YAML of N four-bars in a row: each bar's rocker is a bell crank that drives the next bar.

    Bar i (pivots at x = 0.1 i and 0.1 (i+1)): input arm (0.03 m for the crank, 0.057 m after),
    coupler 0.1 m, rocker arm 0.06 m; the rocker's second arm, opposite, is the next bar's input. The first
    input is a crank at 600 rpm. The last K coupler–rocker pins have clearance 0.1 mm (frictionless).
    """
    lines = ["name: four-bar chain", "units: SI  # the coordinates and masses below are written in m and kg", "gravity: [0, 0]",
             "defaults: {bearing_radius: 5 mm, contact: {law: lankarani_nikravesh, restitution: 0.9, stiffness: auto}, "
             "friction: {law: none}}", "bodies:",
             "  - {name: crank, mass: 0.1, inertia: 1e-5, position: [0.0, 0.015], angle: 90 deg}"]
    joints = ["  - {name: O0, type: revolute, bodies: [ground, crank], at: [0, 0]}"]
    tip = (0.0, 0.03)  # the first input arm points up from the origin
    for i in range(bars):
        pivot = (SPACING * (i + 1), 0.0)
        end = _rocker_end(tip, pivot)
        centre = ((tip[0] + end[0]) / 2, (tip[1] + end[1]) / 2)
        angle = math.degrees(math.atan2(end[1] - tip[1], end[0] - tip[0]))
        lines.append(f"  - {{name: coupler{i}, mass: 0.2, inertia: 2e-4, position: [{centre[0]}, {centre[1]}], angle: {angle} deg}}")
        lines.append(f"  - {{name: rocker{i}, mass: 0.15, inertia: 6e-5, position: [{pivot[0]}, {pivot[1]}]}}")
        driver = "crank" if i == 0 else f"rocker{i - 1}"
        clearance = ", clearance: 0.1 mm" if i >= bars - clearance_joints else ""
        joints += [f"  - {{name: A{i}, type: revolute, bodies: [{driver}, coupler{i}], at: [{tip[0]}, {tip[1]}]}}",
                   f"  - {{name: B{i}, type: revolute, bodies: [rocker{i}, coupler{i}], at: [{end[0]}, {end[1]}]{clearance}}}",
                   f"  - {{name: O{i + 1}, type: revolute, bodies: [ground, rocker{i}], at: [{pivot[0]}, {pivot[1]}]}}"]
        # the next input arm: on the rocker, opposite its coupler arm (a near-parallelogram passes the swing on)
        ux, uy = (end[0] - pivot[0]) / ROCKER, (end[1] - pivot[1]) / ROCKER
        tip = (pivot[0] - NEXT_ARM * ux, pivot[1] - NEXT_ARM * uy)
    lines += ["joints:", *joints,
              "drivers:", "  - {name: motor, joint: O0, motion: {law: constant_speed, speed: 600 rpm}}",
              "sensors:", f"  - {{name: last_rocker, type: body_angular_velocity, body: rocker{bars - 1}}}",
              f"solver: {{t_end: {t_end}, output_rate: 10 kHz}}"]
    return "\n".join(lines) + "\n"


def validates(text: str, folder: Path) -> bool:
    """`clearsim validate` on the generated file (exit code 0: it loads and assembles)."""
    path = folder / "chain-validate.yaml"
    path.write_text(text)
    done = subprocess.run([sys.executable, "-m", "clearsim.cli", "validate", str(path)], capture_output=True, text=True)
    return done.returncode == 0


def timed_run(system) -> dict:
    """One integration of a prepared system: complete or not, steps, RHS and the compiled loop's wall time."""
    from clearsim.solver.simulate import Run

    run = Run(system)
    try:
        for _chunk in run.chunks():
            pass
        complete = True
    except Exception:  # noqa: BLE001 — a chain that fails is a row marked incomplete, not a crash
        complete = False
    stats = run.statistics()
    return {"complete": complete, "steps": stats.steps, "rhs_evaluations": stats.rhs_evaluations,
            "integration_s": stats.wall_time}


def _row(bars: int, clearances: int, t_end: float, folder: Path) -> dict:
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare

    loaded = load_mechanism_text(four_bar_chain(bars, clearances, t_end), f"chain-{bars}-{clearances}.yaml", (), folder)
    system = prepare(loaded)
    timed_run(system)  # the first run loads this size's kernels; the second is timed
    run = timed_run(system)
    wall = run["integration_s"]
    return {"bars": bars, "bodies": 2 * bars + 1, "clearance_joints": clearances, "coordinates": system.coordinate_count,
            "steps": run["steps"], "rhs_evaluations": run["rhs_evaluations"], "integration_s": wall,
            "us_per_step": 1e6 * wall / max(run["steps"], 1), "us_per_rhs": 1e6 * wall / max(run["rhs_evaluations"], 1),
            "complete": run["complete"]}


def _order(rows: list[dict], x: str, y: str) -> float | None:
    usable = [r for r in rows if r["complete"] and r[x] > 0 and r[y] > 0]
    if len(usable) < 2:
        return None
    return float(np.polyfit(np.log([r[x] for r in usable]), np.log([r[y] for r in usable]), 1)[0])


def scaling(quick: bool, folder: Path, measurements, repeats: int = 1) -> dict:
    """µs per step and per RHS vs bodies (K = 0 and K = 1), and vs K at fixed N; log–log slopes."""
    sizes = [1, 2, 5] if quick else [1, 2, 5, 10, 20, 50]
    t_end = 0.005 if quick else 0.02
    by_size = [_row(n, k, t_end, folder) for k in (0, 1) for n in sizes]
    fixed = sizes[-2] if quick else 10
    by_clearances = [_row(fixed, k, t_end, folder) for k in ([1, 2] if quick else [1, 2, 5, 10])]
    orders = {}
    for k in (0, 1):
        mine = [r for r in by_size if r["clearance_joints"] == k]
        orders[f"us_per_step_vs_bodies_K{k}"] = _order(mine, "bodies", "us_per_step")
        orders[f"us_per_rhs_vs_bodies_K{k}"] = _order(mine, "bodies", "us_per_rhs")
        orders[f"integration_vs_bodies_K{k}"] = _order(mine, "bodies", "integration_s")
    orders["us_per_step_vs_K_at_N"] = _order(by_clearances, "clearance_joints", "us_per_step")
    orders["integration_vs_K_at_N"] = _order(by_clearances, "clearance_joints", "integration_s")
    return {"t_end_s": t_end, "validated": validates(four_bar_chain(sizes[-1], 1, t_end), folder),
            "rows_by_size": by_size, "fixed_bars": fixed, "rows_by_clearances": by_clearances, "orders": orders}


def figure(result: dict, path: Path = FIGURE) -> Path:
    """Log–log plot of µs per step against bodies (K = 0, 1) and against K at fixed N."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for k, marker in ((0, "o"), (1, "s")):
        rows = [r for r in result["rows_by_size"] if r["clearance_joints"] == k and r["complete"]]
        order = result["orders"][f"us_per_step_vs_bodies_K{k}"]
        label = f"K = {k}" + (f" (slope {order:.2f})" if order is not None else "")
        left.loglog([r["bodies"] for r in rows], [r["us_per_step"] for r in rows], marker + "-", label=label)
    left.set_xlabel("moving bodies (2N + 1)")
    left.set_ylabel("integration µs per accepted step")
    left.set_title("four-bar chain: cost per step vs size")
    left.legend()
    rows = [r for r in result["rows_by_clearances"] if r["complete"]]
    order = result["orders"]["us_per_step_vs_K_at_N"]
    right.loglog([r["clearance_joints"] for r in rows], [r["us_per_step"] for r in rows], "d-",
                 label=f"N = {result['fixed_bars']}" + (f" (slope {order:.2f})" if order is not None else ""))
    right.set_xlabel("clearance joints K")
    right.set_ylabel("integration µs per accepted step")
    right.set_title("cost per step vs clearance joints")
    right.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
