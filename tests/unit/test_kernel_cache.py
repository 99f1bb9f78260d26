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
