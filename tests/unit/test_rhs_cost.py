"""The right-hand side's cheaper paths give what the straightforward formulas give: the accelerations and multipliers
of assembly/dynamics.accelerations against a dense numpy solve of the same M, Φ_q (with the stick rows G) and γ at
random states of the bundled breaker, and the contact force of physics/cylindrical.law_force bit for bit law_state's."""

import numpy as np
import pytest

from clearsim.assembly.constraints import constraint_count, dense_jacobian, evaluate_acceleration_rhs
from clearsim.assembly.dynamics import accelerations
from clearsim.assembly.forces import CONTACT, STICK, stick_row
from clearsim.model.loader import load_mechanism
from clearsim.physics.cylindrical import ELASTIC_LAWS, law_force, law_state
from clearsim.runner import BUNDLED_CONFIG, prepare
from tests.unit.test_banded_solve import Scratch


def dense_accelerations(system, t, q, qd, force, modes):
    """(q̈, λ) of M q̈ + Aᵀ λ = Q, A q̈ = γ by numpy: A = [Φ_q; G of each sticking joint], γ = [γ_Φ; −Ġq̇],
    λ = S⁻¹ (A M⁻¹ Q − γ) with S = A M⁻¹ Aᵀ dense."""
    minv = system.inverse_mass
    m = constraint_count(system.system)
    rows = [dense_jacobian(system.system, q)]
    gamma = np.zeros(m)
    evaluate_acceleration_rhs(system.system, t, q, qd, gamma)
    gammas = [gamma]
    for k in np.flatnonzero(modes == STICK):
        bearing_block, journal_block, curvature = stick_row(system.system, k, q, qd)
        row = np.zeros(q.size)
        for body, block in zip(system.clearance_bodies[k], (bearing_block, journal_block)):
            if body >= 0:
                row[3 * body:3 * body + 3] += block
        rows.append(row[None, :])
        gammas.append(np.array([-curvature]))
    jac, gamma = np.vstack(rows), np.concatenate(gammas)
    lam = np.linalg.solve(jac @ np.diag(minv) @ jac.T, jac @ (minv * force) - gamma)
    return minv * (force - jac.T @ lam), lam


@pytest.mark.parametrize("modes", [(CONTACT, CONTACT), (STICK, CONTACT), (CONTACT, STICK), (STICK, STICK)])
def test_accelerations_are_the_dense_solve_at_random_breaker_states(modes):
    system = prepare(load_mechanism(BUNDLED_CONFIG))
    scratch = Scratch(system.arrays)
    rng = np.random.default_rng(28)
    modes = np.array(modes, np.int64)
    for _ in range(5):
        q = system.q0 + 1e-3 * rng.normal(size=system.q0.size)
        qd = rng.normal(size=q.size)
        force = 100.0 * rng.normal(size=q.size)
        qdd, lam = accelerations(scratch.system, 0.01, q, qd, force, modes)
        expected_qdd, expected_lam = dense_accelerations(scratch, 0.01, q, qd, force, modes)
        assert np.max(np.abs(qdd - expected_qdd)) <= 1e-12 * np.max(np.abs(expected_qdd))
        assert np.max(np.abs(lam - expected_lam)) <= 1e-12 * np.max(np.abs(expected_lam))


@pytest.mark.parametrize("law", sorted(ELASTIC_LAWS.values()))
def test_law_force_is_law_state_force_bit_for_bit(law):
    stiffness, exponent, clearance = 1.205e12, 1.5, 1e-5
    for penetration in (-1e-6, 0.0, 1e-12, 3e-9, 2e-7, 1e-5, 4e-4):
        assert law_force(law, penetration, stiffness, exponent, clearance) == law_state(
            law, penetration, stiffness, exponent, clearance)[0]
