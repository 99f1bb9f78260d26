"""DOP853's tables (clearsim/solver/dop853.py) on a nonlinear ODE with a closed form: the step of order 8, the
continuous extension written as stage weights (DENSE) of order 7, its error estimates of orders 5 and 3
(tests/validation/test_dop853.py: the method through the whole integration loop)."""

import numpy as np
import pytest

from clearsim.solver import dop853


def kepler(t, y):
    """The two-body problem: nonlinear, non-trivial in every order condition; a circular orbit is its closed form."""
    r = y[:2]
    return np.concatenate([y[2:], -r / np.linalg.norm(r) ** 3])


def orbit(t):
    return np.array([np.cos(t), np.sin(t), -np.sin(t), np.cos(t)])


def stages_of_step(t, y, h):
    """The 16 stage vectors of one step (12 for the solution, f at its end, 3 for the extension) and y_new."""
    k = np.zeros((dop853.STAGES, y.size))
    for s in range(dop853.STAGES):
        k[s] = kepler(t + dop853.C[s] * h, y + h * dop853.A[s, :s] @ k[:s])
    return k, y + h * dop853.B @ k[:dop853.N_STAGES]


def slope(errors):
    """log2 of the ratio of the last two errors, at halved steps."""
    return np.log2(errors[-2] / errors[-1])


STEPS = [0.8, 0.4, 0.2]  # the finest local error 1e-12, well above round-off


def test_the_step_and_its_error_estimates_have_their_orders():
    """Local error of one step O(h⁹); the 5th-order estimate O(h⁶), the 3rd-order one O(h⁴)."""
    local, high, low = [], [], []
    for h in STEPS:
        k, y_new = stages_of_step(0.3, orbit(0.3), h)
        local.append(np.abs(y_new - orbit(0.3 + h)).max())
        high.append(np.abs(h * dop853.E5 @ k[:dop853.N_STAGES + 1]).max())
        low.append(np.abs(h * dop853.E3 @ k[:dop853.N_STAGES + 1]).max())
    assert local[-1] > 1e-13  # precondition: above round-off
    assert slope(local) == pytest.approx(9.0, abs=0.2)
    assert slope(high) == pytest.approx(6.0, abs=0.2)
    assert slope(low) == pytest.approx(4.0, abs=0.2)


@pytest.mark.parametrize("theta", [0.23, 0.5, 0.81])
def test_the_continuous_extension_as_stage_weights_has_order_7(theta):
    """y + h Σ_j K_j Σ_p DENSE_jp θ^(p+1) (the loop's form) against the orbit: local error O(h⁸) inside the step."""
    errors = []
    for h in STEPS:
        k, _ = stages_of_step(0.3, orbit(0.3), h)
        weights = dop853.DENSE @ theta ** np.arange(1, dop853.DENSE.shape[1] + 1)
        errors.append(np.abs(orbit(0.3) + h * weights @ k - orbit(0.3 + theta * h)).max())
    assert errors[-1] > 1e-13
    assert slope(errors) == pytest.approx(8.0, abs=0.2)


def test_the_continuous_extension_meets_the_step_at_both_ends():
    k, y_new = stages_of_step(0.3, orbit(0.3), 0.2)
    at = lambda theta: orbit(0.3) + 0.2 * (dop853.DENSE @ theta ** np.arange(1, 8)) @ k  # noqa: E731
    assert np.abs(at(1.0) - y_new).max() < 1e-14
    assert np.abs(at(0.0) - orbit(0.3)).max() == 0.0
