"""Ctrl-C during a sweep: finished case files stay intact, the summary is written, a re-run resumes."""

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py

from clearsim.sweep import LocalPool, SweepRequest, plan_sweep, run_sweep
from clearsim.sweep.execute import recovered, tasks_of
from clearsim.sweep.worker import COMPLETE, INTERRUPTED, CaseOutcome, run_case

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
CLEARANCES = "0.05,0.1,0.2,0.3,0.4,0.5,0.6"


def _wait_for_files(folder: Path, count: int, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while len(list(folder.glob("*.h5"))) < count and time.monotonic() < deadline:
        time.sleep(0.05)


def test_ctrl_c_keeps_finished_cases_and_a_rerun_resumes(tmp_path):
    out = tmp_path / "sweep"
    command = [sys.executable, "-m", "clearsim.cli", "sweep", str(SLIDER_CRANK), "--clearance", CLEARANCES,
               "--workers", "2", "-o", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True, cwd=tmp_path)
    _wait_for_files(out, 4)
    os.killpg(process.pid, signal.SIGINT)  # what the terminal does on Ctrl-C: the whole process group
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stdout + stderr
    assert "Traceback" not in stderr and "run the same command again to resume" in stdout
    with (out / "summary.csv").open(newline="") as handle:
        rows = {row["case"]: row for row in csv.DictReader(handle)}
    status = {case: row["status"] for case, row in rows.items()}
    finished = {case for case, state in status.items() if state == "complete"}
    assert finished and set(status.values()) <= {"complete", "interrupted", "not run"}
    for path in out.glob("*.h5"):
        with h5py.File(path) as handle:  # every file is readable; only the finished ones say complete
            assert bool(handle.attrs["complete"]) == (path.stem in finished), (path.name, rows[path.stem], stdout)
    plan = plan_sweep(SweepRequest(SLIDER_CRANK, [], CLEARANCES, out=out), SLIDER_CRANK)
    result = run_sweep(plan, LocalPool(2))
    assert sorted(result.ran) == sorted(set(status) - finished)
    assert result.count("complete") == 8


def test_a_case_finished_as_ctrl_c_came_is_read_back_from_its_complete_file(tmp_path):
    """The race behind a flaky run of the test above: a worker writes its file complete, Ctrl-C comes before its
    outcome reaches the sweep, and the summary called the case not run. `recovered` reads such cases back from
    their files — only complete files of the case's own YAML."""
    plan = plan_sweep(SweepRequest(SLIDER_CRANK, ["solver.t_end=2ms"], "0.1,0.2,0.3", out=tmp_path / "sweep"),
                      SLIDER_CRANK)
    plan.folder.mkdir(parents=True)
    tasks = tasks_of(plan)
    finished = run_case(tasks[0])
    assert finished.state == COMPLETE
    other = tasks[1]
    Path(tasks[0].output).with_name("copy.h5").write_bytes(Path(tasks[0].output).read_bytes())
    Path(tasks[0].output).with_name("copy.h5").replace(other.output)  # complete, but of another case's YAML
    back = recovered(tasks, {other.name: CaseOutcome(other.name, INTERRUPTED, True, "interrupted")})
    assert set(back) == {tasks[0].name}  # the third has no file; the second's file is not its own
    assert back[tasks[0].name].state == COMPLETE
    assert back[tasks[0].name].record.peak_acceleration == finished.record.peak_acceleration
