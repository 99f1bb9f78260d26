"""Every kernel a run needs is compiled once, and what the compile-ahead helper writes is what the run loads
(docs/performance.md, *Compile time*).

numba types a constant argument (`True`, `-1`, `NORMAL`) as a literal and compiles the callee, with its whole
subtree, once for each literal it sees (a `with_sticks` flag passed as a literal once cost ~1 s of compile time). On an empty kernel cache, the helper
(`python -m clearsim.solver.precompile`) compiles its kernels (`kernels_ahead`) first, as it does beside a first run;
a run in a fresh process then compiles the rest and is checked for kernels compiled twice, for kernels the helper
wrote that it compiled itself (the helper's signatures no longer match the run's), and for results that differ from a
run on the suite's own kernel cache.
"""

import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

from clearsim.runner import BUNDLED_CONFIG, simulate_config
from clearsim.solver.precompile import DISABLE_VARIABLE, kernels_ahead

ROOT = Path(__file__).resolve().parents[2]
CRANK = BUNDLED_CONFIG.parent / "slider_crank_flores.yaml"
LUBRICATED = ("defaults.lubrication.viscosity=0.1Pa*s", "defaults.lubrication.length=50mm", "solver.t_end=0.2ms")
FILM_KERNELS = ("clearsim.assembly.forces.film_forces", "clearsim.physics.lubrication.film_force")
BORE_KERNELS = ("clearsim.physics.wear.nearest_bore_point", "clearsim.physics.wear.refined_foot")
WORN = ("joints.J.wear={profile: {cos: [0.03 mm, 0, 0.02 mm], sin: [0.005 mm]}, wall: 2 mm}", "solver.t_end=0.2ms")
SCRIPT = """
import collections, sys
from numba.core import event
with event.install_recorder("numba:compile") as recorder:
    if sys.argv[1] == "helper":
        from clearsim.solver.precompile import compile_ahead
        print(" ".join(compile_ahead()))
    else:
        from clearsim.runner import simulate_config
        simulate_config(sys.argv[1], ["solver.t_end=1ms", *sys.argv[3:]], sys.argv[2])
        print()
counts = collections.Counter()
for _, compile_event in recorder.buffer:
    function = getattr(compile_event.data.get("dispatcher"), "py_func", None)
    if compile_event.is_start and function is not None and str(function.__module__).startswith("clearsim"):
        counts[f"{function.__module__}.{function.__qualname__}"] += 1
print(";".join(f"{name}={count}" for name, count in sorted(counts.items())))
"""

def _datasets(path):
    values = {}
    with h5py.File(path) as result:
        result.visititems(lambda name, item: values.__setitem__(name, item[()])
                          if isinstance(item, h5py.Dataset) and item.dtype.kind in "fiu" else None)
    return values


def _compiled(env, *arguments) -> tuple[list[str], dict[str, int]]:
    """(the helper's list, {kernel: compilations}) of a fresh process."""
    done = subprocess.run([sys.executable, "-c", SCRIPT, *map(str, arguments)], env=env, capture_output=True,
                          text=True, timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    listed, counts = done.stdout.split("\n")[:2]
    return listed.split(), {name: int(count) for name, count in (item.split("=") for item in counts.split(";"))}


def test_helper_then_run_compile_every_kernel_once_with_the_same_results(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty-cache"), **{DISABLE_VARIABLE: "0"})
    ahead = [kernel.py_func.__name__ for kernel, _ in kernels_ahead()]
    listed, by_helper = _compiled(env, "helper")
    assert listed == ahead
    _, by_run = _compiled(env, BUNDLED_CONFIG, tmp_path / "run.h5")
    assert len(by_helper) + len(by_run) > 50 and "clearsim.solver.integrator.advance" in by_run  # an empty cache
    assert [name for name, count in {**by_helper, **by_run}.items() if count > 1] == []
    assert sorted(by_helper.keys() & by_run.keys()) == []  # the run loaded all the helper wrote
    step = "clearsim.solver.rosenbrock.attempt"
    assert step not in by_helper and step not in by_run  # an explicit run compiles no Rosenbrock step (its stand-in)
    high_order = ("clearsim.solver.dop853.attempt", "clearsim.solver.dop853.step", "clearsim.solver.dop853.extend")
    assert [name for name in high_order if name in by_helper or name in by_run] == []  # nor a DOP853 step
    _, by_high_order = _compiled(env, CRANK, tmp_path / "high-order.h5", "solver.method=dop853")
    assert all(by_high_order.get(name) == 1 for name in high_order)  # a DOP853 run compiles it
    assert "clearsim.solver.integrator.advance" not in by_high_order  # for the same loop
    assert [name for name in FILM_KERNELS if name in by_helper or name in by_run] == []  # a dry model: no film kernel
    assert [name for name in BORE_KERNELS if name in by_helper or name in by_run] == []  # no worn bore: no geometry
    _, by_implicit = _compiled(env, CRANK, tmp_path / "implicit.h5", "solver.method=rosenbrock")
    assert by_implicit.get(step) == 1 and "clearsim.solver.integrator.advance" not in by_implicit  # the same loop
    with h5py.File(tmp_path / "implicit.h5") as implicit:
        assert bool(implicit.attrs["kernels_compiled"])  # its step was compiled: the run says so
    _, by_lubricated = _compiled(env, CRANK, tmp_path / "lubricated.h5", *LUBRICATED)
    assert all(by_lubricated.get(name) == 1 for name in FILM_KERNELS)  # a model with oil films compiles them
    assert [name for name, count in by_lubricated.items() if count > 1] == []
    assert "clearsim.solver.integrator.advance" not in by_lubricated  # in the same loop
    with h5py.File(tmp_path / "lubricated.h5") as lubricated:
        assert bool(lubricated.attrs["kernels_compiled"])
    _, by_worn = _compiled(env, BUNDLED_CONFIG, tmp_path / "worn.h5", *WORN)
    assert all(by_worn.get(name) == 1 for name in BORE_KERNELS)  # a model with a worn bore compiles its geometry
    assert "clearsim.solver.integrator.advance" not in by_worn  # for the same loop, which calls it by address

    simulate_config(BUNDLED_CONFIG, ["solver.t_end=1ms"], tmp_path / "suite-cache-filled.h5")  # compiles if cold
    simulate_config(BUNDLED_CONFIG, ["solver.t_end=1ms"], tmp_path / "suite-cache.h5")
    ours, theirs = _datasets(tmp_path / "run.h5"), _datasets(tmp_path / "suite-cache.h5")
    assert ours.keys() == theirs.keys()
    assert [name for name in ours if not np.array_equal(ours[name], theirs[name], equal_nan=True)] == []
    with h5py.File(tmp_path / "run.h5") as cold, h5py.File(tmp_path / "suite-cache.h5") as warm:
        assert bool(cold.attrs["kernels_compiled"]) and not bool(warm.attrs["kernels_compiled"])
