"""Applied forces and prescribed motions against closed-form solutions."""

import numpy as np
import pytest

OSCILLATOR = """
name: slider on a spring-damper
points: {O: [0 m, 0 m], W: [-0.2 m, 0 m]}
bodies:
  - {name: block, mass: 2 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m], velocity: [0.5 m/s, 0 m/s]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [1, 0]}
forces:
  - {name: spring, type: spring_damper, bodies: [ground, block], at: [W, O], stiffness: 800 N/m, damping: DAMPING}
sensors:
  - {name: x, type: point_displacement, body: block, direction: [1, 0]}
  - {name: spring_force, type: joint_force, joint: guide, component: magnitude}
solver: {t_end: 1 s, output_rate: 1 kHz, rtol: 1e-10, atol: 1e-12, max_step: 1 ms}
"""


@pytest.mark.parametrize("damping", [0.0, 8.0])
def test_spring_damper_oscillator_matches_closed_form(simulate, damping):
    result = simulate(OSCILLATOR.replace("DAMPING", f"{damping} N*s/m"))
    t = result["time"]
    omega0, zeta = np.sqrt(800 / 2), damping / (2 * np.sqrt(800 * 2))
    omega_d = omega0 * np.sqrt(1 - zeta**2)
    expected = 0.5 / omega_d * np.exp(-zeta * omega0 * t) * np.sin(omega_d * t)  # x(0) = 0, ẋ(0) = 0.5 m/s
    assert np.max(np.abs(result["sensors/x"] - expected)) <= 1e-7 * 0.5 / omega0
    work = result["energy/damping_dissipated"][-1]
    assert work == pytest.approx(0.25 - result["energy/kinetic"][-1] - result["energy/potential"][-1], rel=1e-6, abs=1e-9 * 0.25)  # J: integration error at rtol 1e-10


CONSTANT_AND_TABLE = """
name: block pushed by a constant force and a tabulated force
points: {O: [0 m, 0 m]}
bodies:
  - {name: block, mass: 4 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [0.6, 0.8]}
forces:
  - {name: push, type: constant, body: block, force: [6 N, 8 N]}
  - {name: ramp, type: tabulated, body: block, direction: [0.6, 0.8], file: ramp.csv, time_unit: ms, value_unit: kN}
sensors:
  - {name: s, type: point_displacement, body: block, direction: [0.6, 0.8]}
solver: {t_end: 0.1 s, output_rate: 1 kHz, rtol: 1e-10, atol: 1e-12}
"""


def test_constant_and_tabulated_forces(simulate, tmp_path):
    (tmp_path / "ramp.csv").write_text("time,force\n0,0\n50,0.1\n100,0.2\n")  # F = 2 kN/s · t, linear

    config = tmp_path / "push.yaml"
    config.write_text(CONSTANT_AND_TABLE)
    result = simulate(str(config))
    t = result["time"]
    expected = (10.0 * t**2 / 2 + 2000.0 * t**3 / 6) / 4.0  # s̈ = (10 N + 2000 N/s · t)/4 kg
    assert np.max(np.abs(result["sensors/s"] - expected)) <= 1e-9 * np.max(expected)
    assert result["energy/applied_work"][-1] == pytest.approx(result["energy/kinetic"][-1], rel=1e-8)


DRIVEN = """
name: crank driven by angle, slider driven by a table
units: SI  # the polynomial coefficients: rad/s and rad/s^2
points: {O: [0 m, 0 m]}
bodies:
  - {name: crank, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m], angle: 30 deg}
  - {name: carriage, mass: 2 kg, inertia: 0.01 kg*m^2, position: [1 m, 0 m]}
joints:
  - {name: pivot, type: revolute, bodies: [ground, crank], at: O}
drivers:
  - {name: turn, body: crank, coordinate: angle, motion: {law: polynomial, coefficients: [2.0, 0.5]}}
  - {name: carry_x, body: carriage, coordinate: x, motion: {law: table, file: stroke.csv, time_unit: ms, value_unit: mm}}
  - {name: carry_y, body: carriage, coordinate: y, motion: {law: stroke, stroke: 30 mm, duration: 40 ms}}
  - {name: carry_angle, body: carriage, coordinate: angle, motion: {law: constant_speed, speed: 60 rpm}}
solver: {t_end: 80 ms, output_rate: 1 kHz, rtol: 1e-9}
"""


def test_drivers_follow_their_laws(simulate, tmp_path):
    times = np.linspace(0, 100, 101)
    (tmp_path / "stroke.csv").write_text("t,x\n" + "\n".join(f"{a},{5 * a}" for a in times))  # 5 mm/ms = 5 m/s
    config = tmp_path / "driven.yaml"
    config.write_text(DRIVEN)
    result = simulate(str(config))
    t = result["time"]
    crank, carriage = result["bodies/crank/q"], result["bodies/carriage/q"]
    assert np.allclose(crank[:, 2], np.radians(30) + 2.0 * t + 0.5 * t**2, atol=1e-10)
    assert np.allclose(carriage[:, 0], 1.0 + 5.0 * t, atol=1e-10)  # a linear table is reproduced exactly
    tau = np.minimum(t / 0.04, 1.0)
    assert np.allclose(carriage[:, 1], 0.03 * tau**2 * (3 - 2 * tau), atol=1e-10)
    assert np.allclose(carriage[:, 2], 2 * np.pi * t, atol=1e-10)
    assert np.allclose(result["bodies/carriage/qdd"][:, 0], 0.0, atol=1e-6)


def test_a_driven_prismatic_joint_located_by_points_starts_where_the_file_puts_it(simulate):
    text = """
name: carriage on a guide, joint located by named points
bodies:
  - {name: carriage, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0.1 m, 0 m], points: {centre: [0 m, 0 m]}}
points: {origin: [0 m, 0 m]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, carriage], points: [origin, centre], axis: [1, 0]}
drivers:
  - {name: push, joint: guide, motion: {law: constant_speed, speed: 2 m/s}}
solver: {t_end: 10 ms, output_rate: 1 kHz}
"""
    result = simulate(text)
    assert np.allclose(result["bodies/carriage/q"][:, 0], 0.1 + 2.0 * result["time"], atol=1e-12)
