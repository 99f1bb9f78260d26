"""Mechanism (names, SI floats) → SystemArrays (indices, arrays): the only place that turns names into offsets.

Joint locations given as global points at t = 0 (`at:`) become body-fixed points through each
body's initial pose; drivers and prismatic guides take their reference values from that pose.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from clearsim.assembly.arrays import (
    CLEARANCE_COLUMNS, CLEARANCE_LAW_COLUMNS, CL_BEARING_POINT, CL_BEARING_RADIUS, CL_CLEARANCE, CL_DRY_GAP,
    CL_EXPONENT, CL_FILM_LENGTH, CL_JOURNAL_POINT, CL_JOURNAL_RADIUS, CL_MIN_IMPACT_SPEED, CL_MU_D, CL_MU_S,
    CL_RESTITUTION, CL_STIFFNESS, CL_V_HIGH, CL_V_LOW, CL_VISCOSITY, HYDRAULIC_COLUMNS, HYDRAULIC_LAW_COLUMNS,
    LOAD_COLUMNS, SPRING_COLUMNS, TORSION_COLUMNS, WEAR_LINE_STIFFNESS, WEAR_SCALE, WEAR_WEIGHTS, SystemArrays,
)
from clearsim.errors import Problem
from clearsim.model import schema
from clearsim.model.resolve import ClearanceParameters, resolve_clearance
from clearsim.physics import contact, cylindrical, friction, lubrication, motion, wear
from clearsim.physics.tables import read_table_column
from clearsim.units import UnitError, to_si

GROUND_NAME = "ground"


class BuildError(Exception):
    """Problems found while turning names into arrays; the caller locates them in the file."""

    def __init__(self, problems: list[Problem]):
        super().__init__("; ".join(p.message for p in problems))
        self.problems = problems


def _rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


@dataclass
class Poses:
    """Initial poses by body index (the ground at the origin) and the named global points."""

    index: dict[str, int]
    position: np.ndarray
    angle: np.ndarray
    global_points: dict[str, tuple[float, float]]
    body_points: dict[str, dict[str, tuple[float, float]]]

    def pose(self, body: int) -> tuple[np.ndarray, float]:
        if body < 0:
            return np.zeros(2), 0.0
        return self.position[body], float(self.angle[body])

    def to_body_frame(self, body: int, global_point) -> np.ndarray:
        r, angle = self.pose(body)
        return _rotation(angle).T @ (np.asarray(global_point, float) - r)

    def direction_to_body_frame(self, body: int, direction) -> np.ndarray:
        return _rotation(self.pose(body)[1]).T @ np.asarray(direction, float)

    def to_global(self, body: int, body_point) -> np.ndarray:
        r, angle = self.pose(body)
        return r + _rotation(angle) @ np.asarray(body_point, float)

    def point_global(self, reference, body: int, path) -> np.ndarray:
        """A `PointRef` (named global point or [x, y]) or None (the body's centre of mass), globally."""
        if reference is None:
            return self.pose(body)[0].copy()
        if isinstance(reference, str):
            if reference not in self.global_points:
                raise BuildError([Problem(path, f"unknown point '{reference}'", "define it under `points:`")])
            return np.asarray(self.global_points[reference], float)
        return np.asarray(reference, float)

    def named_body_point(self, body_name: str, point_name: str, path) -> tuple[np.ndarray, int]:
        """(body-frame point, body index) of a point named on a body (ground: a global point)."""
        body = self.index[body_name]
        table = self.global_points if body < 0 else self.body_points[body_name]
        if point_name not in table:
            raise BuildError([Problem(path, f"body '{body_name}' has no point '{point_name}'", None)])
        return np.asarray(table[point_name], float), body


def initial_poses(mechanism: schema.Mechanism) -> Poses:
    index = {GROUND_NAME: -1} | {b.name: i for i, b in enumerate(mechanism.bodies)}
    return Poses(
        index=index,
        position=np.array([b.position for b in mechanism.bodies], float).reshape(-1, 2),
        angle=np.array([b.angle for b in mechanism.bodies], float),
        global_points=dict(mechanism.points),
        body_points={b.name: dict(b.points) for b in mechanism.bodies},
    )


def joint_points(poses: Poses, joint, path) -> tuple[int, int, np.ndarray, np.ndarray]:
    """(body i, body j, point on i, point on j) in body frames, from `at:` or `points:`."""
    bi, bj = poses.index[joint.bodies[0]], poses.index[joint.bodies[1]]
    if joint.points is not None:
        si, _ = poses.named_body_point(joint.bodies[0], joint.points[0], path + ("points", 0))
        sj, _ = poses.named_body_point(joint.bodies[1], joint.points[1], path + ("points", 1))
        return bi, bj, si, sj
    location = poses.point_global(joint.at, bi, path + ("at",))
    return bi, bj, poses.to_body_frame(bi, location), poses.to_body_frame(bj, location)


def force_ends(poses: Poses, force, path) -> tuple[int, int, np.ndarray, np.ndarray, float]:
    """(body i, body j, point i and point j in their body frames, length between them at t = 0) of a two-ended
    force (`bodies:` with `at:` or `points:`; by default the centres of mass)."""
    if force.points is not None:
        si, bi = poses.named_body_point(force.bodies[0], force.points[0], path + ("points", 0))
        sj, bj = poses.named_body_point(force.bodies[1], force.points[1], path + ("points", 1))
        pi, pj = poses.to_global(bi, si), poses.to_global(bj, sj)
    else:
        bi, bj = poses.index[force.bodies[0]], poses.index[force.bodies[1]]
        ends = force.at if force.at is not None else (None, None)
        pi = poses.point_global(ends[0], bi, path + ("at", 0))
        pj = poses.point_global(ends[1], bj, path + ("at", 1))
        si, sj = poses.to_body_frame(bi, pi), poses.to_body_frame(bj, pj)
    return bi, bj, si, sj, float(np.linalg.norm(pj - pi))


def perpendicular(vector) -> np.ndarray:
    return np.array([-vector[1], vector[0]], float)


@dataclass
class ConstraintRows:
    """Growing lists of the three primitives, with the name that owns each row."""

    pins: list = field(default_factory=list)  # (bi, bj, si, sj, owner)
    offsets: list = field(default_factory=list)  # (bi, bj, si, sj, w̄, c0, law, owner)
    angles: list = field(default_factory=list)  # (bi, bj, c0, law, owner)

    def row_owners(self) -> list[str]:
        owners = [p[-1] for p in self.pins for _ in range(2)]
        return owners + [o[-1] for o in self.offsets] + [a[-1] for a in self.angles]

    def places(self, names: list[str]) -> np.ndarray:
        """arrays.row_place: each row's place when every owner's rows lie together, the owners in the order of
        `names` (the joints', then the drivers'), a joint's pins before its offset before its angle."""
        owners = self.row_owners()
        rank = {name: k for k, name in reversed(list(enumerate(names)))}
        order = sorted(range(len(owners)), key=lambda row: rank[owners[row]])
        places = np.empty(len(owners), np.int64)
        places[order] = np.arange(len(owners))
        return places


@dataclass
class Laws:
    items: list = field(default_factory=list)

    def add(self, law: motion.PiecewisePolynomial) -> int:
        self.items.append(law)
        return len(self.items) - 1


def _motion_law(driver: schema.Driver, kind: str, base_dir: Path, path) -> motion.PiecewisePolynomial:
    """The driver's law in SI units of its coordinate (kind 'length' or 'angle'), through the actuator's lag."""
    law = _written_law(driver, kind, base_dir, path)
    try:
        return motion.lagged(law, driver.lag)
    except (ValueError, ArithmeticError):
        raise BuildError([Problem(path + ("lag",), f"the motion seen through a lag of {driver.lag:g} s exceeds the "
                                  "range of floating-point numbers", "a lag is a fraction of the motion's time scale, "
                                  "e.g. 2 ms: check the value and its unit")]) from None


def _written_law(driver: schema.Driver, kind: str, base_dir: Path, path) -> motion.PiecewisePolynomial:
    """The driver's law as written, in SI units of its coordinate."""
    law = driver.motion
    rate_kind = "speed" if kind == "length" else "angular_speed"
    try:
        if isinstance(law, schema.StrokeMotion):
            return motion.stroke_law(to_si(law.stroke, kind), law.duration, law.start)
        if isinstance(law, schema.ConstantSpeedMotion):
            return motion.polynomial_law([to_si(law.speed, rate_kind)])
        if isinstance(law, schema.PolynomialMotion):
            return motion.polynomial_law(law.coefficients)
        unit = law.value_unit or ("m" if kind == "length" else "rad")
        times, values = read_table_column(base_dir / law.file, law.time_column, law.value_column,
                                          law.time_unit, unit, kind, path + ("motion",))
        return motion.table_law(times, values)
    except UnitError as exc:
        raise BuildError([Problem(path + ("motion",), str(exc), f"the driven coordinate is a {kind}")]) from None
    except ValueError as exc:
        raise BuildError([Problem(path + ("motion",), str(exc), None)]) from None
    except ArithmeticError:  # e.g. a stroke over a duration of 1e-300 s
        raise BuildError([Problem(path + ("motion",), "the motion law exceeds the range of floating-point numbers",
                                  "check its values and their units: a duration far too short, or values far "
                                  "too large")]) from None


def add_joint(rows: ConstraintRows, clearances: list, poses: Poses, joint, defaults, path) -> None:
    bi, bj, si, sj = joint_points(poses, joint, path)
    if isinstance(joint, schema.PrismaticJoint):
        axis_body = _rotation(poses.pose(bi)[1]).T @ np.asarray(joint.axis, float)
        rows.offsets.append((bi, bj, si, sj, perpendicular(axis_body), 0.0, -1, joint.name))
        rows.angles.append((bi, bj, poses.pose(bj)[1] - poses.pose(bi)[1], -1, joint.name))
        return
    parameters = resolve_clearance(joint, defaults)
    if parameters is None:
        rows.pins.append((bi, bj, si, sj, joint.name))
    else:
        clearances.append((bi, bj, si, sj, parameters, joint.name))


def add_driver(rows: ConstraintRows, laws: Laws, mechanism, poses: Poses, driver, base_dir: Path, path) -> None:
    if driver.joint is not None:
        joint = mechanism.joint(driver.joint)
        bi, bj, si, sj = joint_points(poses, joint, ("joints", mechanism.joints.index(joint)))
        if isinstance(joint, schema.PrismaticJoint):
            axis_body = _rotation(poses.pose(bi)[1]).T @ np.asarray(joint.axis, float)
            law = laws.add(_motion_law(driver, "length", base_dir, path))
            start = np.dot(joint.axis, poses.to_global(bj, sj) - poses.to_global(bi, si))  # 0 for `at:`
            rows.offsets.append((bi, bj, si, sj, axis_body, start, law, driver.name))
        else:
            law = laws.add(_motion_law(driver, "angle", base_dir, path))
            rows.angles.append((bi, bj, poses.pose(bj)[1] - poses.pose(bi)[1], law, driver.name))
        return
    body = poses.index[driver.body]
    r, angle = poses.pose(body)
    if driver.coordinate == "angle":
        law = laws.add(_motion_law(driver, "angle", base_dir, path))
        rows.angles.append((-1, body, angle, law, driver.name))
    else:
        axis = 0 if driver.coordinate == "x" else 1
        law = laws.add(_motion_law(driver, "length", base_dir, path))
        rows.offsets.append((-1, body, np.zeros(2), np.zeros(2), np.eye(2)[axis], r[axis], law, driver.name))


def clearance_row(si, sj, parameters: ClearanceParameters) -> np.ndarray:
    row = np.zeros(CLEARANCE_COLUMNS)
    row[CL_BEARING_POINT:CL_BEARING_POINT + 2] = si
    row[CL_JOURNAL_POINT:CL_JOURNAL_POINT + 2] = sj
    row[CL_BEARING_RADIUS] = parameters.bearing_radius
    row[CL_JOURNAL_RADIUS] = parameters.journal_radius
    row[CL_CLEARANCE] = parameters.clearance
    row[CL_STIFFNESS] = parameters.stiffness
    row[CL_EXPONENT] = parameters.exponent
    row[CL_RESTITUTION] = parameters.restitution
    row[CL_MIN_IMPACT_SPEED] = parameters.min_impact_speed
    row[CL_MU_S] = parameters.mu_s
    row[CL_MU_D] = parameters.mu_d
    row[CL_V_LOW] = parameters.v_low
    row[CL_V_HIGH] = parameters.v_high
    row[CL_VISCOSITY] = parameters.viscosity
    row[CL_FILM_LENGTH] = parameters.film_length
    row[CL_DRY_GAP] = parameters.dry_below
    return row


def _int_array(values, columns=None) -> np.ndarray:
    shape = (len(values),) if columns is None else (len(values), columns)
    return np.array(values, dtype=np.int64).reshape(shape)


def _float_array(values, columns) -> np.ndarray:
    return np.array(values, dtype=np.float64).reshape((len(values), columns))


def pack(mechanism, rows: ConstraintRows, clearances: list, laws: Laws, loads: list, springs: list,
         torsions: list, drivelines: dict, cylinders: list = ()) -> SystemArrays:
    """The arrays the kernels read, from the named lists (drivelines: the driveline_* arrays; cylinders:
    system._cylinders')."""
    breaks, coefficients, first, count = motion.concatenate(laws.items)
    return SystemArrays(
        mass=np.array([b.mass for b in mechanism.bodies], float),
        inertia=np.array([b.inertia for b in mechanism.bodies], float),
        gravity=np.array(mechanism.gravity, float),
        pin_bodies=_int_array([p[:2] for p in rows.pins], 2),
        pin_points=_float_array([np.concatenate([p[2], p[3]]) for p in rows.pins], 4),
        offset_bodies=_int_array([o[:2] for o in rows.offsets], 2),
        offset_params=_float_array([np.concatenate([o[2], o[3], o[4], [o[5]]]) for o in rows.offsets], 7),
        offset_law=_int_array([o[6] for o in rows.offsets]),
        angle_bodies=_int_array([a[:2] for a in rows.angles], 2),
        angle_value=np.array([a[2] for a in rows.angles], float),
        angle_law=_int_array([a[3] for a in rows.angles]),
        law_breaks=breaks, law_coefficients=coefficients, law_first=first, law_count=count,
        clearance_bodies=_int_array([c[:2] for c in clearances], 2),
        clearance_laws=_int_array([(contact.CONTACT_LAWS[c[4].law], friction.FRICTION_LAWS[c[4].friction_law],
                                    friction.STICK_TREATMENTS[c[4].stick], cylindrical.ELASTIC_LAWS[c[4].elastic],
                                    lubrication.BEARING_MODELS[c[4].film_model])
                                   for c in clearances], CLEARANCE_LAW_COLUMNS),
        clearance_params=_float_array([clearance_row(c[2], c[3], c[4]) for c in clearances], CLEARANCE_COLUMNS),
        load_bodies=_int_array([ld[0] for ld in loads]),
        load_params=_float_array([ld[1] for ld in loads], LOAD_COLUMNS),
        load_law=_int_array([ld[2] for ld in loads]),
        spring_bodies=_int_array([s[0] for s in springs], 2),
        spring_params=_float_array([s[1] for s in springs], SPRING_COLUMNS),
        **drivelines,
        hydraulic_bodies=_int_array([c[1] for c in cylinders], 2),
        hydraulic_params=_float_array([c[2] for c in cylinders], HYDRAULIC_COLUMNS),
        hydraulic_laws=_int_array([c[3] for c in cylinders], HYDRAULIC_LAW_COLUMNS),
        torsion_bodies=_int_array([s[0] for s in torsions], 2),
        torsion_params=_float_array([s[1] for s in torsions], TORSION_COLUMNS),
        **wear_arrays([c[4] for c in clearances], first_slot=sum(len(c[4]) for c in cylinders)),
        row_place=rows.places([joint.name for joint in mechanism.joints] + [driver.name for driver in mechanism.drivers])
        if mechanism.rows_along_the_chain else np.zeros(0, np.int64),
    )


def wear_arrays(parameters: list[ClearanceParameters], first_slot: int) -> dict:
    """The wear_* arrays of the clearance joints (arrays.py): their worn profiles and the bores' sampled points
    (wear.bore_samples), and the slots in z (from first_slot on, after the cylinders' states) and rate factors of
    their Archard profiles."""
    count = len(parameters)
    profile_width = max([len(p.wear_profile) for p in parameters] + [1])
    profile = np.zeros((count, profile_width))
    rate_width = max([WEAR_WEIGHTS + p.archard.harmonics + 1 for p in parameters if p.archard] + [WEAR_WEIGHTS + 1])
    rates = np.zeros((count, rate_width))
    slots = np.full((count, 2), -1, np.int64)
    for k, p in enumerate(parameters):
        profile[k, :len(p.wear_profile)] = p.wear_profile
        if p.archard is not None:
            slots[k] = first_slot, p.archard.harmonics
            first_slot += archard_state_count(p.archard)
            rates[k, WEAR_SCALE] = p.archard.coefficient / (p.archard.hardness * p.archard.length * p.bearing_radius
                                                            * p.clearance)
            rates[k, WEAR_LINE_STIFFNESS] = p.archard.line_stiffness
            rates[k, WEAR_WEIGHTS:WEAR_WEIGHTS + p.archard.harmonics + 1] = wear.kernel_weights(p.archard.sigma,
                                                                                             p.archard.harmonics)
    samples = [wear.bore_samples(p.wear_profile, p.bearing_radius) if len(p.wear_profile) > 1 else np.zeros(2)
               for p in parameters]
    sampled = np.zeros((count, max([len(row) for row in samples] + [2])))
    for k, row in enumerate(samples):
        sampled[k, :len(row)] = row
    return {"wear_harmonics": np.array([(len(p.wear_profile) - 1) // 2 for p in parameters], np.int64).reshape(count),
            "wear_profile": profile, "wear_samples": sampled,
            "wear_depth_range": np.array([wear.depth_range(p.wear_profile) for p in parameters]),
            "wear_bounds": np.array([(wear.inner_reach(p.wear_profile, p.bearing_radius),
                                      wear.innermost_radius(p.wear_profile, p.bearing_radius)) for p in parameters]
                                    ).reshape(count, 2),
            "wear_slots": slots, "wear_rates": rates}


def archard_state_count(archard) -> int:
    """States of an accumulated profile: its 2M + 1 Fourier coefficients."""
    return 2 * archard.harmonics + 1


def wear_state_count(arrays: SystemArrays) -> int:
    """States of all accumulated wear profiles (at the end of z)."""
    return int(sum(2 * harmonics + 1 for slot, harmonics in arrays.wear_slots if slot >= 0))
