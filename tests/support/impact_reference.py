"""High-precision 1-DOF impact: m δ̈ = −F(δ, δ̇) from δ = 0, δ̇ = v⁻ until δ returns to 0.

The reference against which contact laws (and the full solver's first
impacts) are checked. Integration is DOP853 at rtol 1e-12 with events at the
deepest penetration (δ̇ = 0) and at separation (δ = 0, decreasing), so every
reported quantity comes from an event location, not from a sampled output.
"""

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from clearsim.physics.contact import damped_force, hertz_max_penetration, normal_force
from clearsim.physics.cylindrical import law_max_penetration, law_state

# Damped laws at low restitution leave the wall slowly (exit speed ≪ v⁻), so the
# contact can last many Hertz times; the separation event ends the run long before.
_SPAN_IN_TIME_SCALES = 1.0e4
_PEAK_SEARCH_SAMPLES = 4001


@dataclass(frozen=True)
class ImpactResult:
    impact_speed: float  # m/s, δ̇⁻ at onset
    exit_speed: float  # m/s, |δ̇| at separation
    restitution: float  # exit_speed / impact_speed
    max_penetration: float  # m
    peak_force: float  # N, max of F over the contact (not F at δ_max for damped laws)
    contact_time: float  # s, onset to separation


def integrate_impact(force, mass, impact_speed, time_scale, rtol=1e-12):
    """Integrate one impact; force(penetration, penetration_rate) -> N, time_scale ~ contact time in s."""

    def rhs(_t, state):
        return [state[1], -force(state[0], state[1]) / mass]

    def deepest(_t, state):
        return state[1]

    def separation(_t, state):
        return state[0]

    deepest.direction = -1.0
    separation.direction = -1.0
    separation.terminal = True
    length_scale = impact_speed * time_scale
    solution = solve_ivp(
        rhs, (0.0, _SPAN_IN_TIME_SCALES * time_scale), [0.0, impact_speed], method="DOP853",
        rtol=rtol, atol=[rtol * length_scale, rtol * impact_speed], events=(deepest, separation),
        dense_output=True, first_step=1e-3 * time_scale,
    )
    if solution.status != 1 or len(solution.t_events[1]) != 1:
        raise RuntimeError(f"impact did not separate within {solution.t[-1]:.3e} s: {solution.message}")
    contact_time = solution.t_events[1][0]
    exit_speed = abs(solution.y_events[1][0][1])
    peak = _peak_force(force, solution.sol, contact_time)
    return ImpactResult(impact_speed, exit_speed, exit_speed / impact_speed,
                        solution.y_events[0][0][0], peak, contact_time)


def _peak_force(force, dense, contact_time):
    """Max of F(t) over the contact: dense sampling, then a bounded refinement around the best sample."""

    def force_at(t):
        penetration, penetration_rate = dense(t)
        return force(penetration, penetration_rate)

    times = np.linspace(0.0, contact_time, _PEAK_SEARCH_SAMPLES)
    best = int(np.argmax([force_at(t) for t in times]))
    lower, upper = times[max(best - 1, 0)], times[min(best + 1, len(times) - 1)]
    refined = minimize_scalar(lambda t: -force_at(t), bounds=(lower, upper), method="bounded",
                              options={"xatol": 1e-14 * contact_time})
    return max(-refined.fun, force_at(times[best]))


def law_impact(law, restitution, stiffness=1.0e10, mass=1.0, impact_speed=1.0, exponent=1.5,
               rtol=1e-12):
    """One impact under a clearsim contact law (a CONTACT_LAWS code), SI units."""

    def force(penetration, penetration_rate):
        return normal_force(law, penetration, penetration_rate, impact_speed, stiffness, exponent, restitution)

    time_scale = hertz_max_penetration(mass, stiffness, impact_speed, exponent) / impact_speed
    return integrate_impact(force, mass, impact_speed, time_scale, rtol)


def elastic_law_impact(damping_law, elastic_law, restitution, stiffness, exponent, clearance, mass=1.0,
                       impact_speed=1.0, rtol=1e-12):
    """One impact under damping law `damping_law` (CONTACT_LAWS code) times the elastic law `elastic_law`
    (cylindrical.ELASTIC_LAWS code) with its K, n and ΔR, SI units."""

    def force(penetration, penetration_rate):
        if penetration <= 0.0:
            return 0.0
        elastic = law_state(elastic_law, penetration, stiffness, exponent, clearance)[0]
        return damped_force(damping_law, elastic, penetration_rate, impact_speed, restitution)

    depth = law_max_penetration(elastic_law, mass, impact_speed, stiffness, exponent, clearance)
    return integrate_impact(force, mass, impact_speed, depth / impact_speed, rtol)
