"""Stateless drive-line elements: spring drive, dashpot, gas load, guide friction (docs/model-drives.md).

Each element k has a stroke s and a force F along a unit vector u, applied as +F u on body j and −F u on body i,
so that F ṡ is the power it gives the bodies:
  two-point elements (spring drive, dashpot)  u = σ (P_j − P_i)/ℓ, s = σ (ℓ − ℓ0), σ = +1 lengthening, −1 shortening
  gas load                                    u = d (global), s = d·(P_j − P_j(0)); body i is the ground
  guide friction                              u = A_i ā (the joint's axis), ṡ = u·(v_j(P_j) − v_i(P_j)), both
                                              forces applied at P_j
Forces: spring drive and gas load F(s) (linear a + b s, a table, or the adiabatic puffer), with the stored
energy U(s) = U_ref − ∫₀ˢ F dσ part of the potential; dashpot F = −c ṡ w(s) or −b ṡ|ṡ| w(s), w the engagement
window; guide friction F = −μ(ṡ) N with the clearance joints' friction laws.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numba import njit

from clearsim.assembly.arrays import for_kernels
from clearsim.assembly.build import BuildError, force_ends, joint_points
from clearsim.assembly.kinematics import (
    add_global_force, body_frame, body_rates, frame_point, frame_rotate, frame_velocity,
)
from clearsim.errors import Problem
from clearsim.model import schema
from clearsim.model.resolve import guide_friction_numbers
from clearsim.physics import friction
from clearsim.physics.friction import friction_coefficient, step_blend
from clearsim.physics.tables import read_table_column

# column 0 of driveline_kinds: the element
SPRING_DRIVE, DASHPOT, GAS_LOAD, GUIDE_FRICTION = range(4)
# column 1: its law (spring drive and gas load: LINEAR/TABLE/ADIABATIC; dashpot: LINEAR/ORIFICE; guide: friction law)
LINEAR, TABLE, ADIABATIC, ORIFICE = range(4)

# columns of driveline_params
DL_POINT_I = 0  # 0, 1: point on body i, body frame (gas load: the point's global position at t = 0)
DL_POINT_J = 2  # 2, 3: point on body j, body frame
DL_DIRECTION = 4  # 4, 5: gas load d (global), guide friction ā (body i's frame)
DL_LENGTH = 6  # ℓ0 of a two-point element
DL_SENSE = 7  # σ
DL_A = 8  # linear: F(0) | adiabatic: p0 | dashpot: c or b | guide: μ_s
DL_B = 9  # linear: dF/ds | adiabatic: V0 | dashpot: engagement start | guide: μ_d
DL_C = 10  # adiabatic: A | dashpot: engagement end | guide: v_low
DL_D = 11  # adiabatic: γ | dashpot: engagement length | guide: v_high
DL_E = 12  # adiabatic: p_ambient | guide: N
DL_ENERGY = 13  # U_ref: stored energy at s = 0
DL_RELEASE = 14  # release time (spring drive; 0 for the others)
DL_TABLE_FIRST = 15  # first row of its table in driveline_table
DL_TABLE_COUNT = 16
DRIVELINE_COLUMNS = 17
# columns of driveline_table: stroke, F, ∫ F ds from the element's first row
TB_STROKE, TB_FORCE, TB_INTEGRAL = range(3)


# --- compiled -------------------------------------------------------------------------------------


@njit(cache=True)
def table_force_and_integral(table, first, count, s):
    """(F(s), ∫ F ds from the first row to s) of a table, linear between rows and held beyond the ends."""
    last = first + count - 1
    if s <= table[first, TB_STROKE]:
        return table[first, TB_FORCE], table[first, TB_FORCE] * (s - table[first, TB_STROKE])
    if s >= table[last, TB_STROKE]:
        return table[last, TB_FORCE], table[last, TB_INTEGRAL] + table[last, TB_FORCE] * (s - table[last, TB_STROKE])
    lo, hi = first, last
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if table[mid, TB_STROKE] <= s:
            lo = mid
        else:
            hi = mid
    fraction = (s - table[lo, TB_STROKE]) / (table[hi, TB_STROKE] - table[lo, TB_STROKE])
    force = table[lo, TB_FORCE] + fraction * (table[hi, TB_FORCE] - table[lo, TB_FORCE])
    return force, table[lo, TB_INTEGRAL] + 0.5 * (s - table[lo, TB_STROKE]) * (table[lo, TB_FORCE] + force)


@njit(cache=True)
def adiabatic_force_and_work(p, s):
    """(F(s), ∫₀ˢ F ds) of the puffer: F = −(p0 (V0/V)^γ − p_a) A, V = V0 − A s; NaN once V ≤ 0."""
    p0, v0, area, gamma, ambient = p[DL_A], p[DL_B], p[DL_C], p[DL_D], p[DL_E]
    volume = v0 - area * s
    if volume <= 0.0:
        return np.nan, np.nan
    ratio = v0 / volume
    if gamma == 1.0:
        compression = p0 * v0 * np.log(ratio)
    else:
        compression = p0 * v0 / (gamma - 1.0) * (ratio ** (gamma - 1.0) - 1.0)
    return -(p0 * ratio ** gamma - ambient) * area, -(compression - ambient * area * s)


@njit(cache=True)
def stroke_force_and_work(system, k, s):
    """(F(s), ∫₀ˢ F ds) of a spring drive or gas load."""
    p = system.driveline_params[k]
    law = system.driveline_kinds[k, 1]
    if law == LINEAR:
        return p[DL_A] + p[DL_B] * s, p[DL_A] * s + 0.5 * p[DL_B] * s * s
    if law == ADIABATIC:
        return adiabatic_force_and_work(p, s)
    first, count = int(p[DL_TABLE_FIRST]), int(p[DL_TABLE_COUNT])
    force, integral = table_force_and_integral(system.driveline_table, first, count, s)
    return force, integral - table_force_and_integral(system.driveline_table, first, count, 0.0)[1]


@njit(cache=True)
def element_geometry(system, k, q, qd):
    """(s, ṡ, u_x, u_y, P_i, P_j) of element k (P global; the forces act at P_i on body i and P_j on body j)."""
    p = system.driveline_params[k]
    kind = system.driveline_kinds[k, 0]
    bi, bj = system.driveline_bodies[k, 0], system.driveline_bodies[k, 1]
    frame_i, frame_j = body_frame(q, bi), body_frame(q, bj)
    xj, yj = frame_point(frame_j, p[DL_POINT_J], p[DL_POINT_J + 1])
    vjx, vjy = frame_velocity(frame_j, qd, bj, p[DL_POINT_J], p[DL_POINT_J + 1])
    if kind == GUIDE_FRICTION:  # relative velocity of the coincident material points at P_j, along the axis
        ux, uy = frame_rotate(frame_i, p[DL_DIRECTION], p[DL_DIRECTION + 1])
        vx, vy, omega = body_rates(qd, bi)
        vix, viy = vx - omega * (yj - frame_i[1]), vy + omega * (xj - frame_i[0])  # body i's material point at P_j
        return 0.0, ux * (vjx - vix) + uy * (vjy - viy), ux, uy, xj, yj, xj, yj
    xi, yi = frame_point(frame_i, p[DL_POINT_I], p[DL_POINT_I + 1])
    if kind == GAS_LOAD:
        ux, uy = p[DL_DIRECTION], p[DL_DIRECTION + 1]
        return ux * (xj - xi) + uy * (yj - yi), ux * vjx + uy * vjy, ux, uy, xi, yi, xj, yj
    vix, viy = frame_velocity(frame_i, qd, bi, p[DL_POINT_I], p[DL_POINT_I + 1])
    length = max(np.sqrt((xj - xi) ** 2 + (yj - yi) ** 2), 1e-300)
    sense = p[DL_SENSE]
    ux, uy = sense * (xj - xi) / length, sense * (yj - yi) / length
    return sense * (length - p[DL_LENGTH]), ux * (vjx - vix) + uy * (vjy - viy), ux, uy, xi, yi, xj, yj


@njit(cache=True)
def engagement(p, s):
    """Dashpot window w(s): 0 outside [start, end], 1 inside, smoothstep over the engagement length at each end."""
    start, end, ramp = p[DL_B], p[DL_C], p[DL_D]
    if s < start or s > end:
        return 0.0
    if ramp == 0.0:
        return 1.0
    return step_blend(s, start, 0.0, start + ramp, 1.0) * step_blend(s, end - ramp, 1.0, end, 0.0)


@njit(cache=True)
def element_force(system, k, t, s, rate):
    """(F, latch power) of element k at stroke s and rate ṡ; a latched spring gives no force, its latch the power
    −F ṡ its stored energy changes by."""
    p = system.driveline_params[k]
    kind, law = system.driveline_kinds[k, 0], system.driveline_kinds[k, 1]
    if kind == DASHPOT:
        speed_law = rate if law == LINEAR else rate * abs(rate)
        return -p[DL_A] * speed_law * engagement(p, s), 0.0
    if kind == GUIDE_FRICTION:
        return -friction_coefficient(law, rate, p[DL_A], p[DL_B], p[DL_C], p[DL_D]) * p[DL_E], 0.0
    force = stroke_force_and_work(system, k, s)[0]
    if t < p[DL_RELEASE]:
        return 0.0, -force * rate
    return force, 0.0


@njit(cache=True)
def element_state(system, k, t, q, qd):
    """(F, ṡ, latch power, u_x, u_y, P_i, P_j) of element k."""
    s, rate, ux, uy, xi, yi, xj, yj = element_geometry(system, k, q, qd)
    force, latch = element_force(system, k, t, s, rate)
    return force, rate, latch, ux, uy, xi, yi, xj, yj


@njit(cache=True)
def add_driveline_forces(system, t, q, qd, generalized):
    """Add every element's force pair to the generalised forces."""
    for k in range(system.driveline_kinds.shape[0]):
        force, _, _, ux, uy, xi, yi, xj, yj = element_state(system, k, t, q, qd)
        add_global_force(generalized, q, system.driveline_bodies[k, 1], xj, yj, force * ux, force * uy)
        add_global_force(generalized, q, system.driveline_bodies[k, 0], xi, yi, -force * ux, -force * uy)


@njit(cache=True)
def driveline_powers(system, t, q, qd):
    """(dashpot loss, guide friction loss, latch power) at (t, q, q̇)."""
    dashpot, guide, latch = 0.0, 0.0, 0.0
    for k in range(system.driveline_kinds.shape[0]):
        force, rate, latch_power, _, _, _, _, _, _ = element_state(system, k, t, q, qd)
        latch += latch_power
        kind = system.driveline_kinds[k, 0]
        if kind == DASHPOT:
            dashpot -= force * rate
        elif kind == GUIDE_FRICTION:
            guide -= force * rate
    return dashpot, guide, latch


@njit(cache=True)
def element_histories(system, times, states, out):
    """(s, ṡ, F) of every element at every sample into out (S, elements, 3); states (S, ≥ 2n)."""
    n = 3 * system.mass.shape[0]
    for i in range(times.shape[0]):
        q, qd = states[i, :n], states[i, n:2 * n]
        for k in range(system.driveline_kinds.shape[0]):
            s, rate = element_geometry(system, k, q, qd)[:2]
            out[i, k, 0], out[i, k, 1], out[i, k, 2] = s, rate, element_force(system, k, times[i], s, rate)[0]


@njit(cache=True)
def element_stored_energy(system, k, q):
    """U(s) = U_ref − ∫₀ˢ F ds of element k if it is a spring drive or a gas load; 0 for the others."""
    kind = system.driveline_kinds[k, 0]
    if kind != SPRING_DRIVE and kind != GAS_LOAD:
        return 0.0
    s = element_geometry(system, k, q, np.zeros_like(q))[0]
    return system.driveline_params[k, DL_ENERGY] - stroke_force_and_work(system, k, s)[1]


@njit(cache=True)
def driveline_potential(system, q):
    """Σ U(s) of the spring drives and gas loads."""
    energy = 0.0
    for k in range(system.driveline_kinds.shape[0]):
        energy += element_stored_energy(system, k, q)
    return energy


@njit(cache=True)
def stored_energy_histories(system, states, out):
    """U(s) of every element at every sample into out (S, elements); states (S, ≥ 2n)."""
    n = 3 * system.mass.shape[0]
    for i in range(states.shape[0]):
        for k in range(system.driveline_kinds.shape[0]):
            out[i, k] = element_stored_energy(system, k, states[i, :n])


# --- build: the elements of a mechanism as arrays ---------------------------------------------------


class DrivelineError(ValueError):
    """A driveline element that cannot be built; `place` is relative to its `forces:` entry."""

    def __init__(self, place: tuple, message: str, hint: str | None = None):
        super().__init__(message)
        self.place, self.hint = place, hint


SENSES = {"lengthening": 1.0, "shortening": -1.0}
ELEMENT_TYPES = (schema.SpringDrive, schema.Dashpot, schema.GasLoad, schema.GuideFriction)


def stroke_table(table, base_dir: Path, kind: str, place: tuple) -> tuple[np.ndarray, np.ndarray]:
    """(strokes in m, values in SI of `kind`) of an inline or CSV stroke table (`place`: its key in the element)."""
    if table.rows is not None:
        rows = np.asarray(table.rows, float)
        return rows[:, 0], rows[:, 1]
    try:
        return read_table_column(base_dir / table.file, table.stroke_column, table.value_column, table.stroke_unit,
                                 table.value_unit, kind, argument_kind="length", argument_name="stroke")
    except ValueError as exc:
        raise DrivelineError(place + ("file",), str(exc)) from None


def table_rows(strokes: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """(rows, 3): stroke, force, the exact integral of the piecewise-linear force from the first row."""
    segments = 0.5 * np.diff(strokes) * (forces[1:] + forces[:-1])
    return np.column_stack([strokes, forces, np.concatenate([[0.0], np.cumsum(segments)])])


def _spring_law(force: schema.SpringDrive, start_length: float, base_dir: Path, row, tables: list) -> int:
    if force.table is None:
        sense = SENSES[force.sense]
        preload = force.preload if force.preload is not None else force.stiffness * sense * (force.free_length - start_length)
        row[DL_A], row[DL_B] = preload, -force.stiffness
        row[DL_ENERGY] = preload * preload / (2.0 * force.stiffness) if force.stiffness > 0.0 else 0.0
        return LINEAR
    strokes, forces = stroke_table(force.table, base_dir, "force", ("table",))
    rows = _add_table(row, tables, strokes, forces)
    row[DL_ENERGY] = rows[-1, TB_INTEGRAL] - table_force_and_integral(rows, 0, len(rows), 0.0)[1]  # ∫₀^{s_last} F
    return TABLE


def _add_table(row, tables: list, strokes, forces) -> np.ndarray:
    rows = table_rows(np.asarray(strokes, float), np.asarray(forces, float))
    row[DL_TABLE_FIRST], row[DL_TABLE_COUNT] = sum(len(t) for t in tables), len(rows)
    tables.append(rows)
    return rows


def _gas_law(force: schema.GasLoad, base_dir: Path, row, tables: list) -> int:
    if force.force_table is not None:
        strokes, forces = stroke_table(force.force_table, base_dir, "force", ("force_table",))
        _add_table(row, tables, strokes, -forces)
        return TABLE
    if force.pressure_table is not None:
        strokes, pressures = stroke_table(force.pressure_table, base_dir, "pressure", ("pressure_table",))
        _add_table(row, tables, strokes, -(pressures - force.p_ambient) * force.area)
        return TABLE
    if force.area * force.stroke >= force.volume:
        raise DrivelineError(("stroke",), f"the puffer volume V0 = {force.volume * 1e3:.4g} L is used up at a stroke "
                             f"of V0/A = {force.volume / force.area * 1e3:.4g} mm, before the stated stroke of "
                             f"{force.stroke * 1e3:.4g} mm", "check volume, area and stroke and their units")
    initial = force.initial_pressure if force.initial_pressure is not None else force.p_ambient
    row[DL_A], row[DL_B], row[DL_C], row[DL_D], row[DL_E] = initial, force.volume, force.area, force.gamma, force.p_ambient
    return ADIABATIC


def _two_point_ends(force, poses, path) -> tuple[int, int, np.ndarray, np.ndarray, float]:
    """(body i, body j, point on i, point on j, distance at t = 0) of a spring drive or a dashpot."""
    bi, bj, si, sj, length = force_ends(poses, force, path)
    if length < 1e-9:  # m: no line of action
        place = "at" if force.at is not None else "points" if force.points is not None else "bodies"
        raise DrivelineError((place,), f"the two ends of the {force.type.replace('_', ' ')} coincide at t = 0, so "
                             "it has no line to act along", "give ends apart along the line it acts on "
                             "(`at:` or `points:`; by default the two centres of mass)")
    return bi, bj, si, sj, length


def element_row(mechanism, force, poses, base_dir: Path, tables: list, path) -> tuple[tuple, tuple, np.ndarray]:
    """((element, law), (body i, body j), parameter row) of one element."""
    row = np.zeros(DRIVELINE_COLUMNS)
    if isinstance(force, schema.GuideFriction):
        joint = mechanism.joint(force.joint)
        bi, bj, _, sj = joint_points(poses, joint, ("joints", mechanism.joints.index(joint)))
        row[DL_POINT_J:DL_POINT_J + 2] = sj
        row[DL_DIRECTION:DL_DIRECTION + 2] = poses.direction_to_body_frame(bi, joint.axis)
        numbers = guide_friction_numbers(force.friction)
        row[DL_A], row[DL_B], row[DL_C], row[DL_D] = (numbers[k] for k in ("mu_s", "mu_d", "v_low", "v_high"))
        row[DL_E] = force.normal_force
        return (GUIDE_FRICTION, friction.FRICTION_LAWS[numbers["law"]]), (bi, bj), row
    if isinstance(force, schema.GasLoad):
        body = poses.index[force.body]
        start = poses.point_global(force.point, body, path + ("point",))
        row[DL_POINT_I:DL_POINT_I + 2] = start
        row[DL_POINT_J:DL_POINT_J + 2] = poses.to_body_frame(body, start)
        row[DL_DIRECTION:DL_DIRECTION + 2] = force.direction
        return (GAS_LOAD, _gas_law(force, base_dir, row, tables)), (-1, body), row
    bi, bj, si, sj, length = _two_point_ends(force, poses, path)
    row[DL_POINT_I:DL_POINT_I + 2], row[DL_POINT_J:DL_POINT_J + 2] = si, sj
    row[DL_LENGTH], row[DL_SENSE] = length, SENSES[force.sense]
    if isinstance(force, schema.SpringDrive):
        row[DL_RELEASE] = force.release_time
        return (SPRING_DRIVE, _spring_law(force, length, base_dir, row, tables)), (bi, bj), row
    if force.damping is not None:
        row[DL_A], law = force.damping, LINEAR
    else:
        row[DL_A] = force.density * force.piston_area ** 3 / (2.0 * force.discharge_coefficient ** 2
                                                              * force.orifice_area ** 2)
        law = ORIFICE
    row[DL_B], row[DL_C] = force.engaged if force.engaged is not None else (-np.inf, np.inf)
    row[DL_D] = force.engagement_length
    return (DASHPOT, law), (bi, bj), row


def driveline_arrays(mechanism, poses, base_dir: Path) -> dict:
    """The driveline_* fields of SystemArrays; BuildError located at the element for what cannot be built."""
    kinds, bodies, rows, tables = [], [], [], []
    for index, force in enumerate(mechanism.forces):
        if not isinstance(force, ELEMENT_TYPES):
            continue
        path = ("forces", index)
        try:
            kind, pair, row = element_row(mechanism, force, poses, base_dir, tables, path)
        except DrivelineError as exc:
            raise BuildError([Problem(path + exc.place, str(exc), exc.hint)]) from None
        kinds.append(kind)
        bodies.append(pair)
        rows.append(row)
    return {
        "driveline_kinds": np.array(kinds, dtype=np.int64).reshape(-1, 2),
        "driveline_bodies": np.array(bodies, dtype=np.int64).reshape(-1, 2),
        "driveline_params": np.array(rows, dtype=np.float64).reshape(-1, DRIVELINE_COLUMNS),
        "driveline_table": np.concatenate(tables) if tables else np.zeros((0, 3)),
    }


def puffer_overrun(system, q: np.ndarray) -> tuple[str, str, str] | None:
    """(element, message, hint) of the first adiabatic puffer whose stroke at q is past the `stroke:` it states (the
    build checked that this stroke leaves gas in the volume); None if there is none."""
    arrays = system.arrays
    elements = [force for force in system.mechanism.forces if isinstance(force, ELEMENT_TYPES)]
    for k, force in enumerate(elements):
        if arrays.driveline_kinds[k, 1] != ADIABATIC:
            continue
        p, body = arrays.driveline_params[k], arrays.driveline_bodies[k, 1]
        x, y, angle = q[3 * body:3 * body + 3]
        c, s = np.cos(angle), np.sin(angle)
        point = np.array([x + c * p[DL_POINT_J] - s * p[DL_POINT_J + 1], y + s * p[DL_POINT_J] + c * p[DL_POINT_J + 1]])
        stroke = float(np.dot(p[DL_DIRECTION:DL_DIRECTION + 2], point - p[DL_POINT_I:DL_POINT_I + 2]))
        if stroke > force.stroke:
            return (force.name, f"the puffer is compressed to a stroke of {stroke * 1e3:.4g} mm, past its stated stroke "
                    f"of {force.stroke * 1e3:.4g} mm; its volume is used up at V0/A = {force.volume / force.area * 1e3:.4g} mm",
                    "the motion compresses the gas further than `stroke:` says: check the drive's stroke, and the "
                    "puffer's volume, area and stroke and their units")
    return None


STORED_ENERGY_NAMES = {SPRING_DRIVE: "drive_spring_stored", GAS_LOAD: "gas_stored"}


def driveline_stored_energies(system, states: np.ndarray) -> dict:
    """{energy name: Σ U(s) over the elements of that kind} of the spring drives (`drive_spring_stored`) and gas
    loads (`gas_stored`), only for the kinds the model has; both are also part of the potential energy."""
    kinds = system.arrays.driveline_kinds[:, 0]
    present = [kind for kind in STORED_ENERGY_NAMES if np.any(kinds == kind)]
    if not present:
        return {}
    values = np.empty((states.shape[0], kinds.shape[0]))
    stored_energy_histories(for_kernels(system.arrays), np.ascontiguousarray(states), values)
    return {STORED_ENERGY_NAMES[kind]: values[:, kinds == kind].sum(axis=1) for kind in present}


def driveline_histories(system, times: np.ndarray, states: np.ndarray) -> dict:
    """{dataset: (values, unit)} of each element: /drives/<name>/stroke (m) or, for a guide friction,
    sliding_velocity (m/s), and force (N, along the element's stroke; latched spring: 0)."""
    names = [force.name for force in system.mechanism.forces if isinstance(force, ELEMENT_TYPES)]
    if not names:
        return {}
    values = np.empty((times.shape[0], len(names), 3))
    element_histories(for_kernels(system.arrays), times, np.ascontiguousarray(states), values)
    out = {}
    for k, name in enumerate(names):
        if system.arrays.driveline_kinds[k, 0] == GUIDE_FRICTION:
            out[f"drives/{name}/sliding_velocity"] = (values[:, k, 1], "m/s")
        else:
            out[f"drives/{name}/stroke"] = (values[:, k, 0], "m")
        out[f"drives/{name}/force"] = (values[:, k, 2], "N")
    return out
