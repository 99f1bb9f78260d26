"""Equations of motion and constraint stabilisation (compiled).

M q̈ + Φ_qᵀ λ = Q (Meng 2015 eq. 14/15) with Φ_q q̈ = γ. M is diagonal (m, m, J per body),
so λ comes from the Schur complement S λ = Φ_q M⁻¹ Q − γ, S = Φ_q M⁻¹ Φ_qᵀ (symmetric
positive definite when no constraint is redundant, which assembly checks), then
q̈ = M⁻¹ (Q − Φ_qᵀ λ). After each step the state is projected onto Φ = 0 and Φ_q q̇ = ν
in the kinetic-energy metric M (the projection method of Hairer, Lubich & Wanner,
Geometric Numerical Integration, §IV.4), which keeps ‖Φ‖ at round-off level.

The state vector is y = [q, q̇, W, z], W the integrated powers (WORK_* below), z the states of the force elements
that have some (hydraulic cylinders: assembly/hydraulics.py); z is integrated and error-controlled like q and q̇ but
not projected (it is bound by no constraint).
"""

from __future__ import annotations

import numpy as np
from numba import njit, types

from clearsim.assembly.constraints import (
    constraint_count, evaluate_acceleration_rhs, evaluate_constraints, evaluate_jacobian_blocks, evaluate_velocity_rhs,
    jacobian_times, jacobian_transpose_times, prescribed, schur_complement,
)
from clearsim.assembly.forces import (
    STICK, add_applied_forces, add_clearance_forces, add_global_force, add_wear_rates, clearance_kinematics, film_forces,
    no_film_forces, stick_row,
)
from clearsim.assembly.drivelines import add_driveline_forces, driveline_powers
from clearsim.assembly.hydraulics import add_hydraulic_forces, hydraulic_rates
from clearsim.assembly.kinematics import point_position
from clearsim.assembly.arrays import CL_BEARING_POINT, CL_VISCOSITY, copy_into

WORK_DRIVER = 0
WORK_CONTACT = 1
WORK_FRICTION = 2
WORK_DAMPING = 3
WORK_APPLIED = 4
WORK_SUPPLY = 5  # energy the hydraulic supplies delivered, ∫ p_s Q_s dt
WORK_TANK = 6  # energy the oil carried into the tanks, ∫ p_T Q_T dt
WORK_ORIFICE = 7  # dissipated in the orifices, ∫ Σ Q Δp dt
WORK_OIL = 8  # stored in the oil's compression, ∫ Σ p (Q_in − V̇) dt
WORK_DASHPOT = 9  # dissipated in the dashpots (assembly/drivelines.py)
WORK_GUIDE_FRICTION = 10  # dissipated by the guide frictions
WORK_COUNT = 11

# factor_key[0]: what the scratch holds (factored_jacobian)
FACTOR_NONE, FACTOR_SPD, FACTOR_SINGULAR = 0, 1, 2


@njit(cache=True)
def coordinate_count(system):
    return 3 * system.mass.shape[0]


@njit(cache=True)
def solve_rows(system, x):
    """x ← S⁻¹ x in place, x in the rows' order (pins, offsets, angles, stick rows), with the factor of the last
    factored_jacobian, which holds them in their places (arrays.row_place): moved there, solved, moved back."""
    if system.row_place.shape[0] == 0:
        solve_factored(system, x)
        return
    places = system.solve_place
    placed = system.solve_placed[:x.shape[0]]
    for r in range(x.shape[0]):
        placed[places[r]] = x[r]
    solve_factored(system, placed)
    for r in range(x.shape[0]):
        x[r] = placed[places[r]]


@njit(cache=True)
def factorize(system, m):
    """Envelope (skyline) Cholesky factor of the symmetric m × m matrix S in system.solve_schur (small, dense)
    into system.solve_lower; False if S is not positive definite.

    Row i of L starts where row i of S does (first[i], its first nonzero, searched from the band schur_complement
    wrote), since the factor has no fill-in left of the envelope, so the zeros of a chain's S cost nothing; only the
    envelope of solve_lower is written and read: O(rows × bandwidth²).
    """
    matrix = system.solve_schur
    first = system.solve_envelope
    band = system.solve_band
    for i in range(m):
        first[i] = i
        for j in range(band[i], i):
            if matrix[i, j] != 0.0:
                first[i] = j
                break
    lower = system.solve_lower
    for i in range(m):
        for j in range(first[i], i + 1):
            acc = matrix[i, j]
            for k in range(max(first[i], first[j]), j):
                acc -= lower[i, k] * lower[j, k]
            if i == j:
                if acc <= 0.0:
                    return False
                lower[i, i] = np.sqrt(acc)
            else:
                lower[i, j] = acc / lower[j, j]
    return True


@njit(cache=True)
def solve_factored(system, x):
    """x ← S⁻¹ x in place with the factor of the last factored_jacobian (NaN if S was not positive definite), x in
    the factor's order (solve_rows: in the rows').

    Both substitutions loop over the envelope only, O(envelope): the forward one along row i of L from first[i],
    the backward one down column i of L, over the rows k > i whose envelope reaches it (first[k] ≤ i) in ascending
    order. Those rows are a linked list (system.solve_next_row) kept while i descends: row i + 1 joins at its head,
    a row leaves when i passes its first column, and never comes back. Each sum runs in a register (not x[i] in
    memory, which LLVM cannot keep apart from the x[k] read: ≈ 1.6× the time), subtracting in the same order.
    """
    m = x.shape[0]
    if system.factor_key[0] != FACTOR_SPD:
        for r in range(m):
            x[r] = np.nan
        return
    first = system.solve_envelope
    lower = system.solve_lower
    for i in range(m):
        value = x[i]
        for k in range(first[i], i):
            value -= lower[i, k] * x[k]
        x[i] = value / lower[i, i]
    following = system.solve_next_row
    head = -1  # the first row of the list, −1: empty; following[k]: the row after k
    for i in range(m - 1, -1, -1):
        if i + 1 < m and first[i + 1] <= i:
            following[i + 1] = head
            head = i + 1
        previous = -1
        k = head
        value = x[i]
        while k >= 0:
            after = following[k]
            if first[k] > i:
                if previous < 0:
                    head = after
                else:
                    following[previous] = after
            else:
                value -= lower[k, i] * x[k]
                previous = k
            k = after
        x[i] = value / lower[i, i]


@njit(cache=True)
def constrained_response(system, blocks, bodies, force, gamma):
    """(a, λ) with a = M⁻¹ (f − Φ_qᵀ λ) and Φ_q a = γ, for the rows of the last factored_jacobian."""
    minv = system.inverse_mass
    n = force.shape[0]
    scaled = system.solve_vector
    for i in range(n):
        scaled[i] = minv[i] * force[i]
    lam = np.empty(gamma.shape[0])
    jacobian_times(blocks, bodies, scaled, lam)
    for r in range(lam.shape[0]):
        lam[r] -= gamma[r]
    solve_rows(system, lam)
    reaction = system.solve_vector
    jacobian_transpose_times(blocks, bodies, lam, reaction)
    a = np.empty(n)
    for i in range(n):
        a[i] = minv[i] * (force[i] - reaction[i])
    return a, lam


@njit(cache=True)
def subtract_minimum_norm_correction(system, blocks, bodies, residual, x):
    """x −= M⁻¹Φ_qᵀ S⁻¹ r: the smallest change (in the M metric) that removes a constraint residual r, for the
    rows of the last factored_jacobian (residual is overwritten)."""
    solve_rows(system, residual)
    correction = system.solve_vector
    jacobian_transpose_times(blocks, bodies, residual, correction)
    minv = system.inverse_mass
    for i in range(x.shape[0]):
        x[i] -= minv[i] * correction[i]


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
    """Row of sticking joint k among the rows of factored_jacobian: after Φ's rows, in joint order."""
    row = constraint_count(system)
    for other in range(k):
        if modes[other] == STICK:
            row += 1
    return row


@njit(cache=True)
def _factor_matches(system, q, modes, with_sticks):
    """The factor in the scratch is that of Φ_q at this q (bit for bit) with these stick rows."""
    key = system.factor_key
    if key[0] == FACTOR_NONE:
        return False
    for k in range(key.shape[0] - 1):
        if key[1 + k] != (with_sticks and modes[k] == STICK):
            return False
    stored = system.factor_q
    for i in range(q.shape[0]):
        if stored[i] != q[i]:
            return False
    return True


@njit(cache=True)
def factored_jacobian(system, q, qd, modes, rows, curvature):
    """(blocks, bodies) of Φ_q at q, with one row G per sticking joint appended if rows asks for them (rows: Φ's
    alone or with the stick rows; a count computed at run time, not a literal flag, which would compile this kernel
    once for each value), as views of the solve scratch, and S = Φ_q M⁻¹ Φ_qᵀ factorised there; Ġq̇ of the stick
    rows into curvature.

    The rows depend on q alone (and on which joints stick), so a state's projection and its accelerations share
    one factor: it is computed again only when q or the stick rows change (the key kept with it in the scratch;
    every kernel that writes the scratch's rows comes through here).
    """
    m = constraint_count(system)
    with_sticks = rows > m
    blocks = system.solve_blocks[:rows]
    bodies = system.solve_bodies[:rows]
    fresh = not _factor_matches(system, q, modes, with_sticks)
    if fresh:
        evaluate_jacobian_blocks(system, q, blocks, bodies)
    row = m
    for k in range(system.factor_key.shape[0] - 1):
        if with_sticks and modes[k] == STICK:
            bearing_block, journal_block, curvature[row - m] = stick_row(system, k, q, qd)
            if fresh:
                bodies[row, 0] = system.clearance_bodies[k, 0]
                bodies[row, 1] = system.clearance_bodies[k, 1]
                for c in range(3):
                    blocks[row, 0, c] = bearing_block[c]
                    blocks[row, 1, c] = journal_block[c]
            row += 1
    if fresh:
        key = system.factor_key
        schur_complement(system, blocks, bodies)
        key[0] = FACTOR_SPD if factorize(system, rows) else FACTOR_SINGULAR
        for k in range(key.shape[0] - 1):
            key[1 + k] = with_sticks and modes[k] == STICK
        copy_into(system.factor_q, q)
    return blocks, bodies


@njit(cache=True)
def accelerations(system, t, q, qd, generalized, modes):
    """(q̈, λ) from M q̈ + Φ_qᵀ λ = Q, Φ_q q̈ = γ; λ ends with −F_t of each sticking joint."""
    m = constraint_count(system)
    sticking = stick_count(modes)
    if m + sticking == 0:
        return system.inverse_mass * generalized, np.zeros(0)
    gamma = system.solve_residual[:m + sticking]
    blocks, bodies = factored_jacobian(system, q, qd, modes, m + sticking, gamma[m:])
    for i in range(sticking):
        gamma[m + i] = -gamma[m + i]
    evaluate_acceleration_rhs(system, t, q, qd, gamma)
    return constrained_response(system, blocks, bodies, generalized, gamma)


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
    """(Q, applied power, damping loss, contact loss, friction loss), oil films included."""
    return model_forces(system, t, q, qd, modes, impact_speeds, True)


@njit(cache=True)
def model_forces(system, t, q, qd, modes, impact_speeds, with_films):
    """generalized_forces, without the oil films' forces where `with_films` is None (forces.add_clearance_forces)."""
    generalized = np.zeros(q.shape[0])
    applied, damping = add_applied_forces(system, t, q, qd, generalized)
    contact, friction = add_clearance_forces(system, q, qd, modes, impact_speeds, generalized, with_films)
    add_driveline_forces(system, t, q, qd, generalized)  # their powers: driveline_powers, in rhs
    return generalized, applied, damping, contact, friction


@njit(cache=True, inline="always")
def model_dynamics(system, t, q, qd, z, modes, impact_speeds, with_films):
    """(q̈, λ, applied power, damping loss, contact loss, friction loss) at (t, q, q̇) and element states z, with
    `with_films` as in model_forces (inlined into each of the two dynamics kernels: not a library of its own to be
    optimised again in theirs)."""
    generalized, applied, damping, contact, friction = model_forces(system, t, q, qd, modes, impact_speeds,
                                                                    with_films)
    add_hydraulic_forces(system, q, z, generalized)
    qdd, lam = accelerations(system, t, q, qd, generalized, modes)
    return qdd, lam, applied, damping, contact, friction


@njit(cache=True)
def forces_and_accelerations(system, t, q, qd, z, modes, impact_speeds):
    """model_dynamics with the oil films: the dynamics of a model with a lubricated joint, which the loop's kernels
    call by address (their `dynamics` argument), so it is compiled once, not into each of them."""
    return model_dynamics(system, t, q, qd, z, modes, impact_speeds, True)


@njit(cache=True)
def dry_forces_and_accelerations(system, t, q, qd, z, modes, impact_speeds):
    """model_dynamics without the oil films: the dynamics of a model that has none, which therefore compiles no film
    kernel (dynamics_kernel)."""
    return model_dynamics(system, t, q, qd, z, modes, impact_speeds, None)


def dynamics_kernel(lubricated: bool):
    """The dynamics `advance` takes by address for a model with (lubricated) or without oil films; both of
    dynamics_type."""
    return forces_and_accelerations if lubricated else dry_forces_and_accelerations


def films_kernel(lubricated: bool):
    """The oil films' forces the sampling takes by address (samples.derive_sample): film_forces, or its stand-in for a
    model without oil films; both of films_type."""
    return film_forces if lubricated else no_film_forces


def films_type(system_type):
    """The numba type of a `films` argument called by address: film_forces' (F_n, F_t, T, ω_J − ω_B)(system, k, q, q̇)."""
    vector, real = types.float64[::1], types.float64
    return types.FunctionType(types.Tuple((real, real, real, real))(system_type, types.int64, vector, vector))


def has_oil_films(arrays) -> bool:
    """Whether a joint of these system arrays (SystemArrays) has an oil film (CL_VISCOSITY > 0)."""
    return bool(np.any(arrays.clearance_params[:, CL_VISCOSITY] > 0.0))


def dynamics_type(system_type):
    """The numba type of a `dynamics` argument: forces_and_accelerations called by its address."""
    vector, integers = types.float64[::1], types.int64[::1]
    result = types.Tuple((vector, vector, types.float64, types.float64, types.float64, types.float64))
    return types.FunctionType(result(system_type, types.float64, vector, vector, vector, integers, vector))


@njit(cache=True)
def wear_state_count(system):
    """States of the accumulated Archard profiles, which end z (build.wear_arrays): 2M + 1 per wearing joint. Like the
    integrated powers they feed nothing back within a run, so they steer no step (dopri.error_norm)."""
    count = 0
    for k in range(system.wear_slots.shape[0]):
        if system.wear_slots[k, 0] >= 0:
            count += 2 * system.wear_slots[k, 1] + 1
    return count


@njit(cache=True, inline="always")
def element_states(system, y):
    """z: the force elements' states at the end of y."""
    return y[2 * coordinate_count(system) + WORK_COUNT:]


@njit(cache=True)
def rhs(system, dynamics, t, y, modes, impact_speeds, ydot):
    """ẏ = f(t, y) for the current contact modes."""
    n = coordinate_count(system)
    q = y[:n]
    qd = y[n:2 * n]
    z = element_states(system, y)
    qdd, lam, applied, damping, contact, friction = dynamics(system, t, q, qd, z, modes, impact_speeds)
    copy_into(ydot[:n], qd)
    copy_into(ydot[n:2 * n], qdd)
    ydot[2 * n + WORK_DRIVER] = driver_power(system, t, lam)
    ydot[2 * n + WORK_CONTACT] = contact
    ydot[2 * n + WORK_FRICTION] = friction
    ydot[2 * n + WORK_DAMPING] = damping
    dashpot, guide_friction, latch = driveline_powers(system, t, q, qd)
    ydot[2 * n + WORK_APPLIED] = applied + latch
    supply, tank, orifice, oil = hydraulic_rates(system, t, q, qd, z, element_states(system, ydot))
    add_wear_rates(system, q, qd, modes, impact_speeds, element_states(system, ydot))
    ydot[2 * n + WORK_SUPPLY] = supply
    ydot[2 * n + WORK_TANK] = tank
    ydot[2 * n + WORK_ORIFICE] = orifice
    ydot[2 * n + WORK_OIL] = oil
    ydot[2 * n + WORK_DASHPOT] = dashpot
    ydot[2 * n + WORK_GUIDE_FRICTION] = guide_friction


@njit(cache=True)
def largest_magnitude(values):
    """max |v_i| (0 for no values); np.max(np.abs(v)) without its temporary."""
    largest = 0.0
    for value in values:
        magnitude = abs(value)
        if magnitude > largest or magnitude != magnitude:  # NaN wins, as in np.max
            largest = magnitude
    return largest


@njit(cache=True, inline="always")
def project_positions(system, t, q, modes, tolerance, max_iterations):
    """Newton projection of q onto Φ(q, t) = 0 in the M metric; returns the final max |Φ|."""
    m = constraint_count(system)
    if m == 0:
        return 0.0
    phi = system.solve_residual[:m]
    for _ in range(max_iterations):
        evaluate_constraints(system, t, q, phi)
        violation = largest_magnitude(phi)
        if violation <= tolerance:
            return violation
        blocks, bodies = factored_jacobian(system, q, q, modes, m, phi)
        subtract_minimum_norm_correction(system, blocks, bodies, phi, q)
    evaluate_constraints(system, t, q, phi)
    return largest_magnitude(phi)


@njit(cache=True, inline="always")
def project_velocities(system, t, q, qd, modes):
    """q̇ ← q̇ − M⁻¹Φ_qᵀ S⁻¹ (Φ_q q̇ − ν): the nearest consistent velocity in the M metric (stick rows: ν = 0)."""
    m = constraint_count(system) + stick_count(modes)
    if m == 0:
        return
    residual = system.solve_residual[:m]
    blocks, bodies = factored_jacobian(system, q, qd, modes, m, residual[constraint_count(system):])
    nu = np.empty(m)
    evaluate_velocity_rhs(system, t, nu)
    jacobian_times(blocks, bodies, qd, residual)
    for r in range(m):
        residual[r] -= nu[r]
    subtract_minimum_norm_correction(system, blocks, bodies, residual, qd)


@njit(cache=True, inline="always")
def effective_mass(system, k, q, modes):
    """m_eff of clearance joint k along n: 1/(wᵀ P w), P the constrained mobility, w the unit force pair."""
    n = q.shape[0]
    zero = np.zeros(n)
    ex, ey, _, _, _, _, nx, ny, _ = clearance_kinematics(system, k, q, zero)
    p = system.clearance_params[k]
    bx, by = point_position(q, system.clearance_bodies[k, 0], p[CL_BEARING_POINT], p[CL_BEARING_POINT + 1])
    pair = np.zeros(n)
    add_global_force(pair, q, system.clearance_bodies[k, 1], bx + ex, by + ey, nx, ny)
    add_global_force(pair, q, system.clearance_bodies[k, 0], bx, by, -nx, -ny)
    m = constraint_count(system)
    if m == 0:
        response = system.inverse_mass * pair
    else:
        blocks, bodies = factored_jacobian(system, q, q, modes, m, pair)
        response = constrained_response(system, blocks, bodies, pair, np.zeros(m))[0]
    mobility = 0.0
    for i in range(n):  # not `pair @ response`: numba's dot is BLAS, whose set-up loads scipy.linalg (arrays.py)
        mobility += pair[i] * response[i]
    return 1.0 / mobility if mobility > 0.0 else np.inf
