"""Axially flexible links: a two-joint link as two halves sliding along the line between its joints.

The half at the first joint (in file order) keeps the body's name; the other, `<body>_<joint>_half`, is new.
Both start with the body's pose, centre of mass and body points, half its mass and half its inertia, so the
pair has the link's mass, centre of mass and inertia. A prismatic joint `<body>_stretch` along the line
between the joints keeps them aligned, and a spring-damper `<body>_compliance` between the two joint points
is the link's axial stiffness k and damping c. Joints, sensors and loads at points nearer the second joint
move to the new half. A body's `flexible:` block is expanded so when the file is loaded (expanded_document);
diagnose's compliance candidate writes the same split into a document (split_link).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace

import numpy as np

from clearsim.errors import ClearsimError, Problem
from clearsim.model.schema import TWO_ENDED, PrismaticJoint, validate_mechanism
from clearsim.units import si_text


@dataclass(frozen=True)
class LinkSplit:
    """Where a two-joint link is cut and what moves to its second half (docs/model.md, flexible links)."""

    body: str
    half: str  # the new body, at the second joint
    near: tuple[float, float]  # global location of the first joint at t = 0
    far: tuple[float, float]  # of the second
    moved_joint: str  # the second joint: its reference to the body goes to the new half
    moved_sensors: frozenset  # point sensors nearer the second joint
    moved_ends: dict  # force name → indices of its ends on the body nearer the second joint (single-body force: (0,))
    mass: float  # kg, of the whole link
    inertia: float  # kg·m², of the whole link
    tension: float = 0.0  # N: the axial tension the spring carries at t = 0 (free length L − T₀/k)

    @property
    def guide(self) -> str:
        return f"{self.body}_stretch"

    @property
    def spring(self) -> str:
        return f"{self.body}_compliance"

    @property
    def length(self) -> float:
        return float(np.hypot(self.far[0] - self.near[0], self.far[1] - self.near[1]))


def axial_stiffness(flexibility, length: float) -> float:
    """k (N/m): given, or E A / L with L the distance between the two joints at t = 0."""
    if flexibility.axial_stiffness is not None:
        return flexibility.axial_stiffness
    return flexibility.youngs_modulus * flexibility.area / length


def axial_damping(damping_ratio: float, stiffness: float, mass: float, stiffness_damping: float = 0.0) -> float:
    """c = 2 ζ √(k m_eff) + β k (N·s/m), m_eff = m/4: the reduced mass of the two halves m/2 and m/2, so ζ is the
    damping ratio of the free link's own axial mode; β (s) the Rayleigh stiffness-proportional coefficient."""
    return 2.0 * damping_ratio * math.sqrt(stiffness * mass / 4.0) + stiffness_damping * stiffness


def set_spring(document: dict, split: LinkSplit, stiffness: float, damping_ratio: float,
               stiffness_damping: float = 0.0) -> None:
    """The split's spring-damper in `document` gets k, c = 2 ζ √(k m/4) + β k and the free length L − T₀/k."""
    spring = next(f for f in document["forces"] if f.get("name") == split.spring)
    spring["stiffness"] = si_text(stiffness, "spring_stiffness")
    spring["damping"] = si_text(axial_damping(damping_ratio, stiffness, split.mass, stiffness_damping), "damping")
    spring["free_length"] = si_text(split.length - split.tension / float(stiffness), "length")


def joint_lists(mechanism) -> tuple[dict[str, list], set[str]]:
    """body → its revolute joints (file order), and the bodies that cannot stretch: in a prismatic joint or
    moved by a body driver."""
    revolute = {b.name: [] for b in mechanism.bodies}
    excluded = {d.body for d in mechanism.drivers if d.body is not None}
    for joint in mechanism.joints:
        for name in set(joint.bodies) & set(revolute):
            if isinstance(joint, PrismaticJoint):
                excluded.add(name)
            else:
                revolute[name].append(joint)
    return revolute, excluded


def two_joint_links(mechanism) -> list[tuple[str, list]]:
    """Bodies with exactly two revolute joints, in no prismatic joint and driven by no body driver."""
    revolute, excluded = joint_lists(mechanism)
    return [(name, joints) for name, joints in revolute.items() if len(joints) == 2 and name not in excluded]


def _joint_location(mechanism, poses, joint, body: str) -> np.ndarray:
    """Where the joint sits on `body`, globally, at t = 0 (as the assembly reads `at:` or `points:`)."""
    from clearsim.assembly.build import joint_points

    _, _, si, sj = joint_points(poses, joint, ("joints", mechanism.joints.index(joint)))
    return poses.to_global(poses.index[body], si if joint.bodies[0] == body else sj)


def _force_ends(poses, force, body: str) -> list[tuple[int, np.ndarray]]:
    """(end index, global location at t = 0) of each end of a force that acts on `body`."""
    index = poses.index[body]
    if not isinstance(force, TWO_ENDED):
        return [(0, poses.point_global(force.point, index, ()))] if force.body == body else []
    ends = []
    for end, name in enumerate(force.bodies):
        if name != body:
            continue
        if force.points is not None:
            ends.append((end, poses.to_global(index, poses.named_body_point(body, force.points[end], ())[0])))
        else:
            ends.append((end, poses.point_global(force.at[end] if force.at is not None else None, index, ())))
    return ends


def link_split(mechanism, body: str, joints: list) -> LinkSplit | None:
    """The split of a two-joint link; None when its joints coincide or the new names are taken."""
    from clearsim.assembly.build import initial_poses

    poses = initial_poses(mechanism)
    near, far = (_joint_location(mechanism, poses, j, body) for j in joints)
    axis = far - near
    if np.linalg.norm(axis) < 1e-9:
        return None

    def nearer_far(point) -> bool:
        return float(np.dot(np.asarray(point, float) - near, axis)) > 0.5 * float(np.dot(axis, axis))

    sensors = frozenset(s.name for s in mechanism.sensors if getattr(s, "body", None) == body and hasattr(s, "point")
                        and nearer_far(poses.point_global(s.point, poses.index[body], ())))
    moved = {f.name: tuple(end for end, where in _force_ends(poses, f, body) if nearer_far(where)) for f in mechanism.forces}
    split = LinkSplit(body, f"{body}_{joints[1].name}_half", tuple(near.tolist()), tuple(far.tolist()), joints[1].name, sensors,
                      {name: ends for name, ends in moved.items() if ends}, mechanism.body(body).mass,
                      mechanism.body(body).inertia)
    taken = {b.name for b in mechanism.bodies} | {j.name for j in mechanism.joints} | {f.name for f in mechanism.forces}
    return None if {split.half, split.guide, split.spring} & taken else split


def split_link(document: dict, split: LinkSplit) -> None:
    """Make the link two halves joined by a prismatic joint along it and a spring-damper (no force yet)."""
    bodies = document["bodies"]
    position = next(i for i, b in enumerate(bodies) if b["name"] == split.body)
    near = bodies[position]
    near.pop("flexible", None)
    near["mass"] = si_text(split.mass / 2.0, "mass")
    near["inertia"] = si_text(split.inertia / 2.0, "inertia")
    bodies.insert(position + 1, {**copy.deepcopy(near), "name": split.half})

    def moved(names, ends):
        return [split.half if k in ends and n == split.body else n for k, n in enumerate(names)]

    for joint in document["joints"]:
        if joint["name"] == split.moved_joint:
            joint["bodies"] = moved(joint["bodies"], (0, 1))
    for sensor in document.get("sensors") or []:
        if sensor["name"] in split.moved_sensors:
            sensor["body"] = split.half
    for force in document.get("forces") or []:
        ends = split.moved_ends.get(force["name"], ())
        if ends and "body" in force:
            force["body"] = split.half
        elif ends:
            force["bodies"] = moved(force["bodies"], ends)
    axis = np.subtract(split.far, split.near)
    document["joints"].append({"name": split.guide, "type": "prismatic", "bodies": [split.body, split.half],
                               "at": point_text(split.near), "axis": (axis / np.linalg.norm(axis)).tolist()})
    document["forces"] = (document.get("forces") or []) + [{
        "type": "spring_damper", "name": split.spring, "bodies": [split.body, split.half],
        "at": [point_text(split.near), point_text(split.far)], "stiffness": 0.0, "damping": 0.0,
        "free_length": si_text(split.length, "length")}]


def point_text(point) -> list[str]:
    return [si_text(coordinate, "length") for coordinate in point]


def flexible_link_names(document: dict) -> list[str]:
    """The bodies the file declares flexible, in file order."""
    return [body["name"] for body in document.get("bodies") or [] if isinstance(body, dict) and body.get("flexible")]


def flexible_problems(mechanism) -> list[Problem]:
    """Each flexible body that cannot be split: not exactly two revolute joints, in a prismatic joint or driven,
    its joints at one point, or its new names taken."""
    revolute, excluded = joint_lists(mechanism)
    problems = []
    for index, body in enumerate(mechanism.bodies):
        if body.flexible is None:
            continue
        path, joints = ("bodies", index, "flexible"), revolute[body.name]
        if body.name in excluded:
            problems.append(Problem(path, f"a flexible body stretches between two revolute joints; {body.name} is in "
                                    "a prismatic joint or moved by a driver", "remove `flexible:` from this body"))
        elif len(joints) != 2:
            problems.append(Problem(path, f"an axial flexible link has exactly two revolute joints; {body.name} has "
                                    f"{len(joints)}", "remove `flexible:` or join the body at exactly two points"))
        elif link_split(mechanism, body.name, joints) is None:
            problems.append(Problem(path, f"{body.name} cannot stretch: its two joints are at the same point, or the "
                                    f"names {body.name}_{joints[1].name}_half, {body.name}_stretch or "
                                    f"{body.name}_compliance are taken", "place the joints apart, or rename"))
    return problems


def initial_tensions(document: dict, splits: list[LinkSplit], base_dir) -> list[float]:
    """Each split link's axial tension at t = 0 in the model as given (N): the splits with their slides locked by
    drivers (the rigid links again), assembled, and each lock's multiplier at t = 0 (the force along the link on
    the second half is −λ·axis, as a spring's tension λ). 0 when that model cannot be assembled."""
    from clearsim.assembly.arrays import for_kernels
    from clearsim.assembly.build import BuildError
    from clearsim.assembly.dynamics import accelerations, generalized_forces
    from clearsim.assembly.hydraulics import add_hydraulic_forces
    from clearsim.assembly.system import assemble

    locked = copy.deepcopy(document)
    for split in splits:
        split_link(locked, split)
    locks = [f"{split.guide}_lock" for split in splits]
    locked["drivers"] = (locked.get("drivers") or []) + [
        {"name": lock, "joint": split.guide, "motion": {"law": "polynomial", "coefficients": [0.0]}}
        for lock, split in zip(locks, splits)]
    try:
        system = assemble(validate_mechanism(locked), base_dir)
    except (BuildError, ClearsimError, ValueError):
        return [0.0] * len(splits)
    free = np.zeros(len(system.clearance_joints), np.int64)  # every journal starts in free flight (mode FREE)
    kernel_arrays = for_kernels(system.arrays)
    forces = generalized_forces(kernel_arrays, 0.0, system.q0, system.qd0, free, np.zeros(free.size))[0]
    add_hydraulic_forces(kernel_arrays, system.q0, system.z0, forces)
    multipliers = accelerations(kernel_arrays, 0.0, system.q0, system.qd0, forces, free)[1]
    return [float(multipliers[dict(system.drivers)[lock]]) for lock in locks]


def expanded_document(document: dict, mechanism, base_dir) -> dict:
    """A copy of the document with every flexible body split, its spring carrying the rigid link's tension at
    t = 0 (flexible_problems found none; `base_dir`: where the file's tables are)."""
    revolute, _ = joint_lists(mechanism)
    flexible = [body for body in mechanism.bodies if body.flexible is not None]
    splits = [link_split(mechanism, body.name, revolute[body.name]) for body in flexible]
    tensions = initial_tensions(document, splits, base_dir)
    expanded = copy.deepcopy(document)
    for body, split, tension in zip(flexible, splits, tensions):
        split = replace(split, tension=tension)
        split_link(expanded, split)
        set_spring(expanded, split, axial_stiffness(body.flexible, split.length), body.flexible.damping_ratio,
                   body.flexible.stiffness_damping)
    return expanded
