"""The sweep summary of the bundled hydraulic breaker: each case's travel figures over its full stroke in
summary.csv, as its result file stores them."""

import csv
from pathlib import Path

from typer.testing import CliRunner

from clearsim.cli import app

from tests.sweep.test_travel_columns import assert_rows_are_the_case_files_travel_figures

HYDRAULIC_BREAKER = Path(__file__).resolve().parents[2] / "configs" / "uhv_breaker_hydraulic.yaml"
runner = CliRunner()


def test_the_hydraulic_breaker_sweep_writes_each_clearance_case_travel_figures(tmp_path):
    out = tmp_path / "sweep"
    result = runner.invoke(app, ["sweep", str(HYDRAULIC_BREAKER), "--clearance", "0.01,0.1", "--no-ideal",
                                 "--set", "solver.output_rate=10kHz", "--workers", "2", "-o", str(out)],
                           terminal_width=200)
    assert result.exit_code == 0, result.output
    with (out / "summary.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [row["case"] for row in rows] == ["clearance-0.01_mm", "clearance-0.1_mm"]
    assert_rows_are_the_case_files_travel_figures(out, rows)
    for row in rows:
        assert 50.0 < float(row["operating_time_ms"]) < 150.0  # the stroke reached the contact touch
        assert float(row["zone_speed_m_s"]) > 1.0
