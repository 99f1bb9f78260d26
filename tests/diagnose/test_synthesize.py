"""`clearsim synthesize` end to end on the fast slider-crank, read back with read_measured."""

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose import read_measured
from clearsim.io.hdf5 import read_result
from clearsim.runner import simulate_config

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = str(CONFIGS / "slider_crank_flores.yaml")
SHORT = ["--set", "solver.t_end=6ms"]
UNITS = {"slider_displacement": "m", "slider_velocity": "m/s"}
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def synthesize(out, *options, sensors="slider_displacement,slider_velocity"):
    result = invoke("synthesize", SLIDER_CRANK, *SHORT, "--sensors", sensors, "-o", out, *options)
    assert result.exit_code == 0, result.output
    return read_measured(out, UNITS)


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    """The model's own sensors at its output rate (100 kHz, above every rate used below)."""
    out = tmp_path_factory.mktemp("model") / "model.h5"
    simulate_config(SLIDER_CRANK, ["solver.t_end=6ms"], out)
    return read_result(out)


def test_round_trip_equals_the_model_at_the_shifted_times(tmp_path, model):
    offset = 0.7e-3
    data = synthesize(tmp_path / "bench.csv", "--rate", "20kHz", "--trigger-offset", "0.7ms")
    assert data.time[1] == pytest.approx(5e-5, rel=1e-9)
    assert data.time[-1] == pytest.approx(6e-3 + offset, abs=5e-5)
    for sensor in UNITS:
        expected = np.interp(data.time - offset, model["time"], model[f"sensors/{sensor}"])
        span = np.ptp(model[f"sensors/{sensor}"])
        # the run is written at 100 kHz, so both sides interpolate the same samples: only the
        # CSV's 10 significant digits separate them
        np.testing.assert_allclose(data.values[sensor], expected, rtol=0, atol=1e-8 * span)
    held = data.time < offset  # before the trigger the sensor holds its initial value
    assert np.all(data.values["slider_displacement"][held] == pytest.approx(model["sensors/slider_displacement"][0]))


def test_same_seed_same_record_other_seed_other_record(tmp_path):
    options = ("--noise", "1%", "--lowpass", "2kHz", "--seed")
    first = synthesize(tmp_path / "a.csv", *options, "3")
    again = synthesize(tmp_path / "b.csv", *options, "3")
    other = synthesize(tmp_path / "c.csv", *options, "4")
    for sensor in UNITS:
        np.testing.assert_array_equal(first.values[sensor], again.values[sensor])
        assert not np.allclose(first.values[sensor], other.values[sensor])


@pytest.mark.parametrize("noise, level", [("2%", None), ("0.5mm", 5e-4)])
def test_noise_level_as_requested(tmp_path, noise, level):
    clean = synthesize(tmp_path / "clean.csv", "--rate", "50kHz")
    # an absolute level with a unit fits one kind of sensor only
    noisy = synthesize(tmp_path / "noisy.csv", "--rate", "50kHz", "--noise", noise, "--seed", "1",
                       sensors="slider_displacement")
    signal = clean.values["slider_displacement"]
    expected = level if level is not None else 0.02 * np.ptp(signal)
    # 301 samples: the sample std of white noise is within 10 % of the true one with > 99.9 % probability
    measured_std = np.std(noisy.values["slider_displacement"] - signal)
    assert measured_std == pytest.approx(expected, rel=0.10)


def test_lowpass_removes_most_of_the_noise(tmp_path):
    clean = synthesize(tmp_path / "clean.csv", "--rate", "50kHz")
    raw = synthesize(tmp_path / "raw.csv", "--rate", "50kHz", "--noise", "2%", "--seed", "1")
    filtered = synthesize(tmp_path / "filtered.csv", "--rate", "50kHz", "--noise", "2%", "--seed", "1", "--lowpass", "2kHz")
    signal = clean.values["slider_displacement"]
    # white noise through a 2 kHz low-pass at 50 kHz keeps about √(2·2/50) ≈ 0.28 of its std
    ratio = np.std(filtered.values["slider_displacement"] - signal) / np.std(raw.values["slider_displacement"] - signal)
    assert 0.15 < ratio < 0.45


def test_refuses_to_overwrite_unless_forced(tmp_path):
    out = tmp_path / "bench.csv"
    out.write_text("keep me\n")
    result = invoke("synthesize", SLIDER_CRANK, *SHORT, "-o", out)
    assert result.exit_code == 2
    assert f"{out} exists; choose another -o or pass --force to overwrite it" in result.output
    assert out.read_text() == "keep me\n"
    result = invoke("synthesize", SLIDER_CRANK, *SHORT, "-o", out, "--force")
    assert result.exit_code == 0, result.output
    assert out.read_text().count("\n") > 20


@pytest.mark.parametrize("options, message", [
    (["--sensors", "slider_displacment"],
     "--sensors: the model has no sensor 'slider_displacment'; did you mean 'slider_displacement'?"),
    (["--rate", "15 mm"], "--rate '15 mm': expected a frequency"),
    (["--lowpass", "20kHz", "--rate", "15kHz"], "--lowpass '20kHz': the cut-off must lie between 0 and half the rate (7.5 kHz)"),
    (["--noise", "0.1 N"], "--noise '0.1 N' for sensor 'slider_displacement' [m]: expected a length"),
    (["--noise", "lots%"], "--noise 'lots%': expected a percentage such as 1% or a value with a unit"),
    (["--set", "solver.t_end=0.5ms"], "only 8 samples at 15000 Hz over the run and trigger offset"),
    (["--seed", "-1"], "--seed -1: the seed must be 0 or more"),
    (["--noise", "nan%"], "--noise 'nan%': expected a finite percentage such as 1%"),
    (["--noise", "inf%"], "--noise 'inf%': expected a finite percentage such as 1%"),
    (["--noise", "-1%"], "--noise '-1%': the noise level cannot be negative"),
    (["--noise", "-0.01mm"], "--noise '-0.01mm': the noise level cannot be negative"),
    (["--noise", "nan mm"], "--noise 'nan mm' for sensor 'slider_displacement' [m]: expected a finite number"),
    (["--rate", "0Hz"], "--rate '0Hz': the sampling rate must be positive"),
    (["--rate", "nan Hz"], "--rate 'nan Hz': expected a finite number"),
    (["--rate", "1e12Hz"], "--rate '1e12Hz' with --trigger-offset '0ms': the record would hold 6e+09 samples over 6 ms, "
     "more than 1e+07; lower --rate or the trigger offset"),
    (["--trigger-offset", "1e6s"], "--rate '15kHz' with --trigger-offset '1e6s': the record would hold 1.5e+10 samples"),
    (["--trigger-offset", "-10ms"], "--trigger-offset '-10ms': a record that starts 10 ms after the trigger misses the "
     "whole run (solver.t_end = 6 ms); give an offset above -6 ms"),
    (["--trigger-offset", "nan ms"], "--trigger-offset 'nan ms': expected a finite number"),
    (["--lowpass", "nan Hz"], "--lowpass 'nan Hz': expected a finite number"),
    (["--sensors", ",,"], "--sensors ',,': names no sensor"),
    (["--set", "solver.t_end=nan ms"], "in --set solver.t_end=nan ms solver → t_end expected a finite number"),
], ids=lambda value: " ".join(value) if isinstance(value, list) else "")
def test_bad_options_exit_2_with_the_message(tmp_path, options, message):
    result = invoke("synthesize", SLIDER_CRANK, *SHORT, "-o", tmp_path / "bench.csv", *options)
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output
    assert not (tmp_path / "bench.csv").exists()


@pytest.mark.parametrize("options, message", [
    (["--noise", "-1%"], "--noise '-1%': the noise level cannot be negative"),
    (["--rate", "1e12Hz"], "the record would hold"),
], ids=["negative noise", "a rate of a TeraHertz"])
def test_bad_options_are_refused_before_the_model_runs(tmp_path, monkeypatch, options, message):
    import clearsim.runner

    def no_run(*args, **kwargs):
        raise AssertionError("the model ran")

    monkeypatch.setattr(clearsim.runner, "run_to_file", no_run)
    result = invoke("synthesize", SLIDER_CRANK, *SHORT, "-o", tmp_path / "bench.csv", *options)
    assert result.exit_code == 2 and message in " ".join(result.output.split()), result.output


def test_an_output_that_is_a_folder_is_named_even_with_force(tmp_path):
    result = invoke("synthesize", SLIDER_CRANK, *SHORT, "-o", tmp_path, "--force")
    assert result.exit_code == 2
    assert f"-o {tmp_path}: is a folder; give the file to write, e.g. -o {tmp_path / 'bench.csv'}" in \
        " ".join(result.output.split())
