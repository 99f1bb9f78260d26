"""The compiled integration loop: adaptive steps of the run's method (DOPRI5, DOP853 or Rosenbrock), contact events,
fixed-rate samples.

Each clearance joint has a mode (free / contact) that is constant within a step, so every
step integrates a smooth right-hand side. Contact onset (δ rising through 0) and loss (δ
falling through −ε, a hysteresis of ε = 1e-12 m so that a restart at δ ≈ 0 neither
re-fires nor misses the event) are found on the step's continuous extension, including a
graze that enters and leaves inside one step (an extremum of δ, located where δ̇ = 0). The
step that holds the earliest event is then integrated again exactly up to the event, with
Newton corrections of its length until |δ| < 1e-3 ε (docs/model.md §4). At onset
the impact speed δ̇⁻ is stored for the damping law and the next step starts from the Hertz
contact time t_c = 3.218 (m_eff/K)^(2/5) δ̇⁻^(−1/5) / 20. Free flight steps never exceed the
time to cross the clearance c at the current relative speed. Output samples come from the
continuous extension of the step that contains them, which never spans a mode switch, and are
projected onto the constraints like every step end.

The loop runs until t_stop, a full sample buffer, STEPS_PER_CALL tried steps or a failure, then returns to
Python (progress bar, writing, Ctrl-C); all its state lives in the arrays of `Run`, so a return anywhere
at the top of the loop changes no result (tested with a return every 7 steps: every result file bitwise equal).

Compile time (docs/performance.md): numba compiles every kernel it calls as a library of its own,
with all its callees linked in and optimised again. So six kernels are called by address: `advance` takes
the mode switch, the projection, the model's dynamics (forces and constrained accelerations), the oil films' forces
for the samples, the Rosenbrock step (solver.method: rosenbrock; linked into the loop it added ~10 s to a compile
on an empty cache) and the DOP853 step (solver.method: dop853; ~4 s of compile CPU linked in) in one structref
whose fields are typed as function types (`addressed_kernels`, `loop_kernels`, `compiled_loop`; numba converts a
function-type argument at every call, a field once) and passes the projection, the dynamics and the films on to the
kernels that need them. A run that does not need the Rosenbrock step, the DOP853 step or the films passes a
stand-in of the same type instead (`addressed`), so the same compiled loop never compiles them. Each is then
compiled once, not into every library above it, and none has to be compiled before `advance` is typed, so on an
empty cache a second process compiles them meanwhile (clearsim/solver/precompile.py). A call by address is not
inlined (the slider-crank's loop runs 6–9 % slower, the UHV's 2–5 %), so the parts called every step (the event
search, the sampling, the peak search, the DOPRI step) and the scalar helpers stay inlined by numba
(inline="always"); kernels called many times per step stay
ordinary calls, since an inlined copy takes and releases a reference to each of its arrays.
"""

from __future__ import annotations

import numpy as np
from numba import njit, typeof, types
from numba.experimental import structref

from clearsim.assembly.arrays import (
    CL_CLEARANCE, CL_EXPONENT, CL_JOURNAL_RADIUS, CL_MIN_IMPACT_SPEED, CL_MU_D, CL_MU_S, CL_STIFFNESS, copy_into,
)
from clearsim.assembly.dynamics import (
    WORK_COUNT, constraint_count, coordinate_count, dry_forces_and_accelerations, dynamics_kernel, dynamics_type,
    effective_mass, element_states, films_kernel, films_type, forces_and_accelerations, project_positions,
    project_velocities, rhs, stick_count, stick_row_index, wear_state_count,
)
from clearsim.assembly.forces import (
    CONTACT, FREE, SLIDE_BACK, STICK, clearance_kinematics, contact_force_magnitudes, exact_stick,
)
from clearsim.physics.contact import HERTZ_CONTACT_TIME_FACTOR
from clearsim.physics.cylindrical import is_power_law, law_max_penetration
from clearsim.physics.friction import static_coefficient
from clearsim.solver import dop853, rosenbrock
from clearsim.solver.dopri import DENSE, STAGES, dense_elements, dense_output, dense_weights, error_norm, step
from clearsim.solver.samples import derive_sample

# real_state slots
(R_TIME, R_STEP, R_T_END, R_RTOL, R_ATOL, R_MAX_STEP, R_MIN_STEP, R_SAMPLE_DT, R_VIOLATION, R_COARSE_TIME,
 R_COARSE_RATIO) = range(11)
# the output acceleration sensor (body index, −1 for none; its point in the body frame; its direction) and its peak
R_OUTPUT_BODY, R_OUTPUT_POINT_X, R_OUTPUT_POINT_Y, R_OUTPUT_DIRECTION_X, R_OUTPUT_DIRECTION_Y, R_PEAK_ACCELERATION = (
    range(11, 17))
REAL_SLOTS = 17
# int_state slots
(I_STATUS, I_STEPS, I_REJECTED, I_RHS, I_EVENTS, I_SAMPLES, I_NEXT_SAMPLE, I_FAIL_JOINT, I_LOG, I_TOTAL_SAMPLES,
 I_FRICTION_EVENTS, I_STALLED, I_COARSE, I_COARSE_JOINT) = range(14)
# the integration method (METHODS) and, for ROSENBROCK, the accepted steps its Jacobian has served (−1: none yet, or
# one to take anew: rosenbrock.jacobian_is_stale)
I_METHOD, I_JACOBIAN_AGE = 14, 15
# the states at the end of y that steer no step (dynamics.wear_state_count: fixed at assembly, set once per call)
I_UNSTEERING_TAIL = 16
# the tries rejected by the penetration guard alone (penetration_error_ratio)
I_PENETRATION_REJECTED = 17
INT_SLOTS = 18
DOPRI5, ROSENBROCK, DOP853 = range(3)
DOPRI5_ERROR_ORDER = 4  # DOPRI5's embedded solution
METHODS = {"dopri5": DOPRI5, "rosenbrock": ROSENBROCK, "dop853": DOP853}

RUNNING, DONE, MIN_STEP, NOT_FINITE, DRIFT, TOO_DEEP, BUFFER_FULL, CHUNK_END, CHATTER, FIRST_STEP, PAUSED = range(11)
# PAUSED: STEPS_PER_CALL steps tried since the call began; call again (Ctrl-C and the progress bar are handled in
# Python between calls, so a run with a tiny max_step must come back that often)
STEPS_PER_CALL = 20_000
# FIRST_STEP: real[R_STEP] was 0 (no first step chosen), ẏ at the start is in f: choose it, call again
STALLED_STEPS = 2000  # consecutive accepted steps shorter than min_step: the events no longer advance the time

SUBDIVISIONS = 4  # points per step at which the event functions are sampled
# fill_point_kinematics: a row per point (the step's start, its subdivisions, its end y_new, then EXTENSION_END: the
# continuous extension at θ = 1, a rounding away from y_new, which the peak search reads), a joint's δ, δ̇ and v_t each
EXTENSION_END = SUBDIVISIONS + 1
K_PENETRATION, K_RATE, K_SLIDING = range(3)
PROJECTION_TOLERANCE = 1e-13  # m (rad): max |Φ| kept after each step
DRIFT_LIMIT = 1e-8  # m: a projection that cannot get below this has lost the assembly
SAFETY = 0.9
PEAK_CANDIDATE = 0.9  # a step's sampled F_n maximum within 10 % of the peak so far is refined
PEAK_RESOLUTION = 1e-5  # of the step: the peak's location error; F_n is flat there, so its error is ~1e-10
NORMAL, TANGENTIAL = 0, 1  # the two event functions of a clearance joint
UNSOLVED = np.nan  # event_value's friction of a sticking joint: not known, solve for it
SLIDE_HYSTERESIS = 1e-9  # m/s: ε_v of the sliding-stops event, far below any resolved sliding speed
DECIDE_SPEED = 1e-6  # m/s: below it a contact tests whether it sticks (settle_friction)
JUMP_WIDENING = 1e-6  # of the event step: its first lengthening past a jump of the sliding speed (refine_event)
DEEPEST_PENETRATION = 0.05  # of the journal radius: beyond it no contact law means anything
UNRESOLVED_RATIO = 3.0  # position tolerance over an impact's Hertz penetration above which a run warns (model.md §4)
PENETRATION_ERROR_SHARE = 0.01  # of the penetration: the largest error estimate a step may leave in a contact's δ


@njit(cache=True)
def hysteresis(system, k):
    """ε of the loss event of joint k (m): far above round-off of e (~1e-16 m), far below any penetration."""
    return 1e-12


@njit(cache=True)
def friction_reserve(system, dynamics, t, y, modes, speeds, k):
    """(μ_s F_n − |F_t|, F_t) of sticking joint k: the friction force its stick constraint needs, and what is left."""
    n = coordinate_count(system)
    friction = -dynamics(system, t, y[:n], y[n:2 * n], element_states(system, y), modes, speeds)[1][
        stick_row_index(system, modes, k)]
    kin = clearance_kinematics(system, k, y[:n], y[n:2 * n])
    return reserve_left(system, k, kin[4], kin[5], kin[8], modes, speeds, friction)


@njit(cache=True, inline="always")
def reserve_left(system, k, penetration, rate, sliding, modes, speeds, friction):
    """(μ_s F_n − |F_t|, F_t) of sticking joint k at δ, δ̇ and v_t (clearance_kinematics), whose stick constraint needs
    the friction force F_t."""
    normal = contact_force_magnitudes(system, k, penetration, rate, sliding, modes[k], speeds[k])[0]
    p = system.clearance_params[k]
    return static_coefficient(system.clearance_laws[k, 1], p[CL_MU_S], p[CL_MU_D]) * normal - abs(friction), friction


@njit(cache=True)
def stick_frictions(system, dynamics, t, y, modes, speeds, frictions):
    """frictions[k] ← F_t of every sticking joint k at (t, y), −λ of its stick row: one constrained solve for all of
    them (friction_reserve's solve, once per state instead of once per sticking joint); nothing when none sticks."""
    if stick_count(modes) == 0:
        return
    n = coordinate_count(system)
    multipliers = dynamics(system, t, y[:n], y[n:2 * n], element_states(system, y), modes, speeds)[1]
    row = constraint_count(system)
    for k in range(modes.shape[0]):
        if modes[k] == STICK:
            frictions[k] = -multipliers[row]
            row += 1


@njit(cache=True)
def event_value(system, dynamics, k, kind, t, y, modes, speeds, friction):
    """(g, ġ) of joint k's event function; the event is g crossing 0 (ġ = 0: unknown).

    NORMAL: δ in free flight (onset at g ↑ 0), δ + ε in contact (loss at g ↓ 0).
    TANGENTIAL (exact-stick laws in contact): μ_s F_n − |F_t| while sticking (slip at g ↓ 0),
    s v_t + ε_v while sliding in direction s (the sliding stops or reverses at g ↓ 0).
    friction: F_t of a sticking joint at (t, y) as stick_frictions gives it, or UNSOLVED to solve for it here (a
    constrained solve of the whole state); the other event functions read the joint's two bodies alone.
    """
    n = coordinate_count(system)
    if kind == TANGENTIAL and (modes[k] == FREE or not exact_stick(system, k)):
        return 1.0, 0.0
    if kind == TANGENTIAL and modes[k] == STICK and friction != friction:  # UNSOLVED
        return friction_reserve(system, dynamics, t, y, modes, speeds, k)[0], 0.0
    kin = clearance_kinematics(system, k, y[:n], y[n:2 * n])
    return kinematic_event_value(system, k, kind, kin[4], kin[5], kin[8], modes, speeds, friction)


@njit(cache=True, inline="always")
def kinematic_event_value(system, k, kind, penetration, rate, sliding, modes, speeds, friction):
    """event_value from joint k's δ, δ̇ and v_t (clearance_kinematics), a sticking joint's F_t known."""
    mode = modes[k]
    if kind == NORMAL:
        shift = hysteresis(system, k) if mode != FREE else 0.0
        return penetration + shift, rate
    if mode == FREE or not exact_stick(system, k):
        return 1.0, 0.0
    if mode == STICK:
        return reserve_left(system, k, penetration, rate, sliding, modes, speeds, friction)[0], 0.0
    direction = -1.0 if mode == SLIDE_BACK else 1.0
    return direction * sliding + SLIDE_HYSTERESIS, 0.0


@njit(cache=True, inline="always")
def needs_stick_solve(system, k, kind, modes):
    """Joint k's event function of this kind is a sticking joint's friction reserve, which takes a constrained solve
    of the whole state (every other event function reads the joint's two bodies alone)."""
    return kind == TANGENTIAL and modes[k] == STICK and exact_stick(system, k)


@njit(cache=True)
def interpolate(y, stages, h, theta, out):
    """The step's continuous extension y(t + θh) into out; the rows of `stages` name the method's: DOP853's 16, else
    DOPRI5's 7 (in whose form the Rosenbrock steps write theirs)."""
    if stages.shape[0] == dop853.STAGES:
        dense_output(y, stages, dop853.DENSE, h, theta, out)
    else:
        dense_output(y, stages, DENSE, h, theta, out)


@njit(cache=True, inline="always")
def interpolate_joint(system, k, y, stages, h, theta, out):
    """q and q̇ of joint k's two bodies on the step's continuous extension (interpolate's bits) into their places in
    out, the rest of out left as it is: all that the joint's kinematics, contact force and event functions but the
    friction reserve read, at O(1) cost instead of the whole state's O(bodies)."""
    if stages.shape[0] == dop853.STAGES:
        dense = dop853.DENSE
    else:
        dense = DENSE
    weights = dense_weights(dense, h, theta)
    n = coordinate_count(system)
    for part in range(4):  # the bearing's q, its q̇, the journal's q, its q̇
        body = system.clearance_bodies[k, part // 2]
        if body >= 0:
            first = (part % 2) * n + 3 * body
            dense_elements(y, stages, dense, weights, first, first + 3, out)


@njit(cache=True, inline="always")
def _crossed(mode, kind, before, after):
    if kind == NORMAL and mode == FREE:
        return before < 0.0 and after >= 0.0
    return before >= 0.0 and after < 0.0


@njit(cache=True)
def _value_at(system, dynamics, k, kind, t, y, stages, h, theta, modes, speeds, scratch):
    if needs_stick_solve(system, k, kind, modes):
        interpolate(y, stages, h, theta, scratch)
    else:
        interpolate_joint(system, k, y, stages, h, theta, scratch)
    return event_value(system, dynamics, k, kind, t + theta * h, scratch, modes, speeds, UNSOLVED)


@njit(cache=True, inline="always")
def _extremum(system, dynamics, k, kind, t, y, stages, h, lo, hi, modes, speeds, scratch):
    """θ where ġ = 0 between lo and hi (ġ changes sign there), by bisection (NORMAL events, which know ġ)."""
    rate_lo = _value_at(system, dynamics, k, kind, t, y, stages, h, lo, modes, speeds, scratch)[1]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        rate = _value_at(system, dynamics, k, kind, t, y, stages, h, mid, modes, speeds, scratch)[1]
        if (rate > 0.0) == (rate_lo > 0.0):
            lo, rate_lo = mid, rate
        else:
            hi = mid
        if hi - lo < 1e-12:
            break
    return 0.5 * (lo + hi)


@njit(cache=True, inline="always")
def _root(system, dynamics, k, kind, t, y, stages, h, lo, hi, modes, speeds, scratch):
    """θ just past the crossing of g in [lo, hi] (Illinois false position on the dense output)."""
    mode = modes[k]
    g_lo = _value_at(system, dynamics, k, kind, t, y, stages, h, lo, modes, speeds, scratch)[0]
    g_hi = _value_at(system, dynamics, k, kind, t, y, stages, h, hi, modes, speeds, scratch)[0]
    side = 0
    for _ in range(100):
        if hi - lo <= 1e-13:
            break
        mid = (lo * g_hi - hi * g_lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (lo + hi)
        mid = min(max(mid, lo + 0.01 * (hi - lo)), hi - 0.01 * (hi - lo))
        g_mid = _value_at(system, dynamics, k, kind, t, y, stages, h, mid, modes, speeds, scratch)[0]
        if _crossed(mode, kind, g_lo, g_mid):
            hi, g_hi = mid, g_mid
            if side == -1:
                g_lo *= 0.5
            side = -1
        else:
            lo, g_lo = mid, g_mid
            if side == 1:
                g_hi *= 0.5
            side = 1
    return hi


@njit(cache=True, inline="always")
def first_event(system, dynamics, k, kind, t, y, stages, h, kinematics, frictions, modes, speeds, scratch):
    """θ in (0, 1] of joint k's first event of this kind in the step, or 2.0 when there is none (kinematics: the
    joints' δ, δ̇ and v_t at the step's start, subdivisions and end, fill_point_kinematics; frictions: the sticking
    joints' F_t there, fill_stick_frictions)."""
    mode = modes[k]
    if kind == TANGENTIAL and (mode == FREE or not exact_stick(system, k)):
        return 2.0
    g_prev, r_prev = point_event_value(system, k, kind, kinematics[0, k], modes, speeds, frictions[0, k])
    theta_prev = 0.0
    for i in range(1, SUBDIVISIONS + 1):
        theta = i / SUBDIVISIONS
        g, r = point_event_value(system, k, kind, kinematics[i, k], modes, speeds, frictions[i, k])
        if _crossed(mode, kind, g_prev, g):
            return _root(system, dynamics, k, kind, t, y, stages, h, theta_prev, theta, modes, speeds, scratch)
        turning = (r_prev > 0.0 and r < 0.0) if mode == FREE else (r_prev < 0.0 and r > 0.0)
        if kind == NORMAL and turning:  # a graze: δ may cross and return between the two samples
            peak = _extremum(system, dynamics, k, kind, t, y, stages, h, theta_prev, theta, modes, speeds, scratch)
            g_peak = _value_at(system, dynamics, k, kind, t, y, stages, h, peak, modes, speeds, scratch)[0]
            if _crossed(mode, kind, g_prev, g_peak):
                return _root(system, dynamics, k, kind, t, y, stages, h, theta_prev, peak, modes, speeds, scratch)
        g_prev, r_prev, theta_prev = g, r, theta
    return 2.0


@njit(cache=True, inline="always")
def point_event_value(system, k, kind, kinematics, modes, speeds, friction):
    """event_value of joint k at one of the step's points from its row of fill_point_kinematics."""
    return kinematic_event_value(system, k, kind, kinematics[K_PENETRATION], kinematics[K_RATE],
                                 kinematics[K_SLIDING], modes, speeds, friction)


@njit(cache=True, inline="always")
def earliest_event(system, dynamics, t, y, y_new, stages, h, points, kinematics, frictions, modes, speeds, scratch):
    """(θ, joint, kind) of the step's first event, or (2.0, −1, NORMAL) when there is none (kinematics: room for
    fill_point_kinematics, filled here)."""
    fill_point_kinematics(system, y_new, points, modes, kinematics)
    fill_stick_frictions(system, dynamics, t, y, y_new, h, points, modes, speeds, frictions)
    event_theta = 2.0
    event_joint = np.int64(-1)  # int64 from the start: a literal would compile each callee once more for it
    event_kind = np.int64(NORMAL)
    for k in range(modes.shape[0]):
        for kind in range(2):
            theta = first_event(system, dynamics, k, kind, t, y, stages, h, kinematics, frictions, modes, speeds,
                                scratch)
            if theta < event_theta:
                event_theta, event_joint, event_kind = theta, k, kind
    return event_theta, event_joint, event_kind


@njit(cache=True, inline="always")
def fill_stick_frictions(system, dynamics, t, y, y_new, h, points, modes, speeds, frictions):
    """frictions[i, k] ← F_t of each sticking joint k at the step's point i (its start y, its subdivisions, its end
    y_new), where first_event reads them: one solve a point for every sticking joint (stick_frictions)."""
    for i in range(SUBDIVISIONS + 1):
        if i == 0:
            state, time = y, t
        elif i == SUBDIVISIONS:
            state, time = y_new, t + h
        else:
            state, time = points[i], t + i / SUBDIVISIONS * h
        stick_frictions(system, dynamics, time, state, modes, speeds, frictions[i])


@njit(cache=True)
def project_state(system, t, y, modes):
    """Project q and q̇ of y onto the constraint manifold (and v_t = 0 of sticking joints); returns max |Φ|."""
    n = coordinate_count(system)
    violation = project_positions(system, t, y[:n], modes, PROJECTION_TOLERANCE, 6)
    project_velocities(system, t, y[:n], y[n:2 * n], modes)
    return violation


def projection_type(system_type):
    """The numba type of a `projection` argument: project_state called by its address."""
    return types.FunctionType(types.float64(system_type, types.float64, types.float64[::1], types.int64[::1]))


@njit(cache=True, inline="always")
def emit_samples(system, dynamics, films, projection, implicit_step, high_order, t, y, f, stages, h, t_next, modes,
                 speeds, episode_of, real, ints, jacobian, jacobian_modes, out_t, out_y, out_modes, out_speeds,
                 out_episode, out_qdd, out_lam, out_contact, out_energies, scratch):
    """Write the samples with t < t_k <= t_next (and t_k = t at the very start), projected, with what derives
    from them (derive_sample)."""
    dt = real[R_SAMPLE_DT]
    # where a rosenbrock sample's own step starts: the step's start, then the sample before (model.md §4)
    origin_t, origin_y, origin_f = t, y, f
    while ints[I_NEXT_SAMPLE] < ints[I_TOTAL_SAMPLES]:
        sample_time = min(ints[I_NEXT_SAMPLE] * dt, real[R_T_END])
        if sample_time > t_next:
            break
        row = ints[I_SAMPLES]
        chained = h > 0.0 and ints[I_METHOD] == ROSENBROCK and t < sample_time < t + h
        if chained:
            # a step of its own to the sample: the Hermite extension is not damped like the step (model.md §4)
            ints[I_RHS] += method_step(system, dynamics, implicit_step, high_order, origin_t, origin_y, origin_f,
                                       sample_time - origin_t, modes, speeds, np.empty_like(stages), scratch, real,
                                       ints, jacobian, jacobian_modes, False)[1]
        elif h > 0.0:
            interpolate(y, stages, h, (sample_time - t) / h, scratch)
        else:
            copy_into(scratch, y)
        violation = projection(system, sample_time, scratch, modes)
        out_t[row] = sample_time
        copy_into(out_y[row], scratch)
        copy_into(out_modes[row], modes)
        copy_into(out_speeds[row], speeds)
        copy_into(out_episode[row], episode_of)
        derive_sample(system, dynamics, films, sample_time, scratch, violation, modes, speeds, out_qdd[row],
                      out_lam[row], out_contact[row], out_energies[row])
        if chained:
            origin_t, origin_y, origin_f = sample_time, scratch.copy(), np.empty_like(f)
            rhs(system, dynamics, sample_time, origin_y, modes, speeds, origin_f)
            ints[I_RHS] += 1
        ints[I_SAMPLES] += 1
        ints[I_NEXT_SAMPLE] += 1


@njit(cache=True, inline="always")
def contact_time_step(system, k, q, modes, speed):
    """Initial step into contact: the contact time over 20. Power laws: t_c = 3.218 (m/K)^(2/5) v^(−1/5) (Hertz);
    cylindrical laws: 2.943 δ_max/v with δ_max from the law's own energy (clearsim.physics.cylindrical)."""
    mass = effective_mass(system, k, q, modes)
    stiffness = system.clearance_params[k, CL_STIFFNESS]
    exponent = system.clearance_params[k, CL_EXPONENT]
    v = max(speed, system.clearance_params[k, CL_MIN_IMPACT_SPEED])
    if not np.isfinite(mass):
        return np.inf, mass
    law = system.clearance_laws[k, 3]
    if not is_power_law(law):
        depth = law_max_penetration(law, mass, v, stiffness, exponent, system.clearance_params[k, CL_CLEARANCE])
        return HERTZ_CONTACT_TIME_FACTOR * depth / v / 20.0, mass
    # t_c ∝ (m/K)^(1/(n+1)) v^((1−n)/(n+1)); exact prefactor for n = 1.5, fine as a scale for any n
    t_c = 3.218 * (mass / stiffness) ** (1.0 / (exponent + 1.0)) * v ** ((1.0 - exponent) / (exponent + 1.0))
    return t_c / 20.0, mass


@njit(cache=True, inline="always")
def settle_friction(system, dynamics, projection, k, t, y, modes, speeds, may_stick):
    """Choose how joint k's contact carries friction at time t: slide on, or stick if the wall can hold it.

    Sliding faster than DECIDE_SPEED goes on in its direction. Slower (a reversal, or a new contact
    that barely slides), the joint sticks when the friction force its stick constraint needs is within
    μ_s F_n, and otherwise slides against that force. Sticking starts with v_t projected to 0. A joint
    whose stick just broke (may_stick False) slides even if the state reached sits a hair before the
    crossing, so that the switch always happens and the time moves on.
    """
    if not exact_stick(system, k):
        modes[k] = CONTACT
        return
    n = coordinate_count(system)
    sliding = clearance_kinematics(system, k, y[:n], y[n:2 * n])[8]
    if abs(sliding) > DECIDE_SPEED:
        modes[k] = CONTACT if sliding > 0.0 else SLIDE_BACK
        return
    modes[k] = STICK
    reserve, friction = friction_reserve(system, dynamics, t, y, modes, speeds, k)
    if reserve < 0.0 or not may_stick:
        modes[k] = SLIDE_BACK if friction > 0.0 else CONTACT
    else:
        projection(system, t, y, modes)


@njit(cache=True, inline="always")
def tolerance_over_penetration(system, k, y, mass, speed, rtol, atol):
    """The error control's position tolerance at joint k's bodies over the undamped penetration of the impact at
    its onset: above 1 a step may err by more than the whole penetration, so the contact force is not resolved."""
    p = system.clearance_params[k]
    depth = law_max_penetration(system.clearance_laws[k, 3], mass, max(speed, p[CL_MIN_IMPACT_SPEED]),
                                p[CL_STIFFNESS], p[CL_EXPONENT], p[CL_CLEARANCE])
    scale = 0.0
    for slot in range(2):
        body = system.clearance_bodies[k, slot]
        if body >= 0:
            scale = max(scale, abs(y[3 * body]), abs(y[3 * body + 1]))
    return (atol + rtol * scale) / depth


@njit(cache=True)
def switch_mode(system, dynamics, projection, k, kind, t, y, modes, speeds, episode_of, real, ints, log_joint,
                log_onset, log_loss, log_speed, log_mass):
    """Apply joint k's event at time t; returns the suggested next step."""
    if kind == NORMAL and modes[k] != FREE:  # contact lost
        modes[k] = FREE
        log_loss[episode_of[k]] = t
        episode_of[k] = -1
        return np.inf
    onset = kind == NORMAL
    n = coordinate_count(system)
    if onset:
        speeds[k] = max(clearance_kinematics(system, k, y[:n], y[n:2 * n])[5], 0.0)
    # a stick that just broke slides; a new contact or a sliding one may stick
    settle_friction(system, dynamics, projection, k, t, y, modes, speeds, modes[k] != STICK)
    if not onset:
        ints[I_FRICTION_EVENTS] += 1
        return np.inf
    speed = speeds[k]
    h, mass = contact_time_step(system, k, y[:n], modes, speed)
    coarse = tolerance_over_penetration(system, k, y, mass, speed, real[R_RTOL], real[R_ATOL])
    real[R_COARSE_RATIO] = max(real[R_COARSE_RATIO], coarse)
    if coarse > UNRESOLVED_RATIO:
        if ints[I_COARSE] == 0:
            ints[I_COARSE_JOINT] = k
            real[R_COARSE_TIME] = t
        ints[I_COARSE] += 1
    row = ints[I_LOG]
    log_joint[row] = k
    log_onset[row] = t
    log_loss[row] = np.nan
    log_speed[row] = speed
    log_mass[row] = mass
    episode_of[k] = row
    ints[I_LOG] += 1
    ints[I_EVENTS] += 1
    return h


@njit(cache=True, inline="always")
def consistent_modes(system, dynamics, projection, mode_switch, t, y, modes, speeds, episode_of, real, ints, log_joint,
                     log_onset, log_loss, log_speed, log_mass, frictions):
    """Switch joints whose mode disagrees with the state at the step start (initial state, restarts); frictions: room
    for the sticking joints' F_t (stick_frictions), solved once for all of them until a switch changes the state."""
    h = np.inf
    solved = False
    for k in range(modes.shape[0]):
        for kind in range(2):
            if kind == TANGENTIAL and (modes[k] == FREE or not exact_stick(system, k)):
                continue
            if needs_stick_solve(system, k, kind, modes) and not solved:
                stick_frictions(system, dynamics, t, y, modes, speeds, frictions)
                solved = True
            g = event_value(system, dynamics, k, kind, t, y, modes, speeds, frictions[k])[0]
            if g > 0.0 if (kind == NORMAL and modes[k] == FREE) else g < 0.0:
                h = min(h, mode_switch(system, dynamics, projection, k, kind, t, y, modes, speeds, episode_of, real,
                                       ints, log_joint, log_onset, log_loss, log_speed, log_mass))
                solved = False  # the switch changed the modes, and may have projected y
    return h


@njit(cache=True, inline="always")
def free_flight_limit(system, y, modes):
    """Longest step that keeps every free journal from crossing its clearance c."""
    n = coordinate_count(system)
    limit = np.inf
    for k in range(modes.shape[0]):
        if modes[k] == FREE:
            kin = clearance_kinematics(system, k, y[:n], y[n:2 * n])
            speed = np.sqrt(kin[2] ** 2 + kin[3] ** 2)
            if speed > 0.0:
                limit = min(limit, system.clearance_params[k, CL_CLEARANCE] / speed)
    return limit


@njit(cache=True, inline="always")
def normal_force(system, k, state, modes, speeds):
    """F_n of joint k in a state."""
    n = coordinate_count(system)
    kin = clearance_kinematics(system, k, state[:n], state[n:2 * n])
    return contact_force_magnitudes(system, k, kin[4], kin[5], kin[8], modes[k], speeds[k])[0]


@njit(cache=True)
def normal_force_at(system, k, y, stages, h, theta, modes, speeds, scratch):
    """F_n of joint k at t + θh on the step's continuous extension."""
    interpolate_joint(system, k, y, stages, h, theta, scratch)
    return normal_force(system, k, scratch, modes, speeds)


@njit(cache=True, inline="always")
def fill_subdivisions(y, stages, h, points):
    """points[i] = the step's continuous extension at θ = i/SUBDIVISIONS, i = 0 … SUBDIVISIONS: interpolated once
    per step for the event search and the peak search of every joint."""
    for i in range(SUBDIVISIONS + 1):
        interpolate(y, stages, h, i / SUBDIVISIONS, points[i])


@njit(cache=True, inline="always")
def fill_point_kinematics(system, y_new, points, modes, kinematics):
    """kinematics[i, k] ← (δ, δ̇, v_t) of joint k (clearance_kinematics) at the step's point i: its start points[0]
    (its y bit for bit), its subdivisions, its end y_new, and at EXTENSION_END points[SUBDIVISIONS] for the joints
    in contact. One evaluation a joint and point for the event search and the peak search, point by point, so that
    each body's cosine and sine are computed once a point (kept_frame)."""
    n = coordinate_count(system)
    for i in range(EXTENSION_END + 1):
        state = y_new if i == SUBDIVISIONS else points[min(i, SUBDIVISIONS)]
        for k in range(modes.shape[0]):
            if i == EXTENSION_END and modes[k] == FREE:
                continue
            kin = clearance_kinematics(system, k, state[:n], state[n:2 * n])
            kinematics[i, k, K_PENETRATION] = kin[4]
            kinematics[i, k, K_RATE] = kin[5]
            kinematics[i, k, K_SLIDING] = kin[8]


@njit(cache=True, inline="always")
def point_normal_force(system, k, kinematics, modes, speeds):
    """F_n of joint k at one of the step's points from its row of fill_point_kinematics (normal_force's bits)."""
    return contact_force_magnitudes(system, k, kinematics[K_PENETRATION], kinematics[K_RATE], kinematics[K_SLIDING],
                                    modes[k], speeds[k])[0]


@njit(cache=True, inline="always")
def update_peaks(system, y, stages, h, kinematics, modes, speeds, peak_force, scratch):
    """Raise peak_force[k] to the largest F_n of the step: at its 5 points on the continuous extension (kinematics:
    fill_point_kinematics), then at an interior maximum.

    A maximum near the sampled one that could raise the peak so far is refined by golden-section
    search on the continuous extension (to 1e-5 of the step), so the peak contact force does not
    depend on where the steps happen to end.
    """
    golden = 0.5 * (np.sqrt(5.0) - 1.0)
    for k in range(modes.shape[0]):
        if modes[k] == FREE:
            continue
        best, best_theta = -1.0, 0.0
        for i in range(SUBDIVISIONS + 1):
            force = point_normal_force(system, k, kinematics[EXTENSION_END if i == SUBDIVISIONS else i, k], modes,
                                       speeds)
            if force > best:
                best, best_theta = force, i / SUBDIVISIONS
        if best < PEAK_CANDIDATE * peak_force[k]:
            continue  # far below the peak so far: nothing to refine
        lo = max(best_theta - 1.0 / SUBDIVISIONS, 0.0)
        hi = min(best_theta + 1.0 / SUBDIVISIONS, 1.0)
        a, b = hi - golden * (hi - lo), lo + golden * (hi - lo)
        fa = normal_force_at(system, k, y, stages, h, a, modes, speeds, scratch)
        fb = normal_force_at(system, k, y, stages, h, b, modes, speeds, scratch)
        for _ in range(40):
            if hi - lo < PEAK_RESOLUTION:
                break
            if fa >= fb:
                hi, b, fb = b, a, fa
                a = hi - golden * (hi - lo)
                fa = normal_force_at(system, k, y, stages, h, a, modes, speeds, scratch)
            else:
                lo, a, fa = a, b, fb
                b = lo + golden * (hi - lo)
                fb = normal_force_at(system, k, y, stages, h, b, modes, speeds, scratch)
        peak_force[k] = max(peak_force[k], best, fa, fb)


@njit(cache=True, inline="always")
def update_output_peak(n, y, f, real):
    """Raise real[R_PEAK_ACCELERATION] to |a · d| of the output point at a step's end, q and q̇ from y, q̈ from f = ẏ
    (the steps resolve each impact, so the peak does not depend on the output rate)."""
    b = int(real[R_OUTPUT_BODY])
    if b < 0:
        return
    c, s = np.cos(y[3 * b + 2]), np.sin(y[3 * b + 2])
    arm_x = c * real[R_OUTPUT_POINT_X] - s * real[R_OUTPUT_POINT_Y]
    arm_y = s * real[R_OUTPUT_POINT_X] + c * real[R_OUTPUT_POINT_Y]
    omega, alpha = y[n + 3 * b + 2], f[n + 3 * b + 2]
    ax = f[n + 3 * b] - alpha * arm_y - omega**2 * arm_x
    ay = f[n + 3 * b + 1] + alpha * arm_x - omega**2 * arm_y
    real[R_PEAK_ACCELERATION] = max(real[R_PEAK_ACCELERATION],
                                    abs(ax * real[R_OUTPUT_DIRECTION_X] + ay * real[R_OUTPUT_DIRECTION_Y]))


@njit(cache=True, inline="always")
def method_step(system, dynamics, implicit_step, high_order, t, y, f, h, modes, speeds, stages, y_new, real, ints,
                jacobian, jacobian_modes, take_jacobian):
    """One step of the run's method (ints[I_METHOD]); ROSENBROCK and DOP853: by address (rosenbrock.attempt, J taken
    anew first when take_jacobian; dop853.attempt). Returns (the error norm, the rhs evaluations made, the error
    estimate e, the weight w that makes w·e the estimate the norm measures: 1, or DOP853's combined over its 5th-order
    one)."""
    if ints[I_METHOD] == ROSENBROCK:
        error = implicit_step(system, dynamics, t, y, f, h, modes, speeds, stages, y_new, jacobian, jacobian_modes,
                              take_jacobian, real[R_ATOL] / real[R_RTOL])
        taken = rosenbrock.jacobian_evaluations(jacobian_modes) if take_jacobian else 0
        return steering_norm(system, error, y, y_new, real, ints), rosenbrock.STAGES + taken, error, 1.0
    if ints[I_METHOD] == DOP853:
        high, low = high_order(system, dynamics, t, y, f, h, modes, speeds, stages, y_new, False)
        high_norm = steering_norm(system, high, y, y_new, real, ints)
        norm = dop853.combined_norm(high_norm, steering_norm(system, low, y, y_new, real, ints))
        return norm, dop853.TRIAL_EVALUATIONS, high, norm / high_norm if high_norm > 0.0 else 0.0
    error = step(system, dynamics, t, y, f, h, modes, speeds, stages, y_new)
    return steering_norm(system, error, y, y_new, real, ints), 6, error, 1.0


@njit(cache=True, inline="always")
def guarded_norm(system, norm, error, weight, y, y_new, modes, real, ints, scratch):
    """The step's error norm, or the penetration guard's ratio where that rejects a try the norm would accept: a try
    whose estimated error (weight · error) in a contacting joint's penetration exceeds PENETRATION_ERROR_SHARE of the
    penetration (penetration_error_ratio) is taken again shorter, whatever the tolerance (model.md §4). Once the guard
    has rejected a try in the run, the larger of the two measures every try, so that the next step is proposed for
    the guard too; until then (every default run of the bundled models) the norm alone. scratch: room for a state."""
    ratio = weight * penetration_error_ratio(system, error, y, y_new, modes, real[R_ATOL], scratch)
    if ratio > max(norm, 1.0):
        if norm <= 1.0:
            ints[I_PENETRATION_REJECTED] += 1
        return ratio
    if ratio > norm and ints[I_PENETRATION_REJECTED] > 0:
        return ratio  # the guard has rejected a try in this run: it steers the steps from then on
    return norm  # within the share, or no larger than the norm; a NaN on either side: the norm's


@njit(cache=True)
def penetration_error_ratio(system, error, y, y_new, modes, atol, shifted):
    """max over the joints in contact of |δ(q_new) − δ(q_new − e_q)| / (PENETRATION_ERROR_SHARE · max(δ(q), δ(q_new),
    atol)): the step's error estimate e carried into each contacting joint's penetration, against a share of the
    penetration itself (0 with no joint in contact); shifted: room for q_new − e_q."""
    n = coordinate_count(system)
    for i in range(n):
        shifted[i] = y_new[i] - error[i]
    worst = 0.0
    for k in range(modes.shape[0]):
        if modes[k] == FREE:
            continue
        start = clearance_kinematics(system, k, y[:n], y[n:2 * n])[4]
        end = clearance_kinematics(system, k, y_new[:n], y_new[n:2 * n])[4]
        estimated = clearance_kinematics(system, k, shifted[:n], y_new[n:2 * n])[4]
        worst = max(worst, abs(end - estimated) / (PENETRATION_ERROR_SHARE * max(start, end, atol)))
    return worst


@njit(cache=True, inline="always")
def steering_norm(system, error, y, y_new, real, ints):
    """The error norm over the components that steer the steps (dopri.error_norm)."""
    return error_norm(error, y, y_new, 2 * coordinate_count(system), WORK_COUNT, ints[I_UNSTEERING_TAIL], real[R_RTOL],
                      real[R_ATOL])


@njit(cache=True, inline="always")
def error_order(method):
    """The order q of the error estimate that steers the steps of `method` (METHODS)."""
    if method == ROSENBROCK:
        return rosenbrock.EMBEDDED_ORDER
    if method == DOP853:
        return dop853.ERROR_ORDER
    return DOPRI5_ERROR_ORDER


@njit(cache=True, inline="always")
def extend_step(system, dynamics, high_order, t, y, h, modes, speeds, stages, ints):
    """The continuous extension's own stages of a step taken, where the method has them (DOP853, by address:
    dop853.attempt); returns the rhs evaluations made."""
    if ints[I_METHOD] != DOP853:
        return 0
    high_order(system, dynamics, t, y, y, h, modes, speeds, stages, y, True)
    return dop853.EXTENSION_EVALUATIONS


@njit(cache=True, inline="always")
def jacobian_due(ints, modes, jacobian_modes):
    """ROSENBROCK: the Jacobian held is stale (rosenbrock.jacobian_is_stale): the next step takes it anew."""
    return ints[I_METHOD] == ROSENBROCK and rosenbrock.jacobian_is_stale(ints[I_JACOBIAN_AGE], modes, jacobian_modes)


@njit(cache=True, inline="always")
def jumped_across(system, dynamics, k, kind, t, y, stages, h, theta, modes, speeds, scratch):
    """Whether a sliding joint's TANGENTIAL event at θ of the step (s v_t + ε_v crossing 0) is a jump across 0 rather
    than a zero: just past the located crossing the joint slides the other way faster than DECIDE_SPEED (a smooth
    crossing, located to 1e-13 of the step, is within ~1e-12 m/s of 0 there). v_t jumps where the nearest point of a
    worn bore leaves one rim of a pocket tighter than the journal for the other, turning the contact's normal."""
    if kind != TANGENTIAL or modes[k] == FREE or modes[k] == STICK or not exact_stick(system, k):
        return False
    return _value_at(system, dynamics, k, kind, t, y, stages, h, theta, modes, speeds, scratch)[0] < -DECIDE_SPEED


@njit(cache=True, inline="always")
def refine_event(system, dynamics, projection, implicit_step, high_order, k, kind, t, y, f, h_event, h_limit, modes,
                 speeds, stages, y_event, real, ints, jacobian, jacobian_modes):
    """Integrate from t exactly to joint k's event; returns the step length.

    NORMAL events: Newton on the step length until |δ| < 1e-3 ε. TANGENTIAL events: the dense-output
    root, integrated once (settle_friction decides from the state reached, whichever side it is on); a jump of the
    sliding speed across 0 (jumped_across; h_limit > h_event, the step it lies in) is integrated past: the step
    integrated again puts the jump a little off the dense output's, so it is lengthened (by JUMP_WIDENING of itself,
    then tenfold each time, at most to h_limit) until the state reached is past it and the joint slides on the other
    way.
    """
    tolerance = 1e-3 * hysteresis(system, k)
    widening = JUMP_WIDENING * h_event
    for _ in range(6):
        ints[I_RHS] += method_step(system, dynamics, implicit_step, high_order, t, y, f, h_event, modes, speeds, stages,
                                   y_event, real, ints, jacobian, jacobian_modes, False)[1]
        projection(system, t + h_event, y_event, modes)
        if kind == TANGENTIAL:
            if h_event >= h_limit or event_value(system, dynamics, k, kind, t + h_event, y_event, modes, speeds,
                                                 UNSOLVED)[0] < 0.0:
                break
            h_event = min(h_event + widening, h_limit)
            widening *= 10.0
            continue
        g, rate = event_value(system, dynamics, k, kind, t + h_event, y_event, modes, speeds, UNSOLVED)
        if abs(g) <= tolerance or rate == 0.0:
            break
        h_event = min(max(h_event - g / rate, 0.5 * h_event), 2.0 * h_event)
    return h_event


@njit(cache=True)
def advance(system, kernels, y, f, real, ints, modes, speeds, episode_of, log_joint, log_onset, log_loss, log_speed,
            log_mass, peak_force, jacobian, jacobian_modes, out_t, out_y, out_modes, out_speeds, out_episode, out_qdd,
            out_lam, out_contact, out_energies, t_stop):
    """Integrate until t_stop, the end, a full buffer, STEPS_PER_CALL tried steps or a failure; the status is
    ints[I_STATUS]. `kernels`: the LoopKernels the loop calls by address (loop_kernels)."""
    mode_switch, projection, dynamics = kernels.mode_switch, kernels.projection, kernels.dynamics
    films, implicit_step, high_order = kernels.films, kernels.implicit_step, kernels.high_order
    n = coordinate_count(system)
    stages = np.empty((dop853.STAGES if ints[I_METHOD] == DOP853 else STAGES, y.shape[0]))
    y_new = np.empty_like(y)
    scratch = np.empty_like(y)
    points = np.empty((SUBDIVISIONS + 1, y.shape[0]))
    frictions = np.zeros((SUBDIVISIONS + 1, modes.shape[0]))
    kinematics = np.zeros((EXTENSION_END + 1, modes.shape[0], 3))
    ints[I_STATUS] = RUNNING
    capacity = out_t.shape[0]
    attempts = 0
    ints[I_UNSTEERING_TAIL] = wear_state_count(system)
    # the step-size controller's exponent: −1/(q + 1) for the order q of the method's error estimate
    exponent = -1.0 / (error_order(ints[I_METHOD]) + 1)
    if real[R_STEP] <= 0.0:
        rhs(system, dynamics, real[R_TIME], y, modes, speeds, f)
        ints[I_STATUS] = FIRST_STEP
        return
    while True:
        t = real[R_TIME]
        if t >= real[R_T_END]:
            ints[I_STATUS] = DONE
            return
        if t >= t_stop:
            ints[I_STATUS] = CHUNK_END
            return
        if attempts >= STEPS_PER_CALL:
            ints[I_STATUS] = PAUSED
            return
        attempts += 1
        if ints[I_LOG] >= log_joint.shape[0] - modes.shape[0] - 1:
            ints[I_STATUS] = BUFFER_FULL
            return
        switched = consistent_modes(system, dynamics, projection, mode_switch, t, y, modes, speeds, episode_of, real,
                                    ints, log_joint, log_onset, log_loss, log_speed, log_mass, frictions[0])
        if switched < np.inf or ints[I_NEXT_SAMPLE] == 0:
            rhs(system, dynamics, t, y, modes, speeds, f)
            ints[I_RHS] += 1
            real[R_STEP] = min(real[R_STEP], switched)
        if ints[I_NEXT_SAMPLE] == 0:  # the first sample, in the modes the initial state has
            emit_samples(system, dynamics, films, projection, implicit_step, high_order, t, y, f, stages, 0.0, t, modes, speeds,
                         episode_of, real, ints, jacobian, jacobian_modes, out_t, out_y, out_modes, out_speeds, out_episode, out_qdd, out_lam, out_contact, out_energies,
                         scratch)
        h = min(real[R_STEP], real[R_MAX_STEP], real[R_T_END] - t, free_flight_limit(system, y, modes))
        h = max(h, real[R_MIN_STEP])
        if capacity - ints[I_SAMPLES] < h / real[R_SAMPLE_DT] + 2.0:
            if ints[I_SAMPLES] > 0:
                ints[I_STATUS] = BUFFER_FULL
                return
            h = (capacity - 2) * real[R_SAMPLE_DT]
        take_jacobian = jacobian_due(ints, modes, jacobian_modes)
        norm, evaluations, error, weight = method_step(system, dynamics, implicit_step, high_order, t, y, f, h, modes,
                                                       speeds, stages, y_new, real, ints, jacobian, jacobian_modes,
                                                       take_jacobian)
        norm = guarded_norm(system, norm, error, weight, y, y_new, modes, real, ints, scratch)
        ints[I_RHS] += evaluations
        if take_jacobian:
            ints[I_JACOBIAN_AGE] = 0
        if not np.isfinite(norm):
            norm = 1e10
        if norm > 1.0:
            ints[I_REJECTED] += 1
            if h <= real[R_MIN_STEP] * (1.0 + 1e-12):
                ints[I_STATUS] = MIN_STEP
                return
            real[R_STEP] = max(h * max(0.2, SAFETY * norm ** exponent), real[R_MIN_STEP])
            if ints[I_JACOBIAN_AGE] > 0:  # a Jacobian that has served accepted steps may be what failed: take it anew
                ints[I_JACOBIAN_AGE] = -1
            continue
        real[R_STEP] = h * min(10.0, max(0.2, SAFETY * norm ** exponent)) if norm > 0.0 else 10.0 * h
        ints[I_JACOBIAN_AGE] += 1
        ints[I_RHS] += extend_step(system, dynamics, high_order, t, y, h, modes, speeds, stages, ints)
        fill_subdivisions(y, stages, h, points)
        event_theta, event_joint, event_kind = earliest_event(system, dynamics, t, y, y_new, stages, h, points,
                                                              kinematics, frictions, modes, speeds, scratch)
        if event_joint >= 0:
            jump = jumped_across(system, dynamics, event_joint, event_kind, t, y, stages, h, event_theta, modes, speeds,
                                 scratch)
            h = refine_event(system, dynamics, projection, implicit_step, high_order, event_joint, event_kind, t, y,
                             f, event_theta * h, h if jump else event_theta * h, modes, speeds, stages, y_new, real, ints,
                             jacobian, jacobian_modes)
            ints[I_RHS] += extend_step(system, dynamics, high_order, t, y, h, modes, speeds, stages, ints)
            fill_subdivisions(y, stages, h, points)  # the step integrated again, to the event
            fill_point_kinematics(system, y_new, points, modes, kinematics)
        emit_samples(system, dynamics, films, projection, implicit_step, high_order, t, y, f, stages, h, t + h, modes, speeds,
                     episode_of, real, ints, jacobian, jacobian_modes, out_t, out_y, out_modes, out_speeds, out_episode, out_qdd, out_lam, out_contact, out_energies,
                     scratch)
        if event_joint < 0:  # projected after the samples: the step end's factor then serves its rhs below
            violation = projection(system, t + h, y_new, modes)
            real[R_VIOLATION] = max(real[R_VIOLATION], violation)
            if violation > DRIFT_LIMIT:
                ints[I_STATUS] = DRIFT
                return
        update_peaks(system, y, stages, h, kinematics, modes, speeds, peak_force, scratch)
        copy_into(y, y_new)
        real[R_TIME] = t + h if h < real[R_T_END] - t else real[R_T_END]
        ints[I_STEPS] += 1
        ints[I_STALLED] = ints[I_STALLED] + 1 if h < real[R_MIN_STEP] else 0
        if ints[I_STALLED] > STALLED_STEPS:
            ints[I_STATUS] = CHATTER
            ints[I_FAIL_JOINT] = event_joint
            return
        if not np.all(np.isfinite(y)):
            ints[I_STATUS] = NOT_FINITE
            return
        if event_joint >= 0:
            suggested = mode_switch(system, dynamics, projection, event_joint, event_kind, real[R_TIME], y, modes,
                                    speeds, episode_of, real, ints, log_joint, log_onset, log_loss, log_speed, log_mass)
            real[R_STEP] = min(real[R_STEP], suggested)
        for k in range(modes.shape[0]):
            if clearance_kinematics(system, k, y[:n], y[n:2 * n])[4] > DEEPEST_PENETRATION * system.clearance_params[k, CL_JOURNAL_RADIUS]:
                ints[I_STATUS] = TOO_DEEP
                ints[I_FAIL_JOINT] = k
                return
        rhs(system, dynamics, real[R_TIME], y, modes, speeds, f)
        ints[I_RHS] += 1
        update_output_peak(n, y, f, real)


def addressed(method: int, lubricated: bool) -> tuple:
    """The kernels `advance` takes by address for a run of `method` (METHODS) of a model with or without oil films
    (`lubricated`, dynamics.has_oil_films), in LOOP_KERNEL_FIELDS' order: the Rosenbrock step and the DOP853 step where
    each is the method, else its stand-in of the same type (rosenbrock.not_taken, dop853.not_taken, never called), so
    that only a run that takes such a step compiles it; likewise the dynamics and the sampling's film forces compile
    the oil films' kernels only for a lubricated model (dynamics_kernel, films_kernel). Every choice gives `advance`
    the same type."""
    implicit_step = rosenbrock.attempt if method == ROSENBROCK else rosenbrock.not_taken
    high_order = dop853.attempt if method == DOP853 else dop853.not_taken
    return (switch_mode, project_state, dynamics_kernel(lubricated), films_kernel(lubricated), implicit_step,
            high_order)


def addressed_kernels(system_type, method: int, lubricated: bool) -> list:
    """(kernel, numba function type) of each kernel `advance` takes by address, in LOOP_KERNEL_FIELDS' order.

    A kernel called by address is compiled once, as a library of its own, instead of being linked into (and
    optimised again with) each library that calls it, and the caller's compilation does not wait for it. After
    `advance` is typed the run compiles or loads each one, in this order (precompile.compile_addressed); the compile-ahead
    helper takes them in the reverse order (precompile.kernels_ahead), the largest first, so that on an empty cache
    the two processes share them and meet in the middle."""
    F, I, V, IV, M = types.float64, types.int64, types.float64[::1], types.int64[::1], types.float64[:, ::1]
    dynamics, projection = dynamics_type(system_type), projection_type(system_type)
    implicit_step = V(system_type, dynamics, F, V, V, F, IV, V, M, V, M, IV, types.boolean, F)
    high_order = types.Tuple((V, V))(system_type, dynamics, F, V, V, F, IV, V, M, V, types.boolean)
    signature = {
        rosenbrock.attempt: implicit_step,
        rosenbrock.not_taken: implicit_step,
        dop853.attempt: high_order,
        dop853.not_taken: high_order,
        switch_mode: F(system_type, dynamics, projection, I, I, F, V, IV, V, IV, V, IV, IV, V, V, V, V),
        project_state: projection.signature,
        forces_and_accelerations: dynamics.signature,
        dry_forces_and_accelerations: dynamics.signature,
        films_kernel(True): films_type(system_type).signature,
        films_kernel(False): films_type(system_type).signature,
    }
    return [(kernel, types.FunctionType(signature[kernel])) for kernel in addressed(method, lubricated)]


@structref.register
class LoopKernelsType(types.StructRef):
    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class LoopKernels(structref.StructRefProxy):
    """The kernels `advance` calls by address (addressed), as one object: numba converts a kernel passed as a
    function-type argument to its addresses at every call of the loop (two compile-result lookups each, ~0.25 ms for
    five); packed once per process, they are converted once."""


LOOP_KERNEL_FIELDS = ["mode_switch", "projection", "dynamics", "films", "implicit_step", "high_order"]  # addressed's
structref.define_proxy(LoopKernels, LoopKernelsType, LOOP_KERNEL_FIELDS)


@njit(cache=True)
def _pack_kernels(mode_switch, projection, dynamics, films, implicit_step, high_order):
    return LoopKernels(mode_switch, projection, dynamics, films, implicit_step, high_order)


def loop_kernels_type(system_type, method: int, lubricated: bool) -> LoopKernelsType:
    """The numba type of loop_kernels' object: its fields typed as function types (addressed_kernels)."""
    return LoopKernelsType([(name, kind) for name, (_, kind)
                            in zip(LOOP_KERNEL_FIELDS, addressed_kernels(system_type, method, lubricated))])


_packed_kernels: dict = {}


def loop_kernels(system_type, method: int, lubricated: bool) -> LoopKernels:
    """The kernels `advance` calls by address for a run of `method` of a model with or without oil films, packed
    once per process (each compiled or loaded then, if it was not: precompile.compile_addressed first, on an empty
    cache)."""
    key = (system_type, method, lubricated)
    if key not in _packed_kernels:
        kinds = addressed_kernels(system_type, method, lubricated)
        pack = _pack_kernels.compile(tuple(kind for _, kind in kinds))
        _packed_kernels[key] = pack(*(kernel for kernel, _ in kinds))
    return _packed_kernels[key]


def loop_arguments(system, method: int, lubricated: bool, *state):
    """advance's arguments for a system's kernel arrays, the run's method, whether its model has oil films and its
    state arrays (and t_stop)."""
    return (system, loop_kernels(typeof(system), method, lubricated), *state)


def compiled_loop(system_type, method: int, lubricated: bool, state: tuple):
    """`advance` for a system of this type, a run of `method` with or without oil films and these state arguments,
    with the kernels it takes by address typed as function types (loop_kernels_type), compiled or loaded from the
    cache at the first call in a process, from the types alone: the kernels themselves are compiled after it
    (precompile.compile_addressed), as on an empty cache the compile-ahead process does meanwhile. Then nothing else
    is compiled for it, so arguments of other types fail instead of compiling a second loop that links them in."""
    global _loop_ready
    if not _loop_ready:
        advance.compile((system_type, loop_kernels_type(system_type, method, lubricated),
                         *(typeof(value) for value in state)))
        advance.disable_compile()
        _loop_ready = True
    return advance


_loop_ready = False
