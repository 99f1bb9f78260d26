"""Exact sticking (friction `stick: exact`) against closed forms: a wheel in a bearing under gravity and a torque.

The journal of a clearance joint on the ground carries a wheel (mass m, inertia I, radius R_J) pressed
into the bearing by gravity. With ρ = c + δ the distance of the centres and φ the orbit angle from the
bottom, rolling without slip (v_t = 0) gives ω_J = −ρ φ̇/R_J and the pendulum

    (m + I/R_J²) ρ φ̈ = −m g sin φ − T/R_J,        equilibrium sin φ* = −T/(m g R_J),

which the tests integrate with DOP853 and compare with the full solver. A torque beyond the friction
angle makes the wheel slide: it then sits at tan φ = −μ_d and spins up at ω̇ = (T − μ_d m g cos φ R_J)/I.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

MASS, RADIUS, CLEARANCE, STIFFNESS, G = 2.0, 0.0099, 1e-4, 1e12, 9.81
INERTIA = 0.5 * MASS * RADIUS**2
STATIC_DEPTH = (MASS * G / STIFFNESS) ** (1 / 1.5)  # δ of the wheel resting at the bottom
MU_S, MU_D = 0.2, 0.15

WHEEL = """
name: wheel in a bearing
gravity: [0 m/s^2, -9.81 m/s^2]
defaults:
  contact: {{law: hertz, restitution: 1.0, exponent: 1.5, stiffness: 1e12 N/m^1.5}}
  friction: {{law: stiction_step, mu_s: 0.2, mu_d: 0.15, v_s: 1e-4 m/s, v_d: 1e-2 m/s{stick}}}
points: {{O: [0 m, 0 m]}}
bodies:
  - {{name: wheel, mass: 2 kg, inertia: {inertia} kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, wheel], at: O, bearing_radius: 10 mm, clearance: 0.1 mm,
     initial_eccentricity: [0 m, {depth} m]}}
forces:
  - {{name: motor, type: constant, body: wheel, torque: {torque} N*m}}
solver: {{t_end: {t_end} ms, output_rate: 20 kHz, rtol: 1e-9, atol: 1e-13, max_step: 0.1 ms}}
"""


def wheel(torque: float, t_end_ms: float, stick: str = "") -> str:
    return WHEEL.format(inertia=INERTIA, depth=-(CLEARANCE + STATIC_DEPTH), torque=torque, t_end=t_end_ms,
                        stick=f", stick: {stick}" if stick else "")


def torque_for(angle_deg: float) -> float:
    """T that puts the rolling equilibrium at φ* = angle (sin φ* = −T/(m g R_J))."""
    return -MASS * G * RADIUS * np.sin(np.radians(angle_deg))


def orbit_angle(result) -> np.ndarray:
    e = result["joints/O/eccentricity"]
    return np.arctan2(e[:, 0], -e[:, 1])


def rolling_pendulum(times: np.ndarray, torque: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(φ, F_t, F_n) of the rolling wheel released at rest from the bottom, by DOP853 at rtol 1e-12.

    Along t = (cos φ, sin φ): m ρ φ̈ = −m g sin φ + F_t; along n: F_n = m g cos φ + m ρ φ̇².
    """
    rho = CLEARANCE + STATIC_DEPTH

    def rate(_, state):
        phi, phi_dot = state
        return [phi_dot, (-MASS * G * np.sin(phi) - torque / RADIUS) / ((MASS + INERTIA / RADIUS**2) * rho)]

    solution = solve_ivp(rate, (0.0, times[-1]), [0.0, 0.0], method="DOP853", t_eval=times, rtol=1e-12, atol=1e-14)
    phi, phi_dot = solution.y
    phi_ddot = np.array([rate(0.0, state)[1] for state in solution.y.T])
    return phi, MASS * (rho * phi_ddot + G * np.sin(phi)), MASS * (G * np.cos(phi) + rho * phi_dot**2)


def test_a_wheel_below_the_friction_angle_rolls_like_the_closed_form_pendulum(simulate):
    torque = torque_for(-3.0)
    result = simulate(wheel(torque, 50.0))
    phi = orbit_angle(result)
    expected, friction, normal = rolling_pendulum(result["time"], torque)
    assert np.min(expected) < np.radians(-5.5)  # precondition: it swings to about 2 φ* = −6° and back, twice
    assert np.max(np.abs(phi - expected)) <= 2e-3 * np.radians(6.0)
    assert np.all(result["joints/O/normal_force"] > 0)
    assert np.max(np.abs(result["joints/O/sliding_velocity"])) <= 1e-9  # it never slips
    assert np.all(result["joints/O/stick"] == 1)
    # the stick constraint's multiplier is the friction force the closed form needs
    assert np.max(np.abs(result["joints/O/friction_force"] - friction)) <= 1e-2 * np.max(np.abs(friction))
    assert np.max(np.abs(friction) / normal) < MU_S  # precondition: the closed form never needs more than μ_s
    energy = result["energy/kinetic"] + result["energy/potential"] - result["energy/applied_work"]
    assert np.max(np.abs(energy - energy[0])) <= 1e-6 * np.max(result["energy/kinetic"])  # sticking does no work


def test_the_regularised_law_creeps_where_exact_sticking_holds(simulate):
    """The STEP band through zero lets a loaded contact creep at |v_t| ~ v_s |F_t|/(μ_s F_n); exact sticking does not."""
    torque = torque_for(-3.0)
    smooth = simulate(wheel(torque, 10.0, stick="smooth"))
    creep = np.max(np.abs(smooth["joints/O/sliding_velocity"][smooth["time"] > 2e-3]))
    assert 1e-7 < creep < 1e-4  # within the band, and far from zero


def test_a_wheel_beyond_the_friction_angle_slides_at_the_friction_angle_and_spins_up(simulate):
    torque = 3.0 * torque_for(-np.degrees(np.arctan(MU_D)))  # three times what friction can hold
    result = simulate(wheel(torque, 30.0))
    late = result["time"] > 10e-3
    sliding = result["joints/O/sliding_velocity"][late]
    assert np.all(sliding > 1e-2)  # sliding, and faster than v_d: μ = μ_d
    assert not np.any(result["joints/O/stick"][late])
    ratio = -result["joints/O/friction_force"][late] / result["joints/O/normal_force"][late]
    assert np.allclose(ratio, MU_D, rtol=1e-9, atol=0)
    phi = orbit_angle(result)[late]
    assert np.mean(phi) == pytest.approx(-np.arctan(MU_D), rel=2e-2)
    omega = result["bodies/wheel/qd"][late, 2]
    slope = np.polyfit(result["time"][late], omega, 1)[0]
    friction_torque = MU_D * MASS * G * np.cos(np.arctan(MU_D)) * RADIUS
    assert slope == pytest.approx((torque - friction_torque) / INERTIA, rel=1e-2)


def test_a_torque_just_beyond_static_friction_breaks_the_stick_where_the_closed_form_says(simulate):
    """Rolling from the bottom, the wheel sticks until the pendulum's friction demand |F_t| reaches μ_s F_n."""
    torque = torque_for(-0.75 * np.degrees(np.arctan(MU_S)))  # the swing to 2 φ* needs more than μ_s
    result = simulate(wheel(torque, 15.0))
    _, friction, normal = rolling_pendulum(result["time"], torque)
    demand_exceeds = np.abs(friction) > MU_S * normal
    assert demand_exceeds.any()  # precondition
    slips = np.abs(result["joints/O/sliding_velocity"]) > 1e-9
    assert slips.any()
    expected, first = result["time"][np.argmax(demand_exceeds)], result["time"][np.argmax(slips)]
    assert abs(first - expected) <= 1.5 / 20e3  # the sample of the first slip (20 kHz output)
