"""`python -m benchmarks.step_trace --jacobian-every N` hands rosenbrock's evaluate_jacobian a record of the modes
with the two slots it reads and writes after them (the Jacobians taken since, its rhs evaluations): the process ends
with exit code 0, and every sampled Jacobian has all its columns, so the whole system's h·max|λ| is not zero. It
takes the dynamics by address, as the integrator's loop does: a cached kernel compiled for a dispatcher object gets a
new entry in its cache index in every process, and saving that index fails once an earlier process's object is gone
("underlying object has vanished")."""

import re
import subprocess
import sys
from pathlib import Path

import pytest
from numba.core import types

REPOSITORY = Path(__file__).resolve().parents[2]
FLEXIBLE = REPOSITORY / "clearsim" / "configs" / "uhv_breaker_flexible.yaml"
FRICTION = REPOSITORY / "clearsim" / "configs" / "slider_crank_flores_friction.yaml"


def run_step_trace(*arguments: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "benchmarks.step_trace", *arguments], cwd=REPOSITORY,
                          capture_output=True, text=True, timeout=timeout)


def test_the_flexible_breakers_trace_with_jacobians_exits_cleanly():
    result = run_step_trace("--config", str(FLEXIBLE), "--set", "joints.A.clearance=0.1mm",
                            "--set", "joints.J.clearance=0.1mm", "--set", "solver.t_end=5ms", "--jacobian-every", "50")
    assert result.returncode == 0, result.stderr[-2000:]
    assert "free()" not in result.stderr
    sampled = re.search(r"whole-system Jacobian at (\d+) steps: h·max\|λ\| median ([0-9.e+-]+), 90 % ([0-9.e+-]+)",
                        result.stdout)
    assert sampled, result.stdout
    assert int(sampled[1]) > 1
    assert float(sampled[2]) > 0.0 and float(sampled[3]) > 0.0


def test_the_trace_compiles_no_cached_kernel_for_a_dispatcher_object():
    from benchmarks.step_trace import trace
    from clearsim.assembly.dynamics import rhs
    from clearsim.solver.rosenbrock import evaluate_jacobian

    rows, _, stopped = trace(FLEXIBLE, ["solver.t_end=0.2ms"], jacobian_every=5)
    assert stopped is None
    assert any("jac_h_lambda" in row for row in rows)
    for kernel in (rhs, evaluate_jacobian):
        assert kernel.signatures
        assert not any(isinstance(argument, types.Dispatcher) for signature in kernel.signatures
                       for argument in signature), kernel


def test_a_run_that_fails_stops_the_trace_with_the_runs_own_message():
    """The slider-crank's first impact (0.2273 ms) needs steps below a min_step of 2 µs: the run stops there, and so
    does the trace, with the run's steps before it, the run's message and exit code 2 (it looped without end)."""
    from clearsim.errors import SolverError
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare
    from clearsim.solver.simulate import Run

    overrides = ["solver.t_end=3ms", "solver.min_step=2e-6s"]
    run = Run(prepare(load_mechanism(FRICTION, overrides)))
    with pytest.raises(SolverError, match="min_step") as failure:
        for _ in run.chunks():
            pass
    result = run_step_trace("--config", str(FRICTION), *(f"--set={override}" for override in overrides), timeout=120)
    assert result.returncode == 2, result.stderr[-2000:]
    assert f"the trace stops after {run.statistics().steps} steps: {failure.value}" in result.stderr
    assert "Traceback" not in result.stderr
