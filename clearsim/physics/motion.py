"""Prescribed motions and tabulated loads as piecewise polynomials.

Every time law clearsim knows (the stroke law of Meng 2015 eq. 16, constant
speed, a polynomial, a CSV table) becomes one `PiecewisePolynomial`: breakpoints
b_0 < b_1 < … and, on [b_p, b_p+1), s(t) = Σ_k c_pk (t − b_p)^k. The last piece
extends to +∞ and the first one to −∞, so a compiled kernel evaluates any law,
with its first two derivatives, by one routine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

MAX_COEFFICIENTS = 8  # degree 7: enough for a polynomial law and for a cubic spline


@dataclass(frozen=True)
class PiecewisePolynomial:
    breaks: np.ndarray  # (pieces,) start of each piece, increasing
    coefficients: np.ndarray  # (pieces, MAX_COEFFICIENTS), lowest power first

    def __call__(self, t, derivative: int = 0):
        return np.array([evaluate_piecewise(self.breaks, self.coefficients, 0, len(self.breaks), ti)[derivative]
                         for ti in np.atleast_1d(t)])


def _pad(coefficients) -> np.ndarray:
    row = np.zeros(MAX_COEFFICIENTS)
    row[: len(coefficients)] = coefficients
    return row


def stroke_law(stroke: float, duration: float, start: float = 0.0) -> PiecewisePolynomial:
    """s = S τ²(3 − 2τ), τ = (t − t0)/T on [t0, t0 + T], 0 before, S after (Meng 2015 eq. 16)."""
    cubic = [0.0, 0.0, 3.0 * stroke / duration**2, -2.0 * stroke / duration**3]
    return PiecewisePolynomial(
        np.array([start - 1.0, start, start + duration]),
        np.array([_pad([0.0]), _pad(cubic), _pad([stroke])]),
    )


def polynomial_law(coefficients_from_first_power) -> PiecewisePolynomial:
    """s = Σ_{k≥1} c_k t^k (a constant speed v is the list [v])."""
    if len(coefficients_from_first_power) >= MAX_COEFFICIENTS:
        raise ValueError(f"a polynomial law takes at most {MAX_COEFFICIENTS - 1} coefficients")
    return PiecewisePolynomial(np.array([0.0]), np.array([_pad([0.0, *coefficients_from_first_power])]))


def table_law(times: np.ndarray, values: np.ndarray, relative: bool = True) -> PiecewisePolynomial:
    """Cubic spline through (t_i, s_i), held constant after the last sample; relative: s(t_0) = 0."""
    values = np.asarray(values, dtype=float) - (values[0] if relative else 0.0)
    spline = _spline(np.asarray(times, dtype=float), values)
    pieces = [_pad(spline.c[::-1, p]) for p in range(spline.c.shape[1])]
    breaks = list(spline.x[:-1])
    breaks.append(spline.x[-1])
    pieces.append(_pad([values[-1]]))
    return PiecewisePolynomial(np.array(breaks), np.array(pieces))


def polyline_law(points) -> PiecewisePolynomial:
    """The polyline through [(x, value), …] (x increasing), held at its end values outside them (a valve's opening
    against time, a cushion's open fraction against the stroke)."""
    xs = np.array([x for x, _ in points], dtype=float)
    values = np.array([value for _, value in points], dtype=float)
    slopes = np.diff(values) / np.diff(xs)
    pieces = [_pad([values[0]])] + [_pad([value, slope]) for value, slope in zip(values[:-1], slopes)]
    pieces.append(_pad([values[-1]]))
    return PiecewisePolynomial(np.concatenate([[xs[0] - 1.0], xs]), np.array(pieces))


def _spline(times: np.ndarray, values: np.ndarray):
    """The not-a-knot cubic spline; ValueError when its slopes or coefficients exceed floating-point numbers."""
    from scipy.interpolate import CubicSpline

    with np.errstate(over="ignore", invalid="ignore"):
        finite = np.all(np.isfinite(np.diff(values) / np.diff(times)))
        spline = CubicSpline(times, values, bc_type="not-a-knot") if finite else None
    if spline is None or not np.all(np.isfinite(spline.c)):
        raise ValueError("the samples change faster than floating-point numbers can hold (a slope beyond 1.8e308): "
                         "check the units of the time and value columns")
    return spline


def lagged(law: PiecewisePolynomial, lag: float, samples: int = 1200) -> PiecewisePolynomial:
    """The law seen through a first-order actuator lag, τ ṡ + s = s_law, at rest on the law at its start.

    Solved exactly for the law sampled finely and linear in between, then splined; beyond 20 τ after
    the law's last break the transient (e^-20) is dropped and the lagged law is the particular
    solution Σ_k (−τ)^k s_law^(k) of the law's last piece.
    """
    if lag <= 0.0:
        return law
    breaks, rows = law.breaks, law.coefficients
    constant_start = len(breaks) > 1 and not np.any(rows[0, 1:])
    start = breaks[1] if constant_start else breaks[0]
    end = breaks[-1] + 20.0 * lag if breaks[-1] > start else start + 20.0 * lag
    fine = np.linspace(start, end, 8 * samples + 1)
    driven = law(fine)
    response = _first_order_response(fine, driven, lag)
    coarse = slice(None, None, 8)
    spline = table_law(fine[coarse], response[coarse], relative=False)
    head = PiecewisePolynomial(np.array([start - 1.0]), np.array([_pad([driven[0]])]))
    tail = _steady_lagged_piece(law, lag, end)
    return PiecewisePolynomial(np.concatenate([head.breaks, spline.breaks[:-1], tail.breaks]),
                               np.vstack([head.coefficients, spline.coefficients[:-1], tail.coefficients]))


def _first_order_response(times: np.ndarray, driven: np.ndarray, lag: float) -> np.ndarray:
    """τ y' + y = u for u linear between samples, exact step by step, y(t_0) = u(t_0)."""
    response = np.empty_like(driven)
    response[0] = driven[0]
    for k in range(len(times) - 1):
        step = times[k + 1] - times[k]
        decay = np.exp(-step / lag)
        slope = (driven[k + 1] - driven[k]) / step
        response[k + 1] = decay * response[k] + (1.0 - decay) * (driven[k] - slope * lag) + slope * step
    return response


def _steady_lagged_piece(law: PiecewisePolynomial, lag: float, at: float) -> PiecewisePolynomial:
    """Σ_k (−τ)^k p^(k)(t) of the law's last piece p, re-expanded about `at` (the lag's particular solution)."""
    from numpy.polynomial import Polynomial

    last = Polynomial(law.coefficients[-1])
    steady = sum((((-lag) ** k) * last.deriv(k) for k in range(1, MAX_COEFFICIENTS)), last)
    shifted = steady(Polynomial([at - law.breaks[-1], 1.0]))
    return PiecewisePolynomial(np.array([at]), np.array([_pad(shifted.coef[:MAX_COEFFICIENTS])]))


@njit(cache=True)
def evaluate_piecewise(breaks, coefficients, first, count, t):
    """(s, ṡ, s̈) at t of the polynomial stored in rows first … first+count−1 (binary search for the piece)."""
    low = first
    high = first + count - 1
    while low < high:  # the last piece whose break is <= t (the first piece extends to -inf)
        middle = (low + high + 1) // 2
        if t >= breaks[middle]:
            low = middle
        else:
            high = middle - 1
    piece = low
    x = t - breaks[piece]
    value = 0.0
    rate = 0.0
    curvature = 0.0
    for k in range(MAX_COEFFICIENTS - 1, -1, -1):
        c = coefficients[piece, k]
        curvature = curvature * x + rate
        rate = rate * x + value
        value = value * x + c
    return value, rate, 2.0 * curvature


def concatenate(laws: list[PiecewisePolynomial]):
    """Pack several laws into flat arrays for the kernels: breaks, coefficients, first row, row count."""
    if not laws:
        return np.zeros(1), np.zeros((1, MAX_COEFFICIENTS)), np.zeros(0, np.int64), np.zeros(0, np.int64)
    counts = np.array([len(law.breaks) for law in laws], dtype=np.int64)
    firsts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    return (np.concatenate([law.breaks for law in laws]), np.vstack([law.coefficients for law in laws]),
            firsts, counts)
