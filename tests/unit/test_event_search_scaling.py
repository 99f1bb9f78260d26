"""The loop's per-step work stays linear in bodies and clearance joints (solver/integrator.py): the event search solves
the constrained dynamics once per sampled state for all the sticking joints' friction reserves (not once per sticking
joint, which made a step O(sticking joints × bodies)), and the event and peak searches interpolate only the two
bodies of the joint they search (O(1) a point, not the whole state's O(bodies)), with the same bits as before."""

import functools

import numpy as np
from numba import njit, objmode, typeof, types

from benchmarks.chain import pendulum_chain
from clearsim.assembly.dynamics import coordinate_count, dry_forces_and_accelerations, dynamics_type
from clearsim.assembly.forces import CONTACT, STICK, clearance_kinematics
from clearsim.model.loader import load_mechanism_text
from clearsim.runner import prepare
from clearsim.solver import integrator as ig
from clearsim.solver.simulate import Run

LINKS, STICKING = 12, 6  # the last 6 of 12 joints with clearance, all sticking
STICTION = "friction: {law: stiction_step, mu_s: 0.2, mu_d: 0.16, v_s: 1e-4 m/s, v_d: 1e-2 m/s}"
DYNAMICS_CALLS = []


@functools.cache
def chain_run() -> Run:
    """The pendulum chain with stiction (exact stick) at its last STICKING joints, at its initial state."""
    text = pendulum_chain(LINKS, STICKING, 0.01).replace("friction: {law: none}", STICTION)
    return Run(prepare(load_mechanism_text(text, "chain.yaml")))


def state(run: Run, mode: int):
    """(kernel arrays, y, stages of a step, modes with every clearance joint in `mode`, speeds)."""
    y = run.y.copy()
    stages = np.random.default_rng(28).normal(scale=1e-3, size=(ig.STAGES, y.shape[0]))
    return run.kernel_arrays, y, stages, np.full_like(run.modes, mode), np.zeros_like(run.speeds)


def _counting(system, t, q, qd, z, modes, speeds):
    with objmode():
        DYNAMICS_CALLS.append(t)
    return dry_forces_and_accelerations(system, t, q, qd, z, modes, speeds)


def _reserves(system, dynamics, y, modes, speeds):
    """(each sticking joint's reserve from the shared solve, from a solve of its own)."""
    frictions = np.zeros(modes.shape[0])
    ig.stick_frictions(system, dynamics, 0.0, y, modes, speeds, frictions)
    shared, alone = np.zeros(modes.shape[0]), np.zeros(modes.shape[0])
    for k in range(modes.shape[0]):
        n = coordinate_count(system)
        kin = clearance_kinematics(system, k, y[:n], y[n:2 * n])
        shared[k] = ig.reserve_left(system, k, kin[4], kin[5], kin[8], modes, speeds, frictions[k])[0]
        alone[k] = ig.friction_reserve(system, dynamics, 0.0, y, modes, speeds, k)[0]
    return shared, alone


def _values(system, dynamics, k, kind, y, stages, h, theta, modes, speeds, scratch, full):
    """(the event search's value at θ, interpolating into scratch; event_value on the whole interpolated state)."""
    return (ig._value_at(system, dynamics, k, kind, 0.0, y, stages, h, theta, modes, speeds, scratch),
            ig.event_value(system, dynamics, k, kind, theta * h, full, modes, speeds, ig.UNSOLVED))


def _earliest(system, dynamics, t, y, stages, h, modes, speeds):
    points = np.empty((ig.SUBDIVISIONS + 1, y.shape[0]))
    frictions = np.zeros((ig.SUBDIVISIONS + 1, modes.shape[0]))
    kinematics = np.empty((ig.EXTENSION_END + 1, modes.shape[0], 3))
    ig.fill_subdivisions(y, stages, h, points)
    return ig.earliest_event(system, dynamics, t, y, y, stages, h, points, kinematics, frictions, modes, speeds,
                             np.empty_like(y))


@functools.cache
def kernels(system_type):
    """(a dynamics that records its calls, the event search over a step, _reserves, _values) compiled with the dynamics
    typed as the loop types it, a function by address (a kernel cached for a dispatcher object would fail to save its
    cache index)."""
    dynamics = dynamics_type(system_type)
    counting = njit(dynamics.signature)(_counting)
    V, IV, F, I, M = types.float64[::1], types.int64[::1], types.float64, types.int64, types.float64[:, ::1]
    search = njit((system_type, dynamics, F, V, M, F, IV, V))(_earliest)
    reserves = njit((system_type, dynamics, V, IV, V))(_reserves)
    values = njit((system_type, dynamics, I, I, V, M, F, F, IV, V, V, V))(_values)
    return counting, search, reserves, values


def test_the_event_search_solves_once_a_point_for_all_sticking_joints():
    system, y, stages, modes, speeds = state(chain_run(), STICK)
    counting, search = kernels(typeof(system))[:2]
    DYNAMICS_CALLS.clear()
    search(system, counting, 0.0, y, np.zeros_like(stages), 1e-6, modes, speeds)  # no motion: no event to refine
    assert len(DYNAMICS_CALLS) == ig.SUBDIVISIONS + 1  # one a point (start, subdivisions, end), not one a joint


def test_the_shared_solve_gives_each_joints_own_friction_reserve_bit_for_bit():
    system, y, _, modes, speeds = state(chain_run(), STICK)
    reserves = kernels(typeof(system))[2]
    shared, alone = reserves(system, dry_forces_and_accelerations, y, modes, speeds)
    assert np.all(np.isfinite(alone))
    assert np.array_equal(shared, alone)


def test_the_searches_interpolate_only_the_joints_two_bodies():
    system, y, stages, modes, speeds = state(chain_run(), CONTACT)
    n = 3 * LINKS
    full = np.empty_like(y)
    ig.interpolate(y, stages, 1e-4, 0.3, full)
    values = kernels(typeof(system))[3]
    for k in range(modes.shape[0]):
        for kind in (ig.NORMAL, ig.TANGENTIAL):
            scratch = np.full_like(y, np.nan)
            value, whole = values(system, dry_forces_and_accelerations, k, kind, y, stages, 1e-4, 0.3, modes, speeds,
                                  scratch, full)
            written = np.flatnonzero(~np.isnan(scratch))
            bodies = [b for b in system_bodies(chain_run(), k) if b >= 0]
            expected = sorted(c for b in bodies for c in (*range(3 * b, 3 * b + 3), *range(n + 3 * b, n + 3 * b + 3)))
            assert written.tolist() == expected  # 12 entries whatever the chain's length
            assert np.array_equal(scratch[written], full[written])
            assert value == whole
        scratch = np.full_like(y, np.nan)
        force = ig.normal_force_at(system, k, y, stages, 1e-4, 0.3, modes, speeds, scratch)
        assert np.count_nonzero(~np.isnan(scratch)) == 12
        assert force == ig.normal_force(system, k, full, modes, speeds)


def system_bodies(run: Run, k: int) -> tuple[int, int]:
    """The (bearing, journal) bodies of clearance joint k."""
    return tuple(int(b) for b in run.system.arrays.clearance_bodies[k])


def test_each_points_kinematics_serve_the_event_values_and_the_peak_force_bit_for_bit():
    """fill_point_kinematics evaluates each joint once a point; the event search and the peak search read it."""
    system, y, stages, modes, speeds = state(chain_run(), CONTACT)
    modes[::2] = STICK  # every other joint sticking (its F_t given), the others sliding
    points = np.empty((ig.SUBDIVISIONS + 1, y.shape[0]))
    ig.fill_subdivisions(y, stages, 1e-4, points)
    y_new = points[ig.SUBDIVISIONS] + 1e-9  # the step's end, a little off the extension's, as after the step
    kinematics = np.full((ig.EXTENSION_END + 1, modes.shape[0], 3), np.nan)
    ig.fill_point_kinematics(system, y_new, points, modes, kinematics)
    states = [*points[:ig.SUBDIVISIONS], y_new, points[ig.SUBDIVISIONS]]
    assert np.array_equal(points[0], y)
    for i, point in enumerate(states):
        for k in range(modes.shape[0]):
            for kind in (ig.NORMAL, ig.TANGENTIAL):
                expected = ig.event_value(system, dry_forces_and_accelerations, k, kind, 0.0, point, modes, speeds, 7.0)
                assert ig.point_event_value(system, k, kind, kinematics[i, k], modes, speeds, 7.0) == expected
            assert ig.point_normal_force(system, k, kinematics[i, k], modes, speeds) == ig.normal_force(
                system, k, point, modes, speeds)
