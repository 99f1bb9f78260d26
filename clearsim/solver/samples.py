"""Quantities derived from the sampled states: accelerations, multipliers, contact forces, energies (compiled)."""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.constraints import constraint_count
from clearsim.assembly.dynamics import (
    accelerations, constraint_violation, coordinate_count, generalized_forces, stick_row_index,
)
from clearsim.assembly.forces import STICK, clearance_kinematics, contact_force_magnitudes, potential_energy

# columns of the per-joint contact output
C_ECC_X, C_ECC_Y, C_PENETRATION, C_RATE, C_NORMAL, C_FRICTION, C_SLIDING = range(7)
CONTACT_FIELDS = 7


@njit(cache=True)
def evaluate_samples(system, times, states, modes, speeds):
    """(q̈, λ, contact (S, nc, 7), kinetic, potential, violation) at every sample."""
    samples = times.shape[0]
    n = coordinate_count(system)
    m = constraint_count(system)
    nc = system.clearance_bodies.shape[0]
    qdd = np.zeros((samples, n))
    lam = np.zeros((samples, m))
    contact = np.zeros((samples, nc, CONTACT_FIELDS))
    kinetic = np.zeros(samples)
    potential = np.zeros(samples)
    violation = np.zeros(samples)
    for s in range(samples):
        t = times[s]
        q = states[s, :n].copy()
        qd = states[s, n:2 * n].copy()
        generalized = generalized_forces(system, t, q, qd, modes[s], speeds[s])[0]
        qdd[s], multipliers = accelerations(system, t, q, qd, generalized, modes[s])
        lam[s] = multipliers[:m]
        for k in range(nc):
            ex, ey, _, _, penetration, rate, _, _, sliding = clearance_kinematics(system, k, q, qd)
            fn, ft, _ = contact_force_magnitudes(system, k, penetration, rate, sliding, modes[s, k], speeds[s, k])
            if modes[s, k] == STICK:
                ft = -multipliers[stick_row_index(system, modes[s], k)]
            contact[s, k, :] = (ex, ey, penetration, rate, fn, ft, sliding)
        for b in range(system.mass.shape[0]):
            kinetic[s] += 0.5 * (system.mass[b] * (qd[3 * b] ** 2 + qd[3 * b + 1] ** 2)
                                 + system.inertia[b] * qd[3 * b + 2] ** 2)
        potential[s] = potential_energy(system, q)
        violation[s] = constraint_violation(system, t, q)
    return qdd, lam, contact, kinetic, potential, violation
