"""Chain: an N-link pendulum with K clearance joints, the cost per right-hand side and per step against N.

    python -m benchmarks --cases chain                      # N = 2 … 256, K = 0, 1, N/2; 5 repeats
    python -m benchmarks.chain --sizes 2,16,128 --t-end 0.05 --repeats 3 --json /tmp/chain.json

Each link is a 0.1 m steel bar (10 mm × 10 mm, 78.5 g), hanging in a horizontal line at t = 0 and pinned to the
next; the first joint (to the ground) is driven at 60 rpm, gravity pulls the rest. The last K joints (at the free
end) have 0.1 mm radial clearance. The constraint rows are m = 2(N − K) + 1 (a clearance joint's pin is a contact
force, not two rows), so at K = 0 and 1 the cost per right-hand side against N is the constrained solve's against m.
Each run's wall time and the process's CPU time are both kept (us_per_* and cpu_us_per_*); on a shared machine the
CPU time is the one to read. benchmarks/results/chain.json holds such a result under "chain", with the right-hand
side's parts, the event search's counts a step and the measurements against the dense loops beside it.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import tempfile
import time
from pathlib import Path

from benchmarks.scaling import timed_run

LENGTH, SECTION, DENSITY = 0.1, 0.01, 7850.0  # m, m, kg/m³
MASS = DENSITY * LENGTH * SECTION**2  # kg
INERTIA = MASS * (LENGTH**2 + SECTION**2) / 12.0  # kg m² about the centre
SIZES = (2, 4, 8, 16, 32, 64, 128, 256)
T_END = 0.2  # s


def pendulum_chain(links: int, clearance_joints: int, t_end: float = T_END) -> str:
    """YAML of an N-link pendulum chain whose last K joints have 0.1 mm clearance."""
    lines = ["name: pendulum chain", "units: SI  # the coordinates and masses below are written in m and kg",
             "gravity: [0, -9.81]",
             "defaults: {bearing_radius: 5 mm, material: {youngs_modulus: 207 GPa, poisson_ratio: 0.3}, "
             "contact: {law: lankarani_nikravesh, restitution: 0.9, stiffness: auto}, friction: {law: none}}",
             "bodies:"]
    joints = []
    for i in range(links):
        lines.append(f"  - {{name: link{i}, mass: {MASS!r}, inertia: {INERTIA!r}, position: [{LENGTH * (i + 0.5)!r}, 0.0]}}")
        parent = "ground" if i == 0 else f"link{i - 1}"
        clearance = ", clearance: 0.1 mm" if i >= links - clearance_joints else ""
        joints.append(f"  - {{name: J{i}, type: revolute, bodies: [{parent}, link{i}], at: [{LENGTH * i!r}, 0.0]{clearance}}}")
    lines += ["joints:", *joints,
              "drivers:", "  - {name: motor, joint: J0, motion: {law: constant_speed, speed: 60 rpm}}",
              "sensors:", f"  - {{name: tip_angle, type: body_angle, body: link{links - 1}}}",
              f"solver: {{t_end: {t_end!r}, output_rate: 1 kHz}}"]
    return "\n".join(lines) + "\n"


def cpu_timed_run(system) -> dict:
    """timed_run with the process's CPU time of the run (cpu_s): on a shared machine the wall time counts the time the
    process waits for a core, its CPU time does not."""
    started = time.process_time()
    result = timed_run(system)
    result["cpu_s"] = time.process_time() - started
    return result


def row(links: int, clearances: int, t_end: float, repeats: int, folder: Path) -> dict:
    """Medians over `repeats` timed runs (after one untimed run) of one chain, of the wall time and of the CPU time."""
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare

    loaded = load_mechanism_text(pendulum_chain(links, clearances, t_end), f"chain-{links}-{clearances}.yaml", (), folder)
    system = prepare(loaded)
    cpu_timed_run(system)  # warm-up: this size's first call
    runs = [cpu_timed_run(system) for _ in range(repeats)]
    walls = [r["integration_s"] for r in runs]
    last = runs[-1]
    return {"links": links, "clearance_joints": clearances, "constraint_rows": 2 * (links - clearances) + 1,
            "complete": all(r["complete"] for r in runs), "steps": last["steps"], "rhs_evaluations": last["rhs_evaluations"],
            "integration_median_s": statistics.median(walls), "integration_min_s": min(walls),
            "integration_max_s": max(walls),
            "us_per_rhs": statistics.median(1e6 * r["integration_s"] / max(r["rhs_evaluations"], 1) for r in runs),
            "us_per_step": statistics.median(1e6 * r["integration_s"] / max(r["steps"], 1) for r in runs),
            "cpu_us_per_rhs": statistics.median(1e6 * r["cpu_s"] / max(r["rhs_evaluations"], 1) for r in runs),
            "cpu_us_per_step": statistics.median(1e6 * r["cpu_s"] / max(r["steps"], 1) for r in runs)}


def local_orders(rows: list[dict], key: str) -> list[float | None]:
    """d log(key) / d log(N) between each row and the previous one (None for the first)."""
    orders: list[float | None] = [None]
    for before, after in zip(rows, rows[1:]):
        orders.append(math.log(after[key] / before[key]) / math.log(after["links"] / before["links"]))
    return orders


def series(label: str, clearances_of, sizes, t_end: float, repeats: int, folder: Path) -> dict:
    """One family of chains (K a function of N) with, per row, the local order and the cost per link as a ratio to
    the smallest chain's (the baseline in the same run: 1 for a cost linear in N with no fixed part)."""
    rows = [row(n, clearances_of(n), t_end, repeats, folder) for n in sizes]
    for key in ("us_per_rhs", "us_per_step", "cpu_us_per_rhs", "cpu_us_per_step"):
        for r, order in zip(rows, local_orders(rows, key)):
            r[f"order_{key}"] = order
            r[f"{key}_per_link_ratio"] = (r[key] / r["links"]) / (rows[0][key] / rows[0]["links"])
    return {"family": label, "rows": rows}


FAMILIES = (("K = 0", lambda n: 0), ("K = 1", lambda n: 1), ("K = N/2", lambda n: n // 2))


def chain(quick: bool, folder: Path, measurements=None, repeats: int = 5, sizes=None, t_end: float | None = None) -> dict:
    """The chain study: K = 0, 1 and N/2 for each N in sizes (quick: N ≤ 16, 0.02 s)."""
    sizes = tuple(sizes or (SIZES[:4] if quick else SIZES))
    t_end = t_end or (0.02 if quick else T_END)
    return {"t_end_s": t_end, "repeats": repeats, "sizes": list(sizes),
            "families": [series(label, of, sizes, t_end, repeats, folder) for label, of in FAMILIES]}


def describe(result: dict) -> str:
    lines = [f"chain (N-link pendulum, {result['t_end_s']} s, medians of {result['repeats']}): CPU µs per RHS"]
    for family in result["families"]:
        cells = ", ".join(f"N={r['links']} {r['cpu_us_per_rhs']:.1f}" + (f" (order {r['order_cpu_us_per_rhs']:.2f})"
                                                                           if r["order_cpu_us_per_rhs"] is not None
                                                                           else "")
                          for r in family["rows"])
        lines.append(f"  {family['family']}: {cells}")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.chain", description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)), help="comma-separated link counts N")
    parser.add_argument("--t-end", type=float, default=T_END, help="simulated time, s")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json", type=Path, help="write the result here")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="clearsim-chain-") as tmp:
        result = chain(False, Path(tmp), repeats=args.repeats, sizes=[int(s) for s in args.sizes.split(",")],
                       t_end=args.t_end)
    print(describe(result))
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
