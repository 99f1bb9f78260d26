"""Quantities derived from a sampled state: accelerations, multipliers, contact forces, energies (compiled).

The integration loop derives them as it writes each sample: a kernel called from Python would load
another copy of the dynamics it calls (memory, docs/performance.md)."""

from __future__ import annotations

from numba import njit

from clearsim.assembly.arrays import CL_CLEARANCE, CL_VISCOSITY, copy_into
from clearsim.assembly.constraints import constraint_count
from clearsim.assembly.dynamics import coordinate_count, element_states
from clearsim.assembly.forces import FREE, STICK, clearance_kinematics, contact_force_magnitudes, potential_energy

# columns of the per-joint contact output; the film's (a lubricated joint's oil film, zero while the dry laws act)
C_ECC_X, C_ECC_Y, C_PENETRATION, C_RATE, C_NORMAL, C_FRICTION, C_SLIDING = range(7)
C_FILM_RADIAL, C_FILM_TANGENTIAL, C_FILM_THICKNESS, C_FILM_ACTIVE = range(7, 11)
CONTACT_FIELDS = 11
E_KINETIC, E_POTENTIAL, E_VIOLATION = range(3)  # columns of the per-sample energies
ENERGY_FIELDS = 3


@njit(cache=True)
def derive_sample(system, dynamics, films, t, state, violation, modes, speeds, qdd, lam, contact, energies):
    """One sample's q̈ and λ into qdd and lam, its contact fields (nc, CONTACT_FIELDS) into contact, and (kinetic,
    potential, violation) into energies; violation: max |Φ| at the state (its projection's), `films` the oil films'
    forces, by address (dynamics.films_kernel)."""
    n = coordinate_count(system)
    m = constraint_count(system)
    q = state[:n].copy()
    qd = state[n:2 * n].copy()
    accelerations, multipliers = dynamics(system, t, q, qd, element_states(system, state).copy(), modes, speeds)[:2]
    copy_into(qdd, accelerations)
    copy_into(lam, multipliers[:m])
    stick_row = m  # the next sticking joint's row (dynamics.stick_row_index, counted along)
    for k in range(system.clearance_bodies.shape[0]):
        ex, ey, _, _, penetration, rate, _, _, sliding = clearance_kinematics(system, k, q, qd)
        fn, ft, _ = contact_force_magnitudes(system, k, penetration, rate, sliding, modes[k], speeds[k])
        if modes[k] == STICK:
            ft = -multipliers[stick_row]
            stick_row += 1
        fields = contact[k]
        fields[C_ECC_X], fields[C_ECC_Y], fields[C_PENETRATION], fields[C_RATE] = ex, ey, penetration, rate
        fields[C_NORMAL], fields[C_FRICTION], fields[C_SLIDING] = fn, ft, sliding
        film_active = modes[k] == FREE and system.clearance_params[k, CL_VISCOSITY] > 0.0
        fields[C_FILM_RADIAL], fields[C_FILM_TANGENTIAL] = 0.0, 0.0
        if film_active:
            fields[C_FILM_RADIAL], fields[C_FILM_TANGENTIAL] = films(system, k, q, qd)[:2]
        fields[C_FILM_THICKNESS] = system.clearance_params[k, CL_CLEARANCE] - (ex * ex + ey * ey) ** 0.5
        fields[C_FILM_ACTIVE] = 1.0 if film_active else 0.0
    kinetic = 0.0
    for b in range(system.mass.shape[0]):
        kinetic += 0.5 * (system.mass[b] * (qd[3 * b] ** 2 + qd[3 * b + 1] ** 2)
                          + system.inertia[b] * qd[3 * b + 2] ** 2)
    energies[E_KINETIC] = kinetic
    energies[E_POTENTIAL] = potential_energy(system, q)
    energies[E_VIOLATION] = violation
