"""What is drawn is what the file holds: lines and paths read back from the axes against the HDF5 data."""

import math
from pathlib import Path

import h5py
import numpy as np
import pytest

from clearsim.plot import (load_run, plot_contact_forces, plot_journal_path, plot_merit, plot_signal,
                           plot_spectrum, read_summary)
from clearsim.plot.data import apply_window, parse_time_window
from clearsim.plot.draw import draw_figure
from clearsim.plot.history import amplitude_spectrum, envelope
from clearsim.plot.journal import PATH_GID
from clearsim.plot.labels import run_labels
from clearsim.plot.measured import read_measurement, residual
from clearsim.plot.style import new_figure

JOINT = "slider_pin"


def dataset(path: Path, key: str) -> np.ndarray:
    with h5py.File(path, "r") as handle:
        values = handle[key][()]
        return values.astype(float) if values.dtype == np.float32 else values  # as read_result hands it on


def axes():
    return new_figure((5.0, 4.0)).add_subplot()


def test_journal_path_radius_is_the_files_eccentricity(runs):
    run = load_run(runs["clearance"])
    ax = plot_journal_path(run, JOINT, axes())
    path = next(c for c in ax.collections if c.get_gid() == PATH_GID)
    drawn = np.concatenate([segment for segment in path.get_segments()])
    eccentricity = dataset(runs["clearance"], f"joints/{JOINT}/eccentricity")
    factor = 1e3 if "mm" in ax.get_xlabel() else 1e6  # the axis says mm or µm
    # drawn points are the file's points times the axis factor: equal to rounding error
    assert np.max(np.hypot(*drawn.T)) / factor == pytest.approx(np.max(np.hypot(*eccentricity.T)), rel=1e-12)
    circle = ax.patches[0]
    assert circle.get_radius() / factor == pytest.approx(0.5e-3, rel=1e-12)  # c = R_B − R_J = 10 − 9.5 mm


def test_path_colours_follow_the_contact_modes(runs):
    run = load_run(runs["clearance"])
    ax = plot_journal_path(run, JOINT, axes())
    path = next(c for c in ax.collections if c.get_gid() == PATH_GID)
    mode = dataset(runs["clearance"], f"joints/{JOINT}/mode")[:-1]
    colours = path.get_colors()
    from matplotlib.colors import to_rgba

    from clearsim.plot.style import MODE_COLOURS

    expected = np.array([to_rgba(MODE_COLOURS[m]) for m in mode])
    assert np.array_equal(colours, expected)
    assert set(mode) >= {0, 1}  # 3 ms of the benchmark has free flight and impacts


def test_sensor_lines_are_the_file_in_engineering_units(runs):
    run = load_run(runs["clearance"])
    ax = plot_signal([run], "slider_displacement", axes())
    line = ax.lines[0]
    assert ax.get_xlabel() == "time (ms)" and ax.get_ylabel() == "slider displacement (mm)"
    assert np.allclose(line.get_xdata(), dataset(runs["clearance"], "time") * 1e3, rtol=0, atol=1e-12)
    assert np.allclose(line.get_ydata(), dataset(runs["clearance"], "sensors/slider_displacement") * 1e3,
                       rtol=0, atol=1e-12)


def test_normal_force_in_kN(runs):
    run = load_run(runs["clearance"])
    ax = plot_contact_forces([run], JOINT, axes())
    force = dataset(runs["clearance"], f"joints/{JOINT}/normal_force")
    assert "(kN)" in ax.get_ylabel()  # peak ≈ 46 kN
    assert np.allclose(ax.lines[0].get_ydata(), force * 1e-3, rtol=0, atol=1e-9)


def test_time_window_restricts_every_series(runs):
    run = load_run(runs["clearance"])
    apply_window(run, parse_time_window("1:2"))
    ax = plot_signal([run], "slider_velocity", axes())
    time = ax.lines[0].get_xdata()
    assert time.min() >= 1.0 - 1e-9 and time.max() <= 2.0 + 1e-9 and len(time) == 101  # 100 kHz samples


@pytest.mark.parametrize("text, expected", [("1:2", (1e-3, 2e-3)), ("1ms:0.002s", (1e-3, 2e-3)),
                                            (":2", (-math.inf, 2e-3)), ("0.5:", (0.5e-3, math.inf))])
def test_time_window_syntax(text, expected):
    assert parse_time_window(text) == pytest.approx(expected)


def test_amplitude_spectrum_of_a_sine():
    time = np.arange(4096) * 1e-5  # 100 kHz sampling
    frequency = 100 * (1e5 / 4096)  # on a bin: the Hann window's peak gain is exact there
    values = 3.0 * np.sin(2 * np.pi * frequency * time) + 7.0
    f, amplitude = amplitude_spectrum(time, values)
    assert f[np.argmax(amplitude)] == pytest.approx(frequency)
    assert amplitude.max() == pytest.approx(3.0, rel=1e-3)  # amplitude-corrected window


def test_spectrum_axis_is_kilohertz(runs):
    ax = plot_spectrum([load_run(runs["clearance"])], "slider_acceleration", axes())
    assert ax.get_xlabel() == "frequency (kHz)" and ax.lines[0].get_xdata().max() == pytest.approx(50.0, rel=0.01)


def test_violation_envelope_keeps_the_maximum():
    time = np.linspace(0.0, 1.0, 1000)
    values = np.where(np.arange(1000) % 7 == 0, 1e-13, 0.0)
    _, peaks = envelope(time, values, 50)
    assert peaks.max() == values.max() and len(peaks) == 50


def test_labels_say_what_differs(runs):
    loaded = [load_run(runs[name]) for name in ("ideal", "clearance", "small")]
    assert run_labels(loaded) == ["ideal", "slider_pin clearance 0.5 mm", "slider_pin clearance 0.25 mm"]


def test_labels_fall_back_to_file_names_when_nothing_differs(runs, tmp_path):
    import shutil

    (tmp_path / "a").mkdir()
    copies = [shutil.copy(runs["clearance"], tmp_path / "again.h5"),
              shutil.copy(runs["clearance"], tmp_path / "a" / "sc.h5")]
    assert run_labels([load_run(runs["clearance"]), load_run(copies[0])]) == ["sc", "again"]
    assert run_labels([load_run(runs["clearance"]), load_run(copies[1])]) == ["runs0/sc", "a/sc"]


def test_merit_points_are_the_summary(tmp_path):
    csv = tmp_path / "summary.csv"
    csv.write_text("case,reference,clearance,status,peak_acceleration_m_s2,max_contact_force_N[A]\n"
                   "ideal,,,complete,2000.0,\n"
                   "c2,ideal,20 um,complete,5000.0,30000.0\n"
                   "c1,ideal,0.01 mm,complete,4000.0,20000.0\n"
                   "c3,ideal,0.05 mm,failed,,\n")
    summary = read_summary(csv)
    assert summary.parameters == ["clearance"] and summary.units["clearance"] == "µm"  # the first value's unit
    ax = plot_merit(summary, "max_contact_force_N[A]", axes())
    assert np.allclose(ax.lines[0].get_xdata(), [10.0, 20.0]) and ax.get_xlabel() == "clearance (µm)"
    assert np.allclose(ax.lines[0].get_ydata(), [20.0, 30.0])  # kN, sorted by clearance, failed case left out
    ax = plot_merit(summary, "peak_acceleration_m_s2", axes())
    assert ax.lines[-1].get_ydata()[0] == 2000.0  # the ideal case as a reference line


def test_measured_units_are_converted_and_a_copy_of_the_run_has_no_residual(runs, tmp_path):
    time = dataset(runs["clearance"], "time")
    values = dataset(runs["clearance"], "sensors/slider_velocity")
    csv = tmp_path / "bench.csv"
    rows = "\n".join(f"{float(t) * 1e3!r},{float(v) * 1e3!r}" for t, v in zip(time, values))
    csv.write_text(f"time [ms],slider_velocity [mm/s]\n{rows}\n")
    measurement = read_measurement(csv)
    run = load_run(runs["clearance"])
    from clearsim.plot.measured import measured_si

    _, r = residual(run, "slider_velocity", measurement.time, measured_si(measurement, "slider_velocity", run))
    assert np.max(np.abs(r)) < 1e-9  # m/s: only the round trip through text and ms/mm


def test_drawing_names_every_body_and_joint(runs):
    run = load_run(runs["clearance"])
    q0 = np.concatenate([run.datasets[f"bodies/{b.name}/q"][0] for b in run.mechanism.bodies])
    figure = draw_figure(run.mechanism, [b.name for b in run.mechanism.bodies], q0)
    texts = {t.get_text() for ax in figure.axes for t in ax.texts}
    assert {"crank", "rod", "slider", "crank_pivot", "crank_pin", "slider_pin"} <= texts
