"""`clearsim plot` and `clearsim draw` end to end: the figure sets, their stable names, valid images."""

import shutil
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.plot.animate import FRAMES
from clearsim.plot.figures import _inputs

from .conftest import SLIDER_CRANK, sweep_folder

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def assert_images(paths, size=None):
    """Each file exists, is not empty and decodes as an image (of the given format)."""
    for path in paths:
        assert path.exists() and path.stat().st_size > 0, path
        with Image.open(path) as image:
            image.verify()
            if size is not None:
                assert image.format == size


def written(result) -> list[Path]:
    return [Path(line.strip()) for line in result.stdout.splitlines() if line.strip()]


def test_one_run_gives_the_documented_figure_set(runs, tmp_path):
    result = invoke("plot", runs["clearance"], "--out", tmp_path)
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in written(result))
    assert names == ["sc-energy.png", "sc-joint-slider_pin.png", "sc-output.png", "sc-spectrum.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == names
    assert_images(written(result), "PNG")


def test_default_folder_is_the_files_folder(runs, tmp_path):
    source = shutil.copy(runs["clearance"], tmp_path / "run.h5")
    result = invoke("plot", source)
    assert result.exit_code == 0, result.output
    assert (tmp_path / "run-output.png").exists() and (tmp_path / "run-joint-slider_pin.png").exists()


def test_friction_run_has_the_friction_panel_and_an_ideal_run_no_joint_figure(runs, tmp_path):
    result = invoke("plot", runs["friction"], "--out", tmp_path / "f")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "f" / "friction-joint-slider_pin.png").exists()
    result = invoke("plot", runs["ideal"], "--out", tmp_path / "i")
    assert result.exit_code == 0, result.output
    assert not list((tmp_path / "i").glob("*joint*"))


def test_several_runs_are_overlaid(runs, tmp_path):
    result = invoke("plot", runs["ideal"], runs["clearance"], runs["small"], "--out", tmp_path)
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in written(result))
    assert names == ["compare-energy.png", "compare-joint-slider_pin.png", "compare-output.png", "compare-spectrum.png"]
    assert_images(written(result), "PNG")


@pytest.mark.parametrize("fmt, magic", [("svg", b"<?xml"), ("pdf", b"%PDF")])
def test_vector_formats(runs, tmp_path, fmt, magic):
    result = invoke("plot", runs["clearance"], "--out", tmp_path, "--format", fmt)
    assert result.exit_code == 0, result.output
    for path in written(result):
        assert path.suffix == f".{fmt}" and path.read_bytes().startswith(magic)


def test_sweep_folder_overlays_every_case_and_plots_the_summary(runs, tmp_path):
    folder = sweep_folder(tmp_path / "sweep-sc", {name: runs[name] for name in ("ideal", "clearance", "small")})
    (folder / "summary.csv").write_text(
        "case,reference,clearance,status,peak_acceleration_m_s2,acceleration_ratio,start_delay_ms,end_error_percent,"
        "max_contact_force_N[slider_pin],steps\n"
        "ideal,,,complete,19000.0,1.0,0.0,0.0,,65\n"
        "small,ideal,0.25 mm,complete,248000.0,12.8,0.09,0.17,35800.0,591\n"
        "clearance,ideal,0.5 mm,complete,325000.0,16.8,0.01,0.35,45800.0,511\n")
    result = invoke("plot", folder)
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in written(result))
    assert "sweep-output.png" in names and "sweep-merit.png" in names
    assert all(p.parent == folder for p in written(result))
    assert_images(written(result), "PNG")


def test_sweep_folder_without_summary_has_no_merit_figure(runs, tmp_path):
    sweep_folder(tmp_path, {name: runs[name] for name in ("ideal", "clearance")})
    result = invoke("plot", tmp_path, "--out", tmp_path / "figures")
    assert result.exit_code == 0, result.output
    assert not (tmp_path / "figures" / "sweep-merit.png").exists()
    assert (tmp_path / "figures" / "sweep-output.png").exists()


def test_animation_is_a_gif_with_few_frames(runs, tmp_path):
    result = invoke("plot", runs["clearance"], "--out", tmp_path, "--animate", "--exaggerate", "auto")
    assert result.exit_code == 0, result.output
    gif = tmp_path / "sc-animation.gif"
    assert gif in written(result)
    with Image.open(gif) as image:
        assert image.format == "GIF" and 2 < image.n_frames <= FRAMES
    assert not list(tmp_path.glob("*partial*"))


def test_measured_overlay(runs, tmp_path):
    csv = tmp_path / "bench.csv"
    csv.write_text("# bench\ntime [ms],slider_displacement [mm]\n0,0\n1,-0.5\n2,-3.0\n3,-8.0\n")
    result = invoke("plot", runs["clearance"], "--out", tmp_path, "--measured", csv)
    assert result.exit_code == 0, result.output
    assert_images([tmp_path / "sc-measured.png"], "PNG")


def test_incomplete_run_is_plotted_with_a_note(runs, tmp_path):
    import h5py

    source = shutil.copy(runs["clearance"], tmp_path / "cut.h5")
    with h5py.File(source, "r+") as handle:
        handle.attrs["complete"] = False
        handle.attrs["status"] = "interrupted at t = 3.000 ms"
    result = invoke("plot", source, "--out", tmp_path)
    assert result.exit_code == 0, result.output
    assert "note:" in result.output and "incomplete (interrupted at t = 3.000 ms)" in result.output


def test_draw_writes_the_mechanism(tmp_path):
    out = tmp_path / "drawing.png"
    result = invoke("draw", SLIDER_CRANK, "-o", out)
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == str(out)
    assert_images([out], "PNG")


def test_help_of_both_commands():
    for command in ("plot", "draw"):
        result = invoke(command, "--help")
        assert result.exit_code == 0 and "Usage" in result.output


def test_a_folder_that_no_sweep_made_plots_each_run_on_its_own(runs, tmp_path):
    shutil.copy(runs["clearance"], tmp_path / "crank.h5")
    shutil.copy(runs["friction"], tmp_path / "crank_with_friction.h5")  # another mechanism file, another day
    result = invoke("plot", tmp_path)
    assert result.exit_code == 0, result.output
    names = {p.name for p in written(result)}
    assert {"crank-output.png", "crank_with_friction-output.png"} <= names
    assert not any(name.startswith("sweep-") for name in names)  # never overlaid as if one sweep
    assert "is not a sweep folder (no readable cases.json): each run is plotted on its own" in " ".join(
        result.output.split())


def test_a_result_file_that_is_not_a_case_of_the_sweep_is_left_out_of_its_overlay(runs, tmp_path):
    folder = sweep_folder(tmp_path / "sweep", {"ideal": runs["ideal"], "c05": runs["clearance"]})
    shutil.copy(runs["friction"], folder / "stray.h5")
    notes: list = []
    (overlay,) = _inputs([folder], notes)
    assert sorted(path.name for path in overlay.files) == ["c05.h5", "ideal.h5"]
    assert any("left out stray.h5: not a case of the sweep" in note for note in notes)
    result = invoke("plot", folder)
    assert result.exit_code == 0 and "left out stray.h5" in " ".join(result.output.split()), result.output
    assert not (folder / "stray-output.png").exists()


def test_help_writes_flags_without_a_value():
    for command in ([], ["plot"], ["draw"], ["sweep"], ["synthesize"]):
        result = invoke(*command, "--help")
        assert result.exit_code == 0, result.output
        assert "<bool>" not in result.output and "--help" in result.output
    assert "--show" in invoke("plot", "--help").output


@pytest.mark.parametrize("command", ["plot", "draw"])
def test_a_value_after_a_flag_is_refused_not_taken_for_a_file(runs, tmp_path, command):
    source = runs["clearance"] if command == "plot" else SLIDER_CRANK
    result = invoke(command, source, "--show", "true", "-o", tmp_path / "out")
    assert result.exit_code == 2
    output = " ".join(result.output.split())
    assert "--show is a switch and takes no value" in output and "no such file" not in output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("name, fragment", [
    ("fig.txt", "its extension .txt is no figure format; name the format by the extension, one of"),
    ("fig", "it has no extension"),
])
def test_draw_refuses_an_extension_that_names_no_figure_format(tmp_path, name, fragment):
    result = invoke("draw", SLIDER_CRANK, "-o", tmp_path / name)
    assert result.exit_code == 2, result.output
    output = " ".join(result.output.split())
    assert fragment in output and "png" in output and "svg" in output and "hint: -o" in output
    assert not (tmp_path / name).exists() and "Traceback" not in output


def test_draw_writes_the_format_the_extension_names(tmp_path):
    result = invoke("draw", SLIDER_CRANK, "-o", tmp_path / "fig.jpg")
    assert result.exit_code == 0, result.output
    assert_images([tmp_path / "fig.jpg"], "JPEG")
    result = invoke("draw", SLIDER_CRANK, "-o", tmp_path / "fig.png", "--format", "svg")
    assert result.exit_code == 2 and "names the format png but --format svg" in " ".join(result.output.split())
    assert not (tmp_path / "fig.png").exists()
