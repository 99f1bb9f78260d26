"""The sweep folder: one config's sweep per folder, and a re-run never overwrites a result kept earlier."""

import json
from pathlib import Path

import h5py
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.sweep.worker import _reusable

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = CONFIGS / "slider_crank_flores.yaml"
FRICTION = CONFIGS / "slider_crank_flores_friction.yaml"
runner = CliRunner()


def _sweep_folder(folder: Path, config: Path) -> dict:
    """A folder as a sweep of `config` leaves it: cases.json and a case file."""
    folder.mkdir()
    (folder / "cases.json").write_text(json.dumps({"config": str(config), "cases": []}))
    (folder / "ideal.h5").write_bytes(b"the other config's result")
    return {p.name: p.read_bytes() for p in folder.iterdir()}


def test_a_folder_holding_another_configs_sweep_is_refused_and_left_as_it_was(tmp_path):
    folder = tmp_path / "sweep"
    before = _sweep_folder(folder, SLIDER_CRANK)
    result = runner.invoke(app, ["sweep", str(FRICTION), "--clearance", "0.1", "-o", str(folder)])
    assert result.exit_code == 2, result.output
    output = " ".join(result.output.split())
    assert (f"error: --out {folder}: it holds the sweep of another config, {SLIDER_CRANK} ({folder / 'cases.json'}: "
            f"\"config\"), not of {FRICTION}; the two would be mixed hint: give a new folder") in output
    assert "Traceback" not in output and "sweep of" not in output.split("error:")[0]  # refused before it starts
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before


def test_a_folder_whose_case_list_cannot_be_read_is_refused(tmp_path):
    folder = tmp_path / "sweep"
    _sweep_folder(folder, SLIDER_CRANK)
    (folder / "cases.json").write_text("{\"config\": ")
    result = runner.invoke(app, ["sweep", str(SLIDER_CRANK), "--clearance", "0.1", "-o", str(folder)])
    assert result.exit_code == 2, result.output
    output = " ".join(result.output.split())
    assert f"--out {folder}: its cases.json cannot be read (JSONDecodeError" in output
    assert f"delete {folder / 'cases.json'} and run again" in output and "Traceback" not in output


def test_the_same_config_moved_or_copied_may_continue_its_sweep(tmp_path):
    """The folder names the config by path; a copy of the same file elsewhere (a moved project) is the same sweep."""
    import hashlib

    from clearsim.sweep.plan import check_folder

    folder = tmp_path / "sweep"
    folder.mkdir()
    text = SLIDER_CRANK.read_text()
    (folder / "cases.json").write_text(json.dumps({"config": "/elsewhere/slider_crank_flores.yaml", "cases": [],
                                                   "config_sha256": hashlib.sha256(text.encode()).hexdigest()}))
    check_folder(folder, SLIDER_CRANK, text)  # the same text: accepted
    try:
        check_folder(folder, SLIDER_CRANK, text + "# edited\n")
    except Exception as refused:
        assert "holds the sweep of another config, /elsewhere/slider_crank_flores.yaml" in str(refused)
    else:
        raise AssertionError("another path with other text must be refused")


def _result(path: Path, config_yaml: str, contents: str | None = None) -> Path:
    with h5py.File(path, "w") as handle:
        handle.attrs["clearsim_version"] = "0"
        handle.attrs["config_yaml"] = config_yaml
        handle.attrs["complete"] = True
        handle.attrs["status"] = "complete"
        if contents is not None:
            handle.attrs["contents"] = contents
    return path


def test_a_file_with_the_sensors_alone_serves_a_diagnosis_run_not_a_sweep_case(tmp_path):
    """A full file serves a case that asks for the sensors alone; a sensors-only file (a diagnosis's run) does not
    serve a case that asks for every history: it is kept aside and the case runs."""
    full = _result(tmp_path / "full.h5", "text")
    assert _reusable(full, "text", retry_failed=False, contents="sensors")
    assert _reusable(full, "text", retry_failed=False)
    reduced = _result(tmp_path / "reduced.h5", "text", contents="sensors")
    assert _reusable(reduced, "text", retry_failed=False, contents="sensors")
    assert not _reusable(reduced, "text", retry_failed=False)
    assert not reduced.exists() and (tmp_path / "reduced.previous.h5").exists()


def test_a_summary_file_serves_a_summary_or_diagnosis_case_not_a_full_one(tmp_path):
    """`--keep summary` files serve a later `--keep summary` sweep (and a diagnosis), a full file serves them too;
    a sweep asking for every history keeps the summary file aside and runs the case."""
    assert _reusable(_result(tmp_path / "full.h5", "text"), "text", retry_failed=False, contents="summary")
    summary = _result(tmp_path / "summary.h5", "text", contents="summary")
    assert _reusable(summary, "text", retry_failed=False, contents="summary")
    assert _reusable(summary, "text", retry_failed=False, contents="sensors")
    sensors = _result(tmp_path / "sensors.h5", "text", contents="sensors")
    assert not _reusable(sensors, "text", retry_failed=False, contents="summary")
    assert not _reusable(summary, "text", retry_failed=False)
    assert not summary.exists() and (tmp_path / "summary.previous.h5").exists()


def test_a_figures_file_serves_a_figures_or_diagnosis_case_and_is_served_by_a_summary_or_full_file(tmp_path):
    """`--keep figures` files (what summary.csv reads) are resumed by a `--keep figures` sweep and serve a diagnosis;
    a summary or full file serves a figures case; a figures file does not serve a summary case (kept aside)."""
    assert _reusable(_result(tmp_path / "full.h5", "text"), "text", retry_failed=False, contents="figures")
    assert _reusable(_result(tmp_path / "summary.h5", "text", contents="summary"), "text", retry_failed=False,
                     contents="figures")
    figures = _result(tmp_path / "figures.h5", "text", contents="figures")
    assert _reusable(figures, "text", retry_failed=False, contents="figures")
    assert _reusable(figures, "text", retry_failed=False, contents="sensors")
    assert not _reusable(_result(tmp_path / "sensors.h5", "text", contents="sensors"), "text", retry_failed=False,
                         contents="figures")
    assert not _reusable(figures, "text", retry_failed=False, contents="summary")
    assert not figures.exists() and (tmp_path / "figures.previous.h5").exists()


def test_a_result_of_another_yaml_is_kept_with_a_number_beside_the_earlier_kept_one(tmp_path):
    output = _result(tmp_path / "case.h5", "second")
    oldest = _result(tmp_path / "case.previous.h5", "first")
    assert not _reusable(output, "third", retry_failed=False)
    assert not output.exists()
    assert h5py.File(oldest, "r").attrs["config_yaml"] == "first"  # the older kept result is untouched
    assert h5py.File(tmp_path / "case.previous-2.h5", "r").attrs["config_yaml"] == "second"
    _result(output, "third")
    assert not _reusable(output, "fourth", retry_failed=False)
    assert h5py.File(tmp_path / "case.previous-3.h5", "r").attrs["config_yaml"] == "third"
