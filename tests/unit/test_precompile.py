"""The compile-ahead helper: its system type is every system's, it starts only on a cold cache with a second core,
one at a time per cache, and never when switched off (clearsim/solver/precompile.py)."""

import fcntl
import importlib.util
import inspect
import os
import subprocess
import sys

import pytest
from numba import typeof
from numba.core import config

from clearsim.assembly.arrays import for_kernels
from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare, simulate_config
from clearsim.solver import precompile

CRANK = BUNDLED_CONFIG.parent / "slider_crank_flores.yaml"


@pytest.mark.parametrize("config", [BUNDLED_CONFIG, CRANK], ids=["uhv", "crank"])
def test_the_helpers_system_type_is_an_assembled_systems(config):
    system = prepare(load_mechanism(config, []))
    assert typeof(for_kernels(system.arrays)) == precompile.system_type()


def _spawned(monkeypatch, cold=True, cores=2, variable=None):
    started = []
    monkeypatch.setattr(precompile, "_helper", None)
    monkeypatch.setattr(precompile, "cache_is_cold", lambda: cold)
    monkeypatch.setattr(precompile, "_cores", lambda: cores)
    monkeypatch.setattr(precompile.subprocess, "Popen", lambda *args, **kwargs: started.append(args) or _Finished())
    monkeypatch.setattr(precompile.atexit, "register", lambda function: None)
    if variable is None:
        monkeypatch.delenv(precompile.DISABLE_VARIABLE, raising=False)
    else:
        monkeypatch.setenv(precompile.DISABLE_VARIABLE, variable)
    precompile.start_if_cold()
    precompile.start_if_cold()  # once per process
    return len(started)


class _Finished:
    def poll(self):
        return 0


def test_a_helper_that_cannot_start_leaves_the_run_to_compile_alone(monkeypatch):
    monkeypatch.setattr(precompile, "_helper", None)
    monkeypatch.setattr(precompile, "cache_is_cold", lambda: True)
    monkeypatch.setattr(precompile, "_cores", lambda: 2)
    monkeypatch.setattr(precompile.sys, "executable", "")
    monkeypatch.delenv(precompile.DISABLE_VARIABLE, raising=False)
    precompile.start_if_cold()
    assert precompile._helper is None


def test_the_helper_starts_once_on_a_cold_cache_only(monkeypatch):
    assert _spawned(monkeypatch) == 1
    assert _spawned(monkeypatch, cold=False) == 0
    assert _spawned(monkeypatch, cores=1) == 0
    assert _spawned(monkeypatch, variable="0") == 0
    assert _spawned(monkeypatch, variable="1") == 1


def test_the_cache_is_cold_until_a_run_has_compiled_advance(tmp_path):
    probe = "from clearsim.solver import precompile; print(precompile.cache_is_cold())"
    empty = subprocess.run([sys.executable, "-c", probe], env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)),
                           capture_output=True, text=True, timeout=120)
    assert empty.stdout.strip() == "True", empty.stderr
    simulate_config(CRANK, ["solver.t_end=1ms"], tmp_path / "run.h5")  # this process's cache now holds `advance`
    assert not precompile.cache_is_cold()


TINY_KERNEL = """
from numba import njit


@njit(cache=True)
def doubled(x):
    return 2.0 * x
"""


def _tiny_kernel(source):
    """The kernel of `source` as a fresh numba dispatcher (the module imported anew), as a new process has it."""
    spec = importlib.util.spec_from_file_location("tiny_kernel", source)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.doubled


def test_a_kernel_whose_cache_index_is_stale_counts_as_compiled_not_as_loaded(tmp_path, monkeypatch):
    """numba compiles again a kernel whose index was written for other sources (an edit, a `git pull` on an
    editable install with NUMBA_CACHE_DIR set): the index file is there, but the kernel is not cached, and the
    compilation is counted, as on an empty cache; a fresh index is loaded and counts none."""
    # read when a cached kernel is defined; numba's compiler reloads it from the variable when the variable changes
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path / "cache"))
    source = tmp_path / "tiny_kernel.py"
    source.write_text(TINY_KERNEL)
    first = _tiny_kernel(source)
    assert precompile.not_cached(first)
    assert first(1.5) == 3.0 and precompile.compilations([first]) == 1
    loaded = _tiny_kernel(source)
    assert not precompile.not_cached(loaded)
    assert loaded(1.5) == 3.0 and precompile.compilations([loaded]) == 0
    source.write_text(TINY_KERNEL + "# edited after the cache was written\n")
    stale = _tiny_kernel(source)
    assert os.path.exists(stale._cache._cache_file._index_path)
    assert precompile.not_cached(stale)
    assert stale(1.5) == 3.0 and precompile.compilations([stale]) == 1
    assert precompile.compilations([first, loaded, stale]) == 2


def test_a_second_helper_on_the_same_cache_compiles_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path))
    with open(tmp_path / precompile.LOCK_NAME, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)  # the first helper holds it
        assert precompile.compile_ahead() == []


def test_every_kernel_ahead_exists_with_its_number_of_arguments():
    for kernel, signature in precompile.kernels_ahead():
        arguments = getattr(signature, "args", signature)  # a tuple of types, or a Signature with its return type
        assert len(inspect.signature(kernel.py_func).parameters) == len(arguments), kernel.py_func.__name__


class _Compiling:
    """A helper process still running."""

    def poll(self):
        return None


def test_the_run_waits_for_a_kernel_the_helper_is_compiling_and_for_no_other(tmp_path, monkeypatch):
    """Where the two processes meet, the run waits for the helper's kernel (then loads it) instead of compiling it
    too; a kernel the helper is not on, or no helper of this process, is not waited for."""
    import threading

    from clearsim.solver.integrator import project_state, switch_mode

    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(precompile, "_helper", _Compiling())
    busy = tmp_path / precompile.BUSY_NAME
    busy.write_text(precompile._name(project_state))
    assert precompile.wait_while_helper_compiles(switch_mode) < precompile.WAIT_POLL
    moved_on = threading.Timer(0.3, lambda: busy.write_text(precompile._name(switch_mode)))
    moved_on.start()
    assert 0.3 <= precompile.wait_while_helper_compiles(project_state) < 5.0
    moved_on.join()
    monkeypatch.setattr(precompile, "_helper", _Finished())  # a helper that has ended is not waited for
    assert precompile.wait_while_helper_compiles(switch_mode) < precompile.WAIT_POLL
    monkeypatch.setattr(precompile, "_helper", None)
    assert precompile.wait_while_helper_compiles(switch_mode) == 0.0


def test_the_helper_says_which_kernel_it_is_compiling_and_clears_it_at_the_end(tmp_path, monkeypatch):
    seen = []
    kernels = precompile.kernels_ahead()[:2]

    class _Recording:
        def __init__(self, kernel):
            self.py_func = kernel.py_func

        def compile(self, signature):
            seen.append((tmp_path / precompile.BUSY_NAME).read_text())

    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(precompile, "kernels_ahead", lambda: [(_Recording(k), s) for k, s in kernels])
    assert precompile.compile_ahead() == [k.py_func.__name__ for k, _ in kernels]
    assert seen == [precompile._name(k) for k, _ in kernels]
    assert not (tmp_path / precompile.BUSY_NAME).exists()
