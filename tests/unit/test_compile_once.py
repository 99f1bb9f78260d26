"""Every kernel a run needs is compiled once (docs/performance.md, *Compile time*).

numba types a constant argument (`True`, `-1`, `NORMAL`) as a literal and compiles the callee, with its whole
subtree, once for each literal it sees; session 4 removed 23 such double compilations, and session 6 found one it had
brought back itself (a `with_sticks` flag, ~1 s of compile time). This compiles a short run on an empty kernel cache
in a fresh process (~20 s) and lists the kernels compiled more than once.
"""

import os
import subprocess
import sys
from pathlib import Path

from clearsim.runner import BUNDLED_CONFIG

SCRIPT = """
import collections, sys
from numba.core import event
with event.install_recorder("numba:compile") as recorder:
    from clearsim.runner import simulate_config
    simulate_config(sys.argv[1], ["solver.t_end=1ms"], sys.argv[2])
counts = collections.Counter()
for _, compile_event in recorder.buffer:
    function = getattr(compile_event.data.get("dispatcher"), "py_func", None)
    if compile_event.is_start and function is not None and str(function.__module__).startswith("clearsim"):
        counts[f"{function.__module__}.{function.__qualname__}"] += 1
print(len(counts), sorted(name for name, count in counts.items() if count > 1))
"""


def test_every_kernel_of_a_run_is_compiled_once(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty-cache"))
    done = subprocess.run([sys.executable, "-c", SCRIPT, str(BUNDLED_CONFIG), str(tmp_path / "run.h5")], env=env,
                          capture_output=True, text=True, timeout=600, cwd=Path(__file__).resolve().parents[2])
    assert done.returncode == 0, done.stderr
    kernels, twice = done.stdout.split(" ", 1)
    assert int(kernels) > 40  # the run did compile its kernels (an empty cache)
    assert twice.strip() == "[]"
