"""No fault loses data: a full disk or a file size limit, and runs started together on one -o.

Real faults, in real processes: the file size limit of `ulimit -f` (RLIMIT_FSIZE, set in the child; Python ignores
SIGXFSZ, so a write past it fails with EFBIG as a write to a full disk fails with ENOSPC), a small tmpfs where
mounting one is allowed, and two `clearsim run` processes writing the same file. Where a test needs the run to get
past a check (to reach the write that fails), the child switches that check off before it runs the CLI.
"""

import os
import resource
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import h5py
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.io.hdf5 import NotAResultFile, read_attributes
from clearsim.io.files import abandoned_partials, keep_as_previous, locate, partial_name, publish

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = str(CONFIGS / "slider_crank_flores.yaml")
UHV = str(CONFIGS / "uhv_breaker.yaml")
UHV_SAMPLES = 8501  # 85 ms at 100 kHz

NO_PREFLIGHT = "import clearsim.runner as r; r.check_free_space = lambda path, needed: None"
EVERY_CHUNK = "import clearsim.runner as r; r.FLUSH_SECONDS = 0.0"  # each chunk appended (and checked) as it comes
NO_ROOM_CHECK = "import clearsim.io.hdf5 as h; h.ResultWriter._make_room = lambda self, needed: None"


def clearsim(*args, file_size_limit: int | None = None, patches=(), cwd=None) -> subprocess.CompletedProcess:
    """`clearsim args…` in a child process, under a file size limit (bytes), after the patches (Python lines)."""
    script = "\n".join([*patches, "from clearsim.cli import app", "import sys",
                        f"sys.argv = ['clearsim'] + {[str(a) for a in args]!r}", "app()"])

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        if file_size_limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (file_size_limit, file_size_limit))

    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600,
                          preexec_fn=limit, cwd=cwd, env=os.environ.copy())


@pytest.fixture(scope="module", autouse=True)
def compiled_kernels(tmp_path_factory):
    """The kernels in the cache before any child runs under a file size limit (which would fail to write them)."""
    out = tmp_path_factory.mktemp("warm") / "warm.h5"
    done = clearsim("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=0.1ms")
    assert done.returncode == 0, done.stdout + done.stderr


def assert_clean_exit_2(done: subprocess.CompletedProcess, path: Path) -> str:
    """Exit 2, one message naming the file, no traceback (a SIGSEGV is -11, an uncaught exception 1)."""
    text = done.stdout + done.stderr
    assert done.returncode == 2, text
    assert "Traceback" not in text and "Exception ignored" not in text, text
    assert f"cannot write the result file {path}" in text, text
    return text


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))


def test_a_run_refused_before_it_starts_when_the_file_size_limit_is_too_small(tmp_path):
    """It died with SIGSEGV, or an h5py RuntimeError traceback, leaving status = 'running'."""
    out = tmp_path / "sc.h5"
    out.write_bytes(b"an earlier result")
    done = clearsim("run", SLIDER_CRANK, "-o", out, file_size_limit=100_000)
    text = assert_clean_exit_2(done, out)
    assert "the file size limit of this process (ulimit -f) is 0.0954 MB" in text and "the run writes about" in text
    assert out.read_bytes() == b"an earlier result"  # not moved aside: nothing was written
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sc.h5"]


def test_a_run_whose_compressed_file_fits_is_not_refused_by_its_uncompressed_size(tmp_path):
    """The check before the run counted the uncompressed histories (2.2 MB here) and refused a 0.5 MB file."""
    out = tmp_path / "sc.h5"
    done = clearsim("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=2ms", file_size_limit=1_000_000)
    assert done.returncode == 0, done.stdout + done.stderr
    with h5py.File(out, "r") as handle:
        assert bool(handle.attrs["complete"]) and out.stat().st_size < 1_000_000


def test_a_file_size_limit_reached_mid_run_leaves_the_samples_written_flagged(tmp_path):
    out = tmp_path / "uhv.h5"
    done = clearsim("run", UHV, "-o", out, file_size_limit=2_000_000, patches=[NO_PREFLIGHT, EVERY_CHUNK])
    text = assert_clean_exit_2(done, out)
    assert "the file size limit is reached: the next write needs" in text and "the whole run needs about" in text
    assert f"samples written before are in {out}, flagged complete = false" in text
    with h5py.File(out, "r") as handle:
        assert not handle.attrs["complete"]
        assert handle.attrs["status"].startswith(f"failed: cannot write the result file {out}: the file size limit")
        assert 0 < len(handle["time"]) < UHV_SAMPLES
        assert len(handle["sensors/sealing_rod_displacement"]) == len(handle["time"])
    assert leftovers(tmp_path) == []


def test_a_write_that_fails_past_the_checks_exits_2_without_a_crash(tmp_path):
    """The checks can be outrun (another process fills the disk between the check and the write): the write fails
    inside libhdf5, the file is closed and flagged, or removed when the failure left it unreadable."""
    out = tmp_path / "uhv.h5"
    out.write_bytes(b"an earlier result")
    done = clearsim("run", UHV, "-o", out, file_size_limit=2_000_000,
                    patches=[NO_PREFLIGHT, EVERY_CHUNK, NO_ROOM_CHECK])
    text = assert_clean_exit_2(done, out)
    assert "the whole run needs about" in text
    if "was removed" in text:
        assert out.read_bytes() == b"an earlier result"
    else:
        assert not h5py.File(out, "r").attrs["complete"]
        assert (tmp_path / "uhv.previous.h5").read_bytes() == b"an earlier result"
    assert leftovers(tmp_path) == []


def test_a_result_file_that_cannot_be_created_is_named(tmp_path):
    out = tmp_path / "sc.h5"
    done = clearsim("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=2ms", file_size_limit=1024,
                    patches=[NO_PREFLIGHT])
    assert_clean_exit_2(done, out)
    assert list(tmp_path.iterdir()) == []


def test_sweep_cases_that_cannot_be_written_fail_with_their_file_and_the_room_needed(tmp_path):
    """The pool's processes died (`worker lost: BrokenProcessPool`, no file named)."""
    out = tmp_path / "sweep"
    done = clearsim("sweep", SLIDER_CRANK, "--set", "solver.t_end=2ms,3ms", "--no-ideal", "--workers", 2, "-o", out,
                    file_size_limit=100_000)
    text = done.stdout + done.stderr
    assert done.returncode == 2, text
    assert "Traceback" not in text and "worker lost" not in text, text
    for case in ("solver.t_end-2ms", "solver.t_end-3ms"):
        assert f"cannot write the result file {out / case}.h5: the run writes about" in text
    assert "ulimit -f" in text and not list(out.glob("*.h5")) and leftovers(out) == []


def test_sweep_cases_stopped_mid_run_keep_their_samples_flagged(tmp_path):
    """The pool's processes are spawned: the checks are switched off in each by a sitecustomize module."""
    hooks = tmp_path / "hooks"
    hooks.mkdir()
    (hooks / "sitecustomize.py").write_text(f"{NO_PREFLIGHT}\n{EVERY_CHUNK}\n")
    out = tmp_path / "sweep"
    done = subprocess.run(
        [sys.executable, "-m", "clearsim.cli", "sweep", UHV, "--set", "solver.t_end=85ms,84ms", "--no-ideal",
         "--workers", "2", "-o", str(out)], capture_output=True, text=True, timeout=600,
        preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (2_000_000, 2_000_000)),
        env=os.environ | {"PYTHONPATH": str(hooks)})
    text = done.stdout + done.stderr
    assert done.returncode == 2, text
    assert "Traceback" not in text and "worker lost" not in text, text
    for case in ("solver.t_end-85ms", "solver.t_end-84ms"):
        assert f"cannot write the result file {out / case}.h5: the file size limit is reached" in text
        with h5py.File(out / f"{case}.h5", "r") as handle:
            assert not handle.attrs["complete"] and 0 < len(handle["time"]) < UHV_SAMPLES
    assert leftovers(out) == []


def test_a_diagnosis_whose_runs_cannot_be_written_stops_with_the_file(tmp_path):
    """It said the model 'does not run to the end' (worker lost), as if the model were broken."""
    record = tmp_path / "bench.csv"
    synthesized = CliRunner().invoke(app, ["synthesize", SLIDER_CRANK, "--sensors", "slider_displacement",
                                           "--rate", "20kHz", "--seed", "1", "-o", str(record)])
    assert synthesized.exit_code == 0, synthesized.output
    done = clearsim("diagnose", SLIDER_CRANK, "--measured", record, "-o", tmp_path / "report", "--workers", 1,
                    "--candidates", "clearance", file_size_limit=20_000)
    text = done.stdout + done.stderr
    assert done.returncode == 2, text
    assert "Traceback" not in text and "does not run to the end" not in text, text
    assert f"cannot write the result file {tmp_path / 'report' / 'runs'}" in text and "ulimit -f" in text


@pytest.fixture
def small_tmpfs(tmp_path):
    """A 2 MB tmpfs (root, and a kernel that lets it mount one); skipped elsewhere."""
    folder = tmp_path / "tmpfs"
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(folder)], capture_output=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.decode().strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


def test_a_disk_that_fills_up_mid_run_leaves_the_samples_written_flagged(small_tmpfs):
    out = small_tmpfs / "uhv.h5"
    done = clearsim("run", UHV, "-o", out, patches=[NO_PREFLIGHT, EVERY_CHUNK])
    text = assert_clean_exit_2(done, out)
    assert f"the disk is full: the next write needs" in text and f"{small_tmpfs} has" in text
    with h5py.File(out, "r") as handle:
        assert not handle.attrs["complete"] and "the disk is full" in handle.attrs["status"]
        assert 0 < len(handle["time"]) < UHV_SAMPLES
    assert leftovers(small_tmpfs) == []


# each run waits, as it starts writing, until the other gets there too: they write at once, every time
MEET_AS_WRITING_STARTS = textwrap.dedent("""
    import os, pathlib, time
    import clearsim.io.hdf5 as h
    start_writing = h.ResultWriter.__init__
    def meet(self, *args, **kwargs):
        here = pathlib.Path(os.environ["MEETING_POINT"])
        (here / str(os.getpid())).touch()
        deadline = time.monotonic() + 60
        while len(list(here.iterdir())) < 2 and time.monotonic() < deadline:
            time.sleep(0.005)
        start_writing(self, *args, **kwargs)
    h.ResultWriter.__init__ = meet
""")


@pytest.mark.parametrize("locking", ["TRUE", "FALSE"])
@pytest.mark.parametrize("meeting", [True, False], ids=["writing-at-once", "started-together"])
def test_runs_on_one_output_both_keep_their_result(tmp_path, locking, meeting):
    """One moved the other's file aside, then read back a file that was not its own and still locked (exit 1,
    NotAResultFile); without HDF5 file locking, the second file created over the first: one result was left."""
    out, meeting_point = tmp_path / "out" / "sc.h5", tmp_path / "meeting"
    out.parent.mkdir()
    meeting_point.mkdir()
    end_times = ("2ms", "2.01ms")  # which file is which run's
    patches = [MEET_AS_WRITING_STARTS] if meeting else []
    script = "\n".join([*patches, "from clearsim.cli import app", "app()"])
    environment = os.environ | {"HDF5_USE_FILE_LOCKING": locking, "MEETING_POINT": str(meeting_point)}
    runs = [subprocess.Popen([sys.executable, "-c", script, "run", SLIDER_CRANK, "--set", f"solver.t_end={t_end}",
                              "-o", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=environment) for t_end in end_times]
    for run in runs:
        stdout, stderr = run.communicate(timeout=300)
        assert run.returncode == 0, stdout + stderr
        assert "Traceback" not in stderr and "complete →" in stdout, stdout + stderr
    assert sorted(p.name for p in out.parent.iterdir()) == ["sc.h5", "sc.previous.h5"]
    kept = set()
    for name in ("sc.h5", "sc.previous.h5"):
        with h5py.File(out.parent / name, "r") as handle:
            assert handle.attrs["complete"]
            kept.add(handle.attrs["config_yaml"].split("t_end: ")[1].split("\n")[0])
    assert len(kept) == 2, kept


def test_a_result_moved_aside_between_finding_and_opening_it_is_read_where_it_went(tmp_path):
    """A later run with the same output name renamed the file after `report.output` found it and before it was
    opened (seen once as exit 1 in the two-runs test above): it is read once more where it is now."""
    from clearsim.runner import read_where_it_is

    out, aside = tmp_path / "sc.h5", tmp_path / "sc.previous.h5"
    aside.write_text("the run's result")

    class Report:  # `output` found the file at `out`, then the other run moved it
        places = iter([out, aside])

        @property
        def output(self):
            return next(self.places)

    assert read_where_it_is(Report(), lambda path: path.read_text()) == "the run's result"

    class Unmoved:
        output = out  # missing, and still where it was looked for: the error is not hidden

    with pytest.raises(FileNotFoundError):
        read_where_it_is(Unmoved(), lambda path: path.read_text())


def test_a_published_file_is_found_where_a_later_one_with_its_name_moved_it(tmp_path):
    out = tmp_path / "run.h5"
    first, second = partial_name(out), partial_name(out)
    assert first != second and first.parent == tmp_path and first.name.startswith(".run.h5.")
    assert abandoned_partials(out) == []  # this process writes them
    assert first.suffix == ".tmp"  # no reader of results (*.h5) takes it for one
    first.write_text("first")
    second.write_text("second")
    assert publish(first, out) is None
    identity = out.stat()
    assert publish(second, out) == tmp_path / "run.previous.h5"
    assert locate(out, identity) == tmp_path / "run.previous.h5"
    assert locate(out, out.stat()) == out and out.read_text() == "second"
    out.write_text("third")
    assert keep_as_previous(out) == tmp_path / "run.previous-2.h5"


def test_a_file_being_written_is_no_result_to_the_readers_of_a_folder(tmp_path):
    from clearsim.plot.sweep import result_files

    (tmp_path / "case.h5").write_bytes(b"")
    partial_name(tmp_path / "other.h5").write_bytes(b"")
    assert result_files(tmp_path) == [tmp_path / "case.h5"]


def test_a_report_reads_its_own_file_after_a_later_run_took_the_name(tmp_path):
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare, run_to_file

    out = tmp_path / "sc.h5"
    reports = []
    for t_end in ("1ms", "1.5ms"):
        loaded = load_mechanism(SLIDER_CRANK, [f"solver.t_end={t_end}"])
        reports.append(run_to_file(prepare(loaded), loaded, out))
    assert reports[0].output == tmp_path / "sc.previous.h5" and reports[1].output == out
    assert "t_end: 1ms\n" in read_attributes(reports[0].output)["config_yaml"]


def test_a_file_left_by_a_killed_run_is_kept_as_previous_by_the_next_run(tmp_path):
    out = tmp_path / "sc.h5"
    killed = subprocess.Popen([sys.executable, "-m", "clearsim.cli", "run", SLIDER_CRANK, "-o", str(out), "--set",
                               "solver.t_end=2s", "--set", "solver.output_rate=10kHz"], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".sc.h5.*.tmp")) and time.monotonic() < deadline and killed.poll() is None:
        time.sleep(0.1)
    time.sleep(1.0)  # samples appended meanwhile
    killed.kill()
    killed.wait()
    assert abandoned_partials(out) and not out.exists()
    done = clearsim("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=1ms")
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sc.h5", "sc.previous.h5"]
    try:  # killed between two appends, as nearly always, it reads as a run that says it did not end
        attrs = read_attributes(tmp_path / "sc.previous.h5")
    except NotAResultFile:  # killed inside a write
        return
    assert not attrs["complete"] and attrs["status"] == "running"


def test_only_files_of_processes_gone_are_taken_up(tmp_path):
    import socket

    from clearsim.io.files import adopt_abandoned

    ended = subprocess.Popen(["true"])
    ended.wait()
    out = tmp_path / "case.h5"
    host = socket.gethostname()
    gone = tmp_path / f".case.h5.{host}.{ended.pid}.0a0a0a0a.tmp"
    running = tmp_path / f".case.h5.{host}.{os.getpid()}.0b0b0b0b.tmp"
    elsewhere = tmp_path / f".case.h5.another-{host}.{ended.pid}.0c0c0c0c.tmp"
    for partial in (gone, running, elsewhere):
        partial.write_text(partial.name)
    adopt_abandoned(out)
    assert out.read_text() == gone.name
    assert running.exists() and elsewhere.exists() and not gone.exists()


def test_a_table_that_would_not_fit_is_refused_before_it_is_written(tmp_path, monkeypatch):
    """A long run's episode tables come after its samples: written into the room kept to close the file, they could
    fail inside libhdf5 and take the file with them."""
    import numpy as np

    from clearsim.io import hdf5
    from clearsim.io.files import Room

    writer = hdf5.ResultWriter(tmp_path / "run.h5", "yaml: text")
    writer.append(np.arange(3.0), {"sensors/s": (np.ones(3), "m")})
    episodes = {"onset": (np.zeros(100_000), "s")}
    monkeypatch.setattr(hdf5, "room_for", lambda path: Room(hdf5.FINISH_BYTES + 700_000, "the disk is full", "…"))
    with pytest.raises(hdf5.NoRoom):
        writer.write_table("joints/A/episodes", episodes)
    assert writer.finish(False, "failed: the disk is full", {})
    attrs = read_attributes(tmp_path / "run.h5")
    assert attrs["status"] == "failed: the disk is full"
