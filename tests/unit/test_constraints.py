"""Constraint kernels against finite differences: Φ_q, ν = −Φ_t and γ = d²Φ/dt² − Φ_q q̈."""

import numpy as np
import pytest

from clearsim.assembly.arrays import (CLEARANCE_COLUMNS, LOAD_COLUMNS, SPRING_COLUMNS, TORSION_COLUMNS, KernelArrays,
                                      SystemArrays, for_kernels)
from clearsim.assembly.constraints import (
    constraint_count, dense_jacobian, evaluate_acceleration_rhs, evaluate_constraints, evaluate_velocity_rhs,
)
from clearsim.assembly.drivelines import DRIVELINE_COLUMNS
from clearsim.physics import motion


def mixed_system() -> KernelArrays:
    """Three bodies with one of each primitive, two of them driven, and a body pinned to ground (as the kernels take it)."""
    law = motion.polynomial_law([0.3, -0.7, 0.2])
    breaks, coefficients, first, count = motion.concatenate([law, motion.stroke_law(0.4, 0.05)])
    return for_kernels(SystemArrays(
        mass=np.array([1.0, 2.0, 3.0]), inertia=np.array([0.1, 0.2, 0.3]), gravity=np.zeros(2),
        pin_bodies=np.array([[-1, 0], [0, 1]]), pin_points=np.array([[0.1, 0.2, -0.3, 0.05], [0.2, -0.1, 0.4, 0.3]]),
        offset_bodies=np.array([[1, 2], [0, 2]]),
        offset_params=np.array([[0.1, 0.3, -0.2, 0.1, 0.6, 0.8, 0.05], [0.0, 0.2, 0.1, 0.0, 1.0, 0.0, 0.3]]),
        offset_law=np.array([-1, 0]),
        angle_bodies=np.array([[1, 2], [-1, 0]]), angle_value=np.array([0.2, 0.1]), angle_law=np.array([-1, 1]),
        law_breaks=breaks, law_coefficients=coefficients, law_first=first, law_count=count,
        clearance_bodies=np.zeros((0, 2), np.int64), clearance_laws=np.zeros((0, 2), np.int64),
        clearance_params=np.zeros((0, CLEARANCE_COLUMNS)),
        load_bodies=np.zeros(0, np.int64), load_params=np.zeros((0, LOAD_COLUMNS)), load_law=np.zeros(0, np.int64),
        spring_bodies=np.zeros((0, 2), np.int64), spring_params=np.zeros((0, SPRING_COLUMNS)),
        torsion_bodies=np.zeros((0, 2), np.int64), torsion_params=np.zeros((0, TORSION_COLUMNS)),
        driveline_kinds=np.zeros((0, 2), np.int64), driveline_bodies=np.zeros((0, 2), np.int64),
        driveline_params=np.zeros((0, DRIVELINE_COLUMNS)), driveline_table=np.zeros((0, 3)),
    ))


def phi(system, t, q):
    out = np.zeros(constraint_count(system))
    evaluate_constraints(system, t, q, out)
    return out


@pytest.fixture
def state():
    rng = np.random.default_rng(4)
    return 0.013, rng.normal(size=9), rng.normal(size=9), rng.normal(size=9)


def test_jacobian_matches_finite_differences(state):
    system = mixed_system()
    t, q, _, _ = state
    jac = dense_jacobian(system, q)
    step = 1e-7
    numeric = np.column_stack([(phi(system, t, q + step * e) - phi(system, t, q - step * e)) / (2 * step)
                               for e in np.eye(9)])
    assert np.allclose(jac, numeric, atol=1e-8)  # central differences: error O(step²) ≈ 1e-14, round-off 1e-9


def test_velocity_and_acceleration_rhs_match_the_second_time_derivative(state):
    system = mixed_system()
    t, q, qd, qdd = state
    m = constraint_count(system)
    jac, nu, gamma = dense_jacobian(system, q), np.zeros(m), np.zeros(m)
    evaluate_velocity_rhs(system, t, nu)
    evaluate_acceleration_rhs(system, t, q, qd, gamma)
    h = 1e-4

    def along(s):  # Φ along the path q(t + s) = q + s q̇ + s²/2 q̈
        return phi(system, t + s, q + s * qd + 0.5 * s * s * qdd)

    first = (along(h) - along(-h)) / (2 * h)
    second = (along(h) - 2 * along(0.0) + along(-h)) / h**2
    assert np.allclose(first, jac @ qd - nu, atol=1e-6)  # dΦ/dt = Φ_q q̇ + Φ_t
    assert np.allclose(second, jac @ qdd - gamma, atol=1e-5)  # d²Φ/dt² = Φ_q q̈ − γ; O(h²) error ≈ 1e-8
