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
def rotate(angle, sx, sy):
    """A(θ) s."""
    c = np.cos(angle)
    s = np.sin(angle)
    return c * sx - s * sy, s * sx + c * sy


@njit(cache=True)
def point_position(q, body, sx, sy):
    """r + A s: global position of a body-fixed point."""
    x, y, angle = body_pose(q, body)
    ax, ay = rotate(angle, sx, sy)
    return x + ax, y + ay


@njit(cache=True)
def point_velocity(q, qd, body, sx, sy):
    """ṙ + θ̇ B s: global velocity of a body-fixed point."""
    x, y, angle = body_pose(q, body)
    vx, vy, omega = body_rates(qd, body)
    ax, ay = rotate(angle, sx, sy)
    return vx - omega * ay, vy + omega * ax


@njit(cache=True)
def add_point_force(generalized, q, body, sx, sy, fx, fy):
    """Add the generalised force of a global force (fx, fy) acting at a body-fixed point."""
    if body == GROUND:
        return
    ax, ay = rotate(q[3 * body + 2], sx, sy)
    generalized[3 * body] += fx
    generalized[3 * body + 1] += fy
    generalized[3 * body + 2] += ax * fy - ay * fx
