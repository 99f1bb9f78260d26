"""Real sweeps of the Flores slider-crank (4 ms, the first impacts): figures of merit against the ideal
case and a plain `clearsim run`, the local pool against a Dask cluster, resume, and a failing case."""

import csv
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.io.hdf5 import read_attributes
from clearsim.runner import summarize, summary_dataset
from clearsim.sweep import LocalPool, SweepRequest, plan_sweep, run_sweep

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = CONFIGS / "slider_crank_flores.yaml"
SHORT = "solver.t_end=4ms"  # first impacts at 0.23 ms: the largest forces of the 24 ms run are in here
CLEARANCES = "0.25,0.5"
CASES = ["ideal", "clearance-0.25_mm", "clearance-0.5_mm"]
RUN_DEPENDENT = {"wall_time_s", "reused"}
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def read_summary(folder: Path) -> dict[str, dict]:
    with (folder / "summary.csv").open(newline="") as handle:
        return {row["case"]: row for row in csv.DictReader(handle)}


def numbers(row: dict) -> dict:
    return {key: value for key, value in row.items() if key not in RUN_DEPENDENT}


@pytest.fixture(scope="module")
def pool_sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("pool") / "sweep"
    result = invoke("sweep", SLIDER_CRANK, "--set", SHORT, "--clearance", CLEARANCES, "--workers", 2, "-o", out)
    assert result.exit_code == 0, result.output
    return out, result.output


def test_the_sweep_folder_holds_a_file_per_case_the_case_list_and_the_summary(pool_sweep):
    out, output = pool_sweep
    assert sorted(p.name for p in out.iterdir()) == sorted([*(f"{c}.h5" for c in CASES), "cases.json", "summary.csv"])
    assert f"sweep of 3 cases of slider_crank_flores.yaml on 2 local worker processes → {out}" in output
    rows = read_summary(out)
    assert list(rows) == CASES and all(row["status"] == "complete" for row in rows.values())
    assert rows["clearance-0.5_mm"]["clearance"] == "0.5 mm" and rows["clearance-0.5_mm"]["reference"] == "ideal"


def test_peak_acceleration_and_contact_force_grow_with_the_clearance(pool_sweep):
    rows = read_summary(pool_sweep[0])
    ideal, small, large = (rows[c] for c in CASES)
    peak = [float(row["peak_acceleration_m_s2"]) for row in (ideal, small, large)]
    force = [float(row["max_contact_force_N[slider_pin]"]) for row in (small, large)]
    assert peak[0] < peak[1] < peak[2]
    assert force[0] < force[1]
    assert float(small["acceleration_ratio"]) == pytest.approx(peak[1] / peak[0], rel=1e-12)
    shares = sum(float(large[f"{kind}_percent[slider_pin]"]) for kind in ("free", "impact", "contact"))
    assert shares == pytest.approx(100.0)
    # the ideal case is its own reference: ratio 1, no delay, no end error
    assert (float(ideal["acceleration_ratio"]), float(ideal["start_delay_ms"]), float(ideal["end_error_percent"])) == (1, 0, 0)
    assert 0 < float(large["end_error_percent"]) < 5  # the slider lags by a fraction of the 0.5 mm clearance (of a 0.1 m stroke)


def test_the_ideal_case_equals_a_plain_run_of_the_same_config(pool_sweep, tmp_path):
    plain = tmp_path / "plain.h5"
    result = invoke("run", SLIDER_CRANK, "-o", plain, "--set", SHORT, "--set", "joints.slider_pin.clearance=0")
    assert result.exit_code == 0, result.output
    ideal = read_summary(pool_sweep[0])["ideal"]
    summary = summarize(plain)
    assert float(ideal["peak_acceleration_m_s2"]) == summary.peak_acceleration[1]
    assert f"{summary.peak_acceleration[1]:.5g} m/s²" in result.output
    large = read_summary(pool_sweep[0])["clearance-0.5_mm"]
    plain_large = tmp_path / "large.h5"
    invoke("run", SLIDER_CRANK, "-o", plain_large, "--set", SHORT, "--set", "joints.slider_pin.clearance=0.5 mm")
    assert float(large["max_contact_force_N[slider_pin]"]) == summarize(plain_large).peak_contact_force["slider_pin"]


def test_a_dask_cluster_gives_the_same_summary_numbers(pool_sweep, tmp_path):
    distributed = pytest.importorskip("distributed")
    out = tmp_path / "dask"
    with distributed.LocalCluster(processes=True, n_workers=2, threads_per_worker=1, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        result = invoke("sweep", SLIDER_CRANK, "--set", SHORT, "--clearance", CLEARANCES,
                        "--scheduler", cluster.scheduler_address, "-o", out)
    assert result.exit_code == 0, result.output
    assert "on the Dask cluster at tcp://127.0.0.1:" in result.output
    pool, dask = read_summary(pool_sweep[0]), read_summary(out)
    assert {c: numbers(r) for c, r in dask.items()} == {c: numbers(r) for c, r in pool.items()}


def test_a_rerun_runs_only_the_missing_case(pool_sweep, tmp_path):
    out = tmp_path / "resume"
    shutil.copytree(pool_sweep[0], out)
    (out / "clearance-0.25_mm.h5").unlink()
    before = (out / "clearance-0.5_mm.h5").stat().st_mtime_ns
    plan = plan_sweep(SweepRequest(SLIDER_CRANK, [SHORT], CLEARANCES, out=out), SLIDER_CRANK)
    result = run_sweep(plan, LocalPool(2))
    assert result.ran == ["clearance-0.25_mm"]
    assert (out / "clearance-0.5_mm.h5").stat().st_mtime_ns == before
    rows = read_summary(out)
    assert [rows[c]["reused"] for c in CASES] == ["yes", "no", "yes"]
    assert {c: numbers(r) for c, r in rows.items()} == {c: numbers(r) for c, r in read_summary(pool_sweep[0]).items()}
    assert not list(out.glob("*.previous*.h5"))


def held_bytes(path: Path) -> int:
    """The bytes of a result file's datasets as arrays (shape × item size): what it holds, independent of how its
    compressed chunks came out (the number of flushes follows the machine's speed)."""
    sizes = []
    with h5py.File(path, "r") as handle:
        handle.visititems(lambda name, node: sizes.append(node.nbytes) if isinstance(node, h5py.Dataset) else None)
    return sum(sizes)


def kept_sweep(full: Path, tmp_path: Path, keep: str, announced: str) -> Path:
    """The sweep of the full one with `--keep keep`: announced as such, with the full sweep's summary numbers, each
    file flagged with what it holds."""
    out = tmp_path / keep
    result = invoke("sweep", SLIDER_CRANK, "--set", SHORT, "--clearance", CLEARANCES, "--workers", 2, "-o", out,
                    "--keep", keep)
    assert result.exit_code == 0, result.output
    assert announced in result.output
    assert {c: numbers(r) for c, r in read_summary(out).items()} == {c: numbers(r) for c, r in read_summary(full).items()}
    assert all(read_attributes(out / f"{case}.h5")["contents"] == keep for case in CASES)
    return out


def test_keep_summary_gives_the_same_summary_from_smaller_files_and_reuse_follows_what_they_hold(pool_sweep, tmp_path):
    """`--keep summary`: the summary numbers of the full sweep, each file flagged and smaller; a full folder serves
    a `--keep summary` sweep as it is, a summary folder does not serve a full sweep (its files are kept aside)."""
    out = kept_sweep(pool_sweep[0], tmp_path, "summary", "(each file: the summary histories)")
    for case in CASES:
        assert held_bytes(out / f"{case}.h5") < 0.6 * held_bytes(pool_sweep[0] / f"{case}.h5")
    served = tmp_path / "served"
    shutil.copytree(pool_sweep[0], served)
    keep_summary = SweepRequest(SLIDER_CRANK, [SHORT], CLEARANCES, out=served, keep="summary")
    assert run_sweep(plan_sweep(keep_summary, SLIDER_CRANK), LocalPool(2)).ran == []
    everything = run_sweep(plan_sweep(SweepRequest(SLIDER_CRANK, [SHORT], CLEARANCES, out=out), SLIDER_CRANK),
                           LocalPool(2))
    assert sorted(everything.ran) == sorted(CASES)
    assert sorted(p.name for p in out.glob("*.previous.h5")) == sorted(f"{c}.previous.h5" for c in CASES)
    assert all("contents" not in read_attributes(out / f"{case}.h5") for case in CASES)


def test_keep_figures_gives_the_same_summary_from_files_of_the_figures_datasets_alone(pool_sweep, tmp_path):
    """`--keep figures`: the summary numbers of the full sweep from files that hold the time, the sensors and the
    clearance joints' normal force, mode and stick flag, bit for bit as the full file has them; such a file does not
    serve a `--keep summary` sweep (kept aside, the case runs again)."""
    out = kept_sweep(pool_sweep[0], tmp_path, "figures", "(each file: the histories the figures of merit read)")
    for case in CASES:
        with h5py.File(out / f"{case}.h5", "r") as reduced, h5py.File(pool_sweep[0] / f"{case}.h5", "r") as whole:
            histories = [name for name, item in _datasets(reduced) if "/episodes/" not in name]
            assert histories and all(name == "time" or summary_dataset(name) for name in histories)
            assert {name for name, _ in _datasets(whole) if summary_dataset(name)} <= set(histories)
            assert all(np.array_equal(reduced[name][()], whole[name][()]) for name in histories)
        assert (out / f"{case}.h5").stat().st_size < 0.5 * (pool_sweep[0] / f"{case}.h5").stat().st_size
    again = run_sweep(plan_sweep(SweepRequest(SLIDER_CRANK, [SHORT], CLEARANCES, out=out, keep="summary"),
                                 SLIDER_CRANK), LocalPool(2))
    assert sorted(again.ran) == sorted(CASES)
    assert all(read_attributes(out / f"{case}.previous.h5")["contents"] == "figures" for case in CASES)


def _datasets(handle) -> list:
    found = []
    handle.visititems(lambda name, item: found.append((name, item)) if isinstance(item, h5py.Dataset) else None)
    return found


def test_a_failing_case_is_recorded_and_the_others_finish(tmp_path):
    out = tmp_path / "failing"
    # a 50 µs minimum step cannot resolve a steel contact (~µs): only the clearance case with it fails
    result = invoke("sweep", SLIDER_CRANK, "--set", "solver.t_end=1ms", "--clearance", "0.5",
                    "--set", "solver.min_step=1e-12s,5e-5s", "--workers", 2, "-o", out)
    assert result.exit_code == 2, result.output
    failing = "clearance-0.5_mm__solver.min_step-5e-5s"
    assert "1 of 4 cases failed" in result.output
    listed = next(line for line in result.output.splitlines() if line.strip().startswith(f"{failing}: "))
    assert "slider_crank_flores.yaml:" in listed and "joints[2] 'slider_pin': at t = " in listed  # where and when
    rows = read_summary(out)
    assert [rows[c]["status"] for c in rows] == ["complete", "complete", "complete", "failed"]
    assert "step size fell below solver.min_step" in rows[failing]["error"]
    assert rows[failing]["peak_acceleration_m_s2"] == ""
    plan = plan_sweep(SweepRequest(SLIDER_CRANK, ["solver.t_end=1ms", "solver.min_step=1e-12s,5e-5s"], "0.5", out=out),
                      SLIDER_CRANK)
    again = run_sweep(plan, LocalPool(1))
    assert again.ran == [] and [o.name for o in again.failed] == [failing]  # kept, not re-run


def test_monte_carlo_adds_percentiles_of_each_figure(tmp_path):
    config = tmp_path / "toleranced.yaml"
    config.write_text(SLIDER_CRANK.read_text() + "tolerances:\n  - {path: joints.slider_pin.clearance, "
                      "distribution: uniform, low: 0.1 mm, high: 0.5 mm}\n")
    out = tmp_path / "mc"
    result = invoke("sweep", config, "--set", "solver.t_end=1ms", "--sample", 3, "--seed", 7, "--workers", 2, "-o", out)
    assert result.exit_code == 0, result.output
    rows = read_summary(out)
    assert list(rows) == ["ideal", "sample-0001", "sample-0002", "sample-0003"]
    assert all(row["joints.slider_pin.clearance"].endswith(" mm") for name, row in rows.items() if name != "ideal")
    with (out / "percentiles.csv").open(newline="") as handle:
        table = {row["figure"]: row for row in csv.DictReader(handle)}
    peak = sorted(float(rows[f"sample-000{k}"]["peak_acceleration_m_s2"]) for k in (1, 2, 3))
    assert table["peak_acceleration_m_s2"]["cases"] == "3"
    assert float(table["peak_acceleration_m_s2"]["p50"]) == pytest.approx(peak[1], rel=1e-12)
    assert "max_contact_force_N[slider_pin]" in table and "max_contact_force_N[slider_pin]" in result.output


def test_a_case_whose_file_cannot_be_written_fails_with_the_reason_and_the_others_finish(tmp_path, monkeypatch):
    from collections import namedtuple

    from clearsim.sweep.execute import tasks_of
    from clearsim.sweep.worker import COMPLETE, FAILED, run_case

    plan = plan_sweep(SweepRequest(SLIDER_CRANK, ["solver.t_end=1ms"], "0.1,0.2", out=tmp_path / "sweep"), SLIDER_CRANK)
    plan.folder.mkdir(parents=True)
    first, second = tasks_of(plan)[:2]
    real_usage = shutil.disk_usage
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(10**9, 10**9 - 10**5, 10**5))
    full = run_case(first)
    monkeypatch.setattr(shutil, "disk_usage", real_usage)
    assert full.state == FAILED and "MB free" in full.error and not Path(first.output).exists()
    assert run_case(second).state == COMPLETE


def test_a_case_run_at_a_tolerance_too_coarse_for_its_contacts_is_named_with_its_warning(tmp_path, pool_sweep):
    out = tmp_path / "coarse"
    # the first impact (not chaotic: the same on every machine) at a position tolerance of 1 mm, 13× its penetration
    result = invoke("sweep", SLIDER_CRANK, "--set", "solver.atol=1e-3,1e-10", "--set", "solver.t_end=0.4ms",
                    "--workers", 2, "-o", out)
    assert result.exit_code == 0, result.output
    rows = read_summary(out)
    warned = [case for case, row in rows.items() if row["warnings"]]
    assert warned == ["solver.atol-1e-3"], rows.keys()
    assert "not resolved by the solver tolerance" in rows[warned[0]]["warnings"]
    assert f"warning: 1 case with warnings ({warned[0]})" in result.output
    assert all(not row["warnings"] for row in read_summary(pool_sweep[0]).values())  # default tolerances: none


# --- an empty kernel cache: the first case alone ---------------------------------------------------------------


def _thread_pool(workers: int):
    """LocalPool's pool in threads, for the order of starts and ends (cases here are plain functions)."""
    import threading
    from concurrent.futures import ThreadPoolExecutor

    from clearsim.sweep import executors

    return executors._Pool(ThreadPoolExecutor(workers), threading.Event())


@pytest.mark.parametrize("cold", [True, False], ids=["empty cache", "filled cache"])
def test_on_an_empty_kernel_cache_the_first_case_runs_alone(monkeypatch, cold):
    import threading
    import time

    from clearsim.solver import precompile
    from clearsim.sweep import executors
    from clearsim.sweep.worker import COMPLETE, CaseOutcome

    events, lock = [], threading.Lock()

    def case(task):
        with lock:
            events.append(("start", task))
        time.sleep(0.2)
        with lock:
            events.append(("end", task))
        return CaseOutcome(task, COMPLETE, True, "")

    monkeypatch.setattr(precompile, "cache_is_cold", lambda: cold)
    monkeypatch.setattr(executors.LocalPool, "_start", staticmethod(_thread_pool))
    collected = []
    assert not LocalPool(2).run(case, ["a", "b", "c"], collected.append)
    assert sorted(outcome.name for outcome in collected) == ["a", "b", "c"]
    first_end, second_start = events.index(("end", "a")), min(events.index(("start", "b")), events.index(("start", "c")))
    assert (first_end < second_start) == cold  # cold: b and c wait for a; filled: they start beside it
