"""What a sweep worker process imports: each holds its own copy, so a module it never uses costs every worker."""

import subprocess
import sys


def test_a_sweep_worker_does_not_import_scipy_optimize():
    """scipy.optimize (36 MB resident) serves only the wear kernel's width; it is imported when that is asked for."""
    code = ("import sys, clearsim.sweep.worker, clearsim.sweep.executors, clearsim.runner; "
            "print('scipy.optimize' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"
