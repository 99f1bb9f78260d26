"""The ROS34PW2 coefficients against the order conditions of Rosenbrock and W-methods (Hairer & Wanner II §IV.7,
Table 7.1; Rang & Angermann 2005), its stability at infinity, and the Hermite continuous extension in DOPRI5's
dense form."""

import numpy as np
import pytest

from clearsim.solver import dopri, rosenbrock as ros


def _tables(weights):
    alpha, gammas, gamma = ros.ALPHA, ros.GAMMAS, ros.GAMMA
    beta = alpha + gammas - gamma * np.eye(ros.STAGES)  # β_ij = α_ij + γ_ij below the diagonal
    return weights, alpha.sum(axis=1), beta, beta.sum(axis=1), gamma


def test_the_solution_weights_meet_the_order_3_conditions():
    b, alpha, beta, beta_sum, gamma = _tables(ros.WEIGHTS)
    assert b.sum() == pytest.approx(1.0, abs=1e-15)
    assert b @ beta_sum == pytest.approx(0.5 - gamma, abs=1e-15)
    assert b @ alpha**2 == pytest.approx(1.0 / 3.0, abs=1e-15)
    assert b @ beta @ beta_sum == pytest.approx(1.0 / 6.0 - gamma + gamma**2, abs=1e-15)


def test_with_any_matrix_in_place_of_the_jacobian_both_weights_keep_order_2():
    """W-method order 2 (Steihaug & Wolfbrandt): Σ b_i α_i = 1/2 and Σ b_i Σ_j<i γ_ij = −γ, whatever J is."""
    for weights in (ros.WEIGHTS, ros.EMBEDDED_WEIGHTS):
        b, alpha, _, _, gamma = _tables(weights)
        assert b.sum() == pytest.approx(1.0, abs=1e-15)
        assert b @ alpha == pytest.approx(0.5, abs=1e-15)
        assert b @ (ros.GAMMAS - gamma * np.eye(ros.STAGES)).sum(axis=1) == pytest.approx(-gamma, abs=1e-15)


def test_the_embedded_weights_are_of_order_2_only_so_their_difference_estimates_the_error():
    b, alpha, _, _, _ = _tables(ros.EMBEDDED_WEIGHTS)
    assert abs(b @ alpha**2 - 1.0 / 3.0) > 0.01


def test_the_method_is_stiffly_accurate_and_l_stable():
    np.testing.assert_allclose(ros.WEIGHTS, ros.ALPHA[-1] + ros.GAMMAS[-1], atol=1e-15)
    stages = ros.ALPHA + ros.GAMMAS
    ones = np.ones(ros.STAGES)

    def stability(z):  # R(z) = 1 + z bᵀ (I − z(α + Γ))⁻¹ 1
        return 1.0 + z * ros.WEIGHTS @ np.linalg.solve(np.eye(ros.STAGES) - z * stages, ones)

    assert abs(stability(-1e12)) < 1e-10
    assert all(abs(stability(z)) <= 1.0 for z in (-0.1, -1.0, -10.0, -1e3, 1j, 10j, -1 + 100j))


def test_the_transformed_coefficients_reproduce_the_method():
    """a = αΓ⁻¹, m = bᵀΓ⁻¹, c = −Γ⁻¹ below the diagonal (HW II (7.4'))."""
    np.testing.assert_allclose(ros.STAGE_MATRIX @ ros.GAMMAS, ros.ALPHA, atol=1e-14)
    np.testing.assert_allclose(ros.SOLUTION @ ros.GAMMAS, ros.WEIGHTS, atol=1e-14)
    np.testing.assert_allclose(ros.ERROR @ ros.GAMMAS, ros.WEIGHTS - ros.EMBEDDED_WEIGHTS, atol=1e-14)
    np.testing.assert_allclose(np.diag(ros.COUPLING), 0.0)


def test_the_hermite_extension_written_as_dopri5_stages_is_the_cubic_through_both_ends():
    rng = np.random.default_rng(1)
    y, y_new, f, f_end = rng.normal(size=(4, 5))
    h = 0.3
    stages = np.zeros((dopri.STAGES, 5))
    ros.hermite_stages(y, y_new, f, f_end, h, stages)
    out = np.empty(5)
    for theta in (0.0, 0.25, 0.5, 1.0):
        dopri.interpolate(y, stages, h, theta, out)
        s = theta
        expected = ((2 * s**3 - 3 * s**2 + 1) * y + (s**3 - 2 * s**2 + s) * h * f
                    + (-2 * s**3 + 3 * s**2) * y_new + (s**3 - s**2) * h * f_end)
        np.testing.assert_allclose(out, expected, rtol=0, atol=1e-13)


def test_lu_solve_solves():
    rng = np.random.default_rng(2)
    matrix = rng.normal(size=(6, 6))
    b = rng.normal(size=6)
    factored, pivots, x = matrix.copy(), np.zeros(6, np.int64), b.copy()
    ros.lu_factor(factored, pivots)
    ros.lu_solve(factored, pivots, x)
    np.testing.assert_allclose(matrix @ x, b, atol=1e-12)


@pytest.mark.parametrize("hg", [1e-9, 1e-6, 1e-3])
def test_the_reduced_solve_solves_the_whole_iteration_matrix(hg):
    """W = I/(hγ) − J with J's first n rows [0 I 0] (f's first n rows are q̇), stiff rows below (|J| up to 1e9, as a
    squeeze film's): reduced_matrix + reduced_solve give W⁻¹ b, the positions eliminated."""
    rng = np.random.default_rng(3)
    n, ny = 4, 11
    jacobian = np.zeros((ny, ny + 1))
    jacobian[n:, :ny] = rng.normal(size=(ny - n, ny)) * np.logspace(0, 9, ny)
    jacobian[:n, n:2 * n] = np.eye(n)
    b = rng.normal(size=ny)
    whole = np.eye(ny) / hg - jacobian[:, :ny]
    matrix, pivots, scratch = np.empty((ny - n, ny - n)), np.zeros(ny - n, np.int64), np.empty(ny - n)
    ros.reduced_matrix(jacobian, hg, n, matrix)
    ros.lu_factor(matrix, pivots)
    u = b.copy()
    ros.reduced_solve(matrix, pivots, jacobian, hg, n, u, scratch)
    np.testing.assert_allclose(u, np.linalg.solve(whole, b), rtol=1e-9, atol=0)
