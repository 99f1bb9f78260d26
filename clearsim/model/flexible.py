"""Flexible links, expanded into rigid bodies, joints and springs when the file is loaded (expanded_document).

Axial (`model: axial`): a two-joint link as two halves sliding along the line between its joints.
The half at the first joint (in file order) keeps the body's name; the other, `<body>_<joint>_half`, is new.
Both start with the body's pose, centre of mass and body points, half its mass and half its inertia, so the
pair has the link's mass, centre of mass and inertia. A prismatic joint `<body>_stretch` along the line
between the joints keeps them aligned, and a spring-damper `<body>_compliance` between the two joint points
is the link's axial stiffness k and damping c. Joints, sensors and loads at points nearer the second joint
move to the new half. diagnose's compliance candidate writes the same split into a document (split_link).

Beam (`model: beam`, the rigid finite element method): the link's axis of length L cut into n equal elements
of length Δ = L/n, a rigid segment from the middle of one element to the middle of the next (the two end
segments Δ/2 long), pins `<body>_hinge<k>` and rotational springs `<body>_bend<k>` k = E I / Δ at the element
middles. The segments' masses, centres of mass and inertias are the moments of one density along the axis,
ρ(u) = a + b u + c u², fitted to the file's mass, centre of mass and inertia. Joints, sensors, loads and springs
go to the segment holding their point's projection on the axis; the segment holding the first joint keeps the
body's name, the others are `<body>_s<k>`. The bend springs start carrying the moments the rigid link carries at
its hinges at t = 0, as the axial spring starts at its tension (lock_multipliers: the model with those joints locked
by drivers, its multipliers at t = 0) (docs/model.md, "Flexible links: the beam element").
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace

import numpy as np

from clearsim.errors import ClearsimError, Problem
from clearsim.model.schema import (TWO_ENDED, AxialFlexibility, BeamFlexibility, PrismaticJoint, RotationalSpring,
                                   SpringDamper, validate_mechanism)
from clearsim.units import si_text


@dataclass(frozen=True)
class LinkSplit:
    """Where a two-joint link is cut and what moves to its second half (docs/model.md, flexible links)."""

    body: str
    half: str  # the new body, at the second joint
    near: tuple[float, float]  # global location of the first joint at t = 0
    far: tuple[float, float]  # of the second
    moved: frozenset  # the attachments (Attachment.key) nearer the second joint: they go to the new half
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
    """Bodies with exactly two revolute joints, in no prismatic joint, driven by no body driver and at no end of a
    rotational spring: two-force members (a rotational spring loads its bodies with a moment, as the bending
    springs between the segments of a beam link do, so a segment is no two-force member)."""
    revolute, excluded = joint_lists(mechanism)
    bending = {name for force in mechanism.forces if isinstance(force, RotationalSpring) for name in force.bodies}
    return [(name, joints) for name, joints in revolute.items()
            if len(joints) == 2 and name not in excluded and name not in bending]


def _joint_location(mechanism, poses, joint, body: str) -> np.ndarray:
    """Where the joint sits on `body`, globally, at t = 0 (as the assembly reads `at:` or `points:`)."""
    from clearsim.assembly.build import joint_points

    _, _, si, sj = joint_points(poses, joint, ("joints", mechanism.joints.index(joint)))
    return poses.to_global(poses.index[body], si if joint.bodies[0] == body else sj)


def _force_ends(poses, force, body: str) -> list[tuple[int, np.ndarray]]:
    """(end index, global location at t = 0) of each end of a force that acts at a point of `body` (a rotational
    spring acts at none: it stays on the body's named part)."""
    index = poses.index[body]
    if isinstance(force, RotationalSpring):
        return []
    if not isinstance(force, TWO_ENDED):  # a guide friction acts on a joint: no end on a body
        return [(0, poses.point_global(force.point, index, ()))] if getattr(force, "body", None) == body else []
    ends = []
    for end, name in enumerate(force.bodies):
        if name != body:
            continue
        if force.points is not None:
            ends.append((end, poses.to_global(index, poses.named_body_point(body, force.points[end], ())[0])))
        else:
            ends.append((end, poses.point_global(force.at[end] if force.at is not None else None, index, ())))
    return ends


@dataclass(frozen=True)
class Attachment:
    """One reference of the file to a body at a point: a joint's end, a point sensor, a force's end."""

    section: str  # "joints", "sensors" or "forces"
    index: int  # of the entry in its section
    end: int  # of the body in the entry's `bodies` (0: an entry with `body:`)
    location: np.ndarray  # global, at t = 0

    @property
    def key(self) -> tuple[str, int, int]:
        return self.section, self.index, self.end


def attachments(mechanism, poses, body: str) -> list[Attachment]:
    """Every joint end, point sensor and force end on `body`, with where it acts at t = 0."""
    found = [Attachment("joints", k, end, _joint_location(mechanism, poses, joint, body))
             for k, joint in enumerate(mechanism.joints) for end, name in enumerate(joint.bodies) if name == body]
    found += [Attachment("sensors", k, 0, poses.point_global(sensor.point, poses.index[body], ()))
              for k, sensor in enumerate(mechanism.sensors)
              if getattr(sensor, "body", None) == body and hasattr(sensor, "point")]
    found += [Attachment("forces", k, end, where) for k, force in enumerate(mechanism.forces)
              for end, where in _force_ends(poses, force, body)]
    return found


def retarget(document: dict, owners: dict[tuple[str, int, int], str]) -> None:
    """Each attachment (by key) to the body `owners` names."""
    for (section, index, end), owner in owners.items():
        entry = document[section][index]
        if "body" in entry:
            entry["body"] = owner
        else:
            entry["bodies"] = [owner if k == end else name for k, name in enumerate(entry["bodies"])]


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

    moved = frozenset(a.key for a in attachments(mechanism, poses, body) if nearer_far(a.location))
    split = LinkSplit(body, f"{body}_{joints[1].name}_half", tuple(near.tolist()), tuple(far.tolist()), moved,
                      mechanism.body(body).mass, mechanism.body(body).inertia)
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
    retarget(document, dict.fromkeys(split.moved, split.half))
    axis = np.subtract(split.far, split.near)
    document["joints"].append({"name": split.guide, "type": "prismatic", "bodies": [split.body, split.half],
                               "at": point_text(split.near), "axis": (axis / np.linalg.norm(axis)).tolist()})
    document["forces"] = (document.get("forces") or []) + [{
        "type": "spring_damper", "name": split.spring, "bodies": [split.body, split.half],
        "at": [point_text(split.near), point_text(split.far)], "stiffness": 0.0, "damping": 0.0,
        "free_length": si_text(split.length, "length")}]


def point_text(point) -> list[str]:
    return [si_text(coordinate, "length") for coordinate in point]


def flexible_link_names(document: dict, model: str | None = None) -> list[str]:
    """The bodies the file declares flexible (of `model`, "axial" or "beam", when given), in file order."""
    return [body["name"] for body in document.get("bodies") or [] if isinstance(body, dict) and body.get("flexible")
            and (model is None or body["flexible"].get("model") == model)]


def flexible_problems(mechanism) -> list[Problem]:
    """Each flexible body that cannot be expanded: an axial link not with exactly two revolute joints, in a prismatic
    joint or driven, its joints at one point, or its new names taken; a beam link as beam_problems says."""
    revolute, excluded = joint_lists(mechanism)
    problems = []
    for index, body in enumerate(mechanism.bodies):
        if isinstance(body.flexible, BeamFlexibility):
            problems += beam_problems(mechanism, index)
        if not isinstance(body.flexible, AxialFlexibility):
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


def lock_multipliers(locked: dict, locks: list[tuple[str, str]], base_dir) -> list[float]:
    """The multiplier at t = 0 of each lock (driver name, joint) added to a copy of `locked`: a driver holding the
    joint's relative coordinate at its t = 0 value. The model is assembled and its accelerations solved at t = 0, so
    λ is the force (prismatic) or moment (revolute) the joint carries then, its sign as a spring's between the joint's
    two bodies: the tension of an axial spring, the torque T = k (θ_j − θ_i − θ₀) of a rotational one. 0 each when
    that model cannot be assembled."""
    from clearsim.assembly.arrays import for_kernels
    from clearsim.assembly.build import BuildError
    from clearsim.assembly.dynamics import accelerations, generalized_forces
    from clearsim.assembly.hydraulics import add_hydraulic_forces
    from clearsim.assembly.system import assemble

    locked = copy.deepcopy(locked)
    locked["drivers"] = (locked.get("drivers") or []) + [
        {"name": lock, "joint": joint, "motion": {"law": "polynomial", "coefficients": [0.0]}} for lock, joint in locks]
    try:
        system = assemble(validate_mechanism(locked), base_dir)
    except (BuildError, ClearsimError, ValueError):
        return [0.0] * len(locks)
    free = np.zeros(len(system.clearance_joints), np.int64)  # every journal starts in free flight (mode FREE)
    kernel_arrays = for_kernels(system.arrays)
    forces = generalized_forces(kernel_arrays, 0.0, system.q0, system.qd0, free, np.zeros(free.size))[0]
    add_hydraulic_forces(kernel_arrays, system.q0, system.z0, forces)
    multipliers = accelerations(kernel_arrays, 0.0, system.q0, system.qd0, forces, free)[1]
    return [float(multipliers[dict(system.drivers)[lock]]) for lock, _ in locks]


def initial_tensions(document: dict, splits: list[LinkSplit], base_dir) -> list[float]:
    """Each split link's axial tension at t = 0 in the model as given (N): the splits with their slides locked (the
    rigid links again) and each lock's multiplier (the force along the link on the second half is −λ·axis, as a
    spring's tension λ)."""
    locked = copy.deepcopy(document)
    for split in splits:
        split_link(locked, split)
    return lock_multipliers(locked, [(f"{split.guide}_lock", split.guide) for split in splits], base_dir)


def expanded_document(document: dict, mechanism, base_dir) -> dict:
    """A copy of the document with every axial link split, its spring carrying the rigid link's tension at t = 0,
    and every beam link cut into segments, its bend springs carrying the rigid link's moments at t = 0; with beam
    links, every body starts with the velocity of the rigid mechanism at t = 0, so that no segment starts bending
    (the velocity nearest to the file's that the chain allows would) (flexible_problems found none; `base_dir`:
    where the file's tables are)."""
    revolute, _ = joint_lists(mechanism)
    flexible = [body for body in mechanism.bodies if isinstance(body.flexible, AxialFlexibility)]
    splits = [link_split(mechanism, body.name, revolute[body.name]) for body in flexible]
    tensions = initial_tensions(document, splits, base_dir)
    expanded = copy.deepcopy(document)
    for body, split, tension in zip(flexible, splits, tensions):
        split = replace(split, tension=tension)
        split_link(expanded, split)
        set_spring(expanded, split, axial_stiffness(body.flexible, split.length), body.flexible.damping_ratio,
                   body.flexible.stiffness_damping)
    beams = [body.name for body in mechanism.bodies if isinstance(body.flexible, BeamFlexibility)]
    if beams:
        velocities = rigid_velocities(mechanism, base_dir)
        set_velocities(expanded, velocities)
        segments = {body: expand_beam(expanded, mechanism, body, velocities[body]) for body in beams}
        set_start_moments(expanded, mechanism, segments, [split.guide for split in splits], base_dir)
    expanded["joints"] = chain_ordered(expanded["joints"])
    return expanded


def rows_along_the_chain(mechanism):
    """The mechanism of an expanded document (its joints chain_ordered), marked so that the assembly places each
    joint's constraint rows together in that order (assembly/build.py)."""
    mechanism._rows_along_the_chain = True
    return mechanism


def chain_ordered(joints: list[dict]) -> list[dict]:
    """The joints ordered along the chain: the bodies numbered by reverse Cuthill–McKee over "shares a joint", from
    the end where the file's first joint is, each joint at the highest number of its bodies (file order among
    equals). The constraint rows of joints that share a body then lie near each other in their groups (pins,
    offsets, angles: assembly/arrays.py), and each joint's rows together in the factor (rows_along_the_chain), so
    the envelope of S = Φ_q M⁻¹ Φ_qᵀ, which the Cholesky factor of every right-hand side fills (assembly/dynamics.py),
    narrows; the split links' and beam segments' joints, appended by
    the expansion, would otherwise reach back across all the rows (docs/performance.md, "Stiff models")."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    from clearsim.assembly.build import GROUND_NAME

    ends = [[body for body in joint["bodies"] if body != GROUND_NAME] for joint in joints]
    bodies = list(dict.fromkeys(body for pair in ends for body in pair))
    if not bodies:
        return list(joints)
    number = {body: k for k, body in enumerate(bodies)}
    shared = np.zeros((len(bodies), len(bodies)), np.int8)
    for pair in ends:
        shared[np.ix_([number[b] for b in pair], [number[b] for b in pair])] = 1
    order = list(reverse_cuthill_mckee(csr_matrix(shared), symmetric_mode=True))
    place = {bodies[k]: position for position, k in enumerate(order)}
    if ends and ends[0] and max(place[body] for body in ends[0]) >= len(bodies) / 2:
        place = {body: len(bodies) - 1 - position for body, position in place.items()}  # numbered from the other end
    last = [max((place[body] for body in pair), default=-1) for pair in ends]
    return [joints[k] for k in sorted(range(len(joints)), key=last.__getitem__)]


# --- the beam element (rigid finite element method) ------------------------------------------------------------

FIRST_CANTILEVER_ROOT = 1.8751040687  # β₁L of a clamped-free Euler–Bernoulli beam
OUTSIDE_TOLERANCE = 1e-6  # × L: how far beyond the axis's ends a point may lie and still count as on the link


@dataclass(frozen=True)
class BeamLayout:
    """A beam link's axis at t = 0 and its cut into n elements of length Δ = L/n (segments between element middles)."""

    body: str
    start: np.ndarray  # global, the axis's first end
    direction: np.ndarray  # unit vector from the first end to the second
    length: float  # L
    elements: int  # n

    @property
    def cuts(self) -> np.ndarray:
        """Arc lengths of the hinges: the element middles (k + 1/2) Δ."""
        return (np.arange(self.elements) + 0.5) * self.length / self.elements

    @property
    def edges(self) -> np.ndarray:
        """Arc lengths bounding the n + 1 segments: 0, the cuts, L."""
        return np.concatenate([[0.0], self.cuts, [self.length]])

    def arc_length(self, point) -> float:
        return float(np.dot(np.asarray(point, float) - self.start, self.direction))

    def distance_from_axis(self, point) -> float:
        relative = np.asarray(point, float) - self.start
        return abs(float(relative[0] * self.direction[1] - relative[1] * self.direction[0]))

    def segment_of(self, point) -> int:
        return int(np.searchsorted(self.cuts, self.arc_length(point)))

    def on_axis(self, arc_length: float) -> np.ndarray:
        return self.start + arc_length * self.direction


def _axis_end(mechanism, poses, body: str, reference, path) -> np.ndarray:
    """An axis end, globally at t = 0: a point named on the body, a named global point or [x, y]."""
    if isinstance(reference, str) and reference in mechanism.body(body).points:
        return poses.to_global(poses.index[body], mechanism.body(body).points[reference])
    return poses.point_global(reference, poses.index[body], path)


def beam_layout(mechanism, poses, body: str) -> BeamLayout | None:
    """The layout of a beam link: its `axis:`, or its first and last joints; None without two distinct ends."""
    flexibility = mechanism.body(body).flexible
    if flexibility.axis is not None:
        index = next(i for i, b in enumerate(mechanism.bodies) if b.name == body)
        ends = [_axis_end(mechanism, poses, body, reference, ("bodies", index, "flexible", "axis", k))
                for k, reference in enumerate(flexibility.axis)]
    else:
        joints = [a.location for a in attachments(mechanism, poses, body) if a.section == "joints"]
        if len(joints) < 2:
            return None
        ends = [joints[0], joints[-1]]
    axis = ends[1] - ends[0]
    length = float(np.linalg.norm(axis))
    if length < 1e-9:
        return None
    return BeamLayout(body, ends[0], axis / length, length, flexibility.segments)


def density_along_axis(mass: float, inertia: float, first: float, last: float) -> tuple[np.ndarray, float]:
    """((a, b, c), M) of the mass along the axis, u ∈ [first, last] (u: arc length from the centre of mass's
    projection), whose mass is m, centre of mass u = 0 and inertia about it ∫ ρ u² du = J: the density
    ρ(u) = a + b u + c u² (kg/m) and M = 0 when that density is positive; otherwise (J below what a positive
    quadratic density gives: a link whose mass sits in a hub) the density a + b u and a concentrated mass M at u = 0."""
    moments = [(last ** (k + 1) - first ** (k + 1)) / (k + 1) for k in range(5)]
    system = np.array([[moments[i + j] for j in range(3)] for i in range(3)])
    quadratic = np.linalg.solve(system, np.array([mass, 0.0, inertia]))
    if lowest_density(quadratic, first, last) > 0.0:
        return quadratic, 0.0
    with_hub = np.array([[moments[0], moments[1], 1.0], [moments[1], moments[2], 0.0], [moments[2], moments[3], 0.0]])
    a, b, hub = np.linalg.solve(with_hub, np.array([mass, 0.0, inertia]))
    return np.array([a, b, 0.0]), float(hub)


def lowest_density(coefficients: np.ndarray, first: float, last: float) -> float:
    """The least value of ρ(u) = a + b u + c u² on [first, last]."""
    a, b, c = coefficients
    candidates = [first, last] + ([-b / (2 * c)] if c != 0 and first < -b / (2 * c) < last else [])
    return min(a + b * u + c * u * u for u in candidates)


def segment_moments(coefficients: np.ndarray, edges: np.ndarray, hub: float = 0.0
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(masses, centres u, inertias about their centres) of the density between consecutive `edges` (u), with the
    concentrated mass `hub` at u = 0 in the segment that holds it."""
    def integral(power: int) -> np.ndarray:
        return sum(c * (edges[1:] ** (j + power + 1) - edges[:-1] ** (j + power + 1)) / (j + power + 1)
                   for j, c in enumerate(coefficients))

    holding = (edges[:-1] <= 0.0) & (0.0 < edges[1:])
    masses = integral(0) + hub * holding
    centres = integral(1) / masses
    return masses, centres, integral(2) - masses * centres ** 2


@dataclass(frozen=True)
class BeamSegments:
    """The segments of a beam link at t = 0 and where its centre of mass lies relative to its axis."""

    layout: BeamLayout
    names: list[str]
    masses: np.ndarray
    centres: np.ndarray  # global centres of mass
    inertias: np.ndarray

    def stiffness(self, flexibility) -> float:
        """k = E I / Δ (N·m/rad)."""
        bending = flexibility.youngs_modulus * flexibility.second_moment_of_area
        return bending * self.layout.elements / self.layout.length

    def damping(self, flexibility) -> float:
        """c = β k, β = stiffness_damping + 2 ζ / ω₁ with ω₁ = (β₁L)² √(E I / (m L³)) the link's first cantilever
        bending mode (N·m·s/rad)."""
        bending = flexibility.youngs_modulus * flexibility.second_moment_of_area
        first_mode = FIRST_CANTILEVER_ROOT ** 2 * math.sqrt(bending / (self.masses.sum() * self.layout.length ** 3))
        proportional = flexibility.stiffness_damping + 2.0 * flexibility.damping_ratio / first_mode
        return proportional * self.stiffness(flexibility)


def beam_segments(mechanism, poses, layout: BeamLayout) -> BeamSegments | None:
    """Segment masses, centres and inertias from the density fitted to the body's m, centre of mass and J; None when
    no positive density of that form gives them. The segment holding the body's first joint keeps its name."""
    body = mechanism.body(layout.body)
    centre = np.asarray(body.position, float)
    along = layout.arc_length(centre)
    coefficients, hub = density_along_axis(body.mass, body.inertia, -along, layout.length - along)
    if lowest_density(coefficients, -along, layout.length - along) < 0.0 or hub < 0.0:
        return None
    masses, centres, inertias = segment_moments(coefficients, layout.edges - along, hub)
    joints = [a.location for a in attachments(mechanism, poses, layout.body) if a.section == "joints"]
    named = layout.segment_of(joints[0] if joints else centre)
    names = [layout.body if k == named else f"{layout.body}_s{k + 1}" for k in range(layout.elements + 1)]
    return BeamSegments(layout, names, masses, centre + np.outer(centres, layout.direction), inertias)


def beam_problems(mechanism, index: int) -> list[Problem]:
    """What stops a beam link's expansion: no axis, an axis end or an attached point outside the link, an inertia no
    positive density along the axis gives, names taken."""
    from clearsim.assembly.build import initial_poses

    body, poses = mechanism.bodies[index], initial_poses(mechanism)
    path = ("bodies", index, "flexible")
    layout = beam_layout(mechanism, poses, body.name)
    if layout is None:
        return [Problem(path, f"a beam link needs an axis of non-zero length: {body.name} has no `axis:` and not two "
                        "joints at different points", "give `axis: [A, B]`, the link's two ends")]
    centre = np.asarray(body.position, float)
    attached = attachments(mechanism, poses, body.name)
    extent = max([np.linalg.norm(a.location - centre) for a in attached]
                 + [math.hypot(*point) for point in body.points.values()], default=0.0)
    problems = [Problem(path + ("axis", k), f"the axis end of {body.name} lies {np.linalg.norm(end - centre):.4g} m "
                        f"from its centre of mass, beyond the link's extent ({extent:.4g} m: its joints and points)",
                        "give the link's two ends, on the link")
                for k, end in enumerate((layout.start, layout.on_axis(layout.length)))
                if body.flexible.axis is not None and np.linalg.norm(end - centre) > extent * (1 + 1e-9) + 1e-12]
    tolerance = OUTSIDE_TOLERANCE * layout.length
    for a in attached:
        along, across = layout.arc_length(a.location), layout.distance_from_axis(a.location)
        if not (-tolerance <= along <= layout.length + tolerance) or across > layout.length:
            problems.append(Problem((a.section, a.index), f"its point on beam link {body.name} lies outside the link: "
                                    f"{along:.4g} m along its axis of length {layout.length:.4g} m, {across:.4g} m off "
                                    "it", f"attach it between the ends of {body.name}'s axis, or give {body.name} an "
                                    "`axis:` that spans it"))
    if problems:
        return problems
    if beam_segments(mechanism, poses, layout) is None:
        uniform = body.mass * layout.length ** 2 / 12.0
        return [Problem(("bodies", index, "inertia"), f"no positive mass distribution along {body.name}'s axis "
                        f"(L = {layout.length:.4g} m) has its mass, centre of mass and inertia {body.inertia:.4g} "
                        "kg·m²", f"give the link's inertia about its centre of mass (a uniform link: m L²/12 = "
                        f"{uniform:.4g} kg·m²) or place its centre of mass nearer the middle of its axis")]
    taken = {b.name for b in mechanism.bodies} | {j.name for j in mechanism.joints} | {f.name for f in mechanism.forces}
    new = [f"{body.name}_{kind}{k + 1}" for kind in ("s", "hinge", "bend") for k in range(layout.elements + 1)]
    clashes = sorted(set(new) & taken)
    return [Problem(path, f"the names {', '.join(clashes)} the beam link's expansion makes are taken",
                    "rename those entries")] if clashes else []


def explicit_centres(document: dict, mechanism, poses, body: str) -> None:
    """Sensors, loads and springs on `body` at its centre of mass (no point given) get that point, globally, so that
    they stay there when the body is cut."""
    centre = point_text(poses.pose(poses.index[body])[0])
    for sensor, entry in zip(mechanism.sensors, document.get("sensors") or []):
        if getattr(sensor, "body", None) == body and hasattr(sensor, "point") and sensor.point is None:
            entry["point"] = centre
    for force, entry in zip(mechanism.forces, document.get("forces") or []):
        if isinstance(force, TWO_ENDED) and body in force.bodies and force.at is None and force.points is None:
            entry["at"] = [point_text(poses.pose(poses.index[name])[0]) for name in force.bodies]
        elif getattr(force, "body", None) == body and force.point is None:
            entry["point"] = centre


def rigid_velocities(mechanism, base_dir) -> dict[str, tuple[float, float, float]]:
    """Each body's (v_x, v_y, ω) at t = 0 in the mechanism as given, its links rigid (made consistent by assembly);
    the file's velocities when that model cannot be assembled."""
    from clearsim.assembly.build import BuildError
    from clearsim.assembly.system import assemble

    try:
        system = assemble(mechanism, base_dir)
    except (BuildError, ClearsimError, ValueError):
        return {b.name: (*b.velocity, b.angular_velocity) for b in mechanism.bodies}
    return {name: tuple(float(v) for v in system.qd0[3 * k:3 * k + 3]) for k, name in enumerate(system.body_names)}


def set_velocities(document: dict, velocities: dict[str, tuple[float, float, float]]) -> None:
    """The bodies of `document` named in `velocities` start with those (v_x, v_y, ω)."""
    for entry in document["bodies"]:
        if entry["name"] in velocities:
            vx, vy, rate = velocities[entry["name"]]
            entry["velocity"] = [si_text(vx, "speed"), si_text(vy, "speed")]
            entry["angular_velocity"] = si_text(rate, "angular_speed")


def expand_beam(document: dict, mechanism, body: str, velocity: tuple[float, float, float]) -> BeamSegments:
    """Replace a beam link (beam_problems found none) by its segments, hinges and rotational springs in `document`;
    they start straight and unstressed, moving as the rigid link with `velocity` (v_x, v_y, ω). Its segments."""
    from clearsim.assembly.build import initial_poses

    poses = initial_poses(mechanism)
    source = mechanism.body(body).model_copy(update={"velocity": velocity[:2], "angular_velocity": velocity[2]})
    segments = beam_segments(mechanism, poses, beam_layout(mechanism, poses, body))
    layout = segments.layout
    explicit_centres(document, mechanism, poses, body)
    retarget(document, {a.key: segments.names[layout.segment_of(a.location)]
                        for a in attachments(mechanism, poses, body)})
    rotation = np.array([[math.cos(source.angle), -math.sin(source.angle)],
                         [math.sin(source.angle), math.cos(source.angle)]])
    parts = []
    for name, mass, centre, inertia in zip(segments.names, segments.masses, segments.centres, segments.inertias):
        arm = centre - np.asarray(source.position, float)
        velocity = np.asarray(source.velocity, float) + source.angular_velocity * np.array([-arm[1], arm[0]])
        local = rotation.T @ arm
        parts.append({"name": name, "mass": si_text(mass, "mass"), "inertia": si_text(inertia, "inertia"),
                      "position": point_text(centre), "angle": si_text(source.angle, "angle"),
                      "velocity": [si_text(v, "speed") for v in velocity],
                      "angular_velocity": si_text(source.angular_velocity, "angular_speed"),
                      "points": {key: point_text(np.asarray(point, float) - local)
                                 for key, point in source.points.items()}})
    position = next(i for i, b in enumerate(document["bodies"]) if b["name"] == body)
    document["bodies"][position:position + 1] = parts
    stiffness, damping = segments.stiffness(source.flexible), segments.damping(source.flexible)
    names = segments.names
    document["joints"] = (document.get("joints") or []) + [
        {"name": f"{body}_hinge{k + 1}", "type": "revolute", "bodies": [names[k], names[k + 1]],
         "at": point_text(layout.on_axis(cut))} for k, cut in enumerate(layout.cuts)]
    document["forces"] = (document.get("forces") or []) + [
        {"type": "rotational_spring", "name": f"{body}_bend{k + 1}", "bodies": [names[k], names[k + 1]],
         "stiffness": si_text(stiffness, "rotational_stiffness"), "damping": si_text(damping, "rotational_damping")}
        for k in range(layout.elements)]
    return segments


def set_start_moments(expanded: dict, mechanism, beams: dict[str, BeamSegments], slides: list[str], base_dir) -> None:
    """Each bend spring of the beam links ({body: its segments}) in `expanded` starts carrying the moment M its hinge
    carries at t = 0 with every hinge and every axial link's slide (`slides`) locked (the rigid mechanism again,
    lock_multipliers): its free angle θ₀ = −M/k (the segments start in line), so T = k (0 − θ₀) = M and the released
    model starts in the rigid one's dynamic equilibrium, its spring energy the beam's strain energy M²/(2k). The
    slides are locked so that the assembly closes the chain as the rigid one does (free, it could close a journal's
    start eccentricity by stretching a stiff axial spring, whose force the hinges would then carry)."""
    bends = [(f"{body}_hinge{k + 1}", f"{body}_bend{k + 1}", segments.stiffness(mechanism.body(body).flexible))
             for body, segments in beams.items() for k in range(segments.layout.elements)]
    joints = [hinge for hinge, _, _ in bends] + slides
    moments = lock_multipliers(expanded, [(f"{joint}_lock", joint) for joint in joints], base_dir)[:len(bends)]
    springs = {force["name"]: force for force in expanded["forces"] if force.get("type") == "rotational_spring"}
    for (_, bend, stiffness), moment in zip(bends, moments):
        springs[bend]["free_angle"] = si_text(-moment / stiffness, "angle")
