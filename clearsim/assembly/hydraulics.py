"""Hydraulic cylinders: force elements with states of their own (docs/model-drives.md "Hydraulic cylinder").

A cylinder between point i (barrel end) and point j (rod end) pushes them apart with F = p_A A_A − p_B A_B along
u = (P_j − P_i)/ℓ. Its stroke is s = ℓ − ℓ0, its chambers hold V_A = V_A0 + A_A s and V_B = V_B0 + A_B (S − s) of oil,
and each pressure follows ṗ = β/V (Q_in − V̇) (Merritt, Hydraulic Control Systems, 1967). Each chamber's port is an
orifice to the supply, to the tank, or through a 3/2-way valve to both; an accumulator's gas obeys p V_g^n = p_0 V_0^n.

The states of cylinder k are the slots ELEMENT_STATES·k + Z_* of z (the end of the solver's y): the two pressures
over the reference pressure p_ref (the supply's at t = 0) and the gas volume over V_0, so that every state is of
order 1 and the solver's tolerances weigh them like positions (atol of 1e-10 is 1e-10 p_ref).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.arrays import HYDRAULIC_COLUMNS, HYDRAULIC_LAW_COLUMNS
from clearsim.assembly.constraints import prescribed
from clearsim.assembly.kinematics import add_point_force, line_kinematics
from clearsim.errors import Problem
from clearsim.physics import motion

# columns of hydraulic_params
(HY_POINT_I, _, HY_POINT_J, _, HY_INITIAL_LENGTH, HY_STROKE, HY_AREA_A, HY_AREA_B, HY_DEAD_A, HY_DEAD_B, HY_BULK,
 HY_FLOW_GAIN, HY_TRANSITION, HY_TANK, HY_GAS_PRESSURE, HY_GAS_VOLUME, HY_POLYTROPIC, HY_PORT_AREA_A, HY_PORT_AREA_B,
 HY_REFERENCE) = range(HYDRAULIC_COLUMNS)
# columns of hydraulic_laws: the valve's law of t, the cushion's law of s (−1: none), each chamber's port kind
HL_VALVE, HL_CUSHION, HL_PORT_A, HL_PORT_B = range(HYDRAULIC_LAW_COLUMNS)
PORT_VALVE, PORT_SUPPLY, PORT_TANK = 0, 1, 2
PORT_KINDS = {"valve": PORT_VALVE, "supply": PORT_SUPPLY, "tank": PORT_TANK}
# a cylinder's states, scaled (module docstring)
Z_PISTON, Z_ROD, Z_GAS = range(3)
ELEMENT_STATES = 3


@njit(cache=True)
def orifice_flow(gain, area, pressure_drop, transition):
    """Q = C_d a √(2|Δp|/ρ) sgn Δp (gain = C_d √(2/ρ)), linear in Δp below p_tr and continuous there."""
    if area <= 0.0:
        return 0.0
    if abs(pressure_drop) < transition:
        return gain * area * pressure_drop / np.sqrt(transition)
    return gain * area * np.sign(pressure_drop) * np.sqrt(abs(pressure_drop))


@njit(cache=True)
def supply_pressure(p, gas_volume_ratio):
    """The supply's pressure (Pa): p_0 (V_0/V_g)^n of an accumulator, p_0 of a constant source (V_0 = 0)."""
    if p[HY_GAS_VOLUME] <= 0.0:
        return p[HY_GAS_PRESSURE]
    return p[HY_GAS_PRESSURE] * gas_volume_ratio ** -p[HY_POLYTROPIC]


@njit(cache=True)
def cylinder_line(system, k, q, qd):
    """(s, ṡ, u_x, u_y) of cylinder k: stroke, stroke rate and the unit vector from the barrel end to the rod end."""
    p = system.hydraulic_params[k]
    bi, bj = system.hydraulic_bodies[k, 0], system.hydraulic_bodies[k, 1]
    length, rate, ux, uy = line_kinematics(q, qd, bi, bj, p[HY_POINT_I], p[HY_POINT_I + 1], p[HY_POINT_J],
                                           p[HY_POINT_J + 1])
    return length - p[HY_INITIAL_LENGTH], rate, ux, uy


@njit(cache=True)
def cylinder_force(system, k, z):
    """F = p_A A_A − p_B A_B (N), pushing the two ends apart."""
    p = system.hydraulic_params[k]
    first = ELEMENT_STATES * k
    return p[HY_REFERENCE] * (z[first + Z_PISTON] * p[HY_AREA_A] - z[first + Z_ROD] * p[HY_AREA_B])


@njit(cache=True)
def add_hydraulic_forces(system, q, z, generalized):
    """Add every cylinder's force pair to Q."""
    for k in range(system.hydraulic_bodies.shape[0]):
        p = system.hydraulic_params[k]
        force = cylinder_force(system, k, z)
        _, _, ux, uy = cylinder_line(system, k, q, q)
        add_point_force(generalized, q, system.hydraulic_bodies[k, 0], p[HY_POINT_I], p[HY_POINT_I + 1],
                        -force * ux, -force * uy)
        add_point_force(generalized, q, system.hydraulic_bodies[k, 1], p[HY_POINT_J], p[HY_POINT_J + 1],
                        force * ux, force * uy)


@njit(cache=True)
def port_flows(p, kind, area, opening, pressure, supply, tank):
    """(flow from the supply, flow to the tank) (m³/s) of a chamber at `pressure` through its port."""
    gain, transition = p[HY_FLOW_GAIN], p[HY_TRANSITION]
    supply_area = area * opening if kind == PORT_VALVE else (area if kind == PORT_SUPPLY else 0.0)
    tank_area = area * (1.0 - opening) if kind == PORT_VALVE else (area if kind == PORT_TANK else 0.0)
    return (orifice_flow(gain, supply_area, supply - pressure, transition),
            orifice_flow(gain, tank_area, pressure - tank, transition))


@njit(cache=True)
def valve_opening(system, k, t):
    """a_v(t)/a_max of cylinder k's valve, within [0, 1]."""
    return min(max(prescribed(system, system.hydraulic_laws[k, HL_VALVE], t)[0], 0.0), 1.0)


@njit(cache=True)
def cushion_factor(system, k, stroke):
    """The rod port's open fraction at stroke s: 1 without a cushion."""
    law = system.hydraulic_laws[k, HL_CUSHION]
    return 1.0 if law < 0 else prescribed(system, law, stroke)[0]


@njit(cache=True)
def hydraulic_rates(system, t, q, qd, z, zdot):
    """ż of every cylinder into zdot; returns the powers (W) summed over the cylinders: (supply's delivered p_s Q_s,
    tank's received p_T Q_T, orifice dissipation Σ Q Δp, oil compression Σ p (Q_in − V̇))."""
    supply_power, tank_power, orifice_loss, oil_power = 0.0, 0.0, 0.0, 0.0
    for k in range(system.hydraulic_bodies.shape[0]):
        p = system.hydraulic_params[k]
        first = ELEMENT_STATES * k
        reference = p[HY_REFERENCE]
        piston, rod = reference * z[first + Z_PISTON], reference * z[first + Z_ROD]
        supply, tank = supply_pressure(p, z[first + Z_GAS]), p[HY_TANK]
        stroke, rate, _, _ = cylinder_line(system, k, q, qd)
        opening = valve_opening(system, k, t)
        from_supply_a, to_tank_a = port_flows(p, system.hydraulic_laws[k, HL_PORT_A], p[HY_PORT_AREA_A], opening,
                                              piston, supply, tank)
        rod_area = p[HY_PORT_AREA_B] * cushion_factor(system, k, stroke)
        from_supply_b, to_tank_b = port_flows(p, system.hydraulic_laws[k, HL_PORT_B], rod_area, opening, rod,
                                              supply, tank)
        inflow_a, inflow_b = from_supply_a - to_tank_a, from_supply_b - to_tank_b
        compression_a = inflow_a - p[HY_AREA_A] * rate  # Q_in − V̇_A
        compression_b = inflow_b + p[HY_AREA_B] * rate  # Q_in − V̇_B
        volume_a = p[HY_DEAD_A] + p[HY_AREA_A] * stroke
        volume_b = p[HY_DEAD_B] + p[HY_AREA_B] * (p[HY_STROKE] - stroke)
        zdot[first + Z_PISTON] = p[HY_BULK] / volume_a * compression_a / reference
        zdot[first + Z_ROD] = p[HY_BULK] / volume_b * compression_b / reference
        drawn = from_supply_a + from_supply_b
        zdot[first + Z_GAS] = drawn / p[HY_GAS_VOLUME] if p[HY_GAS_VOLUME] > 0.0 else 0.0
        supply_power += supply * drawn
        tank_power += tank * (to_tank_a + to_tank_b)
        orifice_loss += ((from_supply_a * (supply - piston) + to_tank_a * (piston - tank))
                         + (from_supply_b * (supply - rod) + to_tank_b * (rod - tank)))
        oil_power += piston * compression_a + rod * compression_b
    return supply_power, tank_power, orifice_loss, oil_power


# --- the Python side: from the YAML's cylinder to its row of the arrays -----------------------------


def valve_points(valve) -> list[tuple[float, float]]:
    """The valve law as [time, opening] points (a cylinder without a valve: closed for good)."""
    if valve is None:
        return [(0.0, 0.0), (1.0, 0.0)]
    if valve.law == "linear":
        return [(valve.delay, 0.0), (valve.delay + valve.opening_time, 1.0)]
    return [tuple(point) for point in valve.points]


def cushion_points(cylinder) -> list[tuple[float, float]]:
    """The cushion as [stroke, open fraction] points."""
    cushion = cylinder.cushion
    if cushion.law == "linear":
        return [(cylinder.stroke - cushion.length, 1.0), (cylinder.stroke, cushion.residual_fraction)]
    return [tuple(point) for point in cushion.points]


def port_pressure(kind: str, opening: float, supply: float, tank: float) -> float:
    """The pressure a port holds a still chamber at (Pa). Through a valve opened by u the flows in, ∝ u √(p_s − p),
    and out, ∝ (1 − u) √(p − p_T), balance at p = (u² p_s + (1 − u)² p_T)/(u² + (1 − u)²)."""
    if kind == "valve":
        inlet, outlet = opening**2, (1.0 - opening) ** 2
        return (inlet * supply + outlet * tank) / (inlet + outlet)
    return supply if kind == "supply" else tank


def initial_pressures(cylinder) -> tuple[float, float]:
    """[p_A, p_B] at t = 0: as the file gives them, else each chamber at its port's pressure."""
    if cylinder.initial_pressures is not None:
        return tuple(cylinder.initial_pressures)
    opening = float(np.clip(np.interp(0.0, *zip(*valve_points(cylinder.valve))), 0.0, 1.0))
    supply = cylinder.supply.pressure
    return (port_pressure(cylinder.ports.piston, opening, supply, cylinder.tank_pressure),
            port_pressure(cylinder.ports.rod, opening, supply, cylinder.tank_pressure))


def opening_time(valve) -> float:
    """The time (s) at which the valve begins to open (inf: never)."""
    points = valve_points(valve)
    opened = [index for index, (_, fraction) in enumerate(points) if fraction > 0.0]
    if not opened:
        return np.inf
    return points[max(opened[0] - 1, 0)][0] if opened[0] > 0 else -np.inf


def open_force(cylinder) -> float:
    """F = p_A A_A − p_B A_B (N) with the valve fully open and both chambers at their ports' pressures (at t = 0)."""
    supply, tank = cylinder.supply.pressure, cylinder.tank_pressure
    piston = port_pressure(cylinder.ports.piston, 1.0, supply, tank)
    rod = port_pressure(cylinder.ports.rod, 1.0, supply, tank)
    return piston * cylinder.piston_area - rod * cylinder.rod_side_area


def _valve_problems(cylinder, t_end: float, path: tuple) -> list[Problem]:
    if cylinder.valve is None or opening_time(cylinder.valve) < t_end:
        return []
    return [Problem(path + ("valve",), f"the valve does not open before the run ends (t_end = {t_end:g} s): the "
                    "cylinder would never move", "open it earlier (its delay or table) or run longer")]


def _supply_problems(cylinder, path: tuple) -> list[Problem]:
    force = open_force(cylinder)
    if force > cylinder.resisting_force:
        return []
    return [Problem(path + ("resisting_force",),
                    f"the supply ({cylinder.supply.pressure:.4g} Pa) pushes with at most {force:.4g} N with the valve "
                    f"open (p_A A_A − p_B A_B), not more than the resisting force {cylinder.resisting_force:.4g} N: the "
                    "cylinder cannot extend", "raise the supply pressure or the piston area, or check the areas' units")]


def _stroke_problems(cylinder, length: float, path: tuple) -> list[Problem]:
    start = length - (cylinder.initial_length if cylinder.initial_length is not None else length)
    if 0.0 <= start <= cylinder.stroke:
        return []
    return [Problem(path + ("initial_length",), f"the stroke at t = 0 is {start:.4g} m, outside 0 … "
                    f"{cylinder.stroke:g} m", "state the length at which the stroke is 0")]


def _volume_problems(cylinder, path: tuple) -> list[Problem]:
    return [Problem(path + ("dead_volumes", index), f"a chamber's dead volume must be positive, got {volume:g} m^3",
                    "give the oil volume left in the chamber at its stroke's end")
            for index, volume in enumerate(cylinder.dead_volumes) if volume <= 0.0]


def build_problems(cylinder, length: float, t_end: float, path: tuple) -> list[Problem]:
    """What makes a cylinder unable to run: a valve that does not open before t_end, a supply that cannot overcome the
    stated resisting force, a stroke at t = 0 outside [0, S], an empty chamber."""
    return (_valve_problems(cylinder, t_end, path) + _supply_problems(cylinder, path)
            + _stroke_problems(cylinder, length, path) + _volume_problems(cylinder, path))


def cylinder_row(cylinder, si, sj, length: float, add_law) -> tuple[list[float], list[int], list[float]]:
    """(hydraulic_params row, hydraulic_laws row, initial scaled states) of one cylinder; add_law(law) → law index."""
    supply = cylinder.supply
    accumulator = supply.type == "accumulator"
    reference = supply.pressure
    row = [*si, *sj, cylinder.initial_length if cylinder.initial_length is not None else length, cylinder.stroke,
           cylinder.piston_area, cylinder.rod_side_area, *cylinder.dead_volumes, cylinder.bulk_modulus,
           cylinder.discharge_coefficient * np.sqrt(2.0 / cylinder.density), cylinder.transition_pressure,
           cylinder.tank_pressure, supply.pressure, supply.gas_volume if accumulator else 0.0,
           supply.polytropic_index if accumulator else 1.0, cylinder.port_areas.piston, cylinder.port_areas.rod,
           reference]
    laws = [add_law(motion.polyline_law(valve_points(cylinder.valve))) if cylinder.valve is not None else -1,
            add_law(motion.polyline_law(cushion_points(cylinder))) if cylinder.cushion is not None else -1,
            PORT_KINDS[cylinder.ports.piston], PORT_KINDS[cylinder.ports.rod]]
    piston, rod = initial_pressures(cylinder)
    return row, laws, [piston / reference, rod / reference, 1.0]


def _point_positions(q: np.ndarray, body: int, point) -> np.ndarray:
    """(S, 2) global positions of a body-fixed point over samples of q (S, n); the ground's point is fixed."""
    if body < 0:
        return np.tile(np.asarray(point, float), (q.shape[0], 1))
    x, y, angle = q[:, 3 * body], q[:, 3 * body + 1], q[:, 3 * body + 2]
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([x + c * point[0] - s * point[1], y + s * point[0] + c * point[1]], axis=1)


def drive_histories(names: list[str], bodies: np.ndarray, params: np.ndarray, q: np.ndarray,
                    states: np.ndarray) -> dict:
    """/drives/<name>/…: each cylinder's states in SI (from the scaled z, (S, ELEMENT_STATES · cylinders)), its stroke,
    force and supply pressure, over samples of q (S, n)."""
    out = {}
    for k, name in enumerate(names):
        p = params[k]
        z = states[:, ELEMENT_STATES * k:ELEMENT_STATES * (k + 1)]
        piston, rod = p[HY_REFERENCE] * z[:, Z_PISTON], p[HY_REFERENCE] * z[:, Z_ROD]
        ends = [_point_positions(q, bodies[k, end], p[column:column + 2])
                for end, column in ((0, HY_POINT_I), (1, HY_POINT_J))]
        out[f"drives/{name}/piston_pressure"] = (piston, "Pa")
        out[f"drives/{name}/rod_pressure"] = (rod, "Pa")
        out[f"drives/{name}/stroke"] = (np.linalg.norm(ends[1] - ends[0], axis=1) - p[HY_INITIAL_LENGTH], "m")
        out[f"drives/{name}/force"] = (piston * p[HY_AREA_A] - rod * p[HY_AREA_B], "N")
        if p[HY_GAS_VOLUME] > 0.0:  # a constant source has no gas
            gas = z[:, Z_GAS]
            out[f"drives/{name}/gas_volume"] = (gas * p[HY_GAS_VOLUME], "m^3")
            out[f"drives/{name}/supply_pressure"] = (p[HY_GAS_PRESSURE] * gas ** -p[HY_POLYTROPIC], "Pa")
    return out
