"""Where the integrator's steps go: one row per accepted step of a run, and a breakdown.

    python -m benchmarks.step_trace                                   # the bundled breaker (A and J at 0.01 mm)
    python -m benchmarks.step_trace --set joints.A.clearance=0.1mm --set joints.J.clearance=0.1mm
    python -m benchmarks.step_trace --csv steps.csv

A run that fails stops the trace where it stops `clearsim run`, with the rows up to there, the run's message and exit
code 2.

The compiled loop is called once per accepted step (a return at the top of the loop changes no result), so each
row has: the step h, the rejected tries before it, each clearance joint's mode (free / contact / stick / slide
back), whether the step follows a mode switch, and for the step's first try (recomputed from the saved state) the
error component that dominates the error norm (a body's x, y, θ or its rate, an element state), and whether a
joint's sliding speed crossed the stiction band's ends v_s, v_d or its damping's clip (F_n = 0 with δ > 0) in the
step (kinks of the right-hand side). For each joint in contact: h·|λ| of its normal contact as a linear
oscillator, m λ² + c λ + k = 0 with k = ∂F_n/∂δ (n K δ^(n−1) for a power law) and c = ∂F_n/∂δ̇ (the damping
D K δ^n/δ̇⁻, D = 3(1 − e²)/4 for Lankarani–Nikravesh; 0 where the law clips F_n to 0), m the effective mass, and
|R(hλ)| of DOPRI5's stability function there: above 1 the step amplifies the contact's mode (stability-limited);
h|λ| far below DOPRI5's boundary ≈ 3.3: accuracy-limited. `--jacobian-every N` also takes the eigenvalues of the
whole system's finite-difference Jacobian every N steps (the same picture without the one-joint model).
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections import Counter
from pathlib import Path

import numpy as np
from numba import njit, typeof, types

from clearsim.solver.dopri import MATRIX, STAGES, WEIGHTS, step
from clearsim.solver.rosenbrock import evaluate_jacobian

UHV = Path(__file__).resolve().parents[1] / "clearsim" / "configs" / "uhv_breaker.yaml"
MODE_NAMES = {0: "free", 1: "contact", 2: "stick", 3: "slide_back"}
COORDINATE = ("x", "y", "θ")


def trial_error(system, dynamics, t, y, f, h, modes, speeds):
    """The error vector and y_new of one DOPRI5 try (the loop's own step)."""
    stages = np.empty((STAGES, y.shape[0]))
    y_new = np.empty_like(y)
    error = step(system, dynamics, t, y, f, h, modes, speeds, stages, y_new)
    return error, y_new


def whole_jacobian(system, dynamics, t, y, f, h, modes, speeds, skipped_from, skipped_count, floor, jacobian, record):
    """rosenbrock's finite-difference Jacobian into jacobian (record: evaluate_jacobian's, which it reads and writes)."""
    return evaluate_jacobian(system, dynamics, t, y, f, h, modes, speeds, skipped_from, skipped_count, floor, jacobian,
                             record)


def by_address(arrays, lubricated: bool):
    """trial_error and whole_jacobian compiled for these kernel arrays with the dynamics taken by address, as the
    integrator's loop takes it (integrator.addressed_kernels): the cached kernels they call (the right-hand side,
    evaluate_jacobian) are then compiled for a function signature, found in the cache by the next process, and not
    for this process's dispatcher object, whose type the cache index cannot store again once that object is gone."""
    from clearsim.solver import integrator as ig

    system_type = typeof(arrays)
    dynamics = ig.addressed_kernels(system_type, ig.DOPRI5, lubricated)[2][1]
    F, I, V, IV, M = types.float64, types.int64, types.float64[::1], types.int64[::1], types.float64[:, ::1]
    trial = njit(types.Tuple((V, V))(system_type, dynamics, F, V, V, F, IV, V))(trial_error)
    jacobian = njit(I(system_type, dynamics, F, V, V, F, IV, V, I, I, F, M, IV))(whole_jacobian)
    return trial, jacobian


def stability_function(z: complex) -> complex:
    """R(z) = 1 + z bᵀ (I − zA)⁻¹ 1 of DOPRI5 (its 7th stage only gives the error estimate)."""
    a = np.zeros((6, 6))
    a[:, :5] = MATRIX
    return 1.0 + z * WEIGHTS @ np.linalg.solve(np.eye(6) - z * a, np.ones(6))


def contact_eigenvalues(arrays, k, y, modes, speeds, n) -> tuple[np.ndarray, float, float]:
    """Roots of m λ² + c λ + k = 0 for joint k's normal contact linearised at its state: k = ∂F_n/∂δ,
    c = ∂F_n/∂δ̇ (the damping D F_el/δ̇⁻, zero where the law clips F_n to 0) by central differences, m the
    effective mass now; and (k, c)."""
    from clearsim.assembly.dynamics import effective_mass
    from clearsim.assembly.forces import clearance_kinematics, contact_force_magnitudes

    kin = clearance_kinematics(arrays, k, y[:n], y[n:2 * n])
    depth, rate, sliding = kin[4], kin[5], kin[8]

    def force(d, r):
        return contact_force_magnitudes(arrays, k, d, r, sliding, modes[k], speeds[k])[0]

    d_step, r_step = 1e-6 * depth, 1e-6 * max(abs(rate), 1e-4)
    stiffness = (force(depth + d_step, rate) - force(depth - d_step, rate)) / (2.0 * d_step)
    damping = (force(depth, rate + r_step) - force(depth, rate - r_step)) / (2.0 * r_step)
    mass = effective_mass(arrays, k, y[:n], modes)
    return np.roots([mass, damping, stiffness]), stiffness, damping


def damping_clipped(arrays, k, y, modes, speeds, n) -> bool:
    """Joint k penetrates, but its damping term cancels the elastic force (F_n = max(0, F_el (1 + D δ̇/δ̇⁻)) = 0):
    the force's kink lies between this state and the one where F_n > 0."""
    from clearsim.assembly.forces import FREE, clearance_kinematics, contact_force_magnitudes

    kin = clearance_kinematics(arrays, k, y[:n], y[n:2 * n])
    return bool(modes[k] != FREE and kin[4] > 0.0
                and contact_force_magnitudes(arrays, k, kin[4], kin[5], kin[8], modes[k], speeds[k])[0] == 0.0)


def component_name(system, index: int) -> str:
    n = system.coordinate_count
    if index < 2 * n:
        body = system.body_names[(index % n) // 3]
        return f"{body}.{'d' if index >= n else ''}{COORDINATE[index % 3]}"
    return f"state[{index}]"


def jacobian_stability(jacobian_of, arrays, dynamics, t, y, f, h, tried, modes, speeds, n, floor,
                       no_jacobian_yet) -> dict:
    """The whole system's picture: eigenvalues of the finite-difference ∂f/∂y of q, q̇ (rosenbrock's), the largest
    h·|λ| and max |R(hλ)| over them at the accepted and at the first-tried step. no_jacobian_yet: a new zeroed record
    shaped as the run's jacobian_modes (the modes and the two counts after them, which evaluate_jacobian reads and
    writes), so every column is taken; jacobian_of: whole_jacobian compiled by_address."""
    from clearsim.assembly.dynamics import WORK_COUNT

    jacobian = np.zeros((y.size, y.size + 1))
    jacobian_of(arrays, dynamics, t, y, f, h, modes, speeds, 2 * n, WORK_COUNT, floor, jacobian, no_jacobian_yet)
    eigenvalues = np.linalg.eigvals(jacobian[:2 * n, :2 * n])
    fastest = eigenvalues[np.argmax(np.abs(eigenvalues))]
    return {"jac_h_lambda": float(h * abs(fastest)), "jac_fastest_real": float(fastest.real),
            "jac_fastest_imag": float(abs(fastest.imag)),
            "jac_R": float(max(abs(stability_function(h * z)) for z in eigenvalues)),
            "jac_tried_R": float(max(abs(stability_function(tried * z)) for z in eigenvalues))}


def trace(config: Path, overrides: list[str], jacobian_every: int = 0) -> tuple[list[dict], object, Exception | None]:
    """The rows of the run's accepted steps, the run, and the SolverError that stopped it early (None: it reached
    t_end): a failure status of the loop or a hopeless pace (Run.judge_pace) stops the trace as it stops a run."""
    from clearsim.errors import SolverError
    from clearsim.assembly.dynamics import WORK_COUNT, wear_state_count
    from clearsim.assembly.forces import FREE, clearance_kinematics
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare
    from clearsim.solver import integrator as ig
    from clearsim.solver.simulate import Run, _initial_step

    system = prepare(load_mechanism(config, overrides))
    run = Run(system)
    arrays, dynamics = run.kernel_arrays, ig.addressed(ig.DOPRI5, run.lubricated)[2]
    n = system.coordinate_count
    rtol, atol = run.real[ig.R_RTOL], run.real[ig.R_ATOL]
    trial, jacobian_of = by_address(arrays, run.lubricated)
    controlled = np.r_[np.arange(2 * n), np.arange(2 * n + WORK_COUNT, run.y.size - wear_state_count(arrays))]
    rows: list[dict] = []
    while True:
        t = run.time
        y, f, modes, speeds = run.y.copy(), run.f.copy(), run.modes.copy(), run.speeds.copy()
        rejected, events = int(run.ints[ig.I_REJECTED]), int(run.ints[ig.I_EVENTS] + run.ints[ig.I_FRICTION_EVENTS])
        tried = min(run.real[ig.R_STEP], run.real[ig.R_MAX_STEP], run.real[ig.R_T_END] - t,
                    ig.free_flight_limit(arrays, y, modes))
        run._advance(np.nextafter(t, np.inf))
        run.ints[ig.I_SAMPLES] = 0
        status = int(run.ints[ig.I_STATUS])
        if status == ig.FIRST_STEP:
            run.real[ig.R_STEP] = _initial_step(system, run.y, run.f)
            continue
        if status not in (ig.DONE, ig.CHUNK_END, ig.BUFFER_FULL, ig.PAUSED):
            return rows, run, run._failure(status)
        try:
            run.judge_pace()
        except SolverError as collapse:
            return rows, run, collapse
        if run.time <= t:
            if status == ig.DONE:
                break
            continue
        row = {"t": t, "h": run.time - t, "rejected": int(run.ints[ig.I_REJECTED]) - rejected, "tried": tried,
               "after_switch": bool(rows) and rows[-1]["switched"],
               "switched": int(run.ints[ig.I_EVENTS] + run.ints[ig.I_FRICTION_EVENTS]) > events
               or not np.array_equal(modes, run.modes)}
        error, y_new = trial(arrays, dynamics, t, y, f, max(tried, run.real[ig.R_MIN_STEP]), modes, speeds)
        scaled = (error / (atol + rtol * np.maximum(np.abs(y), np.abs(y_new))))[controlled]
        worst = int(np.argmax(np.abs(scaled)))
        row["limiting"] = component_name(system, int(controlled[worst]))
        row["limiting_share"] = float(scaled[worst] ** 2 / max(np.sum(scaled**2), 1e-300))
        row["first_norm"] = float(np.sqrt(np.sum(scaled**2) / (run.y.size - WORK_COUNT - wear_state_count(arrays))))
        if jacobian_every and len(rows) % jacobian_every == 0:
            row.update(jacobian_stability(jacobian_of, arrays, dynamics, t, y, f, row["h"], tried, modes, speeds, n, atol / rtol,
                                          np.zeros_like(run.jacobian_modes)))
        for k, name in enumerate(system.clearance_joints):
            row[f"sliding_{name}"] = clearance_kinematics(arrays, k, y[:n], y[n:2 * n])[8]
            row[f"sliding_end_{name}"] = clearance_kinematics(arrays, k, run.y[:n], run.y[n:2 * n])[8]
            row[f"clipped_{name}"] = damping_clipped(arrays, k, y, modes, speeds, n)
            row[f"clipped_end_{name}"] = damping_clipped(arrays, k, run.y, modes, speeds, n)
            row[f"mode_{name}"] = MODE_NAMES[int(modes[k])]
            row[f"h_lambda_{name}"] = 0.0
            row[f"R_{name}"] = 0.0
            if modes[k] == FREE or run.episode_of[k] < 0:
                continue
            if clearance_kinematics(arrays, k, y[:n], y[n:2 * n])[4] <= 0.0:
                continue
            roots, row[f"k_{name}"], row[f"c_{name}"] = contact_eigenvalues(arrays, k, y, modes, speeds, n)
            h = row["h"]
            row[f"h_lambda_{name}"] = float(np.max(np.abs(roots)) * h)
            row[f"R_{name}"] = float(max(abs(stability_function(h * r)) for r in roots))
            row[f"tried_R_{name}"] = float(max(abs(stability_function(tried * r)) for r in roots))
        rows.append(row)
        if status == ig.DONE:
            break
    return rows, run, None


def band_crossings(rows: list[dict], bands: dict[str, tuple[float, float]]) -> list[dict]:
    """The steps in which a sliding joint's |v_t| crossed an end of its stiction band (v_s or v_d): kinks of
    μ(v), the STEP blend being C¹ only."""
    return [r for r in rows if any(
        r[f"mode_{j}"] in ("contact", "slide_back")
        and (abs(r[f"sliding_{j}"]) - v) * (abs(r[f"sliding_end_{j}"]) - v) < 0.0
        for j, ends in bands.items() for v in ends)]


def breakdown(rows: list[dict], joints: list[str], bands: dict[str, tuple[float, float]]) -> str:
    """The summary: steps and rejects by mode combination, the limiting components, the stability picture.
    DOPRI5's real stability boundary is h|λ| ≈ 3.3; |R(hλ)| > 1: the step amplifies that mode."""
    lines = [f"{len(rows)} accepted steps, {sum(r['rejected'] for r in rows)} rejected"]
    by_modes: dict[str, list[dict]] = {}
    for r in rows:
        by_modes.setdefault(" ".join(f"{j}:{r[f'mode_{j}']}" for j in joints), []).append(r)
    lines.append("modes | steps | rejected | time share | median h | median, max h·|λ| of the contacts | steps with |R(hλ)| > 1")
    total_time = sum(r["h"] for r in rows)
    for key, group in sorted(by_modes.items(), key=lambda item: -len(item[1])):
        hl = [max(r[f"h_lambda_{j}"] for j in joints) for r in group]
        near = sum(1 for r in group if max(r[f"R_{j}"] for j in joints) > 1.0)
        lines.append(f"{key} | {len(group)} | {sum(r['rejected'] for r in group)} | "
                     f"{sum(r['h'] for r in group) / total_time:.3f} | {np.median([r['h'] for r in group]):.3g} | "
                     f"{np.median(hl):.3g}, {np.max(hl):.3g} | {near}")
    after = [r for r in rows if r["after_switch"]]
    lines.append(f"steps right after a mode switch: {len(after)}, rejected before them: "
                 f"{sum(r['rejected'] for r in after)}")
    rejecting = [r for r in rows if r["rejected"] > 0]
    lines.append(f"steps with rejects: {len(rejecting)}; of those with |R(h_tried λ)| > 1 at the first try: "
                 f"{sum(1 for r in rejecting if max(r.get(f'tried_R_{j}', 0.0) for j in joints) > 1.0)}")
    for j in joints:
        kinked = [r for r in rows if r[f"clipped_{j}"] != r[f"clipped_end_{j}"]]
        clipped = [r for r in rows if r[f"clipped_{j}"] and r[f"clipped_end_{j}"]]
        lines.append(f"joint {j}: steps across the damping's clip (F_n = 0 with δ > 0 at one end): {len(kinked)}, "
                     f"rejected before them: {sum(r['rejected'] for r in kinked)}; steps clipped throughout: "
                     f"{len(clipped)} (rejected {sum(r['rejected'] for r in clipped)})")
    crossing = band_crossings(rows, bands)
    lines.append(f"steps across an end of the stiction band (v_s, v_d): {len(crossing)}, rejected before them: "
                 f"{sum(r['rejected'] for r in crossing)}")
    sampled = [r for r in rows if "jac_h_lambda" in r]
    if sampled:
        values = np.array([r["jac_h_lambda"] for r in sampled])
        lines.append(f"whole-system Jacobian at {len(sampled)} steps: h·max|λ| median {np.median(values):.3g}, 90 % "
                     f"{np.percentile(values, 90):.3g}, max {values.max():.3g}; |λ| median "
                     f"{np.median(values / np.array([r['h'] for r in sampled])):.3g} 1/s")
    limiting = Counter(r.get("limiting") for r in rows)
    lines.append("dominant error component (first try), steps: " +
                 ", ".join(f"{name} {count}" for name, count in limiting.most_common(8)))
    limiting_rejects = Counter()
    for r in rejecting:
        limiting_rejects[r.get("limiting")] += r["rejected"]
    lines.append("... of the rejected tries: " +
                 ", ".join(f"{name} {count}" for name, count in limiting_rejects.most_common(8)))
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--config", type=Path, default=UHV)
    parser.add_argument("--set", action="append", default=[], help="a config override, as `clearsim run --set`")
    parser.add_argument("--jacobian-every", type=int, default=0,
                        help="every this many steps, the eigenvalues of the finite-difference Jacobian (0: none)")
    parser.add_argument("--csv", type=Path, help="write the rows to this CSV file")
    args = parser.parse_args(argv)
    from clearsim.assembly.arrays import CL_V_HIGH, CL_V_LOW

    rows, run, stopped = trace(args.config, args.set, args.jacobian_every)
    joints = run.system.clearance_joints
    params = run.system.arrays.clearance_params
    bands = {j: (params[k, CL_V_LOW], params[k, CL_V_HIGH]) for k, j in enumerate(joints)}
    print(breakdown(rows, joints, bands))
    if args.csv:
        keys = sorted({key for r in rows for key in r})
        with args.csv.open("w", newline="") as handle:
            writer = csv.DictWriter(handle, keys)
            writer.writeheader()
            writer.writerows(rows)
    if stopped is not None:
        print(f"the trace stops after {len(rows)} steps: {stopped}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
