"""Dormand–Prince 5(4) with its 4th-order continuous extension (compiled).

Coefficients as in Hairer, Nørsett & Wanner, Solving ODEs I, §II.5 and scipy's RK45 (the
dense-output matrix P gives y(t + θh) = y + h Σ_j K_j Σ_p P_jp θ^(p+1)).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.arrays import copy_into
from clearsim.assembly.dynamics import rhs

STAGES = 7
NODES = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0])
MATRIX = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1 / 5, 0.0, 0.0, 0.0, 0.0],
    [3 / 40, 9 / 40, 0.0, 0.0, 0.0],
    [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
])
WEIGHTS = np.array([35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84])
ERROR_WEIGHTS = np.array([-71 / 57600, 0.0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40])
DENSE = np.array([
    [1.0, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
    [0.0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
    [0.0, 127303824393 / 49829197408, -318862633887 / 49829197408, 701980252875 / 199316789632],
    [0.0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
    [0.0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
])


@njit(cache=True)
def accumulate(out, base, coefficients, h, stages, count):
    """out = base + Σ_{j<count} (h a_j) K_j, skipping zero coefficients (no temporaries)."""
    copy_into(out, base)
    for j in range(count):
        if coefficients[j] != 0.0:
            weight = h * coefficients[j]
            for i in range(out.shape[0]):
                out[i] += weight * stages[j, i]


@njit(cache=True, inline="always")
def evaluate_stages(system, dynamics, t, y, h, modes, speeds, stages, matrix, nodes, first, last):
    """stages[s] = f(t + c_s h, y + h Σ_{j<s} a_sj K_j) for s = first … last − 1 (an explicit tableau's rows)."""
    work = np.empty_like(y)
    # nodes at the step's end are evaluated just left of it: a prescribed motion may jump in acceleration
    # exactly there (the end of a stroke), and the step must see the piece it integrates over
    end = np.nextafter(t + h, t)
    for s in range(first, last):
        accumulate(work, y, matrix[s], h, stages, s)
        rhs(system, dynamics, min(t + nodes[s] * h, end), work, modes, speeds, stages[s])


@njit(cache=True, inline="always")
def step(system, dynamics, t, y, f, h, modes, speeds, stages, y_new):
    """One DOPRI5 step from (t, y) with ẏ(t) = f; fills stages (7, ny) and y_new; returns the error vector."""
    copy_into(stages[0], f)
    evaluate_stages(system, dynamics, t, y, h, modes, speeds, stages, MATRIX, NODES, np.int64(1), MATRIX.shape[0])
    accumulate(y_new, y, WEIGHTS, h, stages, WEIGHTS.shape[0])
    rhs(system, dynamics, np.nextafter(t + h, t), y_new, modes, speeds, stages[6])
    error = np.zeros_like(y)
    accumulate(error, error, ERROR_WEIGHTS, h, stages, ERROR_WEIGHTS.shape[0])
    return error


@njit(cache=True, inline="always")
def _scaled_square(error, y, y_new, i, rtol, atol):
    """(error_i/(atol + rtol max(|y_i|, |y_new,i|)))²."""
    scale = atol + rtol * max(abs(y[i]), abs(y_new[i]))
    return (error[i] / scale) ** 2


@njit(cache=True)
def error_norm(error, y, y_new, count, skipped, tail, rtol, atol):
    """RMS of error/(atol + rtol max(|y|, |y_new|)) over the first `count` components and those after the `skipped`
    ones that follow them, but for the last `tail` (the integrated powers, which steer no step, sit between q̇ and the
    element states; the accumulated wear profiles, which steer none either, end the element states)."""
    total = 0.0
    for i in range(count):
        total += _scaled_square(error, y, y_new, i, rtol, atol)
    for i in range(count + skipped, y.shape[0] - tail):
        total += _scaled_square(error, y, y_new, i, rtol, atol)
    return np.sqrt(total / (y.shape[0] - skipped - tail))


@njit(cache=True, inline="always")
def dense_output(y, stages, dense, h, theta, out):
    """y(t + θh) = y + h Σ_j K_j Σ_p dense_jp θ^(p+1) into out (one pass, no temporaries; each element sums its stages
    in order): the continuous extension of a method whose stage weights are the polynomials of `dense`. Inlined, so
    that a method's own table is a constant there, its loops of known length (as fast as a loop written for it)."""
    dense_elements(y, stages, dense, dense_weights(dense, h, theta), 0, out.shape[0], out)


@njit(cache=True, inline="always")
def dense_weights(dense, h, theta):
    """h Σ_p dense_jp θ^(p+1) of each stage j (exactly 0 where the polynomial is)."""
    weights = np.empty(dense.shape[0])
    for j in range(dense.shape[0]):
        weight = 0.0
        power = theta
        for p in range(dense.shape[1]):
            weight += dense[j, p] * power
            power *= theta
        weights[j] = h * weight if weight != 0.0 else 0.0
    return weights


@njit(cache=True, inline="always")
def dense_elements(y, stages, dense, weights, first, end, out):
    """out[i] = y[i] + Σ_j weights_j K_j[i] for first ≤ i < end (weights: dense_weights of the table `dense`, whose
    length bounds the loop), the stages summed in order: the same bits as dense_output's element i."""
    for i in range(first, end):
        value = y[i]
        for j in range(dense.shape[0]):
            if weights[j] != 0.0:
                value += weights[j] * stages[j, i]
        out[i] = value


@njit(cache=True)
def interpolate(y, stages, h, theta, out):
    """DOPRI5's continuous extension y(t + θh) into out (dense_output with DENSE)."""
    dense_output(y, stages, DENSE, h, theta, out)
