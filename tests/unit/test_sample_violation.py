"""A sample's recorded constraint violation (`/constraints/violation`, docs/model.md "Stabilisation") is max |Φ(q, t)|
of the very state it records: its projection's last evaluation, not recomputed and not one taken before the
projection's last correction."""

import numpy as np

from clearsim.assembly.arrays import for_kernels
from clearsim.assembly.constraints import constraint_count, evaluate_constraints
from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare
from clearsim.solver.simulate import simulate


def test_each_samples_violation_is_that_of_its_recorded_state():
    system = prepare(load_mechanism(BUNDLED_CONFIG, ["solver.t_end=2ms", "joints.A.clearance=0", "joints.J.clearance=0"]))
    history = simulate(system)
    arrays, n = for_kernels(system.arrays), 3 * len(system.arrays.mass)
    phi = np.empty(constraint_count(arrays))
    recomputed = np.empty(history.chunk.times.size)
    for i, (time, state) in enumerate(zip(history.chunk.times, history.chunk.states)):
        evaluate_constraints(arrays, time, state[:n].copy(), phi)
        recomputed[i] = np.max(np.abs(phi))
    assert history.chunk.times.size == 201
    assert np.all(recomputed <= 1e-13)  # projected (PROJECTION_TOLERANCE)
    assert np.array_equal(history.chunk.violation, recomputed)
