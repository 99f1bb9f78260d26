"""A sweep on a Dask cluster whose workers do not see the sweep folder (separate machines, no shared file system):
the result files come back to the client, which writes them into its folder; a re-run reuses them there."""

import csv
import os
import sys
from pathlib import Path

import h5py
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.sweep import DaskCluster, SweepRequest, plan_sweep, run_sweep

distributed = pytest.importorskip("distributed")

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
SHORT = "solver.t_end=2ms"
CASES = ["ideal", "clearance-0.25_mm", "clearance-0.5_mm"]
TOUCHING = {"open", "os.remove", "os.rename", "os.replace", "os.mkdir", "os.listdir", "os.scandir", "os.rmdir"}


class SeparateMachine(distributed.WorkerPlugin):
    """Makes a worker process behave as if it ran on another machine: its own working directory, and no access to
    the client's folder (any open, listing, rename or removal of a path under it raises, h5py's too)."""

    def __init__(self, client_root: str, worker_root: str):
        self.client_root, self.worker_root = client_root, worker_root

    def setup(self, worker):
        import h5py as worker_h5py

        home = Path(self.worker_root) / f"worker-{worker.name}"
        home.mkdir(parents=True, exist_ok=True)
        os.chdir(home)
        client_root = self.client_root

        def unseen(path) -> bool:
            return isinstance(path, (str, bytes, os.PathLike)) and os.path.abspath(os.fsdecode(path)).startswith(
                client_root)

        def refuse(event, args):
            if event in TOUCHING and any(unseen(arg) for arg in args[:2]):
                raise PermissionError(f"{args[0]}: not on this machine")

        sys.addaudithook(refuse)
        opened = worker_h5py.File.__init__

        def guarded(self, name, *args, **kwargs):
            if unseen(name):
                raise PermissionError(f"{name}: not on this machine")
            opened(self, name, *args, **kwargs)

        worker_h5py.File.__init__ = guarded


@pytest.fixture(scope="module")
def separate_cluster(tmp_path_factory):
    root = tmp_path_factory.mktemp("dask")
    client_root, worker_root = root / "client", root / "workers"
    client_root.mkdir()
    with distributed.LocalCluster(processes=True, n_workers=2, threads_per_worker=1, host="127.0.0.1",
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        client.register_plugin(SeparateMachine(str(client_root), str(worker_root)))
        yield cluster.scheduler_address, client_root, worker_root


def test_workers_that_do_not_see_the_sweep_folder_send_every_case_file_back(separate_cluster, monkeypatch):
    address, client_root, worker_root = separate_cluster
    monkeypatch.chdir(client_root)
    result = CliRunner().invoke(app, ["sweep", str(SLIDER_CRANK), "--set", SHORT, "--clearance", "0.25,0.5",
                                      "--scheduler", address, "-o", "sweep"])
    assert result.exit_code == 0, result.output
    out = client_root / "sweep"
    assert sorted(p.name for p in out.iterdir()) == sorted([*(f"{c}.h5" for c in CASES), "cases.json", "summary.csv"])
    with (out / "summary.csv").open(newline="") as handle:
        assert [row["status"] for row in csv.DictReader(handle)] == ["complete"] * 3
    for case in CASES:
        with h5py.File(out / f"{case}.h5") as handle:
            assert bool(handle.attrs["complete"]) and handle["time"].shape[0] > 100
    assert not [p for p in worker_root.rglob("*") if p.suffix in (".h5", ".part")]  # the scratch folders are gone
    plotted = CliRunner().invoke(app, ["plot", str(out)])
    assert plotted.exit_code == 0, plotted.output


def test_a_rerun_on_the_cluster_reuses_the_files_of_the_clients_folder_and_keeps_other_results(separate_cluster):
    address, client_root, _ = separate_cluster
    out = client_root / "rerun"
    request = SweepRequest(SLIDER_CRANK, [SHORT], "0.25", out=out)
    first = run_sweep(plan_sweep(request, SLIDER_CRANK), DaskCluster(address))
    assert sorted(first.ran) == ["clearance-0.25_mm", "ideal"]
    assert run_sweep(plan_sweep(request, SLIDER_CRANK), DaskCluster(address)).ran == []
    changed = SweepRequest(SLIDER_CRANK, [SHORT, "solver.rtol=1e-7"], "0.25", out=out)  # other YAML, same names
    again = run_sweep(plan_sweep(changed, SLIDER_CRANK), DaskCluster(address))
    assert sorted(again.ran) == ["clearance-0.25_mm", "ideal"]
    assert sorted(p.name for p in out.glob("*.previous.h5")) == ["clearance-0.25_mm.previous.h5", "ideal.previous.h5"]


def test_the_csv_tables_of_the_mechanism_go_with_each_case_to_workers_that_do_not_see_them(separate_cluster):
    address, client_root, _ = separate_cluster
    config = client_root / "kicked" / "slider_crank.yaml"
    (config.parent / "tables").mkdir(parents=True)
    config.write_text(SLIDER_CRANK.read_text() + "forces:\n  - {type: tabulated, name: kick, body: slider, "
                      "direction: [1, 0], file: tables/kick.csv}\n")
    (config.parent / "tables" / "kick.csv").write_text("0,0\n0.001,50\n0.002,0\n")
    result = run_sweep(plan_sweep(SweepRequest(config, [SHORT], "0.25", out=client_root / "kicked-sweep"), config),
                       DaskCluster(address))
    assert {name: outcome.error for name, outcome in result.outcomes.items()} == {"ideal": "",
                                                                                   "clearance-0.25_mm": ""}
    assert result.count("complete") == 2
