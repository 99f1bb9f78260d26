"""ROS34PW2, a linearly implicit Rosenbrock-W method of order 3 with an embedded order-2 estimate (compiled).

Rang & Angermann 2005 (BIT 45:761, Table 4.2 "ROS34PW2"): 4 stages, stiffly accurate, L-stable, order 3 with the
exact Jacobian and order 2 with any matrix in its place (a W-method). In Hairer & Wanner II §IV.7 form (7.4) with
Γ = (γ_ij), γ_ii = γ, and a time derivative for non-autonomous right-hand sides:

    (I − hγJ) k_i = h f(t + α_i h, y + Σ_j<i α_ij k_j) + hJ Σ_j<i γ_ij k_j + γ_i h² f_t,   y₁ = y + Σ b_i k_i

and computed in the transformed variables u_i = Σ_j≤i γ_ij k_j (HW II (7.4')), so that each stage is one solve with
W = I/(hγ) − J (LU-factored once per step, reduced_matrix) and no product with J:

    W u_i = f(t + α_i h, y + Σ_j<i a_ij u_j) + Σ_j<i (c_ij / h) u_j + γ_i h f_t,   y₁ = y + Σ m_i u_i,
    a = α Γ⁻¹,  c = −Γ⁻¹ off the diagonal,  m = bᵀ Γ⁻¹,  the error estimate Σ e_i u_i with e = (b − b̂)ᵀ Γ⁻¹.

J = ∂f/∂y and f_t = ∂f/∂t are differences of the compiled rhs (evaluate_jacobian: central in the columns an oil film
depends on, forward elsewhere; those kept over SLOW_COLUMNS_MAX_AGE Jacobians), and W is factored with the positions
eliminated (reduced_matrix: the first n rows of f are q̇). The continuous extension
is the cubic Hermite interpolant of y, f(y) at both ends (local error O(h⁴), the method's order), written as the
stage vectors of DOPRI5's dense form (dopri.interpolate), so that event location, samples and peak search read
both methods' steps alike.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.arrays import CL_VISCOSITY, copy_into
from clearsim.assembly.kinematics import GROUND
from clearsim.assembly.dynamics import WORK_COUNT, coordinate_count, rhs
from clearsim.solver import dopri

STAGES = 4
GAMMA = 0.435866521508459
ALPHA = np.array([  # α_ij
    [0.0, 0.0, 0.0, 0.0],
    [0.87173304301691801, 0.0, 0.0, 0.0],
    [0.84457060015369423, -0.11299064236484185, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
])
GAMMAS = np.array([  # γ_ij, γ_ii = GAMMA
    [GAMMA, 0.0, 0.0, 0.0],
    [-0.87173304301691801, GAMMA, 0.0, 0.0],
    [-0.90338057013044082, 0.054180672388095326, GAMMA, 0.0],
    [0.24212380706095346, -1.2232505839045147, 0.54526025533510214, GAMMA],
])
WEIGHTS = np.array([0.24212380706095346, -1.2232505839045147, 1.5452602553351020, 0.435866521508459])  # b_i
EMBEDDED_WEIGHTS = np.array([0.37810903145819369, -0.096042292212423178, 0.5, 0.2179332607542295])  # b̂_i
ORDER, EMBEDDED_ORDER = 3, 2

_INVERSE = np.linalg.inv(GAMMAS)
STAGE_MATRIX = ALPHA @ _INVERSE  # a_ij
COUPLING = np.tril(-_INVERSE, -1)  # c_ij
SOLUTION = WEIGHTS @ _INVERSE  # m_i
ERROR = (WEIGHTS - EMBEDDED_WEIGHTS) @ _INVERSE  # e_i
NODES = ALPHA.sum(axis=1)  # α_i
TIME_WEIGHTS = GAMMAS.sum(axis=1)  # γ_i (with the diagonal)
# the Hermite cubic's coefficient vectors c_p (of θ, θ², θ³, over h) → DOPRI5 stage vectors K = S c with S the first
# three columns of P (PᵀP)⁻¹, P = dopri.DENSE (7 × 4): then h Σ_j K_j Σ_p P_jp θ^(p+1) = h Σ_p c_p θ^(p+1), no θ⁴
HERMITE_STAGES = (dopri.DENSE @ np.linalg.inv(dopri.DENSE.T @ dopri.DENSE))[:, :3].copy()
# J is taken anew after this many accepted steps (evaluate_jacobian, which then takes the film columns and, when
# refreshes_all_columns, every column; docs/model.md §4): 1, a J for each new step,
# kept through its rejected attempts and its event refinement. Reusing it longer, as a W-method may, cost more than it
# saved on the squeeze film (ε 0 → 0.9 in tests/validation/test_lubricated_joint.py): up to 20 steps, 4 573 steps and
# 3 567 rejected (0.18 s); up to 3, 3 566 rejected; 1: 2 972 steps and 6 rejected (0.09 s)
JACOBIAN_MAX_AGE = 1
# the columns no oil film depends on are taken anew after this many Jacobians (refreshes_all_columns): the greased
# breaker's stroke (2 185 steps) with 10: 1.75 s of integration against 2.49 s with every column at each step, the
# same peak to 4e-6; the film's position columns kept with them too: 7 763 steps, peak 260 against 195 m/s²
SLOW_COLUMNS_MAX_AGE = 10
ROUNDOFF = np.sqrt(np.finfo(np.float64).eps)


@njit(cache=True)
def jacobian_is_stale(age, modes, jacobian_modes):
    """J must be taken anew: none yet (age < 0), the contact modes changed since, or it has served its steps."""
    if age < 0 or age >= JACOBIAN_MAX_AGE:
        return True
    for k in range(modes.shape[0]):
        if modes[k] != jacobian_modes[k]:
            return True
    return False


@njit(cache=True)
def film_columns(system, y):
    """True for the columns of J whose rhs the oil film of a lubricated joint depends on: q and q̇ of the bearing and
    the journal of each joint with a viscosity (evaluate_jacobian takes these by central differences)."""
    n = coordinate_count(system)
    central = np.zeros(y.shape[0], np.bool_)
    for k in range(system.clearance_bodies.shape[0]):
        if system.clearance_params[k, CL_VISCOSITY] <= 0.0:
            continue
        for side in range(2):
            body = system.clearance_bodies[k, side]
            if body == GROUND:
                continue
            for c in range(3):
                central[3 * body + c] = True
                central[n + 3 * body + c] = True
    return central


@njit(cache=True)
def refreshes_all_columns(modes, jacobian_modes):
    """evaluate_jacobian takes every column anew, not only the film's: none taken yet, the contact modes changed since
    the last full one, or it has served SLOW_COLUMNS_MAX_AGE Jacobians (jacobian_modes[len(modes)], evaluate_jacobian)."""
    served = jacobian_modes[modes.shape[0]]
    if served == 0 or served >= SLOW_COLUMNS_MAX_AGE:
        return True
    for k in range(modes.shape[0]):
        if modes[k] != jacobian_modes[k]:
            return True
    return False


@njit(cache=True)
def evaluate_jacobian(system, dynamics, t, y, f, h, modes, speeds, skipped_from, skipped_count, floor, jacobian,
                      jacobian_modes):
    """∂f/∂y into jacobian[:, :ny] and ∂f/∂t into jacobian[:, ny] by differences from f = f(t, y) (increments
    √ε max(|y_j|, floor), in time √ε max(|t|, h), at most h/2): forward differences, but central ones in the columns
    an oil film depends on (film_columns); the columns of the integrated powers (skipped_from, skipped_count: f does
    not depend on them) are zero. The other columns are kept from the last full Jacobian while it has served fewer
    than SLOW_COLUMNS_MAX_AGE and the modes are those it was taken in (refreshes_all_columns); jacobian_modes holds
    those modes, then the Jacobians taken since (1 right after a full one, 0 before the first), then the rhs
    evaluations this one made (jacobian_evaluations). Returns those evaluations.

    The film force is homogeneous of degree one in its rates (ε̇, ε w) and turns with their direction (the
    cavitated half moves with it), so it is curved on the scale of the relative speed in the film, c |(2ε̇, ε w)|
    (~1e-5 m/s), not of the bodies' speeds: a forward difference with the increment √ε |v| ≈ 7e-8 m/s at |v| = 5 m/s
    is off by ~1 % in the film's block, and the step then leaves a fast transient of the film (λ ≈ 3e8 1/s) that
    the error control does not see in q̇ but the accelerations do (docs/performance.md, "Stiff models"). A central
    difference cancels the error's first-order term."""
    ny = y.shape[0]
    shifted = y.copy()
    column = np.empty(ny)
    back = np.empty(ny)
    central = film_columns(system, y)
    every_column = refreshes_all_columns(modes, jacobian_modes)
    count = 0
    for j in range(ny):
        if not (every_column or central[j]):
            continue
        if skipped_from <= j < skipped_from + skipped_count:
            for i in range(ny):
                jacobian[i, j] = 0.0
            continue
        increment = ROUNDOFF * max(abs(y[j]), floor)
        shifted[j] = y[j] + increment
        increment = shifted[j] - y[j]  # the increment as represented
        rhs(system, dynamics, t, shifted, modes, speeds, column)
        count += 1
        if central[j]:
            shifted[j] = y[j] - increment
            rhs(system, dynamics, t, shifted, modes, speeds, back)
            count += 1
            for i in range(ny):
                jacobian[i, j] = (column[i] - back[i]) / (2.0 * increment)
        else:
            for i in range(ny):
                jacobian[i, j] = (column[i] - f[i]) / increment
        shifted[j] = y[j]
    increment = min(ROUNDOFF * max(abs(t), h), 0.5 * h)
    rhs(system, dynamics, t + increment, y, modes, speeds, column)
    for i in range(ny):
        jacobian[i, ny] = (column[i] - f[i]) / increment
    copy_into(jacobian_modes, modes)
    jacobian_modes[modes.shape[0]] = 1 if every_column else jacobian_modes[modes.shape[0]] + 1
    jacobian_modes[modes.shape[0] + 1] = count + 1
    return count + 1


@njit(cache=True)
def jacobian_evaluations(jacobian_modes):
    """The rhs evaluations the last evaluate_jacobian made (its record in jacobian_modes' last slot)."""
    return jacobian_modes[jacobian_modes.shape[0] - 1]


@njit(cache=True)
def attempt(system, dynamics, t, y, f, h, modes, speeds, stages, y_new, jacobian, jacobian_modes, take_jacobian, floor):
    """One step (step) from (t, y), J and ∂f/∂t taken anew at (t, y) first when take_jacobian (evaluate_jacobian, the
    increments' floor `floor`); returns the error vector. The loop calls it by address (integrator.addressed_kernels),
    so that it is compiled on its own and not into the loop."""
    if take_jacobian:
        evaluate_jacobian(system, dynamics, t, y, f, h, modes, speeds, 2 * coordinate_count(system), WORK_COUNT, floor,
                          jacobian, jacobian_modes)
    return step(system, dynamics, t, y, f, h, modes, speeds, stages, y_new, jacobian)[0]


@njit(cache=True)
def not_taken(system, dynamics, t, y, f, h, modes, speeds, stages, y_new, jacobian, jacobian_modes, take_jacobian, floor):
    """attempt's stand-in, of its type, in the loop of a run with the explicit method, which never calls it: such a run
    then does not compile the Rosenbrock step (about 6 s of a first run on two cores; integrator.addressed)."""
    return y_new


@njit(cache=True)
def lu_factor(matrix, pivots):
    """LU with partial pivoting in place (Doolittle; L's unit diagonal implied); pivots[i] = the row swapped with i."""
    n = matrix.shape[0]
    for k in range(n):
        pivot = k
        for i in range(k + 1, n):
            if abs(matrix[i, k]) > abs(matrix[pivot, k]):
                pivot = i
        pivots[k] = pivot
        if pivot != k:
            for j in range(n):
                matrix[k, j], matrix[pivot, j] = matrix[pivot, j], matrix[k, j]
        diagonal = matrix[k, k]
        if diagonal == 0.0:
            continue
        for i in range(k + 1, n):
            factor = matrix[i, k] / diagonal
            matrix[i, k] = factor
            if factor != 0.0:
                for j in range(k + 1, n):
                    matrix[i, j] -= factor * matrix[k, j]


@njit(cache=True)
def lu_solve(matrix, pivots, b):
    """Solve with lu_factor's result, b overwritten by the solution."""
    n = matrix.shape[0]
    for k in range(n):
        p = pivots[k]
        if p != k:
            b[k], b[p] = b[p], b[k]
    for i in range(n):
        value = b[i]
        for j in range(i):
            value -= matrix[i, j] * b[j]
        b[i] = value
    for i in range(n - 1, -1, -1):
        value = b[i]
        for j in range(i + 1, n):
            value -= matrix[i, j] * b[j]
        b[i] = value / matrix[i, i]


@njit(cache=True)
def reduced_matrix(jacobian, hg, n, matrix):
    """The iteration matrix W = I/(hγ) − J with the positions eliminated, into matrix ((ny − n)², hg = hγ).

    The first n rows of f are q̇ itself, so J's are [0 I 0]: the q rows of W u = b read u_q/(hγ) − u_q̇ = b_q, i.e.
    u_q = hγ (b_q + u_q̇), and the other rows r become (I/(hγ) − J_rr − hγ J_rq E) u_r = b_r + hγ J_rq b_q, with r the
    q̇, W and z rows and columns and E the q̇ part of u_r (reduced_solve). The LU is then of (ny − n)² instead of
    ny², (1 − n/ny)³ of its cost (0.2 on the breaker: 38 of 65)."""
    ny = jacobian.shape[0]
    size = ny - n
    for a in range(size):
        i = n + a
        for b in range(size):
            matrix[a, b] = -jacobian[i, n + b]
        for b in range(n):
            matrix[a, b] -= hg * jacobian[i, b]
        matrix[a, a] += 1.0 / hg


@njit(cache=True)
def reduced_solve(matrix, pivots, jacobian, hg, n, b, reduced):
    """Solve W u = b with reduced_matrix's LU (lu_factor): b overwritten by u; `reduced` (ny − n) is scratch."""
    size = reduced.shape[0]
    for a in range(size):
        value = b[n + a]
        for c in range(n):
            value += hg * jacobian[n + a, c] * b[c]
        reduced[a] = value
    lu_solve(matrix, pivots, reduced)
    for c in range(n):
        b[c] = hg * (b[c] + reduced[c])
    for a in range(size):
        b[n + a] = reduced[a]


@njit(cache=True)
def step(system, dynamics, t, y, f, h, modes, speeds, stages, y_new, jacobian):
    """One ROS34PW2 step from (t, y) with ẏ(t) = f and J, f_t in jacobian; fills y_new and, as DOPRI5 stage vectors
    (dopri.interpolate), the Hermite continuous extension; returns (the error vector, the rhs evaluations made)."""
    ny = y.shape[0]
    n = coordinate_count(system)
    matrix = np.empty((ny - n, ny - n))
    pivots = np.empty(ny - n, np.int64)
    reduced_matrix(jacobian, h * GAMMA, n, matrix)
    lu_factor(matrix, pivots)
    reduced = np.empty(ny - n)
    units = np.zeros((STAGES, ny))
    work = np.empty(ny)
    argument = np.empty(ny)
    end = np.nextafter(t + h, t)  # as dopri.step: the step sees the piece of a prescribed motion it integrates over
    for s in range(STAGES):
        if s == 0:
            copy_into(work, f)
        else:
            copy_into(argument, y)
            for j in range(s):
                for i in range(ny):
                    argument[i] += STAGE_MATRIX[s, j] * units[j, i]
            rhs(system, dynamics, min(t + NODES[s] * h, end), argument, modes, speeds, work)
        for j in range(s):
            for i in range(ny):
                work[i] += COUPLING[s, j] / h * units[j, i]
        for i in range(ny):
            work[i] += TIME_WEIGHTS[s] * h * jacobian[i, ny]
        reduced_solve(matrix, pivots, jacobian, h * GAMMA, n, work, reduced)
        copy_into(units[s], work)
    error = np.zeros(ny)
    copy_into(y_new, y)
    for s in range(STAGES):
        for i in range(ny):
            y_new[i] += SOLUTION[s] * units[s, i]
            error[i] += ERROR[s] * units[s, i]
    f_end = np.empty(ny)
    rhs(system, dynamics, end, y_new, modes, speeds, f_end)
    hermite_stages(y, y_new, f, f_end, h, stages)
    return error, STAGES


@njit(cache=True)
def hermite_stages(y, y_new, f, f_end, h, stages):
    """The cubic Hermite interpolant of (y, f) and (y_new, f_end) as DOPRI5 stage vectors (HERMITE_STAGES)."""
    for i in range(y.shape[0]):
        slope = (y_new[i] - y[i]) / h
        c1 = f[i]
        c2 = 3.0 * slope - 2.0 * f[i] - f_end[i]
        c3 = f[i] + f_end[i] - 2.0 * slope
        for j in range(stages.shape[0]):
            stages[j, i] = HERMITE_STAGES[j, 0] * c1 + HERMITE_STAGES[j, 1] * c2 + HERMITE_STAGES[j, 2] * c3
