"""Bad input: one clear message, exit code 2, no traceback, no figure written."""

import shutil

import h5py
import pytest
from typer.testing import CliRunner

from clearsim.cli import app

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
    assert "no column is named after a sensor" in fails(tmp_path, runs["clearance"], "--measured", csv)


def test_measurement_with_a_wrong_unit(runs, tmp_path):
    csv = tmp_path / "bench.csv"
    csv.write_text("time [ms],slider_displacement [kg]\n0,1\n1,2\n")
    message = fails(tmp_path, runs["clearance"], "--measured", csv)
    assert "column 'slider_displacement': cannot convert 'kg' to m" in message


def test_draw_of_a_missing_config(tmp_path):
    result = runner.invoke(app, ["draw", str(tmp_path / "absent.yaml"), "-o", str(tmp_path / "d.png")])
    assert result.exit_code == 2 and "Traceback" not in result.output and "cannot read the file" in result.output
    assert not (tmp_path / "d.png").exists()
