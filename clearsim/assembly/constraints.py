"""Constraint equations Φ(q, t) = 0, their Jacobian Φ_q and the right-hand sides ν, γ (compiled).

Φ_q q̇ = ν = −Φ_t (velocity level) and Φ_q q̈ = γ = −(Φ_q q̇)_q q̇ − 2Φ_qt q̇ − Φ_tt
(acceleration level), Nikravesh 1988 eqs. (3.7)–(3.8); the primitives are described in
clearsim.assembly.arrays.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.arrays import OFF_DIRECTION, OFF_POINT_I, OFF_POINT_J, OFF_VALUE
from clearsim.assembly.kinematics import body_pose, body_rates, point_position, point_velocity, rotate
from clearsim.physics.motion import evaluate_piecewise


@njit(cache=True)
def constraint_count(system):
    return 2 * system.pin_bodies.shape[0] + system.offset_bodies.shape[0] + system.angle_bodies.shape[0]


@njit(cache=True)
def prescribed(system, law, t):
    """(s, ṡ, s̈) of a constraint's time law; zero when the row is not driven."""
    if law < 0:
        return 0.0, 0.0, 0.0
    return evaluate_piecewise(system.law_breaks, system.law_coefficients,
                              system.law_first[law], system.law_count[law], t)


@njit(cache=True)
def _arms(q, bi, bj, p):
    """A_i s_i and A_j s_j (global), the joint points of a row's parameters p = [s_i, s_j, …]."""
    aix, aiy = rotate(body_pose(q, bi)[2], p[OFF_POINT_I], p[OFF_POINT_I + 1])
    ajx, ajy = rotate(body_pose(q, bj)[2], p[OFF_POINT_J], p[OFF_POINT_J + 1])
    return aix, aiy, ajx, ajy


@njit(cache=True)
def _offset_terms(system, k, q):
    """w = A_i w̄ and d = P_j − P_i of offset row k."""
    bi = system.offset_bodies[k, 0]
    bj = system.offset_bodies[k, 1]
    p = system.offset_params[k]
    xi, yi = point_position(q, bi, p[OFF_POINT_I], p[OFF_POINT_I + 1])
    xj, yj = point_position(q, bj, p[OFF_POINT_J], p[OFF_POINT_J + 1])
    wx, wy = rotate(body_pose(q, bi)[2], p[OFF_DIRECTION], p[OFF_DIRECTION + 1])
    return wx, wy, xj - xi, yj - yi


@njit(cache=True)
def evaluate_constraints(system, t, q, phi):
    """Φ(q, t) into phi."""
    row = 0
    for k in range(system.pin_bodies.shape[0]):
        s = system.pin_points[k]
        xi, yi = point_position(q, system.pin_bodies[k, 0], s[0], s[1])
        xj, yj = point_position(q, system.pin_bodies[k, 1], s[2], s[3])
        phi[row] = xi - xj
        phi[row + 1] = yi - yj
        row += 2
    for k in range(system.offset_bodies.shape[0]):
        wx, wy, dx, dy = _offset_terms(system, k, q)
        phi[row] = wx * dx + wy * dy - system.offset_params[k, OFF_VALUE] - prescribed(system, system.offset_law[k], t)[0]
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        thi = body_pose(q, system.angle_bodies[k, 0])[2]
        thj = body_pose(q, system.angle_bodies[k, 1])[2]
        phi[row] = thj - thi - system.angle_value[k] - prescribed(system, system.angle_law[k], t)[0]
        row += 1


@njit(cache=True)
def _set(jac, row, body, column, value):
    if body >= 0:
        jac[row, 3 * body + column] += value


@njit(cache=True)
def evaluate_jacobian(system, q, jac):
    """Φ_q into jac (zeroed here)."""
    jac[:, :] = 0.0
    row = 0
    for k in range(system.pin_bodies.shape[0]):
        bi = system.pin_bodies[k, 0]
        bj = system.pin_bodies[k, 1]
        aix, aiy, ajx, ajy = _arms(q, bi, bj, system.pin_points[k])
        for axis in range(2):
            _set(jac, row + axis, bi, axis, 1.0)
            _set(jac, row + axis, bj, axis, -1.0)
        _set(jac, row, bi, 2, -aiy)
        _set(jac, row + 1, bi, 2, aix)
        _set(jac, row, bj, 2, ajy)
        _set(jac, row + 1, bj, 2, -ajx)
        row += 2
    for k in range(system.offset_bodies.shape[0]):
        bi = system.offset_bodies[k, 0]
        bj = system.offset_bodies[k, 1]
        wx, wy, dx, dy = _offset_terms(system, k, q)
        aix, aiy, ajx, ajy = _arms(q, bi, bj, system.offset_params[k])
        _set(jac, row, bi, 0, -wx)
        _set(jac, row, bi, 1, -wy)
        _set(jac, row, bj, 0, wx)
        _set(jac, row, bj, 1, wy)
        # ∂/∂θ_i: (B_i w̄)·d − w·(B_i s_i), with B v = rot90(A v)
        _set(jac, row, bi, 2, (-wy * dx + wx * dy) - (wx * -aiy + wy * aix))
        _set(jac, row, bj, 2, wx * -ajy + wy * ajx)
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        _set(jac, row, system.angle_bodies[k, 0], 2, -1.0)
        _set(jac, row, system.angle_bodies[k, 1], 2, 1.0)
        row += 1


@njit(cache=True)
def evaluate_velocity_rhs(system, t, nu):
    """ν = −Φ_t: the prescribed rates ṡ(t) of driven rows, 0 elsewhere."""
    nu[:] = 0.0
    row = 2 * system.pin_bodies.shape[0]
    for k in range(system.offset_bodies.shape[0]):
        nu[row] = prescribed(system, system.offset_law[k], t)[1]
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        nu[row] = prescribed(system, system.angle_law[k], t)[1]
        row += 1


@njit(cache=True)
def evaluate_acceleration_rhs(system, t, q, qd, gamma):
    """γ = −(Φ_q q̇)_q q̇ + s̈(t)."""
    row = 0
    for k in range(system.pin_bodies.shape[0]):
        bi = system.pin_bodies[k, 0]
        bj = system.pin_bodies[k, 1]
        wi = body_rates(qd, bi)[2]
        wj = body_rates(qd, bj)[2]
        aix, aiy, ajx, ajy = _arms(q, bi, bj, system.pin_points[k])
        gamma[row] = aix * wi * wi - ajx * wj * wj
        gamma[row + 1] = aiy * wi * wi - ajy * wj * wj
        row += 2
    for k in range(system.offset_bodies.shape[0]):
        bi = system.offset_bodies[k, 0]
        bj = system.offset_bodies[k, 1]
        p = system.offset_params[k]
        wi = body_rates(qd, bi)[2]
        wj = body_rates(qd, bj)[2]
        wx, wy, dx, dy = _offset_terms(system, k, q)
        vix, viy = point_velocity(q, qd, bi, p[OFF_POINT_I], p[OFF_POINT_I + 1])
        vjx, vjy = point_velocity(q, qd, bj, p[OFF_POINT_J], p[OFF_POINT_J + 1])
        aix, aiy, ajx, ajy = _arms(q, bi, bj, p)
        centripetal = wx * (ajx * wj * wj - aix * wi * wi) + wy * (ajy * wj * wj - aiy * wi * wi)
        turning = wi * wi * (wx * dx + wy * dy) - 2.0 * wi * (-wy * (vjx - vix) + wx * (vjy - viy))
        gamma[row] = centripetal + turning + prescribed(system, system.offset_law[k], t)[2]
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        gamma[row] = prescribed(system, system.angle_law[k], t)[2]
        row += 1
