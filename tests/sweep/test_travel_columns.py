"""The sweep summary of a mechanism with a `travel:` block: the travel figures of each case in the printed table
and in summary.csv (closing time, zone speed, overtravel, rebound, within the envelope), as the case's result file
stores them; no such columns without the block."""

import csv
import json
from pathlib import Path
from types import SimpleNamespace

import h5py
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.sweep.summary import columns, percentiles

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
SHORT = "solver.t_end=3ms"
# the slider moves inwards (negative travel), ~7 mm in the first millisecond: the ideal case leaves this envelope
# (upper limit −10 mm from 1 ms on) before 1 ms
TRAVEL = ("travel: {sensor: slider_displacement, contact_touch: -30 mm, speed_zone: [-20 mm, -40 mm], "
          "envelope: {lower: [[0 ms, -70 mm], [3 ms, -70 mm]], upper: [[0 ms, 2 mm], [1 ms, -10 mm], [3 ms, -10 mm]]}}")
COLUMNS = {"operating_time_ms": ("operating_time_s", 1e3), "zone_speed_m_s": ("zone_speed_m_per_s", 1.0),
           "overtravel_mm": ("overtravel_m", 1e3), "rebound_mm": ("rebound_m", 1e3)}
runner = CliRunner()


def sweep(tmp_path: Path, config: Path, name: str):
    out = tmp_path / name
    result = runner.invoke(app, ["sweep", str(config), "--set", SHORT, "--clearance", "0.5", "--workers", "1",
                                 "-o", str(out)], terminal_width=200)
    assert result.exit_code == 0, result.output
    with (out / "summary.csv").open(newline="") as handle:
        return out, result.output, list(csv.DictReader(handle))


def assert_rows_are_the_case_files_travel_figures(out: Path, rows: list[dict]):
    """Each summary row's travel columns equal the `travel_figures` its case's result file stores."""
    for row in rows:
        with h5py.File(out / f"{row['case']}.h5") as f:
            stored = json.loads(f.attrs["travel_figures"])
        for column, (key, scale) in COLUMNS.items():
            assert float(row[column]) == pytest.approx(stored[key] * scale, rel=1e-12), (row["case"], column)
        assert row["inside_envelope"] == ("yes" if stored["inside_envelope"] else "no")


def test_each_case_shows_its_travel_figures_and_whether_it_kept_to_the_envelope(tmp_path):
    config = tmp_path / "sc_travel.yaml"
    config.write_text(SLIDER_CRANK.read_text().replace("output: {", f"{TRAVEL}\noutput: {{", 1))
    out, output, rows = sweep(tmp_path, config, "sweep")
    assert [row["case"] for row in rows] == ["ideal", "clearance-0.5_mm"]
    assert_rows_are_the_case_files_travel_figures(out, rows)
    assert rows[0]["inside_envelope"] == "no" and 0.0 < float(rows[0]["operating_time_ms"]) < 3.0
    header = next(line for line in output.splitlines() if "closing" in line)
    assert all(title in output for title in ("closing", "zone", "overtravel", "rebound", "envelope"))
    assert header.index("closing") < header.index("zone")


def test_a_mechanism_without_a_travel_block_has_no_travel_columns(tmp_path):
    _, output, rows = sweep(tmp_path, SLIDER_CRANK, "plain")
    assert not {*COLUMNS, "inside_envelope"} & set(rows[0]) and "closing" not in output


def test_monte_carlo_percentiles_cover_the_travel_figures():
    plan = SimpleNamespace(labels=[], case=lambda name: SimpleNamespace(ideal=name == "ideal"))
    header = columns(plan, [], travel=True)
    times = [60.0, 61.0, 62.0, 63.0, 64.0]
    rows = [{"case": "ideal", "status": "complete", "operating_time_ms": 0.0}]
    rows += [{"case": f"sample-{k}", "status": "complete", "operating_time_ms": t, "inside_envelope": "yes"}
             for k, t in enumerate(times)]
    entries = {entry["figure"]: entry for entry in percentiles(plan, header, rows)}
    assert entries["operating_time_ms"]["cases"] == 5 and entries["operating_time_ms"]["p50"] == 62.0
    assert entries["operating_time_ms"]["p25"] == 61.0 and "inside_envelope" not in entries
