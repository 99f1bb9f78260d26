"""The loop calls its larger kernels by address (clearsim/solver/integrator.py `addressed_kernels`, `loop_kernels`,
`compiled_loop`, docs/performance.md *Compile time*): `advance` has one specialisation, whose kernels (the mode
switch, the projection, the dynamics, the films, the Rosenbrock step, the DOP853 step) come in one object whose fields are function
types, not the dispatchers' own types (which would link those kernels into it and into every kernel it passes them
to), and it compiles nothing else, so arguments of another type fail at once."""

import numpy as np
import pytest
from numba import types, typeof

from clearsim.assembly.arrays import for_kernels
from clearsim.assembly.dynamics import accelerations, dynamics_type, forces_and_accelerations, generalized_forces
from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare, simulate_config
from clearsim.solver import integrator

CRANK = BUNDLED_CONFIG.parent / "slider_crank_flores.yaml"


def test_advance_has_one_specialisation_taking_its_kernels_as_addresses(tmp_path):
    simulate_config(CRANK, ["solver.t_end=1ms"], tmp_path / "run.h5")
    (signature,) = integrator.advance.signatures
    system_type = typeof(for_kernels(prepare(load_mechanism(CRANK, [])).arrays))
    addressed = integrator.addressed_kernels(system_type, integrator.DOPRI5, False)
    assert signature[0] == system_type
    kernels = signature[1]
    assert isinstance(kernels, integrator.LoopKernelsType)
    assert list(kernels.field_dict.values()) == [kind for _, kind in addressed]
    assert all(isinstance(kind, types.FunctionType) for kind in kernels.field_dict.values())
    assert {dynamics_type(system_type), integrator.projection_type(system_type)} <= set(kernels.field_dict.values())
    assert not any(isinstance(kind, (types.FunctionType, integrator.LoopKernelsType)) for kind in signature[2:])
    # every method and films choice packs kernels of that one type
    for method in integrator.METHODS.values():
        for lubricated in (False, True):
            assert integrator.loop_kernels_type(system_type, method, lubricated) == kernels


def _values_of(signature_types):
    """Zero-filled arguments of these numba types (arrays of their dtype and dimensions, zero scalars)."""
    return [np.zeros((0,) * kind.ndim, dtype=kind.dtype.name) if isinstance(kind, types.Array) else 0.0
            for kind in signature_types]


def test_advance_refuses_arguments_of_another_type_instead_of_compiling_them(tmp_path):
    simulate_config(CRANK, ["solver.t_end=1ms"], tmp_path / "run.h5")
    (signature,) = integrator.advance.signatures
    state = _values_of(signature[2:])
    state[0] = state[0].astype(np.float32)  # y of another dtype
    arguments = integrator.loop_arguments(for_kernels(prepare(load_mechanism(CRANK, [])).arrays), integrator.DOPRI5, False,
                                          *state)
    assert len(arguments) == len(signature)
    with pytest.raises(TypeError):
        integrator.compiled_loop(signature[0], integrator.DOPRI5, False, tuple(arguments[2:]))(*arguments)
    assert integrator.advance.signatures == [signature]


def test_the_dynamics_called_by_address_are_the_forces_and_accelerations():
    system = prepare(load_mechanism(CRANK, []))
    arrays = for_kernels(system.arrays)
    modes = np.zeros(system.arrays.clearance_bodies.shape[0], dtype=np.int64)
    speeds = np.zeros(modes.size)
    qdd, lam, applied, damping, contact, friction = forces_and_accelerations(arrays, 0.0, system.q0, system.qd0,
                                                                             system.z0, modes, speeds)
    generalized, *powers = generalized_forces(arrays, 0.0, system.q0, system.qd0, modes, speeds)
    expected_qdd, expected_lam = accelerations(arrays, 0.0, system.q0, system.qd0, generalized, modes)
    assert np.array_equal(qdd, expected_qdd) and np.array_equal(lam, expected_lam)
    assert [applied, damping, contact, friction] == powers
