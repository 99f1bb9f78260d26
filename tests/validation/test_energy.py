"""Energy: conserved by an undriven conservative mechanism, through elastic impacts, and closed by the
written dissipation when contact is damped and frictional."""

import numpy as np
import pytest

DOUBLE_PENDULUM = """
name: double pendulum released horizontally
gravity: [0 m/s^2, -9.81 m/s^2]
points: {O: [0 m, 0 m], A: [0.3 m, 0 m]}
bodies:
  - {name: upper, mass: 1.0 kg, inertia: 0.0075 kg*m^2, position: [0.15 m, 0 m]}
  - {name: lower, mass: 0.5 kg, inertia: 0.00375 kg*m^2, position: [0.45 m, 0 m]}
joints:
  - {name: O, type: revolute, bodies: [ground, upper], at: O}
  - {name: A, type: revolute, bodies: [upper, lower], at: A}
solver: {t_end: 5 s, output_rate: 200 Hz, rtol: 1e-10, atol: 1e-12, max_step: 10 ms}
"""

CLEARANCE_PENDULUM = """
name: pendulum hanging from a pivot with clearance
gravity: [0 m/s^2, -9.81 m/s^2]
defaults:
  contact: {law: hertz, restitution: 1.0, exponent: 1.5, stiffness: auto}
points: {O: [0 m, 0 m]}
bodies:
  - {name: link, mass: 0.5 kg, inertia: 0.00375 kg*m^2, position: [0.15 m, 0 m]}
joints:
  - {name: O, type: revolute, bodies: [ground, link], at: O, bearing_radius: 10 mm, clearance: 0.1 mm}
solver: {t_end: 0.4 s, output_rate: 10 kHz, rtol: 1e-9, atol: 1e-12, max_step: 1 ms}
"""


def total_energy(result):
    return result["energy/kinetic"] + result["energy/potential"]


def test_double_pendulum_conserves_energy_over_many_swings(simulate):
    result = simulate(DOUBLE_PENDULUM)
    energy = total_energy(result)
    scale = np.max(result["energy/kinetic"])  # the energy that moves around; E(0) is 0 by the datum
    assert scale > 1.0  # it did swing: 1.5 kg falling ~0.3 m
    assert np.max(np.abs(energy - energy[0])) <= 1e-6 * scale
    assert np.max(result["constraints/violation"]) <= 1e-9


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
def test_elastic_impacts_conserve_energy_including_contact_potential(simulate, method):
    result = simulate(CLEARANCE_PENDULUM, f"solver.method={method}")
    events = result["joints/O/episodes/onset"]
    assert len(events) >= 100  # hundreds of impacts make the test meaningful
    energy = total_energy(result)
    scale = np.max(result["energy/kinetic"])
    assert np.max(np.abs(energy - energy[0])) <= 1e-4 * scale
    assert np.max(np.abs(result["energy/contact_dissipated"])) <= 1e-9 * scale  # c_e = 1: nothing to dissipate


@pytest.mark.parametrize("settings", [(), ("solver.method=dop853",)])
@pytest.mark.parametrize("friction", ["{law: none}", "{law: stiction_step, mu_s: 0.2, mu_d: 0.15, v_s: 1e-4 m/s, v_d: 1e-2 m/s}"])
def test_written_dissipation_closes_the_energy_balance(simulate, friction, settings):
    text = CLEARANCE_PENDULUM.replace("law: hertz, restitution: 1.0", "law: lankarani_nikravesh, restitution: 0.7")
    text = text.replace("  contact:", f"  friction: {friction}\n  contact:")
    result = simulate(text, *settings)
    lost = result["energy/contact_dissipated"][-1] + result["energy/friction_dissipated"][-1]
    assert lost > 1e-4 * np.max(result["energy/kinetic"])  # precondition: there is dissipation to account for
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-3 * lost
