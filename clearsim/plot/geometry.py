"""The drawable shape of a mechanism: each body's outline and each joint's place, body-fixed.

Joint locations are given in the YAML at t = 0 (a named global point or [x, y] under `at:`, or
named body points under `points:`); as in the assembler, a global location is carried into the
body frame with the body's pose written in the YAML. Placing the body frames at any state q
(the assembled q0, or /bodies/<b>/q of a result) then gives the drawing at that state.

A body is drawn as the convex outline of its joint points and centre of mass: a bar for a
two-point link, a plate for a bell crank. A body that slides in a prismatic joint also gets a
block at the guide.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

GROUND = "ground"
SAME_POINT = 1e-9  # m: points closer than this are one point of the outline


@dataclass(frozen=True)
class JointMark:
    name: str
    kind: str  # revolute | prismatic
    body: str  # the first body (bearing, or guide): the joint is drawn where this body carries it
    point: tuple[float, float]  # on `body`, body frame (global for the ground)
    grounded: bool
    axis: tuple[float, float] | None = None  # prismatic: guide direction in the first body's frame
    clearance: float | None = None  # m, clearance joints only
    other: str = ""  # the second body (journal, or slider)
    other_point: tuple[float, float] = (0.0, 0.0)


@dataclass
class Geometry:
    name: str
    bodies: list[str]  # in the order of the mechanism file (the order of the state vector)
    outlines: dict  # body → (k, 2) body-frame outline, closed when k ≥ 3
    joints: list[JointMark]
    blocks: dict = field(default_factory=dict)  # slider body → (body-frame point, body-frame axis)


def _rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


class _Frames:
    """Initial (YAML) poses: global points at t = 0 ↔ body frames."""

    def __init__(self, mechanism):
        self.mechanism = mechanism
        self.pose = {b.name: (np.asarray(b.position, float), float(b.angle)) for b in mechanism.bodies}
        self.body_points = {b.name: dict(b.points) for b in mechanism.bodies}

    def to_body(self, body: str, point) -> np.ndarray:
        if body == GROUND:
            return np.asarray(point, float)
        r, angle = self.pose[body]
        return _rotation(angle).T @ (np.asarray(point, float) - r)

    def global_point(self, reference, body: str) -> np.ndarray:
        if reference is None:
            return np.zeros(2) if body == GROUND else self.pose[body][0].copy()
        if isinstance(reference, str):
            return np.asarray(self.mechanism.points[reference], float)
        return np.asarray(reference, float)

    def joint_points(self, joint) -> tuple[np.ndarray, np.ndarray]:
        first, second = joint.bodies
        if joint.points is not None:
            return tuple(np.asarray((self.mechanism.points if b == GROUND else self.body_points[b])[p], float)
                         for b, p in zip((first, second), joint.points))
        location = self.global_point(joint.at, first)
        return self.to_body(first, location), self.to_body(second, location)


def _mark(joint, frames: _Frames, defaults) -> JointMark:
    from clearsim.model.resolve import ResolveError, resolve_clearance

    pi, pj = frames.joint_points(joint)
    axis, clearance = None, None
    if joint.type == "prismatic":
        angle = 0.0 if joint.bodies[0] == GROUND else frames.pose[joint.bodies[0]][1]
        axis = tuple(_rotation(angle).T @ np.asarray(joint.axis, float))
    else:
        try:
            parameters = resolve_clearance(joint, defaults)
        except ResolveError:
            parameters = None
        clearance = parameters.clearance if parameters is not None else None
    return JointMark(joint.name, joint.type, joint.bodies[0], tuple(pi), joint.bodies[0] == GROUND, axis,
                     clearance, joint.bodies[1], tuple(pj))


def convex_outline(points: np.ndarray) -> np.ndarray:
    """Distinct points → a segment (2 points) or their convex hull (counter-clockwise)."""
    unique = []
    for p in points:
        if all(np.linalg.norm(p - u) > SAME_POINT for u in unique):
            unique.append(p)
    unique = np.array(sorted(map(tuple, unique)))
    if len(unique) <= 2:
        return unique
    hull = _half_hull(unique) + _half_hull(unique[::-1])
    if len(hull) <= 2:  # collinear: the two extreme points
        return np.array([unique[0], unique[-1]])
    return np.array(hull)


def _cross(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _half_hull(points: np.ndarray) -> list:
    chain: list = []
    for p in points:
        while len(chain) >= 2 and _cross(chain[-1] - chain[-2], p - chain[-2]) <= 0.0:
            chain.pop()
        chain.append(p)
    return chain[:-1]


def mechanism_geometry(mechanism) -> Geometry:
    """The drawable geometry of a validated mechanism (clearsim.model.schema.Mechanism)."""
    frames = _Frames(mechanism)
    marks = [_mark(joint, frames, mechanism.defaults) for joint in mechanism.joints]
    points = {b.name: [np.zeros(2)] for b in mechanism.bodies}
    for mark in marks:
        for body, point in ((mark.body, mark.point), (mark.other, mark.other_point)):
            if body != GROUND:
                points[body].append(np.asarray(point))
    blocks = {}
    for joint, mark in zip(mechanism.joints, marks):
        if mark.kind == "prismatic" and mark.other != GROUND:  # the axis is global at t = 0
            axis_local = _rotation(frames.pose[mark.other][1]).T @ np.asarray(joint.axis, float)
            blocks[mark.other] = (np.asarray(mark.other_point), axis_local)
    outlines = {name: convex_outline(np.array(p)) for name, p in points.items()}
    return Geometry(mechanism.name, [b.name for b in mechanism.bodies], outlines, marks, blocks)


def body_poses(geometry: Geometry, q: np.ndarray) -> dict:
    """{body: (r, θ)} from a state vector ordered like the mechanism's bodies (x, y, θ per body)."""
    q = np.asarray(q, float).reshape(-1, 3)
    return {name: (q[k, :2], float(q[k, 2])) for k, name in enumerate(geometry.bodies)}


def to_global(poses: dict, body: str, point) -> np.ndarray:
    """Body-frame point(s) (…, 2) → global, at the given poses (the ground is the identity)."""
    point = np.asarray(point, float)
    if body == GROUND:
        return point
    r, angle = poses[body]
    return point @ _rotation(angle).T + r


def extent(geometry: Geometry, poses: dict) -> tuple[np.ndarray, np.ndarray]:
    """(lower-left, upper-right) of every outline point and joint at the poses."""
    points = [to_global(poses, b, o) for b, o in geometry.outlines.items()]
    points += [to_global(poses, m.body, m.point)[None, :] for m in geometry.joints]
    stacked = np.vstack(points)
    return stacked.min(axis=0), stacked.max(axis=0)
