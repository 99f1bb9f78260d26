"""Constraint equations Φ(q, t) = 0, their Jacobian Φ_q and the right-hand sides ν, γ (compiled).

Φ_q q̇ = ν = −Φ_t (velocity level) and Φ_q q̈ = γ = −(Φ_q q̇)_q q̇ − 2Φ_qt q̇ − Φ_tt
(acceleration level), Nikravesh 1988 eqs. (3.7)–(3.8); the primitives are described in
clearsim.assembly.arrays.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.arrays import OFF_DIRECTION, OFF_POINT_I, OFF_POINT_J, OFF_VALUE
from clearsim.assembly.kinematics import body_pose, body_rates, frame_point, frame_rotate, frame_velocity, kept_frame
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
def _arms(frame_i, frame_j, p):
    """A_i s_i and A_j s_j (global), the joint points of a row's parameters p = [s_i, s_j, …]."""
    aix, aiy = frame_rotate(frame_i, p[OFF_POINT_I], p[OFF_POINT_I + 1])
    ajx, ajy = frame_rotate(frame_j, p[OFF_POINT_J], p[OFF_POINT_J + 1])
    return aix, aiy, ajx, ajy


@njit(cache=True)
def _offset_terms(frame_i, frame_j, p):
    """w = A_i w̄ and d = P_j − P_i of an offset row with parameters p."""
    xi, yi = frame_point(frame_i, p[OFF_POINT_I], p[OFF_POINT_I + 1])
    xj, yj = frame_point(frame_j, p[OFF_POINT_J], p[OFF_POINT_J + 1])
    wx, wy = frame_rotate(frame_i, p[OFF_DIRECTION], p[OFF_DIRECTION + 1])
    return wx, wy, xj - xi, yj - yi


@njit(cache=True)
def evaluate_constraints(system, t, q, phi):
    """Φ(q, t) into phi."""
    row = 0
    for k in range(system.pin_bodies.shape[0]):
        s = system.pin_points[k]
        xi, yi = frame_point(kept_frame(system, q, system.pin_bodies[k, 0]), s[0], s[1])
        xj, yj = frame_point(kept_frame(system, q, system.pin_bodies[k, 1]), s[2], s[3])
        phi[row] = xi - xj
        phi[row + 1] = yi - yj
        row += 2
    for k in range(system.offset_bodies.shape[0]):
        frame_i = kept_frame(system, q, system.offset_bodies[k, 0])
        frame_j = kept_frame(system, q, system.offset_bodies[k, 1])
        wx, wy, dx, dy = _offset_terms(frame_i, frame_j, system.offset_params[k])
        phi[row] = wx * dx + wy * dy - system.offset_params[k, OFF_VALUE] - prescribed(system, system.offset_law[k], t)[0]
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        thi = body_pose(q, system.angle_bodies[k, 0])[2]
        thj = body_pose(q, system.angle_bodies[k, 1])[2]
        phi[row] = thj - thi - system.angle_value[k] - prescribed(system, system.angle_law[k], t)[0]
        row += 1


@njit(cache=True)
def evaluate_jacobian_blocks(system, q, blocks, bodies):
    """Φ_q in row blocks: blocks[r, s, :] = ∂Φ_r/∂q_b for the row's two bodies b = bodies[r, s] (−1: ground).

    Every row touches at most two bodies, so products with Φ_q cost O(rows), not O(rows × coordinates).
    """
    blocks[:, :, :] = 0.0
    row = 0
    for k in range(system.pin_bodies.shape[0]):
        bi = system.pin_bodies[k, 0]
        bj = system.pin_bodies[k, 1]
        aix, aiy, ajx, ajy = _arms(kept_frame(system, q, bi), kept_frame(system, q, bj), system.pin_points[k])
        for axis in range(2):
            blocks[row + axis, 0, axis] = 1.0
            blocks[row + axis, 1, axis] = -1.0
            bodies[row + axis, 0], bodies[row + axis, 1] = bi, bj
        blocks[row, 0, 2] = -aiy
        blocks[row + 1, 0, 2] = aix
        blocks[row, 1, 2] = ajy
        blocks[row + 1, 1, 2] = -ajx
        row += 2
    for k in range(system.offset_bodies.shape[0]):
        bi = system.offset_bodies[k, 0]
        bj = system.offset_bodies[k, 1]
        frame_i = kept_frame(system, q, bi)
        frame_j = kept_frame(system, q, bj)
        wx, wy, dx, dy = _offset_terms(frame_i, frame_j, system.offset_params[k])
        aix, aiy, ajx, ajy = _arms(frame_i, frame_j, system.offset_params[k])
        bodies[row, 0], bodies[row, 1] = bi, bj
        blocks[row, 0, 0] = -wx
        blocks[row, 0, 1] = -wy
        blocks[row, 1, 0] = wx
        blocks[row, 1, 1] = wy
        # ∂/∂θ_i: (B_i w̄)·d − w·(B_i s_i), with B v = rot90(A v)
        blocks[row, 0, 2] = (-wy * dx + wx * dy) - (wx * -aiy + wy * aix)
        blocks[row, 1, 2] = wx * -ajy + wy * ajx
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        blocks[row, 0, 2] = -1.0
        blocks[row, 1, 2] = 1.0
        bodies[row, 0], bodies[row, 1] = system.angle_bodies[k, 0], system.angle_bodies[k, 1]
        row += 1


@njit(cache=True)
def jacobian_blocks(system, q):
    """(blocks, bodies) of Φ_q at q."""
    m = constraint_count(system)
    blocks = np.empty((m, 2, 3))
    bodies = np.empty((m, 2), np.int64)
    evaluate_jacobian_blocks(system, q, blocks, bodies)
    return blocks, bodies


def dense_jacobian(system, q: np.ndarray) -> np.ndarray:
    """Φ_q as a dense (m, 3 nb) matrix, scattered with numpy from the blocks the solver works on (the assembly's
    Newton steps and checks, tests). Not a kernel: the blocks' kernel is compiled for the loop anyway, and a kernel
    of its own cost a first run ~1.5 s of compiling before the loop's (docs/performance.md, Compile time)."""
    blocks, bodies = jacobian_blocks(system, q)
    jac = np.zeros((blocks.shape[0], q.shape[0]))
    rows, slots = np.nonzero(bodies >= 0)  # the ground (−1) has no columns
    columns = 3 * bodies[rows, slots][:, None] + np.arange(3)
    np.add.at(jac, (rows[:, None], columns), blocks[rows, slots])
    return jac


@njit(cache=True)
def jacobian_times(blocks, bodies, x, out):
    """out = Φ_q x."""
    for row in range(blocks.shape[0]):
        value = 0.0  # summed in a register: out may alias x as far as LLVM knows
        for slot in range(2):
            b = bodies[row, slot]
            if b >= 0:
                value += blocks[row, slot, 0] * x[3 * b] + blocks[row, slot, 1] * x[3 * b + 1] + blocks[row, slot, 2] * x[3 * b + 2]
        out[row] = value


@njit(cache=True)
def jacobian_transpose_times(blocks, bodies, lam, out):
    """out = Φ_qᵀ λ."""
    for i in range(out.shape[0]):
        out[i] = 0.0
    for row in range(blocks.shape[0]):
        for slot in range(2):
            b = bodies[row, slot]
            if b >= 0:
                for c in range(3):
                    out[3 * b + c] += blocks[row, slot, c] * lam[row]


@njit(cache=True)
def clear_band(schur, band):
    """S[i, band[i]:i + 1] = S[band[i]:i + 1, i] = 0 for every row i: what the last schur_complement wrote."""
    for i in range(band.shape[0]):
        for j in range(band[i], i + 1):
            schur[i, j] = 0.0
            schur[j, i] = 0.0


@njit(cache=True)
def schur_complement(system, blocks, bodies):
    """S = Φ_q M⁻¹ Φ_qᵀ from the blocks into system.solve_schur (its leading rows × rows): rows couple only
    through a shared body, so S is summed body by body.

    Row i of S can be nonzero from column band[i] on (system.solve_band: the first row sharing a body with it;
    the rows past these blocks' have band[i] = i and an empty row). Only the band of the last call is cleared and
    only the band is written, so a call costs O(rows × bandwidth), not O(rows²), and S is zero outside the band.
    S, its band and its factor are in the rows' places (arrays.row_place): entry (place[i], place[j]) (solve_place).
    """
    m = blocks.shape[0]
    minv = system.inverse_mass
    nb = minv.shape[0] // 3
    count = system.solve_body_start
    for b in range(nb + 1):
        count[b] = 0
    for row in range(m):
        for slot in range(2):
            if bodies[row, slot] >= 0:
                count[bodies[row, slot] + 1] += 1
    for b in range(nb):
        count[b + 1] += count[b]
    entries = system.solve_entries  # (row, slot) of each block, grouped by body
    filled = system.solve_body_fill
    for b in range(nb):
        filled[b] = count[b]
    for row in range(m):
        for slot in range(2):
            b = bodies[row, slot]
            if b >= 0:
                entries[filled[b], 0], entries[filled[b], 1] = row, slot
                filled[b] += 1
    schur = system.solve_schur
    band = system.solve_band
    clear_band(schur, band)
    for row in range(band.shape[0]):
        band[row] = row
    places = system.solve_place
    for b in range(nb):  # filled[b] ← the first place of the body's rows
        filled[b] = m
        for e in range(count[b], count[b + 1]):
            filled[b] = min(filled[b], places[entries[e, 0]])
    for row in range(m):
        for slot in range(2):
            b = bodies[row, slot]
            if b >= 0:
                place = places[row]
                band[place] = min(band[place], filled[b])
    for b in range(nb):
        for e in range(count[b], count[b + 1]):
            i, si = entries[e, 0], entries[e, 1]
            # Φ_i M⁻¹ once per entry: the products below are (a·m)·b left to right, so the same bits
            ax = blocks[i, si, 0] * minv[3 * b]
            ay = blocks[i, si, 1] * minv[3 * b + 1]
            aw = blocks[i, si, 2] * minv[3 * b + 2]
            for f in range(count[b], e + 1):
                j, sj = entries[f, 0], entries[f, 1]
                total = 0.0
                total += ax * blocks[j, sj, 0]
                total += ay * blocks[j, sj, 1]
                total += aw * blocks[j, sj, 2]
                pi, pj = places[i], places[j]
                schur[pi, pj] += total
                if i != j:
                    schur[pj, pi] += total


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
        aix, aiy, ajx, ajy = _arms(kept_frame(system, q, bi), kept_frame(system, q, bj), system.pin_points[k])
        gamma[row] = aix * wi * wi - ajx * wj * wj
        gamma[row + 1] = aiy * wi * wi - ajy * wj * wj
        row += 2
    for k in range(system.offset_bodies.shape[0]):
        bi = system.offset_bodies[k, 0]
        bj = system.offset_bodies[k, 1]
        p = system.offset_params[k]
        wi = body_rates(qd, bi)[2]
        wj = body_rates(qd, bj)[2]
        frame_i = kept_frame(system, q, bi)
        frame_j = kept_frame(system, q, bj)
        wx, wy, dx, dy = _offset_terms(frame_i, frame_j, p)
        vix, viy = frame_velocity(frame_i, qd, bi, p[OFF_POINT_I], p[OFF_POINT_I + 1])
        vjx, vjy = frame_velocity(frame_j, qd, bj, p[OFF_POINT_J], p[OFF_POINT_J + 1])
        aix, aiy, ajx, ajy = _arms(frame_i, frame_j, p)
        centripetal = wx * (ajx * wj * wj - aix * wi * wi) + wy * (ajy * wj * wj - aiy * wi * wi)
        turning = wi * wi * (wx * dx + wy * dy) - 2.0 * wi * (-wy * (vjx - vix) + wx * (vjy - viy))
        gamma[row] = centripetal + turning + prescribed(system, system.offset_law[k], t)[2]
        row += 1
    for k in range(system.angle_bodies.shape[0]):
        gamma[row] = prescribed(system, system.angle_law[k], t)[2]
        row += 1
