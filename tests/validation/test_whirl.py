"""The whirl warning on the bundled models: the journal of J whirls on the UHV breaker with A and J at 0.01 mm
(docs/validation.md §6); the rattling pin of the Flores slider-crank does not."""

import csv
import re
from pathlib import Path

import numpy as np
import pytest

from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare, run_to_file, summarize

FLORES = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
WARNING = re.compile(r"joint (\w+): the journal whirls around its bearing from ([\d.]+) to ([\d.]+) ms, (\d+) orbits")


def run(tmp_path, config, *overrides):
    loaded = load_mechanism(config, overrides)
    output = tmp_path / "run.h5"
    report = run_to_file(prepare(loaded), loaded, output)
    assert report.complete, report.status
    return report, output


def whirl_lines(lines):
    return [WARNING.match(line) for line in lines if WARNING.match(line)]


def crossings(angle: np.ndarray) -> int:
    """How many multiples of 2π the angle passes from its first to its last sample."""
    return abs(int(np.floor(angle[-1] / (2 * np.pi))) - int(np.floor(angle[0] / (2 * np.pi))))


def test_the_journal_of_j_whirls_on_the_bundled_breaker(tmp_path):
    """A and J at 0.01 mm (the file's): J's journal rolls round its bore from mid-stroke (≈ 80 orbits at ≈ 2 kHz);
    `clearsim run` prints it under its summary, and the file keeps it in its `warnings`."""
    output = tmp_path / "uhv.h5"
    printed = CliRunner().invoke(app, ["run", "-o", str(output)])
    assert printed.exit_code == 0, printed.output
    found = whirl_lines(line.removeprefix("warning: ") for line in printed.output.splitlines())
    assert [m.group(1) for m in found] == ["J"], printed.output
    assert [m.group(0) for m in whirl_lines(summarize(output).warnings)] == [found[0].group(0)]
    start, end, orbits = float(found[0].group(2)) * 1e-3, float(found[0].group(3)) * 1e-3, int(found[0].group(4))
    data = read_result(output)
    t, e = data["time"], data["joints/J/eccentricity"]
    angle = np.unwrap(np.arctan2(e[:, 1], e[:, 0]))  # global frame: the board turns 0.02 turns meanwhile
    inside = (t >= start - 5e-5) & (t <= end + 5e-5)  # the window is printed to 0.1 ms
    assert abs(crossings(angle[inside]) - orbits) <= 1, (crossings(angle[inside]), orbits)
    assert 70 <= orbits <= 90, orbits  # clearsim: 79 in 42.8–81.0 ms
    before = (t >= start - 0.010) & (t < start)
    assert np.ptp(angle[before]) < 2 * np.pi  # no full turn in the 10 ms before: the window starts with the whirl
    rate = np.gradient(angle, t) / (2 * np.pi)
    assert np.mean(np.abs(rate[inside]) > 1000.0) > 0.8  # Hz: the orbit is sustained over the window


def test_the_rattling_pin_of_the_flores_slider_crank_does_not_whirl(tmp_path):
    """The pin hits the slider's bore at the load reversals: ten crank turns, no whirl (its orbit angle follows the
    load, one turn per crank turn, against 0.27 turns of the rod's swing: 3.3 orbits per turn of relative rotation,
    under the criterion's 10)."""
    report, _ = run(tmp_path, FLORES, "solver.t_end=120ms")
    assert not whirl_lines(report.warnings), report.warnings


def test_a_sweep_lists_the_whirl_in_its_warnings_column(tmp_path):
    """A and J at 0.05 mm: J whirls (≈ 16 orbits at ≈ 540 Hz); the ideal case does not."""
    out = tmp_path / "sweep"
    printed = CliRunner().invoke(app, ["sweep", "--clearance", "0.05", "--joints", "A,J", "--workers", "1", "-o", str(out)])
    assert printed.exit_code == 0, printed.output
    with open(out / "summary.csv", newline="") as handle:
        rows = {row["case"]: row["warnings"] for row in csv.DictReader(handle)}
    assert rows["ideal"] == ""
    assert [m.group(1) for m in whirl_lines(rows["clearance-0.05_mm"].split("\n"))] == ["J"], rows
    assert "warning: 1 case with warnings (clearance-0.05_mm)" in printed.output


def test_the_journal_of_j_does_not_whirl_behind_an_axially_compliant_upper_linking_board(tmp_path):
    """The whirl is a rigid chain's: with the upper linking board (J's bearing) at 1 GN/m, ζ = 0.02, J's journal
    turns 3.9 turns in all over the stroke, back and forth, and the run does not warn of a whirl."""
    report, _ = run(tmp_path, BUNDLED_CONFIG,
                    "bodies.upper_linking_board.flexible={model: axial, axial_stiffness: 1 GN/m, damping_ratio: 0.02}")
    assert not whirl_lines(report.warnings), report.warnings
