"""Parameter studies: many runs of one mechanism with overrides, in parallel, with figures of merit.

    plan = plan_sweep(SweepRequest(config, clearance="0.01,0.1"), BUNDLED_CONFIG)   # checked, nothing written
    result = run_sweep(plan, LocalPool(workers=2))                                  # files, summary.csv
    result = run_sweep(plan, DaskCluster("tcp://127.0.0.1:8786"))                   # on a Dask cluster

The figures of merit are defined in docs/sweeps.md.
"""

from clearsim.sweep.execute import SweepFailed, SweepInterrupted, SweepResult, case_file, run_sweep
from clearsim.sweep.executors import DaskCluster, LocalPool
from clearsim.sweep.grid import SweepOptionError
from clearsim.sweep.plan import SweepInputError, SweepPlan, SweepRequest, plan_sweep

__all__ = ["DaskCluster", "LocalPool", "SweepFailed", "SweepInputError", "SweepInterrupted", "SweepOptionError", "SweepPlan",
           "SweepRequest", "SweepResult", "case_file", "plan_sweep", "run_sweep"]
