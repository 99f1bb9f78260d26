"""Equations of motion and constraint stabilisation (compiled).

M q̈ + Φ_qᵀ λ = Q (Meng 2015 eq. 14/15) with Φ_q q̈ = γ. M is diagonal (m, m, J per body),
so λ comes from the Schur complement S λ = Φ_q M⁻¹ Q − γ, S = Φ_q M⁻¹ Φ_qᵀ (symmetric
positive definite when no constraint is redundant, which assembly checks), then
q̈ = M⁻¹ (Q − Φ_qᵀ λ). After each step the state is projected onto Φ = 0 and Φ_q q̇ = ν
in the kinetic-energy metric M (the projection method of Hairer, Lubich & Wanner,
Geometric Numerical Integration, §IV.4), which keeps ‖Φ‖ at round-off level.

The state vector is y = [q, q̇, W], W the integrated powers (WORK_* below).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.constraints import (
    constraint_count, evaluate_acceleration_rhs, evaluate_constraints, evaluate_jacobian_blocks, evaluate_velocity_rhs,
    jacobian_blocks, jacobian_times, jacobian_transpose_times, prescribed, schur_complement,
)
from clearsim.assembly.forces import (
    STICK, add_applied_forces, add_clearance_forces, add_global_force, clearance_kinematics, stick_row,
)
from clearsim.assembly.kinematics import point_position
from clearsim.assembly.arrays import CL_BEARING_POINT, copy_into

WORK_DRIVER = 0
WORK_CONTACT = 1
WORK_FRICTION = 2
WORK_DAMPING = 3
WORK_APPLIED = 4
WORK_COUNT = 5


@njit(cache=True)
def coordinate_count(system):
    return 3 * system.mass.shape[0]


@njit(cache=True)
def inverse_mass(system):
    """Diagonal of M⁻¹."""
    nb = system.mass.shape[0]
    minv = np.empty(3 * nb)
    for b in range(nb):
        minv[3 * b] = 1.0 / system.mass[b]
        minv[3 * b + 1] = 1.0 / system.mass[b]
        minv[3 * b + 2] = 1.0 / system.inertia[b]
    return minv


@njit(cache=True)
def cholesky_solve(matrix, rhs):
    """Solve S x = b for symmetric positive definite S (small, dense); returns x (NaN if not SPD).

    Envelope (skyline) Cholesky: row i of L starts where row i of S does (first[i]), since the
    factor has no fill-in left of the envelope, so the zeros of a chain's S cost nothing.
    """
    m = rhs.shape[0]
    first = np.empty(m, np.int64)
    for i in range(m):
        first[i] = i
        for j in range(i):
            if matrix[i, j] != 0.0:
                first[i] = j
                break
    lower = np.zeros((m, m))
    for i in range(m):
        for j in range(first[i], i + 1):
            acc = matrix[i, j]
            for k in range(max(first[i], first[j]), j):
                acc -= lower[i, k] * lower[j, k]
            if i == j:
                if acc <= 0.0:
                    return np.full(m, np.nan)
                lower[i, i] = np.sqrt(acc)
            else:
                lower[i, j] = acc / lower[j, j]
    x = rhs.copy()
    for i in range(m):
        for k in range(first[i], i):
            x[i] -= lower[i, k] * x[k]
        x[i] /= lower[i, i]
    for i in range(m - 1, -1, -1):
        for k in range(i + 1, m):
            if first[k] <= i:
                x[i] -= lower[k, i] * x[k]
        x[i] /= lower[i, i]
    return x


@njit(cache=True)
def constrained_response(blocks, bodies, minv, force, gamma):
    """(a, λ) with a = M⁻¹ (f − Φ_qᵀ λ) and Φ_q a = γ."""
    lam = cholesky_solve(schur_complement(blocks, bodies, minv), jacobian_times(blocks, bodies, minv * force) - gamma)
    return minv * (force - jacobian_transpose_times(blocks, bodies, lam, force.shape[0])), lam


@njit(cache=True)
def minimum_norm_correction(blocks, bodies, minv, residual, n):
    """M⁻¹Φ_qᵀ S⁻¹ r: the smallest change (in the M metric) that removes a constraint residual r."""
    lam = cholesky_solve(schur_complement(blocks, bodies, minv), residual)
    return minv * jacobian_transpose_times(blocks, bodies, lam, n)


@njit(cache=True)
def stick_count(modes):
    """Number of clearance joints sticking (each adds a row v_t = 0)."""
    count = 0
    for k in range(modes.shape[0]):
        if modes[k] == STICK:
            count += 1
    return count


@njit(cache=True)
def stick_row_index(system, modes, k):
    """Row of sticking joint k in jacobian_with_sticks: after Φ's rows, in joint order."""
    row = constraint_count(system)
    for other in range(k):
        if modes[other] == STICK:
            row += 1
    return row


@njit(cache=True)
def jacobian_with_sticks(system, q, qd, modes):
    """(blocks, bodies, Ġq̇ of the stick rows): Φ_q with one row G per sticking joint appended."""
    m = constraint_count(system)
    sticking = stick_count(modes)
    blocks = np.empty((m + sticking, 2, 3))
    bodies = np.empty((m + sticking, 2), np.int64)
    evaluate_jacobian_blocks(system, q, blocks, bodies)
    curvature = np.zeros(sticking)
    row = m
    for k in range(modes.shape[0]):
        if modes[k] == STICK:
            bearing_block, journal_block, curvature[row - m] = stick_row(system, k, q, qd)
            bodies[row, 0] = system.clearance_bodies[k, 0]
            bodies[row, 1] = system.clearance_bodies[k, 1]
            for c in range(3):
                blocks[row, 0, c] = bearing_block[c]
                blocks[row, 1, c] = journal_block[c]
            row += 1
    return blocks, bodies, curvature


@njit(cache=True)
def accelerations(system, t, q, qd, generalized, modes):
    """(q̈, λ) from M q̈ + Φ_qᵀ λ = Q, Φ_q q̈ = γ; λ ends with −F_t of each sticking joint."""
    m = constraint_count(system)
    sticking = stick_count(modes)
    minv = inverse_mass(system)
    if m + sticking == 0:
        return minv * generalized, np.zeros(0)
    blocks, bodies, curvature = jacobian_with_sticks(system, q, qd, modes)
    gamma = np.empty(m + sticking)
    evaluate_acceleration_rhs(system, t, q, qd, gamma)
    for i in range(sticking):
        gamma[m + i] = -curvature[i]
    return constrained_response(blocks, bodies, minv, generalized, gamma)


@njit(cache=True)
def driver_power(system, t, lam):
    """Power of the driving constraints, −Σ λ_r ṡ_r(t) over rheonomic rows."""
    power = 0.0
    row = 2 * system.pin_bodies.shape[0]
    for k in range(system.offset_bodies.shape[0]):
        power -= lam[row] * prescribed(system, system.offset_law[k], t)[1]
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        power -= lam[row] * prescribed(system, system.angle_law[k], t)[1]
        row += 1
    return power


@njit(cache=True)
def generalized_forces(system, t, q, qd, modes, impact_speeds):
    """(Q, applied power, damping loss, contact loss, friction loss)."""
    generalized = np.zeros(q.shape[0])
    applied, damping = add_applied_forces(system, t, q, qd, generalized)
    contact, friction = add_clearance_forces(system, q, qd, modes, impact_speeds, generalized)
    return generalized, applied, damping, contact, friction


@njit(cache=True)
def rhs(system, t, y, modes, impact_speeds, ydot):
    """ẏ = f(t, y) for the current contact modes."""
    n = coordinate_count(system)
    q = y[:n]
    qd = y[n:2 * n]
    generalized, applied, damping, contact, friction = generalized_forces(system, t, q, qd, modes, impact_speeds)
    qdd, lam = accelerations(system, t, q, qd, generalized, modes)
    copy_into(ydot[:n], qd)
    copy_into(ydot[n:2 * n], qdd)
    ydot[2 * n + WORK_DRIVER] = driver_power(system, t, lam)
    ydot[2 * n + WORK_CONTACT] = contact
    ydot[2 * n + WORK_FRICTION] = friction
    ydot[2 * n + WORK_DAMPING] = damping
    ydot[2 * n + WORK_APPLIED] = applied


@njit(cache=True, inline="always")
def project_positions(system, t, q, tolerance, max_iterations):
    """Newton projection of q onto Φ(q, t) = 0 in the M metric; returns the final max |Φ|."""
    m = constraint_count(system)
    if m == 0:
        return 0.0
    n = q.shape[0]
    minv = inverse_mass(system)
    phi = np.empty(m)
    for _ in range(max_iterations):
        evaluate_constraints(system, t, q, phi)
        if np.max(np.abs(phi)) <= tolerance:
            break
        blocks, bodies = jacobian_blocks(system, q)
        q -= minimum_norm_correction(blocks, bodies, minv, phi, n)
    evaluate_constraints(system, t, q, phi)
    return np.max(np.abs(phi))


@njit(cache=True, inline="always")
def project_velocities(system, t, q, qd, modes):
    """q̇ ← q̇ − M⁻¹Φ_qᵀ S⁻¹ (Φ_q q̇ − ν): the nearest consistent velocity in the M metric (stick rows: ν = 0)."""
    m = constraint_count(system) + stick_count(modes)
    if m == 0:
        return
    blocks, bodies, _ = jacobian_with_sticks(system, q, qd, modes)
    nu = np.empty(m)
    evaluate_velocity_rhs(system, t, nu)
    qd -= minimum_norm_correction(blocks, bodies, inverse_mass(system), jacobian_times(blocks, bodies, qd) - nu, q.shape[0])


@njit(cache=True)
def constraint_violation(system, t, q):
    """max |Φ(q, t)| (m or rad)."""
    m = constraint_count(system)
    if m == 0:
        return 0.0
    phi = np.empty(m)
    evaluate_constraints(system, t, q, phi)
    return np.max(np.abs(phi))


@njit(cache=True, inline="always")
def effective_mass(system, k, q):
    """m_eff of clearance joint k along n: 1/(wᵀ P w), P the constrained mobility, w the unit force pair."""
    n = q.shape[0]
    zero = np.zeros(n)
    ex, ey, _, _, _, _, nx, ny, _ = clearance_kinematics(system, k, q, zero)
    p = system.clearance_params[k]
    bx, by = point_position(q, system.clearance_bodies[k, 0], p[CL_BEARING_POINT], p[CL_BEARING_POINT + 1])
    pair = np.zeros(n)
    add_global_force(pair, q, system.clearance_bodies[k, 1], bx + ex, by + ey, nx, ny)
    add_global_force(pair, q, system.clearance_bodies[k, 0], bx, by, -nx, -ny)
    minv = inverse_mass(system)
    m = constraint_count(system)
    if m == 0:
        response = minv * pair
    else:
        blocks, bodies = jacobian_blocks(system, q)
        response = constrained_response(blocks, bodies, minv, pair, np.zeros(m))[0]
    mobility = 0.0
    for i in range(n):  # not `pair @ response`: numba's dot is BLAS, whose set-up loads scipy.linalg (arrays.py)
        mobility += pair[i] * response[i]
    return 1.0 / mobility if mobility > 0.0 else np.inf
