"""Out of a terminal, `run` and `sweep` print a progress line now and then (the heartbeat in a log)."""

import re
from pathlib import Path

from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.heartbeat import Heartbeat, duration, time_left

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def test_a_line_per_interval_with_the_latest_progress_and_the_time_left():
    clock, lines = Clock(), []
    beat = Heartbeat(lines.append, "clearsim run", interval=10.0, clock=clock)
    beat.update("t = 0 of 80 ms", 0.0, 80.0)
    clock.now += 5.0
    beat.update("t = 10 of 80 ms", 10.0, 80.0)
    assert lines == []  # within the interval: nothing
    clock.now += 5.0
    beat.update("t = 20 of 80 ms", 20.0, 80.0)  # 20 of 80 in 10 s: 30 s left
    clock.now += 10.0
    beat.beat()  # nothing new, but the interval has passed: the ticker's line
    assert lines == ["clearsim run: t = 20 of 80 ms, 10 s elapsed, about 30 s left",
                     "clearsim run: t = 20 of 80 ms, 20 s elapsed, about 1 min 00 s left"]


def test_the_pace_is_measured_from_the_first_update_and_nothing_is_written_when_disabled():
    clock, lines = Clock(), []
    beat = Heartbeat(lines.append, "clearsim run", interval=1.0, clock=clock)
    clock.now += 30.0  # loading the kernels: no progress yet
    beat.update("t = 0", 0.0, 10.0)
    clock.now += 2.0
    beat.update("t = 5", 5.0, 10.0)
    assert lines == ["clearsim run: t = 0, 30 s elapsed", "clearsim run: t = 5, 32 s elapsed, about 2.0 s left"]
    quiet = Heartbeat(lines.append, "clearsim run", interval=0.0, clock=clock, enabled=False)
    with quiet:
        quiet.update("t = 5", 5.0, 10.0)
    assert len(lines) == 2


def test_durations_and_time_left():
    assert [duration(s) for s in (4.24, 42, 185, 7620)] == ["4.2 s", "42 s", "3 min 05 s", "2 h 07 min"]
    assert time_left(10.0, 0.0, 5.0) is None and time_left(10.0, 1.0, None) is None
    assert time_left(10.0, 1.0, 4.0) == 30.0


def test_run_prints_heartbeat_lines_when_its_output_is_not_a_terminal(tmp_path, monkeypatch):
    monkeypatch.setenv("CLEARSIM_HEARTBEAT_SECONDS", "0")
    result = CliRunner().invoke(app, ["run", str(SLIDER_CRANK), "-o", str(tmp_path / "r.h5")])
    assert result.exit_code == 0, result.output
    lines = re.findall(r"^clearsim run: t = ([\d.]+) of 24 ms simulated, [\d.]+ s elapsed", result.output, re.M)
    assert len(lines) >= 2 and float(lines[-1]) == 24.0


def test_sweep_prints_heartbeat_lines_when_its_output_is_not_a_terminal(tmp_path, monkeypatch):
    monkeypatch.setenv("CLEARSIM_HEARTBEAT_SECONDS", "0.05")
    result = CliRunner().invoke(app, ["sweep", str(SLIDER_CRANK), "--clearance", "0.1,0.5", "--no-ideal",
                                      "--set", "solver.t_end=2ms", "--workers", "1", "-o", str(tmp_path / "sweep")])
    assert result.exit_code == 0, result.output
    assert "clearsim sweep: 0 of 2 cases finished" in result.output
    assert re.search(r"^clearsim sweep: 2 of 2 cases finished \(last: .*: complete\), [\d.]+ s elapsed", result.output,
                     re.M), result.output


def test_the_last_progress_is_written_when_the_heartbeat_stops_and_only_if_unwritten():
    """A sweep whose last case ended between two beats left its log at '1 of 2 cases finished'."""
    clock, lines = Clock(), []
    with Heartbeat(lines.append, "clearsim sweep", interval=60.0, clock=clock) as beat:
        clock.now += 61.0
        beat.update("1 of 2 cases finished", 1.0, 2.0)
        clock.now += 1.0
        beat.update("2 of 2 cases finished", 2.0, 2.0)
    assert lines == ["clearsim sweep: 1 of 2 cases finished, 1 min 01 s elapsed",
                     "clearsim sweep: 2 of 2 cases finished, 1 min 02 s elapsed, about 0.0 s left"]
    with Heartbeat(lines.append, "clearsim sweep", interval=0.0, clock=clock) as beat:
        beat.update("2 of 2 cases finished", 2.0, 2.0)
    assert len(lines) == 3  # written at the update: not again at the stop
