"""The kernels' cache folder is clearsim's, keyed by all compiled sources (clearsim/__init__.py), whatever was
imported first: numba imported before clearsim (a notebook, a test module) once sent every kernel's cache next to
its source file, keyed by that file alone, where an edited callee could leave a caller's stale machine code."""

import os
import subprocess
import sys

import pytest

PROBE = """
import os, sys
if sys.argv[1] == "numba first":
    import numba  # noqa: F401
import clearsim.solver.integrator as integrator
print(os.environ["NUMBA_CACHE_DIR"])
print(integrator.advance._cache._cache_file._index_path)
"""


@pytest.mark.parametrize("order", ["numba first", "clearsim first"])
def test_every_kernel_is_cached_in_clearsims_folder(order):
    environment = {name: value for name, value in os.environ.items() if name != "NUMBA_CACHE_DIR"}
    done = subprocess.run([sys.executable, "-c", PROBE, order], env=environment, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    folder, index = done.stdout.split()
    assert os.path.join("clearsim", "numba") in folder
    assert index.startswith(folder + os.sep)


@pytest.mark.parametrize("configured, expected", [
    ("", os.path.join(os.path.expanduser("~"), ".cache", "clearsim")),  # empty: unset (XDG base directory spec)
    ("relative/cache", os.path.join(os.path.expanduser("~"), ".cache", "clearsim")),  # relative: invalid, ignored
    (os.path.join(os.sep, "srv", "cache"), os.path.join(os.sep, "srv", "cache", "clearsim")),
])
def test_the_cache_home_follows_the_xdg_rules(monkeypatch, configured, expected):
    """An empty or relative XDG_CACHE_HOME once put the kernel and unit caches under ./clearsim of whatever folder a
    run started in."""
    from clearsim import cache_home
    from clearsim.units import _pint_cache_folder

    monkeypatch.setenv("XDG_CACHE_HOME", configured)
    assert str(cache_home()) == expected
    assert str(_pint_cache_folder()) == os.path.join(expected, "pint")
