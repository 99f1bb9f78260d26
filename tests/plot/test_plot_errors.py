"""Bad input: one clear message, exit code 2, no traceback, no figure written."""

import shutil

import h5py
import pytest
from typer.testing import CliRunner

from clearsim.cli import app

from .conftest import sweep_folder

runner = CliRunner()


def fails(tmp_path, *args) -> str:
    out = tmp_path / "figures"
    result = runner.invoke(app, [str(a) for a in ("plot", *args, "--out", out)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and result.output.startswith("error: ")
    assert not out.exists() or not any(out.iterdir())
    return " ".join(result.output.split())


def test_missing_dataset_is_named(runs, tmp_path):
    broken = shutil.copy(runs["clearance"], tmp_path / "broken.h5")
    with h5py.File(broken, "r+") as handle:
        del handle["joints/slider_pin/mode"]
    message = fails(tmp_path, broken)
    assert "broken.h5: no dataset /joints/slider_pin/mode (needed for the figures of clearance joint slider_pin)" \
        in message


def test_a_diagnosis_run_file_holding_the_sensors_alone_is_named_as_such(runs, tmp_path):
    reduced = shutil.copy(runs["clearance"], tmp_path / "run.h5")
    with h5py.File(reduced, "r+") as handle:  # as a diagnosis writes its model runs (contents = "sensors")
        handle.attrs["contents"] = "sensors"
        for group in ("bodies", "joints", "energy", "constraints"):
            del handle[group]
    message = fails(tmp_path, reduced)
    assert "run.h5: holds the time and the sensors alone (a diagnosis's model run)" in message
    assert "run its mechanism with `clearsim run` for every history" in message


def test_a_sweep_figures_file_is_named_as_such(runs, tmp_path):
    """A `--keep figures` case file holds what summary.csv reads, not what the joint figures draw."""
    reduced = shutil.copy(runs["clearance"], tmp_path / "case.h5")
    with h5py.File(reduced, "r+") as handle:  # as `clearsim sweep --keep figures` writes its cases
        handle.attrs["contents"] = "figures"
        for group in ("bodies", "energy", "constraints"):
            del handle[group]
        del handle["joints/slider_pin/eccentricity"]
    message = fails(tmp_path, reduced)
    assert "case.h5: holds the histories a sweep keeps with --keep figures" in message


def test_a_sweep_summary_file_plots_its_figures_and_names_itself_for_the_animation(runs, tmp_path):
    """A `--keep summary` case file has what the standard figures read; the animation needs the bodies' poses, and
    the message says which kind of file this is instead of calling it interrupted."""
    reduced = shutil.copy(runs["clearance"], tmp_path / "case.h5")
    with h5py.File(reduced, "r+") as handle:  # as `clearsim sweep --keep summary` writes its cases
        handle.attrs["contents"] = "summary"
        del handle["bodies"]
        for joint in [name for name in handle["joints"] if "reaction" in handle["joints"][name]]:
            del handle[f"joints/{joint}/reaction"]
    plotted = runner.invoke(app, ["plot", str(reduced), "--out", str(tmp_path / "plotted")])
    assert plotted.exit_code == 0, plotted.output
    assert {p.name for p in (tmp_path / "plotted").iterdir()} >= {"case-output.png", "case-joint-slider_pin.png",
                                                                "case-energy.png"}
    message = fails(tmp_path, reduced, "--animate")
    assert "case.h5: holds the histories a sweep keeps with --keep summary" in message
    assert "no /bodies/" in message and "for the animation" in message


def test_animation_of_a_file_without_body_poses(runs, tmp_path):
    broken = shutil.copy(runs["clearance"], tmp_path / "nobody.h5")
    with h5py.File(broken, "r+") as handle:
        del handle["bodies/rod/q"]
    message = fails(tmp_path, broken, "--animate")
    assert "nobody.h5: no dataset /bodies/rod/q (needed for the animation)" in message


def test_missing_sensor_dataset(runs, tmp_path):
    broken = shutil.copy(runs["clearance"], tmp_path / "nosensor.h5")
    with h5py.File(broken, "r+") as handle:
        del handle["sensors/slider_acceleration"]
    message = fails(tmp_path, broken, "--sensor", "slider_acceleration")
    assert "no sensor 'slider_acceleration'" in message


def test_hdf5_that_is_not_a_clearsim_result(tmp_path):
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as handle:
        handle["x"] = [1.0, 2.0]
    assert "other.h5 is not a clearsim result file (no clearsim_version attribute)" in fails(tmp_path, other)


def test_file_that_is_not_hdf5(tmp_path):
    text = tmp_path / "notes.h5"
    text.write_text("not a result\n")
    assert "notes.h5 is not an HDF5 file" in fails(tmp_path, text)


def test_missing_file(tmp_path):
    assert f"no such file: {tmp_path / 'absent.h5'}" in fails(tmp_path, tmp_path / "absent.h5")


def test_folder_without_results(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert "contains no result files (*.h5)" in fails(tmp_path, empty)


def test_one_bad_file_among_good_ones_writes_nothing(runs, tmp_path):
    assert "no such file" in fails(tmp_path, runs["clearance"], tmp_path / "absent.h5")


@pytest.mark.parametrize("option, value, fragment", [
    ("--sensor", "slider_velocty", "no sensor 'slider_velocty'; did you mean 'slider_velocity'?"),
    ("--time-window", "5:1", "--time-window '5:1': the start must come before the end"),
    ("--time-window", "10:20", "fewer than two samples in the time window 10:20 ms"),
    ("--time-window", "1kg:2", "expected a time"),
    ("--format", "jpeg", "--format 'jpeg': expected one of png, svg, pdf"),
    ("--exaggerate", "big", "--exaggerate 'big': expected a factor (e.g. 1000) or 'auto'"),
])
def test_bad_options(runs, tmp_path, option, value, fragment):
    assert fragment in fails(tmp_path, runs["clearance"], option, value)


def test_measurement_without_matching_columns(runs, tmp_path):
    csv = tmp_path / "bench.csv"
    csv.write_text("time [s],pressure [bar]\n0,1\n0.001,2\n")
    message = fails(tmp_path, runs["clearance"], "--measured", csv)
    assert f"bench.csv: no column names a sensor of {runs['clearance']}" in message and "--map" not in message


def test_measurement_with_a_wrong_unit(runs, tmp_path):
    csv = tmp_path / "bench.csv"
    csv.write_text("time [ms],slider_displacement [kg]\n0,1\n1,2\n")
    message = fails(tmp_path, runs["clearance"], "--measured", csv)
    assert "column 'slider_displacement': unit [kg] does not fit (expected a length" in message


def test_draw_of_a_missing_config(tmp_path):
    result = runner.invoke(app, ["draw", str(tmp_path / "absent.yaml"), "-o", str(tmp_path / "d.png")])
    assert result.exit_code == 2 and "Traceback" not in result.output and "cannot read the file" in result.output
    assert not (tmp_path / "d.png").exists()


def _rows(function, n=30):
    return "".join(f"{','.join(map(str, function(k)))}\n" for k in range(n))


@pytest.mark.parametrize("text, fragment", [
    ("time [ms],slider_displacement [mm],slider_displacement [m]\n" + _rows(lambda k: (k, -k, -k / 1e3)),
     "bench.csv:1: columns 2 and 3 are both named 'slider_displacement'; which one is meant is ambiguous"),
    ("time [ms],slider_displacement [mm]\n" + _rows(lambda k: (k, 0.0)),
     "bench.csv: column 'slider_displacement' is constant (0 mm in all 30 samples): a dead channel"),
    ("time [ms],slider_displacement [mm]\n" + _rows(lambda k: (k, "nan")),
     "bench.csv: column 'slider_displacement' holds no numbers (all 30 values are NaN or empty): a dead channel"),
    ("time [ms],slider_displacement [mm]\n" + _rows(lambda k: (k * (1e3 if k > 9 else 1), -k)),
     "bench.csv:3: time in column 'time' goes from 0 to 1 ms, a step 0.001 times the usual one of 1e+03 ms"),
    ("time [ms],slider_displacement [mm]\n" + _rows(lambda k: (k if k != 5 else 2, -k)),
     "bench.csv:7: time in column 'time' does not increase (4 then 2)"),
    ("time [ms],slider_displacement [mm]\n" + _rows(lambda k: (k, "x" if k == 3 else -k)),
     "bench.csv:5: column 'slider_displacement': 'x' is not a number"),
    ("time [ms],slider_displacement [mm]\n", "bench.csv: no samples below the header"),
    ("", "bench.csv: the file is empty"),
], ids=["same name twice", "constant", "all NaN", "time unit changes", "time goes back", "not a number", "header only",
        "empty"])
def test_a_bad_measurement_gets_the_checks_of_diagnose(runs, tmp_path, text, fragment):
    csv = tmp_path / "bench.csv"
    csv.write_text(text)
    assert fragment in fails(tmp_path, runs["clearance"], "--measured", csv)


def test_a_measurement_that_is_not_utf8_or_a_folder(runs, tmp_path):
    csv = tmp_path / "bench.csv"
    csv.write_bytes(b"time [ms],slider_displacement [\xb5m]\n0,1\n1,2\n")
    assert "bench.csv:1: byte 0xb5 is not UTF-8 text" in fails(tmp_path, runs["clearance"], "--measured", csv)
    assert "is a folder; give the measured record itself" in fails(tmp_path, runs["clearance"], "--measured", tmp_path)


def test_a_measurement_with_semicolons_is_plotted(runs, tmp_path):
    csv = tmp_path / "bench.csv"
    csv.write_text("time (ms);slider_displacement (mm)\n" + _rows(lambda k: (k / 10, -k / 10)).replace(",", ";"))
    result = runner.invoke(app, ["plot", str(runs["clearance"]), "--out", str(tmp_path), "--measured", str(csv)])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "sc-measured.png").exists()


def _rewritten(source, path, change):
    shutil.copy(source, path)
    with h5py.File(path, "r+") as handle:
        change(handle)
    return path


def _replace(handle, key, values):
    del handle[key]
    handle.create_dataset(key, data=values)


@pytest.mark.parametrize("change, fragment", [
    (lambda h: _replace(h, "time", [[0.0, 1.0], [2.0, 3.0]]),
     "bad.h5: dataset /time is not a column of numbers (shape (2, 2), type float64)"),
    (lambda h: _replace(h, "time", [b"a", b"b", b"c"]), "bad.h5: dataset /time is not a column of numbers"),
    (lambda h: _replace(h, "time", [0.0]), "bad.h5: dataset /time holds 1 sample(s), too few to plot"),
    (lambda h: _replace(h, "sensors/slider_velocity", [0.0, 1.0, 2.0]),
     "bad.h5: dataset /sensors/slider_velocity has 3 samples, /time has"),
], ids=["time 2-D", "time text", "one sample", "a dataset cut short"])
def test_a_damaged_result_file_is_named_with_the_dataset(runs, tmp_path, change, fragment):
    bad = _rewritten(runs["clearance"], tmp_path / "bad.h5", change)
    message = fails(tmp_path, bad)
    assert fragment in message and "run it again" in message


def test_a_truncated_or_overwritten_result_file(runs, tmp_path):
    data = runs["clearance"].read_bytes()
    cut = tmp_path / "cut.h5"
    cut.write_bytes(data[: len(data) // 2])
    assert "cut.h5 is not a readable HDF5 file" in fails(tmp_path, cut) and "cut short or damaged" in fails(tmp_path, cut)
    spoiled = tmp_path / "spoiled.h5"
    spoiled.write_bytes(data[:4000] + b"\xff" * 20000 + data[24000:])
    message = fails(tmp_path, spoiled)
    assert "spoiled.h5" in message and "run it again" in message


def test_an_incomplete_file_whose_datasets_end_apart_is_plotted_to_their_common_end(runs, tmp_path):
    def cut_short(handle):
        handle.attrs["complete"], handle.attrs["status"] = False, "interrupted"
        _replace(handle, "joints/slider_pin/mode", handle["joints/slider_pin/mode"][:100])
    partial = _rewritten(runs["clearance"], tmp_path / "partial.h5", cut_short)
    result = runner.invoke(app, ["plot", str(partial), "--out", str(tmp_path / "figures")])
    assert result.exit_code == 0, result.output
    output = " ".join(result.output.split())
    assert "partial.h5: the datasets of this incomplete file end at different samples (/joints/slider_pin/mode has " \
           "100, /time" in output and "plotted the first 100" in output
    assert "partial.h5 is incomplete (interrupted)" in output


def test_a_sweep_folder_with_a_damaged_case_plots_the_others_and_names_it(runs, tmp_path):
    folder = sweep_folder(tmp_path / "sweep", {"ideal": runs["ideal"], "slider_pin-0.5mm": runs["clearance"],
                                               "slider_pin-0.25mm": None, "slider_pin-0.1mm": None})
    (folder / "slider_pin-0.25mm.h5").write_bytes(b"")
    (folder / "slider_pin-0.1mm.h5").write_bytes(runs["small"].read_bytes()[:5000])
    (folder / "summary.csv").write_bytes(b"\xff\xfe not text")
    shutil.copy(runs["small"], folder / "slider_pin-0.5mm.previous-2.h5")  # a kept backup is not a case
    result = runner.invoke(app, ["plot", str(folder), "--out", str(tmp_path / "figures")])
    assert result.exit_code == 0, result.output
    output = " ".join(result.output.split())
    assert "skipped case slider_pin-0.25mm:" in output and "skipped case slider_pin-0.1mm:" in output
    assert "summary.csv cannot be read" in output and "Traceback" not in output
    assert "previous-2" not in output
    assert (tmp_path / "figures" / "sweep-output.png").exists()


def test_a_sweep_folder_whose_every_case_is_damaged(tmp_path):
    folder = sweep_folder(tmp_path / "sweep", {"ideal": None})
    (folder / "ideal.h5").write_bytes(b"")
    message = fails(tmp_path, folder)
    assert f"{folder}: no case file can be plotted" in message and "ideal.h5 is not an HDF5 file" in message


def test_a_file_whose_stored_mechanism_cannot_be_read_is_plotted_with_a_note(runs, tmp_path):
    odd = _rewritten(runs["clearance"], tmp_path / "odd.h5", lambda h: h.attrs.__setitem__("config_yaml", "{{{"))
    result = runner.invoke(app, ["plot", str(odd), "--out", str(tmp_path / "figures")])
    assert result.exit_code == 0, result.output
    assert "odd.h5: its stored mechanism (config_yaml) cannot be read" in " ".join(result.output.split())


@pytest.mark.parametrize("window", ["nan:5", "1:inf", "nan:nan"])
def test_a_time_window_that_is_not_finite(runs, tmp_path, window):
    assert f"--time-window '{window}': expected finite times" in fails(tmp_path, runs["clearance"], "--time-window", window)


def test_an_output_folder_that_is_a_file(runs, tmp_path):
    notes = tmp_path / "notes.txt"
    notes.write_text("mine")
    result = runner.invoke(app, ["plot", str(runs["clearance"]), "--out", str(notes)])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert f"--out {notes}: is a file, not a folder; give the folder for the figures" in " ".join(result.output.split())
    assert notes.read_text() == "mine"
