"""assemble(mechanism) → System: arrays for the kernels, names for the outputs, a consistent initial state.

Initial assembly (docs/model.md §1): Newton iteration on Φ(q, 0) = 0 from the YAML's poses with
clearance joints temporarily pinned at their initial eccentricity (centred by default), then
the velocities nearest (in the kinetic-energy metric) to the YAML's that satisfy Φ_q q̇ = ν,
again with the journals moving with their bearings.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from clearsim.assembly import build, hydraulics
from clearsim.assembly.arrays import KernelArrays, SystemArrays, for_kernels, mass_diagonal
from clearsim.assembly.build import BuildError, ConstraintRows, Laws, Poses
from clearsim.assembly.constraints import constraint_count, dense_jacobian, evaluate_constraints, evaluate_velocity_rhs
from clearsim.assembly.drivelines import driveline_arrays
from clearsim.errors import Problem
from clearsim.model import schema
from clearsim.physics import motion
from clearsim.physics.tables import read_table_column

ASSEMBLY_TOLERANCE = 1e-12  # m or rad: max |Φ| after initial assembly
ASSEMBLY_ITERATIONS = 60


@dataclass(frozen=True)
class SensorSpec:
    name: str
    kind: str  # schema sensor type
    body: int = -1
    point: tuple[float, float] = (0.0, 0.0)  # body frame
    direction: tuple[float, float] = (1.0, 0.0)
    joint: str | None = None
    component: str | None = None


@dataclass(frozen=True)
class System:
    """Everything the solver and the writers need; never reads the YAML again."""

    arrays: SystemArrays
    body_names: list[str]
    row_owners: list[str]  # the joint or driver owning each constraint row
    pin_joints: list[str]  # ideal revolute joints, in pin order (rows 2k, 2k+1)
    prismatic_joints: list[tuple[str, int]]  # (name, offset row index among offsets)
    drivers: list[tuple[str, int]]  # (name, constraint row)
    clearance_joints: list[str]
    sensors: list[SensorSpec]
    output: schema.OutputSensors
    q0: np.ndarray
    qd0: np.ndarray
    degrees_of_freedom: int
    mechanism: schema.Mechanism
    hydraulic_cylinders: list[str] = field(default_factory=list)  # in the order of their states in z
    z0: np.ndarray = field(default_factory=lambda: np.zeros(0))  # the force elements' states at t = 0 (scaled)

    @property
    def coordinate_count(self) -> int:
        return 3 * len(self.body_names)


def _loads(mechanism, poses: Poses, laws: Laws, base_dir: Path) -> list:
    loads = []
    for index, force in enumerate(mechanism.forces):
        path = ("forces", index)
        if not isinstance(force, (schema.ConstantForce, schema.TabulatedForce)):
            continue
        body = poses.index[force.body]
        point = poses.to_body_frame(body, poses.point_global(force.point, body, path + ("point",)))
        if isinstance(force, schema.ConstantForce):
            loads.append((body, [*point, *force.force, force.torque], -1))
            continue
        try:
            times, values = read_table_column(base_dir / force.file, force.time_column, force.value_column,
                                              force.time_unit, force.value_unit, "force", path)
            law = laws.add(motion.table_law(times, values, relative=False))
        except ValueError as exc:
            raise BuildError([Problem(path + ("file",), str(exc), None)]) from None
        loads.append((body, [*point, *force.direction, 0.0], law))
    return loads


def _springs(mechanism, poses: Poses) -> list:
    springs = []
    for index, force in enumerate(mechanism.forces):
        if not isinstance(force, schema.SpringDamper):
            continue
        bi, bj, si, sj, length = build.force_ends(poses, force, ("forces", index))
        free = force.free_length if force.free_length is not None else length
        springs.append(((bi, bj), [*si, *sj, force.stiffness, force.damping, free, force.preload]))
    return springs


def _cylinders(mechanism, poses: Poses, laws: Laws) -> list:
    """(name, (body i, body j), params row, laws row, initial states) of each hydraulic cylinder."""
    cylinders = []
    for index, force in enumerate(mechanism.forces):
        if not isinstance(force, schema.HydraulicCylinder):
            continue
        path = ("forces", index)
        bi, bj, si, sj, length = build.force_ends(poses, force, path)
        problems = hydraulics.build_problems(force, length, mechanism.solver.t_end, path)
        if problems:
            raise BuildError(problems)
        cylinders.append((force.name, (bi, bj), *hydraulics.cylinder_row(force, si, sj, length, laws.add)))
    return cylinders


def _torsions(mechanism, poses: Poses) -> list:
    """((i, j), [k, c, θ₀, preload]) of each rotational spring; θ₀ defaults to θ_j − θ_i at t = 0."""
    torsions = []
    for force in mechanism.forces:
        if isinstance(force, schema.RotationalSpring):
            bi, bj = poses.index[force.bodies[0]], poses.index[force.bodies[1]]
            free = force.free_angle if force.free_angle is not None else poses.pose(bj)[1] - poses.pose(bi)[1]
            torsions.append(((bi, bj), [force.stiffness, force.damping, free, force.preload]))
    return torsions


def _sensors(mechanism, poses: Poses) -> list[SensorSpec]:
    sensors = []
    for index, sensor in enumerate(mechanism.sensors):
        if isinstance(sensor, schema.JointForceSensor):
            sensors.append(SensorSpec(sensor.name, sensor.type, joint=sensor.joint, component=sensor.component))
            continue
        body = poses.index[sensor.body]
        if isinstance(sensor, schema.BodySensor):
            sensors.append(SensorSpec(sensor.name, sensor.type, body=body))
            continue
        point = poses.to_body_frame(body, poses.point_global(sensor.point, body, ("sensors", index, "point")))
        sensors.append(SensorSpec(sensor.name, sensor.type, body=body, point=tuple(point),
                                  direction=tuple(sensor.direction)))
    return sensors


def _pinned_clearances(arrays: SystemArrays, clearances: list) -> SystemArrays:
    """The same arrays with every clearance joint as a pin at its initial eccentricity (for assembly)."""
    if not clearances:
        return arrays
    extra_bodies = np.array([c[:2] for c in clearances], dtype=np.int64).reshape(-1, 2)
    extra_points = []
    for bi, bj, si, sj, parameters, _ in clearances:
        # pin P_B + e0 = P_J: shift the bearing point by e0 (global, rotated into the bearing frame at t = 0)
        extra_points.append(np.concatenate([si + np.asarray(parameters.initial_eccentricity), sj]))
    return arrays._replace(
        pin_bodies=np.vstack([arrays.pin_bodies, extra_bodies]),
        pin_points=np.vstack([arrays.pin_points, np.array(extra_points)]),
        row_place=np.zeros(0, np.int64),  # the rows in their own places: the pins added shift the others
    )


def _newton_assembly(arrays: KernelArrays, q: np.ndarray, owners: list[str]) -> np.ndarray:
    """Minimum-norm Newton steps on Φ(q, 0) = 0; BuildError naming the worst rows if it fails."""
    m = constraint_count(arrays)
    if m == 0:
        return q
    phi = np.empty(m)
    for _ in range(ASSEMBLY_ITERATIONS):
        evaluate_constraints(arrays, 0.0, q, phi)
        if np.max(np.abs(phi)) <= ASSEMBLY_TOLERANCE:
            return q
        q = q - np.linalg.lstsq(dense_jacobian(arrays, q), phi, rcond=None)[0]
    worst = [owners[i] for i in np.argsort(-np.abs(phi))[:3] if abs(phi[i]) > ASSEMBLY_TOLERANCE]
    names = ", ".join(dict.fromkeys(worst))
    raise BuildError([Problem(("joints",), f"the mechanism cannot be assembled at t = 0: joints {names} cannot close "
                              f"(residual {np.max(np.abs(phi)):.3g} m)",
                              "check the joint locations and link lengths: the loop through these joints does not close")])


def _consistent_velocities(arrays: KernelArrays, q: np.ndarray, qd: np.ndarray, mass_diag: np.ndarray,
                           clearances: list, first_clearance_row: int) -> np.ndarray:
    """The velocity nearest to qd in the M metric with Φ_q q̇ = ν(0), journals at their initial relative velocity."""
    m = constraint_count(arrays)
    if m == 0:
        return qd
    jac = dense_jacobian(arrays, q)
    nu = np.empty(m)
    evaluate_velocity_rhs(arrays, 0.0, nu)
    for k, clearance in enumerate(clearances):  # pin rows P_B + e0 − P_J: d/dt = −ė0
        row = first_clearance_row + 2 * k
        nu[row:row + 2] = -np.asarray(clearance[4].initial_velocity, float)
    scale = 1.0 / np.sqrt(mass_diag)
    correction = np.linalg.lstsq(jac * scale, jac @ qd - nu, rcond=None)[0]
    return qd - scale * correction


def _check_rank(arrays: KernelArrays, q: np.ndarray, owners: list[str]) -> int:
    """Rank of Φ_q; BuildError naming the joints of a redundant set."""
    m = constraint_count(arrays)
    if m == 0:
        return 0
    jac = dense_jacobian(arrays, q)
    u, sigma, _ = np.linalg.svd(jac)
    tolerance = max(jac.shape) * np.finfo(float).eps * 1e3 * max(sigma[0], 1.0)
    rank = int(np.sum(sigma > tolerance))
    if rank < m:
        involved = np.abs(u[:, rank:]).max(axis=1) > 1e-8
        names = ", ".join(dict.fromkeys(o for o, hit in zip(owners, involved) if hit))
        raise BuildError([Problem(("joints",), f"redundant constraints: {names} constrain the same motion "
                                  f"({m - rank} equation(s) too many)",
                                  "remove one of these joints, replace a revolute by a clearance joint, "
                                  "or drop a driver that fixes an already determined coordinate")])
    return rank


def _check_connected(mechanism, poses: Poses) -> None:
    """Every body reaches the ground through joints, springs or drivers."""
    neighbours = {name: set() for name in poses.index}
    links = [j.bodies for j in mechanism.joints]
    links += [f.bodies for f in mechanism.forces if isinstance(f, schema.TWO_BODY)]
    links += [(build.GROUND_NAME, d.body) for d in mechanism.drivers if d.body is not None]
    for a, b in links:
        neighbours[a].add(b)
        neighbours[b].add(a)
    reached, frontier = {build.GROUND_NAME}, [build.GROUND_NAME]
    while frontier:
        for other in neighbours[frontier.pop()] - reached:
            reached.add(other)
            frontier.append(other)
    loose = [b.name for b in mechanism.bodies if b.name not in reached]
    if loose:
        index = next(i for i, b in enumerate(mechanism.bodies) if b.name == loose[0])
        raise BuildError([Problem(("bodies", index), f"under-constrained: bodies {', '.join(loose)} are connected "
                                  "to the ground by no joint, spring or driver", "add the joint that holds them")])


def assemble(mechanism: schema.Mechanism, base_dir: Path | str = ".") -> System:
    """Names → arrays, initial assembly, consistent velocities, DOF and redundancy checks."""
    base_dir = Path(base_dir)
    poses = build.initial_poses(mechanism)
    _check_connected(mechanism, poses)
    rows, laws, clearances = ConstraintRows(), Laws(), []
    for index, joint in enumerate(mechanism.joints):
        build.add_joint(rows, clearances, poses, joint, mechanism.defaults, ("joints", index))
    for index, driver in enumerate(mechanism.drivers):
        build.add_driver(rows, laws, mechanism, poses, driver, base_dir, ("drivers", index))
    loads = _loads(mechanism, poses, laws, base_dir)
    cylinders = _cylinders(mechanism, poses, laws)
    arrays = build.pack(mechanism, rows, clearances, laws, loads, _springs(mechanism, poses),
                        _torsions(mechanism, poses), driveline_arrays(mechanism, poses, base_dir), cylinders)
    owners = rows.row_owners()
    assembly_arrays = _pinned_clearances(arrays, clearances)
    assembly_owners = owners[: 2 * len(rows.pins)] + [c[-1] for c in clearances for _ in range(2)] + owners[2 * len(rows.pins):]
    assembly_kernel_arrays = for_kernels(assembly_arrays)
    q0 = _newton_assembly(assembly_kernel_arrays, _initial_coordinates(mechanism), assembly_owners)
    rank = _check_rank(for_kernels(arrays), q0, owners)
    mass_diag = mass_diagonal(arrays)
    qd0 = _consistent_velocities(assembly_kernel_arrays, q0, _initial_velocities(mechanism), mass_diag,
                                 clearances, 2 * len(rows.pins))
    n_offsets = len(rows.offsets)
    return System(
        arrays=arrays,
        body_names=[b.name for b in mechanism.bodies],
        row_owners=owners,
        pin_joints=[p[-1] for p in rows.pins],
        prismatic_joints=[(o[-1], i) for i, o in enumerate(rows.offsets) if o[6] < 0],
        drivers=[(o[-1], 2 * len(rows.pins) + i) for i, o in enumerate(rows.offsets) if o[6] >= 0]
        + [(a[-1], 2 * len(rows.pins) + n_offsets + i) for i, a in enumerate(rows.angles) if a[3] >= 0],
        clearance_joints=[c[-1] for c in clearances],
        sensors=_sensors(mechanism, poses),
        output=mechanism.output,
        q0=q0,
        qd0=qd0,
        degrees_of_freedom=3 * len(mechanism.bodies) - rank,
        mechanism=mechanism,
        hydraulic_cylinders=[c[0] for c in cylinders],
        z0=np.concatenate([np.array([z for c in cylinders for z in c[4]], float),
                           np.zeros(build.wear_state_count(arrays))]),  # an accumulated wear profile starts at 0
    )


def _initial_coordinates(mechanism) -> np.ndarray:
    return np.array([[*b.position, b.angle] for b in mechanism.bodies], float).ravel()


def _initial_velocities(mechanism) -> np.ndarray:
    return np.array([[*b.velocity, b.angular_velocity] for b in mechanism.bodies], float).ravel()
