"""Planar rigid-body kinematics of body-fixed points in absolute coordinates (compiled).

Body b has q_b = (x_b, y_b, θ_b) at q[3b:3b+3]; the ground is body −1 with q = 0, so a
ground "body-fixed" point is simply a global point. A(θ) rotates body-frame vectors to the
global frame and B(θ) = dA/dθ (Nikravesh, Computer-Aided Analysis of Mechanical Systems, ch. 4).
"""

from __future__ import annotations

import numpy as np
from numba import njit

GROUND = -1


@njit(cache=True)
def body_pose(q, body):
    """(x, y, θ) of a body; the ground is fixed at the origin."""
    if body == GROUND:
        return 0.0, 0.0, 0.0
    return q[3 * body], q[3 * body + 1], q[3 * body + 2]


@njit(cache=True)
def body_rates(qd, body):
    """(ẋ, ẏ, θ̇) of a body; zero for the ground."""
    if body == GROUND:
        return 0.0, 0.0, 0.0
    return qd[3 * body], qd[3 * body + 1], qd[3 * body + 2]


@njit(cache=True)
def body_frame(q, body):
    """(x, y, cos θ, sin θ) of a body, the ground at the origin and unrotated: each helper below takes it, so that a
    kernel evaluating several points or rows of one body computes its cosine and sine once."""
    if body == GROUND:
        return 0.0, 0.0, 1.0, 0.0
    angle = q[3 * body + 2]
    return q[3 * body], q[3 * body + 1], np.cos(angle), np.sin(angle)


@njit(cache=True)
def kept_frame(system, q, body):
    """body_frame with the body's cosine and sine kept in system.frame_trig (θ, cos θ, sin θ a body; arrays.py),
    computed again only when θ changes bit for bit (and at every θ = 0, which compares equal to −0 but has its own sine):
    Φ_q's blocks, γ and the clearance joints' kinematics at one q share them."""
    if body == GROUND:
        return 0.0, 0.0, 1.0, 0.0
    angle = q[3 * body + 2]
    trig = system.frame_trig
    if trig[body, 0] != angle or angle == 0.0:
        trig[body, 0] = angle
        trig[body, 1] = np.cos(angle)
        trig[body, 2] = np.sin(angle)
    return q[3 * body], q[3 * body + 1], trig[body, 1], trig[body, 2]


@njit(cache=True)
def frame_rotate(frame, sx, sy):
    """A(θ) s."""
    c, s = frame[2], frame[3]
    return c * sx - s * sy, s * sx + c * sy


@njit(cache=True)
def frame_point(frame, sx, sy):
    """r + A s: global position of a body-fixed point."""
    ax, ay = frame_rotate(frame, sx, sy)
    return frame[0] + ax, frame[1] + ay


@njit(cache=True)
def frame_velocity(frame, qd, body, sx, sy):
    """ṙ + θ̇ B s: global velocity of a body-fixed point."""
    vx, vy, omega = body_rates(qd, body)
    ax, ay = frame_rotate(frame, sx, sy)
    return vx - omega * ay, vy + omega * ax


@njit(cache=True)
def point_position(q, body, sx, sy):
    """r + A s: global position of a body-fixed point."""
    return frame_point(body_frame(q, body), sx, sy)


@njit(cache=True)
def point_velocity(q, qd, body, sx, sy):
    """ṙ + θ̇ B s: global velocity of a body-fixed point."""
    return frame_velocity(body_frame(q, body), qd, body, sx, sy)


@njit(cache=True)
def add_point_force(generalized, q, body, sx, sy, fx, fy):
    """Add the generalised force of a global force (fx, fy) acting at a body-fixed point."""
    if body == GROUND:
        return
    ax, ay = frame_rotate(body_frame(q, body), sx, sy)
    generalized[3 * body] += fx
    generalized[3 * body + 1] += fy
    generalized[3 * body + 2] += ax * fy - ay * fx


@njit(cache=True)
def line_kinematics(q, qd, bi, bj, sxi, syi, sxj, syj):
    """(ℓ, ℓ̇, u_x, u_y) of the line from point i of body bi to point j of body bj, u its unit vector."""
    frame_i = body_frame(q, bi)
    frame_j = body_frame(q, bj)
    xi, yi = frame_point(frame_i, sxi, syi)
    xj, yj = frame_point(frame_j, sxj, syj)
    vix, viy = frame_velocity(frame_i, qd, bi, sxi, syi)
    vjx, vjy = frame_velocity(frame_j, qd, bj, sxj, syj)
    length = max(np.sqrt((xj - xi) ** 2 + (yj - yi) ** 2), 1e-300)
    ux, uy = (xj - xi) / length, (yj - yi) / length
    return length, ux * (vjx - vix) + uy * (vjy - viy), ux, uy


@njit(cache=True)
def add_global_force(generalized, q, body, px, py, fx, fy):
    """Add a global force (fx, fy) applied at the global point (px, py) of a body."""
    if body == GROUND:
        return
    x, y, _ = body_pose(q, body)
    generalized[3 * body] += fx
    generalized[3 * body + 1] += fy
    generalized[3 * body + 2] += (px - x) * fy - (py - y) * fx
