"""The compiled integration loop: adaptive DOPRI5 steps, contact events, fixed-rate samples.

Each clearance joint has a mode (free / contact) that is constant within a step, so every
step integrates a smooth right-hand side. Contact onset (δ rising through 0) and loss (δ
falling through −ε, a hysteresis of ε = 1e-12 m so that a restart at δ ≈ 0 neither
re-fires nor misses the event) are found on the step's continuous extension, including a
graze that enters and leaves inside one step (an extremum of δ, located where δ̇ = 0). The
step that holds the earliest event is then integrated again exactly up to the event, with
Newton corrections of its length until |δ| < 1e-3 ε (DESIGN.md §4 "restart state"). At onset
the impact speed δ̇⁻ is stored for the damping law and the next step starts from the Hertz
contact time t_c = 3.218 (m_eff/K)^(2/5) δ̇⁻^(−1/5) / 20. Free flight steps never exceed the
time to cross the clearance c at the current relative speed. Output samples come from the
continuous extension of the step that contains them, which never spans a mode switch, and are
projected onto the constraints like every step end.

The loop runs until t_stop, a full sample buffer or a failure, then returns to Python (progress
bar, writing, Ctrl-C); all its state lives in the arrays of `IntegratorState`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.arrays import CL_CLEARANCE, CL_EXPONENT, CL_JOURNAL_RADIUS, CL_MIN_IMPACT_SPEED, CL_STIFFNESS
from clearsim.assembly.dynamics import (
    coordinate_count, effective_mass, project_positions, project_velocities, rhs,
)
from clearsim.assembly.forces import CONTACT, FREE, clearance_kinematics, contact_force_magnitudes
from clearsim.solver.dopri import STAGES, error_norm, interpolate, step

# real_state slots
R_TIME, R_STEP, R_T_END, R_RTOL, R_ATOL, R_MAX_STEP, R_MIN_STEP, R_SAMPLE_DT, R_VIOLATION = range(9)
# int_state slots
I_STATUS, I_STEPS, I_REJECTED, I_RHS, I_EVENTS, I_SAMPLES, I_NEXT_SAMPLE, I_FAIL_JOINT, I_LOG, I_TOTAL_SAMPLES = range(10)

RUNNING, DONE, MIN_STEP, NOT_FINITE, DRIFT, TOO_DEEP, BUFFER_FULL, CHUNK_END = range(8)

SUBDIVISIONS = 4  # points per step at which the event functions are sampled
PROJECTION_TOLERANCE = 1e-13  # m (rad): max |Φ| kept after each step
DRIFT_LIMIT = 1e-8  # m: a projection that cannot get below this has lost the assembly
SAFETY = 0.9
DEEPEST_PENETRATION = 0.05  # of the journal radius: beyond it no contact law means anything


@njit(cache=True)
def hysteresis(system, k):
    """ε of the loss event of joint k (m): far above round-off of e (~1e-16 m), far below any penetration."""
    return 1e-12


@njit(cache=True)
def event_value(system, k, y, mode):
    """(g, ġ): δ in free flight (onset at g ↑ 0), δ + ε in contact (loss at g ↓ 0)."""
    n = coordinate_count(system)
    kin = clearance_kinematics(system, k, y[:n], y[n:2 * n])
    shift = hysteresis(system, k) if mode == CONTACT else 0.0
    return kin[4] + shift, kin[5]


@njit(cache=True)
def _crossed(mode, before, after):
    if mode == FREE:
        return before < 0.0 and after >= 0.0
    return before >= 0.0 and after < 0.0


@njit(cache=True)
def _value_at(system, k, mode, y, stages, h, theta, scratch):
    interpolate(y, stages, h, theta, scratch)
    return event_value(system, k, scratch, mode)


@njit(cache=True)
def _extremum(system, k, mode, y, stages, h, lo, hi, scratch):
    """θ where ġ = 0 between lo and hi (ġ changes sign there), by bisection."""
    rate_lo = _value_at(system, k, mode, y, stages, h, lo, scratch)[1]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        rate = _value_at(system, k, mode, y, stages, h, mid, scratch)[1]
        if (rate > 0.0) == (rate_lo > 0.0):
            lo, rate_lo = mid, rate
        else:
            hi = mid
        if hi - lo < 1e-12:
            break
    return 0.5 * (lo + hi)


@njit(cache=True)
def _root(system, k, mode, y, stages, h, lo, hi, scratch):
    """θ just past the crossing of g in [lo, hi] (Illinois false position on the dense output)."""
    g_lo = _value_at(system, k, mode, y, stages, h, lo, scratch)[0]
    g_hi = _value_at(system, k, mode, y, stages, h, hi, scratch)[0]
    side = 0
    for _ in range(100):
        if hi - lo <= 1e-13:
            break
        mid = (lo * g_hi - hi * g_lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (lo + hi)
        mid = min(max(mid, lo + 0.01 * (hi - lo)), hi - 0.01 * (hi - lo))
        g_mid = _value_at(system, k, mode, y, stages, h, mid, scratch)[0]
        if _crossed(mode, g_lo, g_mid):
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


@njit(cache=True)
def first_event(system, k, mode, y, y_new, stages, h, scratch):
    """θ in (0, 1] of joint k's first event in the step, or 2.0 when there is none."""
    g_prev, r_prev = event_value(system, k, y, mode)
    theta_prev = 0.0
    for i in range(1, SUBDIVISIONS + 1):
        theta = i / SUBDIVISIONS
        if i == SUBDIVISIONS:
            g, r = event_value(system, k, y_new, mode)
        else:
            g, r = _value_at(system, k, mode, y, stages, h, theta, scratch)
        if _crossed(mode, g_prev, g):
            return _root(system, k, mode, y, stages, h, theta_prev, theta, scratch)
        turning = (r_prev > 0.0 and r < 0.0) if mode == FREE else (r_prev < 0.0 and r > 0.0)
        if turning:  # a graze: δ may cross and return between the two samples
            peak = _extremum(system, k, mode, y, stages, h, theta_prev, theta, scratch)
            g_peak = _value_at(system, k, mode, y, stages, h, peak, scratch)[0]
            if _crossed(mode, g_prev, g_peak):
                return _root(system, k, mode, y, stages, h, theta_prev, peak, scratch)
        g_prev, r_prev, theta_prev = g, r, theta
    return 2.0


@njit(cache=True)
def project_state(system, t, y):
    """Project q and q̇ of y onto the constraint manifold; returns the remaining max |Φ|."""
    n = coordinate_count(system)
    violation = project_positions(system, t, y[:n], PROJECTION_TOLERANCE, 6)
    project_velocities(system, t, y[:n], y[n:2 * n])
    return violation


@njit(cache=True)
def emit_samples(system, t, y, stages, h, t_next, modes, speeds, episode_of, real, ints,
                 out_t, out_y, out_modes, out_speeds, out_episode, scratch):
    """Write the samples with t < t_k <= t_next (and t_k = t at the very start), projected."""
    dt = real[R_SAMPLE_DT]
    while ints[I_NEXT_SAMPLE] < ints[I_TOTAL_SAMPLES]:
        sample_time = min(ints[I_NEXT_SAMPLE] * dt, real[R_T_END])
        if sample_time > t_next:
            break
        row = ints[I_SAMPLES]
        if h > 0.0:
            interpolate(y, stages, h, (sample_time - t) / h, scratch)
        else:
            scratch[:] = y
        project_state(system, sample_time, scratch)
        out_t[row] = sample_time
        out_y[row, :] = scratch
        out_modes[row, :] = modes
        out_speeds[row, :] = speeds
        out_episode[row, :] = episode_of
        ints[I_SAMPLES] += 1
        ints[I_NEXT_SAMPLE] += 1


@njit(cache=True)
def contact_time_step(system, k, q, speed):
    """Initial step into contact: the Hertz contact time t_c = 3.218 (m/K)^(2/5) v^(−1/5), over 20."""
    mass = effective_mass(system, k, q)
    stiffness = system.clearance_params[k, CL_STIFFNESS]
    exponent = system.clearance_params[k, CL_EXPONENT]
    v = max(speed, system.clearance_params[k, CL_MIN_IMPACT_SPEED])
    if not np.isfinite(mass):
        return np.inf, mass
    # t_c ∝ (m/K)^(1/(n+1)) v^((1−n)/(n+1)); exact prefactor for n = 1.5, fine as a scale for any n
    t_c = 3.218 * (mass / stiffness) ** (1.0 / (exponent + 1.0)) * v ** ((1.0 - exponent) / (exponent + 1.0))
    return t_c / 20.0, mass


@njit(cache=True)
def switch_mode(system, k, t, y, modes, speeds, episode_of, ints, log_joint, log_onset, log_loss,
                log_speed, log_mass):
    """Apply joint k's event at time t; returns the suggested next step."""
    n = coordinate_count(system)
    if modes[k] == CONTACT:
        modes[k] = FREE
        log_loss[episode_of[k]] = t
        episode_of[k] = -1
        return np.inf
    speed = max(clearance_kinematics(system, k, y[:n], y[n:2 * n])[5], 0.0)
    modes[k] = CONTACT
    speeds[k] = speed
    h, mass = contact_time_step(system, k, y[:n], speed)
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


@njit(cache=True)
def consistent_modes(system, t, y, modes, speeds, episode_of, ints, log_joint, log_onset, log_loss,
                     log_speed, log_mass):
    """Switch joints whose mode disagrees with δ at the step start (initial state, restarts)."""
    h = np.inf
    for k in range(modes.shape[0]):
        g = event_value(system, k, y, modes[k])[0]
        if (modes[k] == FREE and g > 0.0) or (modes[k] == CONTACT and g < 0.0):
            h = min(h, switch_mode(system, k, t, y, modes, speeds, episode_of, ints, log_joint,
                                   log_onset, log_loss, log_speed, log_mass))
    return h


@njit(cache=True)
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


@njit(cache=True)
def update_peaks(system, y, modes, speeds, peak_force):
    n = coordinate_count(system)
    for k in range(modes.shape[0]):
        kin = clearance_kinematics(system, k, y[:n], y[n:2 * n])
        force = contact_force_magnitudes(system, k, kin[4], kin[5], kin[8], modes[k], speeds[k])[0]
        peak_force[k] = max(peak_force[k], force)


@njit(cache=True)
def refine_event(system, k, t, y, f, h_event, modes, speeds, stages, y_event, ints):
    """Integrate from t exactly to joint k's event (Newton on the step length); returns that length."""
    tolerance = 1e-3 * hysteresis(system, k)
    for _ in range(6):
        step(system, t, y, f, h_event, modes, speeds, stages, y_event)
        ints[I_RHS] += 6
        project_state(system, t + h_event, y_event)
        g, rate = event_value(system, k, y_event, modes[k])
        if abs(g) <= tolerance or rate == 0.0:
            break
        h_event = min(max(h_event - g / rate, 0.5 * h_event), 2.0 * h_event)
    return h_event


@njit(cache=True)
def advance(system, y, f, real, ints, modes, speeds, episode_of, log_joint, log_onset, log_loss,
            log_speed, log_mass, peak_force, out_t, out_y, out_modes, out_speeds, out_episode, t_stop):
    """Integrate until t_stop, the end, a full buffer or a failure; the status is ints[I_STATUS]."""
    n = coordinate_count(system)
    stages = np.empty((STAGES, y.shape[0]))
    y_new = np.empty_like(y)
    scratch = np.empty_like(y)
    ints[I_STATUS] = RUNNING
    capacity = out_t.shape[0]
    while True:
        t = real[R_TIME]
        if ints[I_NEXT_SAMPLE] == 0:
            emit_samples(system, t, y, stages, 0.0, t, modes, speeds, episode_of, real, ints,
                         out_t, out_y, out_modes, out_speeds, out_episode, scratch)
        if t >= real[R_T_END]:
            ints[I_STATUS] = DONE
            return
        if t >= t_stop:
            ints[I_STATUS] = CHUNK_END
            return
        if ints[I_LOG] >= log_joint.shape[0] - modes.shape[0] - 1:
            ints[I_STATUS] = BUFFER_FULL
            return
        switched = consistent_modes(system, t, y, modes, speeds, episode_of, ints, log_joint, log_onset,
                                    log_loss, log_speed, log_mass)
        if switched < np.inf:
            rhs(system, t, y, modes, speeds, f)
            ints[I_RHS] += 1
            real[R_STEP] = min(real[R_STEP], switched)
        h = min(real[R_STEP], real[R_MAX_STEP], real[R_T_END] - t, free_flight_limit(system, y, modes))
        h = max(h, real[R_MIN_STEP])
        if capacity - ints[I_SAMPLES] < h / real[R_SAMPLE_DT] + 2.0:
            if ints[I_SAMPLES] > 0:
                ints[I_STATUS] = BUFFER_FULL
                return
            h = (capacity - 2) * real[R_SAMPLE_DT]
        error = step(system, t, y, f, h, modes, speeds, stages, y_new)
        ints[I_RHS] += 6
        norm = error_norm(error, y, y_new, 2 * n, real[R_RTOL], real[R_ATOL])
        if not np.isfinite(norm):
            norm = 1e10
        if norm > 1.0:
            ints[I_REJECTED] += 1
            if h <= real[R_MIN_STEP] * (1.0 + 1e-12):
                ints[I_STATUS] = MIN_STEP
                return
            real[R_STEP] = max(h * max(0.2, SAFETY * norm ** -0.2), real[R_MIN_STEP])
            continue
        real[R_STEP] = h * min(10.0, max(0.2, SAFETY * norm ** -0.2)) if norm > 0.0 else 10.0 * h
        event_theta = 2.0
        event_joint = -1
        for k in range(modes.shape[0]):
            theta = first_event(system, k, modes[k], y, y_new, stages, h, scratch)
            if theta < event_theta:
                event_theta, event_joint = theta, k
        if event_joint >= 0:
            h = refine_event(system, event_joint, t, y, f, event_theta * h, modes, speeds, stages, y_new, ints)
        else:
            violation = project_state(system, t + h, y_new)
            real[R_VIOLATION] = max(real[R_VIOLATION], violation)
            if violation > DRIFT_LIMIT:
                ints[I_STATUS] = DRIFT
                return
        emit_samples(system, t, y, stages, h, t + h, modes, speeds, episode_of, real, ints,
                     out_t, out_y, out_modes, out_speeds, out_episode, scratch)
        y[:] = y_new
        real[R_TIME] = t + h if h < real[R_T_END] - t else real[R_T_END]
        ints[I_STEPS] += 1
        if not np.all(np.isfinite(y)):
            ints[I_STATUS] = NOT_FINITE
            return
        if event_joint >= 0:
            suggested = switch_mode(system, event_joint, real[R_TIME], y, modes, speeds, episode_of, ints,
                                    log_joint, log_onset, log_loss, log_speed, log_mass)
            real[R_STEP] = min(real[R_STEP], suggested)
        update_peaks(system, y, modes, speeds, peak_force)
        for k in range(modes.shape[0]):
            if event_value(system, k, y, FREE)[0] > DEEPEST_PENETRATION * system.clearance_params[k, CL_JOURNAL_RADIUS]:
                ints[I_STATUS] = TOO_DEEP
                ints[I_FAIL_JOINT] = k
                return
        rhs(system, real[R_TIME], y, modes, speeds, f)
        ints[I_RHS] += 1
