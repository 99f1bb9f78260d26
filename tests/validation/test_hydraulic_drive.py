"""The hydraulic cylinder (docs/model-drives.md "Hydraulic cylinder") against an independent integration of its ODEs.

A 10 kg block on a prismatic guide, held by a 2e5 N/m spring, is pushed by a cylinder fed from a 1 L accumulator at
100 bar through a valve that opens from 2 to 7 ms; the rod chamber drains to the tank through a port that a cushion
closes to 10 % over the last 20 mm of the 60 mm stroke. The run crosses the valve's opening, the laminar region of
the rod port (p_B passes through the tank pressure) and the cushion (the block reaches 48.6 mm). Also: the same
against a differential circuit from a constant source, the pressures' error control, bad cylinders (exit 2 at their
key), a valve port's initial pressure, a flexible link under a cylinder at t = 0, the energy page.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from typer.testing import CliRunner

from clearsim.cli import app

CYLINDER = """
name: hydraulic cylinder pushing a block against a spring
points: {O: [0 m, 0 m], C: [-0.5 m, 0 m], W: [-0.6 m, 0 m]}
bodies:
  - {name: block, mass: 10 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [1, 0]}
forces:
  - {name: spring, type: spring_damper, bodies: [ground, block], at: [W, O], stiffness: 2e5 N/m}
  - name: actuator
    type: hydraulic_cylinder
    bodies: [ground, block]
    at: [C, O]
    stroke: 60 mm
    piston_area: 10 cm^2
    rod_side_area: 5 cm^2
    dead_volumes: [50 cm^3, 50 cm^3]
    bulk_modulus: 1.4 GPa
    density: 850 kg/m^3
    discharge_coefficient: 0.7
    transition_pressure: 1 bar
    supply: {type: accumulator, pressure: 100 bar, gas_volume: 1 L, polytropic_index: 1.4}
    tank_pressure: 0 Pa
    ports: {piston: valve, rod: tank}
    port_areas: {piston: 20 mm^2, rod: 20 mm^2}
    valve: {law: linear, delay: 2 ms, opening_time: 5 ms}
    cushion: {law: linear, length: 20 mm, residual_fraction: 0.1}
sensors:
  - {name: x, type: point_displacement, body: block, direction: [1, 0]}
solver: {t_end: 60 ms, output_rate: 10 kHz, rtol: 1e-10, atol: 1e-12, max_step: 1 ms}
"""

MASS, STIFFNESS = 10.0, 2e5
AREA_A, AREA_B, STROKE, DEAD_A, DEAD_B = 10e-4, 5e-4, 0.06, 50e-6, 50e-6
BULK, DENSITY, CD, TRANSITION = 1.4e9, 850.0, 0.7, 1e5
P0, V0, INDEX, TANK = 100e5, 1e-3, 1.4, 0.0
PORT_A, PORT_B = 20e-6, 20e-6


def flow(pressure_drop, area):
    """Orifice flow, linear below the transition pressure (written here from the docs' formula)."""
    gain = CD * area * np.sqrt(2.0 / DENSITY)
    if abs(pressure_drop) < TRANSITION:
        return gain * pressure_drop / np.sqrt(TRANSITION)
    return gain * np.sign(pressure_drop) * np.sqrt(abs(pressure_drop))


def opening(t):
    return min(max((t - 2e-3) / 5e-3, 0.0), 1.0)


def cushion(x):
    return 1.0 - 0.9 * min(max((x - (STROKE - 0.02)) / 0.02, 0.0), 1.0)


def reference_rhs(t, state, differential=False):
    """[x, v, p_A, p_B, V_gas, orifice loss, oil energy]'. Differential: a constant supply P0 feeds the rod chamber
    permanently and a spring compressed by 25 mm at x = 0 balances its force."""
    x, v, pa, pb, gas = state[:5]
    supply = P0 if differential else P0 * (V0 / gas) ** INDEX
    u = opening(t)
    in_a, out_a = flow(supply - pa, PORT_A * u), flow(pa - TANK, PORT_A * (1.0 - u))
    port_b = flow(supply - pb, PORT_B * cushion(x)) if differential else -flow(pb - TANK, PORT_B * cushion(x))
    net_a, net_b = in_a - out_a - AREA_A * v, port_b + AREA_B * v
    loss = in_a * (supply - pa) + out_a * (pa - TANK) + (port_b * (supply - pb) if differential else -port_b * pb)
    spring = STIFFNESS * (x - (0.025 if differential else 0.0))
    return [v, (pa * AREA_A - pb * AREA_B - spring) / MASS, BULK / (DEAD_A + AREA_A * x) * net_a,
            BULK / (DEAD_B + AREA_B * (STROKE - x)) * net_b, in_a + (port_b if differential else 0.0), loss,
            pa * net_a + pb * net_b]


def run_and_reference(text, folder, differential=False):
    """(clearsim's result, solve_ivp's [x, v, p_A, p_B, V_gas, orifice loss, oil energy] at its sample times)."""
    from clearsim.io.hdf5 import read_result
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare, run_to_file

    loaded = load_mechanism_text(text)
    output = folder / "cylinder.h5"
    report = run_to_file(prepare(loaded), loaded, output)
    assert report.complete, report.status
    result = read_result(output)
    times = result["time"]
    start = [0.0, 0.0, 0.0, P0 if differential else 0.0, V0, 0.0, 0.0]
    reference = solve_ivp(reference_rhs, (0.0, times[-1]), start, method="DOP853", t_eval=times, rtol=1e-12,
                          atol=[1e-15, 1e-13, 1e-6, 1e-6, 1e-18, 1e-12, 1e-12], max_step=2e-5, args=(differential,))
    assert reference.success
    return result, reference.y


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return run_and_reference(CYLINDER, tmp_path_factory.mktemp("hydraulic"))


def within(clearsim, reference, relative=1e-6):
    """max |clearsim − reference| ≤ relative × max |reference| over the run."""
    return np.max(np.abs(clearsim - reference)) <= relative * np.max(np.abs(reference))


def test_travel_and_pressures_match_an_independent_integration(runs):
    result, reference = runs
    x, pa, pb = reference[0], reference[2], reference[3]
    assert 0.045 < np.max(x) < STROKE and np.min(pb) < TANK  # the cushion and the rod port's laminar region ran
    assert within(result["sensors/x"], x)
    assert within(result["drives/actuator/stroke"], x)  # the cylinder's length at t = 0 is its stroke's zero
    assert within(result["drives/actuator/force"], pa * AREA_A - pb * AREA_B)
    assert within(result["drives/actuator/supply_pressure"], P0 * (V0 / reference[4]) ** INDEX)
    assert within(result["drives/actuator/piston_pressure"], pa)
    assert within(result["drives/actuator/rod_pressure"], pb)
    assert within(result["drives/actuator/gas_volume"] - V0, reference[4] - V0)


def test_a_tabulated_cushion_through_the_same_points_is_the_linear_one(runs, tmp_path):
    from clearsim.io.hdf5 import read_result
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare, run_to_file

    table = CYLINDER.replace("{law: linear, length: 20 mm, residual_fraction: 0.1}",
                             "{law: table, points: [[40 mm, 1], [60 mm, 0.1]]}")
    loaded = load_mechanism_text(table)
    run_to_file(prepare(loaded), loaded, tmp_path / "table.h5")
    stroke = read_result(tmp_path / "table.h5")["drives/actuator/stroke"]
    assert within(stroke, runs[0]["drives/actuator/stroke"], relative=1e-9)  # S − L_c = 0.06 − 0.02 is not 0.04 in floating point


def test_the_accumulators_gas_work_closes_the_energy_balance(runs):
    """Gas work p_0 V_0^n (V^(1−n) − V_0^(1−n))/(1 − n) = kinetic + spring + oil compression + orifice losses."""
    result, reference = runs
    gas = result["drives/actuator/gas_volume"]
    gas_work = P0 * V0**INDEX * (gas ** (1 - INDEX) - V0 ** (1 - INDEX)) / (1 - INDEX)
    stored = (result["energy/kinetic"] + result["energy/potential"] + result["energy/oil_compression"]
              + result["energy/orifice_dissipated"])
    assert np.max(np.abs(stored - gas_work)) <= 1e-6 * np.max(gas_work)
    assert within(result["energy/hydraulic_supply_work"], gas_work)
    assert within(result["energy/orifice_dissipated"], reference[5])
    assert within(result["energy/oil_compression"], reference[6])
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-6 * np.max(gas_work)


def test_the_pressures_are_error_controlled_like_the_motion(tmp_path):
    """At the default tolerances (rtol 1e-7, atol 1e-10 of the supply pressure for the scaled pressures) the pressures
    keep 5e-7 of their range (clearsim: 5.3e-7 and 5.2e-7); steps chosen by q and q̇ alone leave them 1e-4 and 2.8e-3
    off."""
    result, reference = run_and_reference(CYLINDER.replace(", rtol: 1e-10, atol: 1e-12, max_step: 1 ms", ""), tmp_path)
    assert within(result["drives/actuator/piston_pressure"], reference[2], relative=1e-5)
    assert within(result["drives/actuator/rod_pressure"], reference[3], relative=1e-5)


DIFFERENTIAL = (CYLINDER.replace("stiffness: 2e5 N/m}", "stiffness: 2e5 N/m, free_length: 625 mm}")
                .replace("{type: accumulator, pressure: 100 bar, gas_volume: 1 L, polytropic_index: 1.4}",
                         "{type: constant, pressure: 100 bar}")
                .replace("rod: tank}", "rod: supply}"))


def test_a_differential_circuit_from_a_constant_source_matches_an_independent_integration(tmp_path):
    """The rod chamber at the supply for good (its cushioned port now lets oil back into the supply), the piston
    chamber switched from tank to supply by the valve: F = p_s (A_A − A_B) once open."""
    result, reference = run_and_reference(DIFFERENTIAL, tmp_path, differential=True)
    x, pa, pb = reference[0], reference[2], reference[3]
    assert np.max(x) > 0.045  # through the cushion
    assert within(result["drives/actuator/stroke"], x)
    assert within(result["drives/actuator/piston_pressure"], pa)
    assert within(result["drives/actuator/rod_pressure"], pb)
    assert "drives/actuator/gas_volume" not in result  # a constant source has no gas
    supplied = result["energy/hydraulic_supply_work"]
    assert within(result["energy/orifice_dissipated"], reference[5])
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-6 * np.max(supplied)


runner = CliRunner()


@pytest.mark.parametrize("old, new, place, words", [
    ("piston_area: 10 cm^2", "piston_area: -10 cm^2", "forces[1] 'actuator' → piston_area", "greater than 0"),
    ("bulk_modulus: 1.4 GPa", "bulk_modulus: -1.4 GPa", "forces[1] 'actuator' → bulk_modulus", "greater than 0"),
    ("delay: 2 ms", "delay: 80 ms", "forces[1] 'actuator' → valve", "does not open before the run ends"),
    ("valve: {law: linear, delay: 2 ms, opening_time: 5 ms}", "valve: {law: table, points: [[0 s, 0], [1 s, 0]]}",
     "forces[1] 'actuator' → valve", "never opens"),
    ("tank_pressure: 0 Pa", "tank_pressure: 0 Pa\n    resisting_force: 12 kN", "forces[1] 'actuator' → resisting_force",
     "cannot extend"),
    ("bodies: [ground, block]\n    at: [C, O]", "bodies: [block, block]\n    at: [C, O]",
     "forces[1] 'actuator' → bodies", "connects two different bodies"),
    ("    valve: {law: linear, delay: 2 ms, opening_time: 5 ms}\n", "", "forces[1] 'actuator'", "has no `valve:` law"),
    ("stroke: 60 mm", "stroke: 60 mm\n    initial_length: 0.2 m", "forces[1] 'actuator' → initial_length",
     "the stroke at t = 0 is 0.3 m, outside 0 … 0.06 m"),
    ("dead_volumes: [50 cm^3, 50 cm^3]", "dead_volumes: [50 cm^3, 0 cm^3]", "forces[1] 'actuator' → dead_volumes[1]",
     "dead volume must be positive"),
], ids=["negative area", "negative bulk modulus", "valve opens after the end", "valve never opens",
        "supply below the load", "one body twice", "valve port without a valve", "stroke outside", "empty chamber"])
def test_bad_cylinders_exit_2_with_a_located_message(tmp_path, old, new, place, words):
    assert old in CYLINDER
    config = tmp_path / "bad.yaml"
    config.write_text(CYLINDER.replace(old, new))
    result = runner.invoke(app, ["run", str(config), "-o", str(tmp_path / "never.h5")])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert place in result.output and words in result.output, result.output
    assert not (tmp_path / "never.h5").exists()


@pytest.mark.parametrize("opening", [0.0, 0.25, 0.5, 0.9, 1.0])
def test_a_valve_ports_initial_pressure_balances_its_two_flows(opening):
    from clearsim.assembly.hydraulics import port_pressure

    pressure = port_pressure("valve", opening, P0, 2e5)
    inflow, outflow = flow(P0 - pressure, PORT_A * opening), flow(pressure - 2e5, PORT_A * (1.0 - opening))
    assert 2e5 <= pressure <= P0 and inflow == pytest.approx(outflow, rel=1e-12, abs=1e-18)


def test_a_flexible_link_starts_carrying_the_cylinders_force(simulate):
    """A cylinder with both chambers on a constant 100 bar source pushes with p_s (A_A − A_B) = 1 kN from t = 0 on the
    tip of an axial flexible link (k = 4e5 N/m): the link starts compressed by that force, so nothing moves
    (started unloaded it would ring with 2.5 mm amplitude)."""
    from tests.validation.test_flexible_axial import mass_on_link

    cylinder = """forces:
  - name: actuator
    type: hydraulic_cylinder
    bodies: [ground, tip]
    at: [[1.0, 0], [0.5, 0]]
    stroke: 0.1
    piston_area: 2e-4
    rod_side_area: 1e-4
    dead_volumes: [1e-5, 1e-5]
    supply: {type: constant, pressure: 1e7}
    ports: {piston: supply, rod: supply}
    port_areas: {piston: 1e-6, rod: 1e-6}
    initial_length: 0.45
"""
    text = mass_on_link(periods=10).replace("forces:\n", cylinder)
    result = simulate(text)
    assert result["drives/actuator/force"][0] == pytest.approx(1000.0, rel=1e-12)
    assert np.max(np.abs(result["sensors/stretch"])) <= 1e-9


def test_the_energy_page_shows_the_hydraulic_energies(tmp_path):
    from clearsim.model.loader import load_mechanism_text
    from clearsim.plot import load_run
    from clearsim.plot.history import plot_energies
    from clearsim.runner import prepare, run_to_file

    loaded = load_mechanism_text(CYLINDER.replace("t_end: 60 ms", "t_end: 20 ms"))
    run_to_file(prepare(loaded), loaded, tmp_path / "cylinder.h5")
    ax = plot_energies(load_run(tmp_path / "cylinder.h5"))
    labels = {line.get_label() for line in ax.get_lines()}
    assert {"hydraulic supply work", "orifice dissipated", "oil compression"} <= labels, labels
