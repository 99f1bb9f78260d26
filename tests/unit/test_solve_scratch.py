"""The constrained solve and its scratch (assembly/dynamics.py): exact against a dense solve of the augmented system,
and its cached factor never stale — a factor computed for one q or one set of stick rows is not used for another;
nor the bodies' kept cosines and sines (kinematics.kept_frame) — those of one angle are not used for another."""

import numpy as np

from clearsim.assembly.arrays import for_kernels
from clearsim.assembly.constraints import constraint_count, dense_jacobian, evaluate_acceleration_rhs
from clearsim.assembly.dynamics import accelerations
from clearsim.assembly.forces import CONTACT, STICK, clearance_kinematics
from clearsim.assembly.kinematics import kept_frame
from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare
from tests.unit.test_constraints import mixed_system


def test_accelerations_match_a_dense_solve_of_the_augmented_system():
    system = mixed_system()
    rng = np.random.default_rng(7)
    t, q, qd, force = 0.013, rng.normal(size=9), rng.normal(size=9), rng.normal(size=9)
    qdd, lam = accelerations(system, t, q, qd, force, np.zeros(0, np.int64))
    m = constraint_count(system)
    jac, gamma = dense_jacobian(system, q), np.zeros(m)
    evaluate_acceleration_rhs(system, t, q, qd, gamma)
    mass = np.diag(np.repeat([1.0, 2.0, 3.0], 3) * np.tile([1.0, 1.0, 0.0], 3) + np.repeat([0.1, 0.2, 0.3], 3)
                   * np.tile([0.0, 0.0, 1.0], 3))
    augmented = np.block([[mass, jac.T], [jac, np.zeros((m, m))]])
    expected = np.linalg.solve(augmented, np.concatenate([force, gamma]))
    assert np.allclose(qdd, expected[:9], rtol=1e-10, atol=1e-12)
    assert np.allclose(lam, expected[9:], rtol=1e-10, atol=1e-12)


def _uhv():
    system = prepare(load_mechanism(BUNDLED_CONFIG))
    return system, np.zeros(system.coordinate_count)


def test_a_cached_factor_is_used_only_for_its_own_q_and_stick_rows():
    system, force = _uhv()
    shared = for_kernels(system.arrays)  # one scratch through every call below, as in a run
    q_a, qd = system.q0, system.qd0
    q_b = q_a + 1e-6 * np.random.default_rng(3).normal(size=q_a.size)
    calls = [(q_a, (CONTACT, CONTACT)), (q_b, (CONTACT, CONTACT)), (q_b, (STICK, CONTACT)), (q_b, (STICK, STICK)),
             (q_a, (STICK, STICK)), (q_a, (CONTACT, CONTACT)), (q_a, (CONTACT, CONTACT))]
    for q, modes in calls:
        modes = np.array(modes, np.int64)
        reused = accelerations(shared, 0.001, q, qd, force, modes)
        fresh = accelerations(for_kernels(system.arrays), 0.001, q, qd, force, modes)  # an empty scratch
        for got, want in zip(reused, fresh):
            assert np.array_equal(got, want)
        assert len(reused[1]) == constraint_count(shared) + int(np.sum(modes == STICK))


def _kinematics_of_both_joints(arrays, q, qd):
    return np.array([clearance_kinematics(arrays, k, q, qd) for k in range(2)])


def test_kept_cosines_and_sines_are_used_only_for_their_own_angle():
    system, force = _uhv()
    shared = for_kernels(system.arrays)
    q_a, qd = system.q0, system.qd0
    q_b = q_a + 1e-6 * np.random.default_rng(5).normal(size=q_a.size)
    q_zero, q_minus_zero = q_b.copy(), q_b.copy()
    q_zero[2::3], q_minus_zero[2::3] = 0.0, -0.0  # equal as numbers, their sines are not the same bits
    for q in (q_a, q_b, q_a, q_zero, q_minus_zero, q_zero, q_b):
        reused = accelerations(shared, 0.001, q, qd, force, np.array((CONTACT, CONTACT), np.int64))
        fresh = accelerations(for_kernels(system.arrays), 0.001, q, qd, force, np.array((CONTACT, CONTACT), np.int64))
        for got, want in zip(reused, fresh):
            assert np.array_equal(got, want)
        got, want = _kinematics_of_both_joints(shared, q, qd), _kinematics_of_both_joints(for_kernels(system.arrays), q, qd)
        assert np.array_equal(np.signbit(got), np.signbit(want)) and np.array_equal(got, want)
    for body in range(q_zero.size // 3):  # the sine of −0 after that of +0 was kept: −0
        assert not np.signbit(kept_frame(shared, q_zero, body)[3])
        assert np.signbit(kept_frame(shared, q_minus_zero, body)[3])
