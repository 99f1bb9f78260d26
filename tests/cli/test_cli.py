"""`clearsim` end to end: the commands on short runs, exit codes and messages."""

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import h5py
import pytest
from typer.testing import CliRunner

from clearsim import __version__
from clearsim.runner import simulate_config
from clearsim.cli import app

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = str(CONFIGS / "slider_crank_flores.yaml")
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_version():
    result = invoke("--version")
    assert result.exit_code == 0 and __version__ in result.output


def test_run_writes_the_file_and_prints_the_summary(tmp_path):
    out = tmp_path / "sc.h5"
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=2ms")
    assert result.exit_code == 0, result.output
    for text in ("peak |slider_velocity|", "peak |slider_acceleration|", "joint slider_pin: max contact force", "joint slider_pin: free / impact / contact",
                 "steps (rejected)", "contact events", "wall time", "compiled loop"):
        assert text in result.output
    with h5py.File(out) as f:
        assert bool(f.attrs["complete"]) and f["time"][-1] == pytest.approx(0.002)


@pytest.mark.parametrize("cold", [True, False], ids=["empty cache", "filled cache"])
def test_a_first_run_says_that_it_compiles(tmp_path, monkeypatch, cold):
    from clearsim.solver import precompile

    monkeypatch.setattr(precompile, "cache_is_cold", lambda: cold)
    monkeypatch.setenv(precompile.DISABLE_VARIABLE, "0")  # no helper process from a pretended empty cache
    result = invoke("run", SLIDER_CRANK, "-o", tmp_path / "sc.h5", "--set", "solver.t_end=1ms")
    assert result.exit_code == 0, result.output
    assert ("compiling the numerical kernels" in result.output) == cold


def test_run_prints_the_warning_of_an_unresolved_contact_and_exits_0(tmp_path):
    out = tmp_path / "coarse.h5"
    # the first impact (before the motion turns chaotic, so on any machine) at a position tolerance of 1 mm
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=0.4ms", "--set", "solver.atol=1e-3")
    assert result.exit_code == 0, result.output
    assert "warning:" in result.output and "not resolved by the solver tolerance" in result.output


def test_rerun_keeps_the_earlier_result(tmp_path):
    out = tmp_path / "sc.h5"
    for _ in range(2):
        result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=1ms")
        assert result.exit_code == 0, result.output
    assert "kept the earlier result as" in result.output and (tmp_path / "sc.previous.h5").exists()


def test_override_makes_the_clearance_joint_ideal(tmp_path):
    out = tmp_path / "ideal.h5"
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=1ms", "--set", "joints.slider_pin.clearance=0")
    assert result.exit_code == 0, result.output
    with h5py.File(out) as f:
        assert "joints/slider_pin/reaction" in f and "joints/slider_pin/penetration" not in f


def test_validate_and_schema(tmp_path):
    result = invoke("validate", SLIDER_CRANK)
    assert result.exit_code == 0 and "OK" in result.output and "2 degrees of freedom" in result.output
    schema = json.loads(invoke("schema").output)
    assert {"bodies", "joints", "solver"} <= set(schema["properties"])


def test_validate_counts_the_file_s_bodies_and_names_the_flexible_links(tmp_path):
    """A flexible link is two halves on a slide inside: validate said 4 bodies, 5 joints for this 3-body file."""
    rod = "{name: rod, mass: 0.21 kg, inertia: 0.00025 kg*m^2, position: [0.11 m, 0 m]}"
    text = Path(SLIDER_CRANK).read_text()
    assert text.count(rod) == 1
    path = tmp_path / "flexible.yaml"
    path.write_text(text.replace(rod, rod[:-1] + ", flexible: {model: axial, axial_stiffness: 1e8 N/m}}"))
    result = invoke("validate", str(path))
    assert result.exit_code == 0, result.output
    summary = " ".join(result.output.split())
    assert "3 bodies, 4 joints, 1 drivers, 3 degrees of freedom" in summary
    assert "(2 from clearance joints: slider_pin, 1 from flexible links: rod)" in summary


REDUNDANT = """
name: body pinned to the ground twice
points: {O: [0 m, 0 m], P: [0.2 m, 0 m]}
bodies:
  - {name: bar, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0.1 m, 0 m]}
joints:
  - {name: first_pin, type: revolute, bodies: [ground, bar], at: O}
  - {name: second_pin, type: revolute, bodies: [ground, bar], at: P}
solver: {t_end: 1 ms}
"""

NOT_ASSEMBLING = """
name: two cranks too short to meet
points: {O: [0 m, 0 m], Q: [1 m, 0 m]}
bodies:
  - {name: left, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0.05 m, 0 m], points: {tip: [0.05 m, 0 m]}}
  - {name: right, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0.95 m, 0 m], points: {tip: [-0.05 m, 0 m]}}
joints:
  - {name: left_pivot, type: revolute, bodies: [ground, left], at: O}
  - {name: right_pivot, type: revolute, bodies: [ground, right], at: Q}
  - {name: coupler_pin, type: revolute, bodies: [left, right], points: [tip, tip]}
solver: {t_end: 1 ms}
"""


@pytest.mark.parametrize("text, expected", [
    (REDUNDANT, ["redundant constraints", "first_pin", "second_pin"]),
    (NOT_ASSEMBLING, ["cannot be assembled", "coupler_pin"]),
    ("bodies: [\n", ["bad.yaml:"]),
])
def test_bad_mechanisms_give_one_located_message_and_exit_2(tmp_path, text, expected):
    config = tmp_path / "bad.yaml"
    config.write_text(text)
    out = tmp_path / "never.h5"
    result = invoke("run", config, "-o", out)
    assert result.exit_code == 2
    assert "Traceback" not in result.output
    for fragment in expected:
        assert fragment in result.output
    assert not out.exists()


@pytest.mark.parametrize("override, place", [
    ("drivers.crank_drive.motion={law: stroke, stroke: 1 rad, duration: 1e-300 s}", "drivers[0] 'crank_drive' → motion"),
    ("drivers.crank_drive.lag=1e300 s", "drivers[0] 'crank_drive' → lag"),
], ids=["stroke", "lag"])
def test_a_motion_beyond_floating_point_exits_2_at_its_driver(override, place):
    result = invoke("validate", SLIDER_CRANK, "--set", override)
    assert result.exit_code == 2, result.output
    assert f"in --set {override}  {place}\n" in result.output and "exceeds the range of floating-point" in result.output


def test_a_force_table_too_steep_for_a_spline_exits_2_at_its_file(tmp_path):
    config = tmp_path / "sc.yaml"
    config.write_text(Path(SLIDER_CRANK).read_text()
                      + "forces:\n  - {type: tabulated, name: kick, body: slider, direction: [1, 0], file: kick.csv}\n")
    (tmp_path / "kick.csv").write_text("0,0\n1e-300,1e300\n")
    result = invoke("validate", config)
    assert result.exit_code == 2, result.output
    assert f"{config}:{len(config.read_text().splitlines())}:" in result.output
    assert "forces[0] 'kick' → file\n  the samples change faster than floating-point numbers can hold" in result.output


def test_solver_failure_exits_2_with_time_and_joint_and_keeps_partial_results(tmp_path):
    out = tmp_path / "failed.h5"
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=3ms", "--set", "solver.min_step=2e-5s")
    assert result.exit_code == 2
    assert "slider_pin" in result.output and "ms" in result.output and "Traceback" not in result.output
    line = next(number for number, text in enumerate(Path(SLIDER_CRANK).read_text().splitlines(), 1)
                if "name: slider_pin" in text)
    assert f"{SLIDER_CRANK}:{line}:" in result.output and "joints[2] 'slider_pin'" in result.output  # the place
    with h5py.File(out) as f:
        assert not f.attrs["complete"] and f["time"].shape[0] > 1


def test_solver_failure_without_a_joint_is_placed_at_the_solver_settings(tmp_path):
    out = tmp_path / "failed.h5"
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=1ms", "--set", "bodies.crank.mass=1e300 kg")
    assert result.exit_code == 2, result.output
    line = next(number for number, text in enumerate(Path(SLIDER_CRANK).read_text().splitlines(), 1)
                if text.startswith("solver:"))
    assert f"error: {SLIDER_CRANK}:{line}:9  solver: at t = 0 ms: the step size fell below solver.min_step" in result.output
    # no contact is closed at t = 0: the hint points at the masses, not at the contact stiffness
    plain = " ".join(result.output.split())
    assert "no clearance joint is in contact here, so it is not a contact" in plain and "contact stiffer" not in plain


def test_the_summary_of_a_run_that_overflowed_reads_its_finite_samples(tmp_path):
    """A run whose state overflowed ends with NaN samples: its printed peaks are those of the finite motion before,
    never 'nan m/s'. Here the last of 51 samples is made NaN in the file; the peak is that of the other 50."""
    import numpy as np

    from clearsim.runner import summarize

    out = tmp_path / "sc.h5"
    assert invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=0.5ms").exit_code == 0
    with h5py.File(out, "r+") as f:
        velocity = f["sensors/slider_velocity"]
        finite_peak = float(np.max(np.abs(velocity[:-1])))
        velocity[-1] = np.nan
        f["joints/slider_pin/normal_force"][-1] = np.nan
    summary = summarize(out)
    assert summary.peak_velocity == ("slider_velocity", finite_peak) and finite_peak > 0.0
    assert np.isfinite(summary.peak_contact_force["slider_pin"])


def test_a_run_that_overflows_reports_the_failure_without_numpy_warnings(tmp_path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = invoke("run", SLIDER_CRANK, "-o", tmp_path / "overflow.h5", "--set", "solver.t_end=1ms",
                        "--set", "units=SI", "--set", "drivers.crank_drive.motion={law: polynomial, coefficients: [1e300, 1e300]}")
    assert result.exit_code == 2, result.output
    assert "at t = 0 ms: the step size fell below solver.min_step" in result.output
    assert [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)] == []


def test_a_run_interrupted_before_its_first_sample_exits_130_without_traceback(tmp_path, monkeypatch):
    from clearsim.solver.simulate import Run

    def interrupted(self, progress=None):
        raise KeyboardInterrupt
        yield  # a generator, as Run.chunks is

    monkeypatch.setattr(Run, "chunks", interrupted)
    out = tmp_path / "interrupted.h5"
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=1ms")
    assert result.exit_code == 130, result.output
    assert "interrupted" in result.output and not isinstance(result.exception, KeyError)
    with h5py.File(out) as f:
        assert not f.attrs["complete"] and "time" not in f


def test_a_place_at_line_100_prints_as_written_not_as_an_emoji(tmp_path):
    config = tmp_path / "long.yaml"
    config.write_text("#\n" * 99 + "- not a mapping\n")
    result = invoke("validate", config)
    assert result.exit_code == 2 and f"{config}:100:1\n  the top level must be a mapping" in result.output, result.output


@pytest.fixture
def warm_kernels(tmp_path):
    """A run first, so that the process signalled below is integrating, not compiling, when the signal comes."""
    simulate_config(SLIDER_CRANK, ["solver.t_end=1ms"], tmp_path / "warm-up.h5")


def _stopped_run(out: Path, *overrides: str) -> tuple[int, bytes]:
    """`clearsim run` in a process sent SIGTERM a second after its result file appears (under the hidden name it
    has until the run ends): (exit code, stderr)."""
    command = [sys.executable, "-m", "clearsim.cli", "run", SLIDER_CRANK, "-o", str(out)]
    command += [part for override in overrides for part in ("--set", override)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=os.environ.copy())
    deadline = time.time() + 120
    while not list(out.parent.glob(f".{out.name}.*.tmp")) and time.time() < deadline and process.poll() is None:
        time.sleep(0.2)
    time.sleep(1.0)
    process.send_signal(signal.SIGTERM)
    try:
        _, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
    return process.returncode, stderr


def test_sigterm_leaves_a_flagged_readable_file(tmp_path, warm_kernels):
    out = tmp_path / "killed.h5"
    # 10 s simulated (~15 s of running): a second after the file appears the run is far from its end on any machine
    # (with 2 s it sometimes finished first)
    code, stderr = _stopped_run(out, "solver.t_end=10s", "solver.output_rate=10kHz")
    assert code == 130, stderr.decode()
    assert b"Traceback" not in stderr
    with h5py.File(out) as f:
        assert not f.attrs["complete"] and str(f.attrs["status"]).startswith("interrupted")
        assert 0.0 < f["time"][-1] < 10.0


def test_a_run_with_a_tiny_max_step_can_still_be_stopped(tmp_path, warm_kernels):
    """2.4e9 steps would take hours; the compiled loop comes back to Python every STEPS_PER_CALL steps, where
    SIGTERM and Ctrl-C are handled (it used to return only at each hundredth of t_end: minutes here)."""
    out = tmp_path / "tiny-steps.h5"
    code, stderr = _stopped_run(out, "solver.max_step=1e-11s")
    assert code == 130, stderr.decode()
    with h5py.File(out) as f:
        assert not f.attrs["complete"] and str(f.attrs["status"]).startswith("interrupted")


from tests.unit.test_loader import BAD_FILES, edited  # noqa: E402  (the same bad files, through the CLI)


@pytest.mark.parametrize("case", list(BAD_FILES), ids=list(BAD_FILES))
def test_every_bad_file_exits_2_from_the_cli_without_traceback_or_output(tmp_path, case):
    old, new, _, fragments = BAD_FILES[case]
    config = tmp_path / "sc.yaml"
    config.write_text(edited(old, new))
    out = tmp_path / "never.h5"
    result = invoke("run", config, "-o", out)
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and "sc.yaml:" in result.output
    assert fragments[-1].split("\n")[0] in result.output
    assert not out.exists()


def test_an_output_folder_that_cannot_be_made_exits_2_with_the_path(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    result = invoke("run", SLIDER_CRANK, "-o", blocker / "run.h5", "--set", "solver.t_end=1ms")
    assert result.exit_code == 2, result.output
    assert f"cannot write the result file {blocker / 'run.h5'}" in result.output and "Traceback" not in result.output


@pytest.mark.parametrize("case", ["config", "folder", "empty", "csv"])
def test_an_output_that_cannot_be_a_result_file_exits_2_and_nothing_is_moved(tmp_path, monkeypatch, case):
    """-o the mechanism file itself (was: renamed to sc.1.yaml, HDF5 written in its place), a folder (was: renamed
    to <folder>.1), "" (was: a ValueError traceback), out.csv (was: HDF5 written as .csv)."""
    config = tmp_path / "sc.yaml"
    config.write_text(Path(SLIDER_CRANK).read_text())
    (tmp_path / "figures").mkdir()
    monkeypatch.chdir(tmp_path)
    out, expected = {"config": ("sc.yaml", "the mechanism file being run"), "folder": ("figures", "is a folder"),
                     "empty": ("", "is a folder"), "csv": ("out.csv", "named *.h5")}[case]
    before = sorted(p.name for p in tmp_path.iterdir())
    result = invoke("run", "sc.yaml", "-o", out, "--set", "solver.t_end=1ms")
    assert result.exit_code == 2, result.output
    assert f"-o {out or '.'}: " in result.output and expected in result.output and "hint:" in result.output
    assert "Traceback" not in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert config.read_text() == Path(SLIDER_CRANK).read_text()


@pytest.mark.parametrize("case", ["config", "folder", "text", "hard link"])
def test_draw_never_overwrites_the_mechanism_file_a_folder_or_another_file(tmp_path, monkeypatch, case):
    """draw -o sc.yaml wrote a PNG over the mechanism file; -o notes.txt over the notes (no copy kept)."""
    config = tmp_path / "sc.yaml"
    config.write_text(Path(SLIDER_CRANK).read_text())
    os.link(config, tmp_path / "link.png")  # the same file under a figure's name
    (tmp_path / "notes.txt").write_text("my notes")
    (tmp_path / "figures").mkdir()
    monkeypatch.chdir(tmp_path)
    out, expected = {"config": ("sc.yaml", "that is the mechanism file being drawn"), "folder": ("figures", "is a folder"),
                     "text": ("notes.txt", "an existing file that is not a figure"),
                     "hard link": ("link.png", "that is the mechanism file being drawn")}[case]
    result = invoke("draw", "sc.yaml", "-o", out)
    assert result.exit_code == 2, result.output
    assert f"-o {out}: {expected}" in result.output and "hint:" in result.output and "Traceback" not in result.output
    assert config.read_text() == Path(SLIDER_CRANK).read_text() and (tmp_path / "notes.txt").read_text() == "my notes"
    assert (tmp_path / "figures").is_dir()


@pytest.mark.parametrize("command", ["validate", "sweep"])
def test_an_endless_file_is_refused_not_read_until_memory_runs_out(command):
    """`clearsim validate /dev/zero` read until memory ended: a MemoryError traceback (here, under a 3 GB limit).
    A device is not read at all; a regular file beyond 32 MB is refused by its size (tests/unit/test_hostile_input)."""
    import resource

    def limit_memory():
        resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))

    args = [sys.executable, "-m", "clearsim.cli", command, "/dev/zero"] + (["--clearance", "0.1"] if command == "sweep" else [])
    done = subprocess.run(args, capture_output=True, text=True, timeout=120, preexec_fn=limit_memory, env=os.environ.copy())
    assert done.returncode == 2, done.stderr
    assert "/dev/zero\n  cannot read the file: it is a device, not a regular file" in done.stderr
    assert "Traceback" not in done.stderr


def test_too_little_free_space_exits_2_before_writing(tmp_path, monkeypatch):
    import shutil
    from collections import namedtuple

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(10**9, 10**9 - 10**5, 10**5))
    out = tmp_path / "sc.h5"
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=2ms")
    assert result.exit_code == 2, result.output
    assert "MB free" in result.output and "solver.output_rate" in result.output
    assert not out.exists()


def test_a_disk_that_fills_up_mid_run_exits_2_and_the_file_says_failed(tmp_path, monkeypatch):
    import errno

    from clearsim import runner
    from clearsim.io.hdf5 import ResultWriter

    real_append = ResultWriter.append

    def full_after_the_first(self, times, datasets):
        if self.rows:
            raise OSError(errno.ENOSPC, "No space left on device")
        real_append(self, times, datasets)

    monkeypatch.setattr(ResultWriter, "append", full_after_the_first)
    monkeypatch.setattr(runner, "FLUSH_SECONDS", 0.0)  # every chunk written as it comes
    out = tmp_path / "sc.h5"
    result = invoke("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=2ms")
    assert result.exit_code == 2, result.output
    assert "the disk is full" in result.output and "Traceback" not in result.output
    with h5py.File(out) as handle:
        assert not handle.attrs["complete"] and "disk is full" in handle.attrs["status"]
        assert 0 < len(handle["time"]) < 201


@pytest.mark.parametrize("command", ["plot", "sweep"])
def test_an_output_folder_under_a_file_exits_2_with_the_path(tmp_path, command):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    if command == "plot":
        result_file = tmp_path / "sc.h5"
        assert invoke("run", SLIDER_CRANK, "-o", result_file, "--set", "solver.t_end=1ms").exit_code == 0
        args = ("plot", result_file, "-o", blocker / "figures")
    else:
        args = ("sweep", SLIDER_CRANK, "--clearance", "0.1", "--set", "solver.t_end=1ms", "-o", blocker / "sweep")
    result = invoke(*args)
    assert result.exit_code == 2, result.output
    assert str(blocker) in result.output and "Traceback" not in result.output
