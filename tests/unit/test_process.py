"""The quick exit: the heap is frozen at exit, once, and every exit handler still runs."""

import atexit
import subprocess
import sys
import textwrap

from clearsim import process


def test_the_freeze_is_registered_once_per_process(monkeypatch):
    registered = []
    monkeypatch.setattr(process, "_registered", False)
    monkeypatch.setattr(atexit, "register", registered.append)
    process.exit_without_final_collection()
    process.exit_without_final_collection()
    assert registered == [process.gc.freeze]


def test_a_process_that_exits_frozen_still_runs_its_exit_handlers_and_closes_its_files(tmp_path):
    """A handler registered after the freeze runs before it (atexit is last in, first out); a file closed by the code
    that wrote it is complete, a temporary folder is removed."""
    script = textwrap.dedent(f"""
        import atexit, tempfile
        from pathlib import Path
        from clearsim.process import exit_without_final_collection
        exit_without_final_collection()
        folder = tempfile.TemporaryDirectory(dir={str(tmp_path)!r})
        Path(folder.name, "inside").write_text("x")
        with open({str(tmp_path / "result.txt")!r}, "w") as handle:
            handle.write("complete")
        atexit.register(lambda: Path({str(tmp_path / "handler.txt")!r}).write_text("ran"))
    """)
    subprocess.run([sys.executable, "-c", script], check=True, timeout=60)
    assert (tmp_path / "result.txt").read_text() == "complete"
    assert (tmp_path / "handler.txt").read_text() == "ran"
    assert [p.name for p in tmp_path.iterdir()] in (["result.txt", "handler.txt"], ["handler.txt", "result.txt"])
