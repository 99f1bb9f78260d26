"""What one right-hand side costs, part by part, and where the right-hand sides beyond six an accepted step go.

    python -m benchmarks.rhs_cost                          # the bundled breaker at 60 ms and the slider-crank
    python -m benchmarks.rhs_cost --json benchmarks/results/rhs-cost.json
    python -m benchmarks.rhs_cost --chains 64,128,256,512 --cpu   # pendulum chains, K = N/2, at 20 ms, CPU time

A model is integrated to a time in its stroke (the breaker at 60 ms: both joints in contact); at the state reached
each kernel of the right-hand side is called in a compiled loop (`count` calls, the minimum over `repeats` timings of
the loop, divided by `count`). "At a new q" alternates between that state and the one a 1e-9 relative change of its
positions away, so that every call factors S again as a stage of a step does; "at the same q" keeps the factor of the
previous call (the right-hand side at a step's end, after the projection). The parts are timed on their own, so their
sum differs from the whole by what the kernels share (the arrays in cache) and by the glue (copies, allocations).
The loop's counters of the whole run split the right-hand sides: six a try (accepted or rejected), one at each step's
end (after the projection), and the rest (the right-hand side after a mode switch, the step integrated again to an
event).
"""

from __future__ import annotations

import argparse
import functools
import json
import tempfile
import time
from pathlib import Path

import numpy as np
from numba import njit, typeof, types

from clearsim.assembly.constraints import (
    constraint_count, evaluate_acceleration_rhs, evaluate_jacobian_blocks, jacobian_times, jacobian_transpose_times,
    schur_complement,
)
from clearsim.assembly.drivelines import add_driveline_forces, driveline_powers
from clearsim.assembly.dynamics import (
    STICK, WORK_COUNT, accelerations, constrained_response, driver_power, dynamics_type, factored_jacobian,
    factorize, rhs, solve_factored, stick_count,
)
from clearsim.assembly.forces import add_applied_forces, add_clearance_forces, add_wear_rates, stick_row
from clearsim.assembly.hydraulics import add_hydraulic_forces, hydraulic_rates

CONFIGS = Path(__file__).resolve().parents[1] / "clearsim" / "configs"
CASES = {  # name: (config, time of the state timed)
    "uhv-c0.01": (CONFIGS / "uhv_breaker.yaml", 0.060),
    "crank-friction": (CONFIGS / "slider_crank_flores_friction.yaml", 0.012),
}


def state_at(config: Path, t_state: float, overrides: list[str] | None = None):
    """(run, kernel arrays, dynamics kernel) of `config` integrated by the compiled loop to t_state (its t_end)."""
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare
    from clearsim.solver import integrator as ig
    from clearsim.solver.simulate import Run

    run = Run(prepare(load_mechanism(config, [*(overrides or []), f"solver.t_end={t_state!r}s"])))
    for _ in run.chunks():
        pass
    return run, run.kernel_arrays, ig.addressed(ig.DOPRI5, run.lubricated)[2]


def _rhs_calls(system, dynamics, t, ya, yb, modes, speeds, ydot, count):
    total = 0.0
    for i in range(count):
        rhs(system, dynamics, t, ya if i % 2 == 0 else yb, modes, speeds, ydot)
        total += ydot[0]
    return total


def _rhs_timer(system):
    """_rhs_calls compiled with the dynamics by address, as the loop calls it (a dynamics passed as a dispatcher would
    compile, and cache, rhs once more for the dispatcher's type)."""
    real, vector, integers = types.float64, types.float64[::1], types.int64[::1]
    system_type = typeof(system)
    signature = real(system_type, dynamics_type(system_type), real, vector, vector, integers, vector, vector,
                     types.int64)
    return njit(signature)(_rhs_calls)


@njit
def _time_jacobian(system, qa, qb, blocks, bodies, count):
    total = 0.0
    for i in range(count):
        evaluate_jacobian_blocks(system, qa if i % 2 == 0 else qb, blocks, bodies)
        total += blocks[0, 0, 2]
    return total


@njit
def _time_stick_rows(system, qa, qb, qd, modes, count):
    total = 0.0
    for i in range(count):
        for k in range(modes.shape[0]):
            if modes[k] == STICK:
                total += stick_row(system, k, qa if i % 2 == 0 else qb, qd)[2]
    return total


@njit
def _time_schur(system, blocks, bodies, count):
    total = 0.0
    for _ in range(count):
        schur_complement(system, blocks, bodies)
        total += system.solve_schur[0, 0]
    return total


@njit
def _time_factorize(system, rows, count):
    total = 0.0
    for _ in range(count):
        factorize(system, rows)
        total += system.solve_lower[0, 0]
    return total


@njit
def _time_gamma(system, t, qa, qb, qd, gamma, count):
    total = 0.0
    for i in range(count):
        evaluate_acceleration_rhs(system, t, qa if i % 2 == 0 else qb, qd, gamma)
        total += gamma[0]
    return total


@njit
def _time_response(system, q, qd, modes, force, gamma, count):
    """constrained_response (Φ_q M⁻¹Q, the two substitutions, Φ_qᵀλ, M⁻¹) with the factor kept."""
    rows = constraint_count(system) + stick_count(modes)
    blocks, bodies = factored_jacobian(system, q, qd, modes, rows, np.zeros(rows))
    total = 0.0
    for _ in range(count):
        total += constrained_response(system, blocks, bodies, force, gamma)[0][0]
    return total


@njit
def _time_accelerations(system, t, qa, qb, qd, force, modes, count):
    total = 0.0
    for i in range(count):
        total += accelerations(system, t, qa if i % 2 == 0 else qb, qd, force, modes)[0][0]
    return total


@njit
def _time_clearance(system, q, qd, modes, speeds, count):
    total = 0.0
    generalized = np.zeros(q.shape[0])
    for _ in range(count):
        total += add_clearance_forces(system, q, qd, modes, speeds, generalized, None)[0]
    return total


@njit
def _time_applied(system, t, q, qd, count):
    total = 0.0
    generalized = np.zeros(q.shape[0])
    for _ in range(count):
        total += add_applied_forces(system, t, q, qd, generalized)[0]
        add_driveline_forces(system, t, q, qd, generalized)
    return total + generalized[0]


@njit
def _time_hydraulics(system, t, q, qd, z, zdot, count):
    total = 0.0
    generalized = np.zeros(q.shape[0])
    for _ in range(count):
        add_hydraulic_forces(system, q, z, generalized)
        total += hydraulic_rates(system, t, q, qd, z, zdot)[0]
    return total + generalized[0]


@njit
def _time_powers(system, t, q, qd, lam, modes, speeds, zdot, count):
    """The integrated powers: the driver's, the drivelines', the wear rates."""
    total = 0.0
    for _ in range(count):
        total += driver_power(system, t, lam) + driveline_powers(system, t, q, qd)[0]
        add_wear_rates(system, q, qd, modes, speeds, zdot)
    return total


@njit
def _refine(system, blocks, bodies, b, lam, product, residual, tolerance, max_iterations):
    """λ of S(q) λ = b with S's factor of another q (the scratch's) by iterative refinement, S products matrix-free
    (Φ_q M⁻¹ Φ_qᵀ x from the blocks at q); returns the refinements made until one changes λ by at most tolerance
    max |λ| (round-off: the residual itself cannot fall below ≈ ε ‖S‖ ‖λ‖)."""
    lam[:] = b
    solve_factored(system, lam)
    for iteration in range(max_iterations):
        _schur_times(system, blocks, bodies, lam, product, residual)
        for r in range(residual.shape[0]):
            residual[r] = b[r] - residual[r]
        solve_factored(system, residual)
        change, size = 0.0, 0.0
        for r in range(lam.shape[0]):
            lam[r] += residual[r]
            change = max(change, abs(residual[r]))
            size = max(size, abs(lam[r]))
        if change <= tolerance * size:
            return iteration + 1
    return max_iterations


@njit
def _schur_times(system, blocks, bodies, x, product, out):
    """out = Φ_q M⁻¹ Φ_qᵀ x from the blocks (product: scratch of the coordinates' size)."""
    minv = system.inverse_mass
    jacobian_transpose_times(blocks, bodies, x, product)
    for i in range(product.shape[0]):
        product[i] *= minv[i]
    jacobian_times(blocks, bodies, product, out)


@njit
def _conjugate_gradients(system, blocks, bodies, b, lam, product, tolerance, max_iterations):
    """λ of S(q) λ = b by conjugate gradients preconditioned with S's factor of another q (the scratch's), S products
    matrix-free; returns the iterations made until one changes λ by at most tolerance max |λ|."""
    m = b.shape[0]
    lam[:] = b
    solve_factored(system, lam)
    residual, preconditioned, direction, image = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    _schur_times(system, blocks, bodies, lam, product, image)
    for r in range(m):
        residual[r] = b[r] - image[r]
    preconditioned[:] = residual
    solve_factored(system, preconditioned)
    direction[:] = preconditioned
    rho = 0.0
    for r in range(m):
        rho += residual[r] * preconditioned[r]
    for iteration in range(max_iterations):
        _schur_times(system, blocks, bodies, direction, product, image)
        curvature = 0.0
        for r in range(m):
            curvature += direction[r] * image[r]
        if curvature <= 0.0:
            return iteration
        alpha = rho / curvature
        change, size = 0.0, 0.0
        for r in range(m):
            lam[r] += alpha * direction[r]
            residual[r] -= alpha * image[r]
            change = max(change, abs(alpha * direction[r]))
            size = max(size, abs(lam[r]))
        if change <= tolerance * size:
            return iteration + 1
        preconditioned[:] = residual
        solve_factored(system, preconditioned)
        rho_next = 0.0
        for r in range(m):
            rho_next += residual[r] * preconditioned[r]
        for r in range(m):
            direction[r] = preconditioned[r] + rho_next / rho * direction[r]
        rho = rho_next
    return max_iterations


@njit
def _time_refined(system, q_old, q_new, qd, modes, b, tolerance, count, gradients=False):
    """A stage's multipliers with the factor of the step's start kept: the blocks at the stage's q, then _refine (or
    _conjugate_gradients)."""
    m = constraint_count(system)
    factored_jacobian(system, q_old, qd, modes, m, np.zeros(m))
    blocks, bodies = np.zeros((m, 2, 3)), np.zeros((m, 2), np.int64)
    lam, product, residual = np.zeros(m), np.zeros(q_old.shape[0]), np.zeros(m)
    iterations = 0
    for _ in range(count):
        evaluate_jacobian_blocks(system, q_new, blocks, bodies)
        if gradients:
            iterations += _conjugate_gradients(system, blocks, bodies, b, lam, product, tolerance, 50)
        else:
            iterations += _refine(system, blocks, bodies, b, lam, product, residual, tolerance, 50)
    return iterations / count, lam


@njit
def _time_fresh(system, q_old, q_new, qd, modes, b, count):
    """The same multipliers as the loop computes them: S at the stage's q formed and factored, one solve."""
    m = constraint_count(system)
    lam = np.zeros(m)
    for i in range(count):
        blocks, bodies = factored_jacobian(system, q_new if i % 2 == 0 else q_old, qd, modes, m, np.zeros(m))
        lam[:] = b
        solve_factored(system, lam)
    factored_jacobian(system, q_new, qd, modes, m, np.zeros(m))
    lam[:] = b
    solve_factored(system, lam)
    return lam


def refinement(run, system, steps=(1e-6, 1e-5, 1e-4), count: int = 5000, repeats: int = 5) -> dict:
    """The multipliers of a stage a step h away (q + h q̇) with the factor of the step's start kept: refinements (and
    preconditioned conjugate gradients) to round-off (the last one changes λ by ≤ 4 ε max |λ|), µs per solve against
    forming and factoring S anew, and how far λ lands from the fresh solve's."""
    n = run.coordinate_count
    q, qd = run.y[:n].copy(), run.y[n:2 * n].copy()
    modes = np.zeros_like(run.modes)  # Φ's rows
    b = np.random.default_rng(28).normal(size=constraint_count(system))
    rows = {}
    for h in steps:
        q_new = q + h * qd
        iterations, refined = _time_refined(system, q, q_new, qd, modes, b, 4 * np.finfo(float).eps, 1)
        fresh = _time_fresh(system, q, q_new, qd, modes, b, 1)
        gradient_iterations, gradients = _time_refined(system, q, q_new, qd, modes, b, 4 * np.finfo(float).eps, 1,
                                                       True)
        rows[f"{h:g}"] = {
            "cg_iterations": gradient_iterations,
            "cg_us": _timed(lambda c: _time_refined(system, q, q_new, qd, modes, b, 4 * np.finfo(float).eps, c,
                                                           True), count, repeats),
            "cg_relative_difference": float(np.max(np.abs(gradients - fresh)) / np.max(np.abs(fresh))),
            "iterations": iterations,
            "refined_us": _timed(lambda c: _time_refined(system, q, q_new, qd, modes, b,
                                                                4 * np.finfo(float).eps, c), count, repeats),
            "fresh_us": _timed(lambda c: _time_fresh(system, q, q_new, qd, modes, b, c), count, repeats),
            "relative_difference": float(np.max(np.abs(refined - fresh)) / np.max(np.abs(fresh)))}
    return rows


def _timed(call, count: int, repeats: int, clock=time.perf_counter) -> float:
    call(1)
    best = np.inf
    for _ in range(repeats):
        started = clock()
        call(count)
        best = min(best, clock() - started)
    return best / count * 1e6


def breakdown(run, system, dynamics, count: int = 20000, repeats: int = 7, clock=time.perf_counter) -> dict:
    """µs per call of the right-hand side and of its parts at the run's state (module docstring), timed by `clock`
    (time.process_time: the process's CPU time, which on a shared machine leaves out the waits for a core)."""
    timed = functools.partial(_timed, clock=clock)

    n = run.coordinate_count
    t, y = run.time, run.y.copy()
    other = y.copy()
    other[:n] *= 1.0 + 1e-9
    modes, speeds = run.modes.copy(), run.speeds.copy()
    q, qd, z = y[:n], y[n:2 * n], y[2 * n + WORK_COUNT:]
    ydot = np.zeros_like(y)
    m = constraint_count(system)
    rows = m + int(np.sum(modes == STICK))
    blocks, bodies = np.zeros((m, 2, 3)), np.zeros((m, 2), np.int64)
    time_rhs = _rhs_timer(system)
    rhs_new = timed(lambda c: time_rhs(system, dynamics, t, y, other, modes, speeds, ydot, c), count, repeats)
    rhs_same = timed(lambda c: time_rhs(system, dynamics, t, y, y, modes, speeds, ydot, c), count, repeats)
    time_rhs(system, dynamics, t, y, y, modes, speeds, ydot, 1)
    force = np.zeros(n)
    force[:] = ydot[n:2 * n]  # any force will do for the timing
    gamma = np.zeros(rows)
    zdot = np.zeros_like(z)
    lam = np.ones(rows)
    parts = {
        "jacobian_blocks": timed(lambda c: _time_jacobian(system, q, other[:n], blocks, bodies, c), count,
                                         repeats),
        "stick_rows": timed(lambda c: _time_stick_rows(system, q, other[:n], qd, modes, c), count, repeats),
        "schur_complement": timed(lambda c: _time_schur(system, blocks, bodies, c), count, repeats),
        "factorize": timed(lambda c: _time_factorize(system, m, c), count, repeats),
        "gamma": timed(lambda c: _time_gamma(system, t, q, other[:n], qd, gamma[:m], c), count, repeats),
        "constrained_response": timed(lambda c: _time_response(system, q, qd, modes, force, gamma, c), count,
                                              repeats),
        "clearance_forces": timed(lambda c: _time_clearance(system, q, qd, modes, speeds, c), count, repeats),
        "applied_and_driveline_forces": timed(lambda c: _time_applied(system, t, q, qd, c), count, repeats),
        "hydraulics": timed(lambda c: _time_hydraulics(system, t, q, qd, z, zdot, c), count, repeats),
        "powers_and_wear_rates": timed(lambda c: _time_powers(system, t, q, qd, lam, modes, speeds, zdot, c),
                                               count, repeats),
    }
    accelerations_new = timed(lambda c: _time_accelerations(system, t, q, other[:n], qd, force, modes, c),
                                      count, repeats)
    return {"t_ms": t * 1e3, "modes": [int(mode) for mode in modes], "rows": rows,
            "rhs_new_q_us": rhs_new, "rhs_same_q_us": rhs_same, "accelerations_new_q_us": accelerations_new,
            "parts_us": parts, "parts_sum_us": sum(parts.values())}


def rhs_accounting(config: Path, overrides: list[str] | None = None) -> dict:
    """The run's right-hand sides: six a try (accepted and rejected), one at each step's end, and the rest."""
    from clearsim.runner import prepare
    from clearsim.model.loader import load_mechanism
    from clearsim.solver import integrator as ig
    from clearsim.solver.simulate import Run

    run = Run(prepare(load_mechanism(config, overrides or [])))
    for _ in run.chunks():
        pass
    steps, rejected, evaluations = (int(run.ints[i]) for i in (ig.I_STEPS, ig.I_REJECTED, ig.I_RHS))
    events = int(run.ints[ig.I_EVENTS] + run.ints[ig.I_FRICTION_EVENTS])
    return {"steps": steps, "rejected": rejected, "rhs": evaluations, "events": events,
            "samples": int(run.ints[ig.I_TOTAL_SAMPLES]), "integration_s": run.wall_time,
            "rhs_per_step": evaluations / steps, "accepted_tries_rhs": 6 * steps, "rejected_tries_rhs": 6 * rejected,
            "step_end_rhs": steps, "other_rhs": evaluations - 7 * steps - 6 * rejected}


def chain_breakdowns(sizes, count: int, repeats: int, clock, t_state: float = 0.020) -> dict:
    """breakdown of the N-link pendulum chain with K = N/2 clearance joints at t_state for each N, count / N calls a
    timing (at least 400), so that each timing takes about as long."""
    from benchmarks.chain import pendulum_chain

    results = {}
    with tempfile.TemporaryDirectory(prefix="clearsim-rhs-cost-") as folder:
        for links in sizes:
            config = Path(folder) / f"chain-{links}.yaml"
            config.write_text(pendulum_chain(links, links // 2, t_state))
            run, system, dynamics = state_at(config, t_state)
            results[f"chain-{links}"] = breakdown(run, system, dynamics, max(400, 20 * count // links), repeats, clock)
    return results


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--count", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--chains", help="instead of --cases: the pendulum chains (benchmarks/chain.py) of these link "
                        "counts N, K = N/2 clearance joints, at their state at 20 ms (the parts alone)")
    parser.add_argument("--cpu", action="store_true", help="time by the process's CPU time, not the wall clock")
    args = parser.parse_args(argv)
    clock = time.process_time if args.cpu else time.perf_counter
    if args.chains:
        results = chain_breakdowns([int(n) for n in args.chains.split(",")], args.count, args.repeats, clock)
        print(json.dumps(results, indent=1))
        if args.json:
            args.json.write_text(json.dumps(results, indent=1) + "\n")
        return 0
    results = {}
    for name in args.cases.split(","):
        config, t_state = CASES[name]
        run, system, dynamics = state_at(config, t_state)
        print(name, "state at", run.time, "modes", run.modes, flush=True)
        result = breakdown(run, system, dynamics, args.count, args.repeats, clock)
        result["refinement"] = refinement(run, system)
        print(name, "refinement", result["refinement"], flush=True)
        result["accounting"] = rhs_accounting(config)
        results[name] = result
        print(name, json.dumps(result, indent=1))
    if args.json:
        args.json.write_text(json.dumps(results, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
