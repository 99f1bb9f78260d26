"""`clearsim run` with a `travel:` block: the travel figures in the summary and the result file; bad blocks exit 2
at their place."""

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.travel import envelope_check

UHV = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "uhv_breaker.yaml"
OUTPUT_LINE = "output: {displacement"
ZONE = "sensor: contact_displacement, contact_touch: 250 mm, speed_zone: [230 mm, 250 mm]"
runner = CliRunner()


def with_travel(tmp_path, block: str) -> Path:
    """The bundled UHV breaker with `travel: {block}` added before its `output:` line."""
    text = UHV.read_text()
    assert OUTPUT_LINE in text
    config = tmp_path / "uhv_travel.yaml"
    config.write_text(text.replace(OUTPUT_LINE, f"travel: {{{block}}}\n{OUTPUT_LINE}", 1))
    return config


def crossing_bracket(time, travel, position):
    """The two sample times between which the travel first reaches `position`."""
    i = int(np.argmax(travel >= position))
    return time[i - 1], time[i]


def test_a_uhv_run_prints_and_stores_the_travel_figures(tmp_path):
    config = with_travel(tmp_path, "sensor: contact_displacement, contact_touch: 250 mm, "
                                   "speed_zone: [230 mm, 250 mm], damping_start: 280 mm")
    out = tmp_path / "uhv.h5"
    result = runner.invoke(app, ["run", str(config), "-o", str(out)], terminal_width=200)
    assert result.exit_code == 0, result.output
    with h5py.File(out) as f:
        figures = json.loads(f.attrs["travel_figures"])
        time, travel = f["time"][()], f["sensors/contact_displacement"][()]
    assert figures["sensor"] == "contact_displacement"
    touch = figures["operating_time_s"]
    early, late = crossing_bracket(time, travel, 0.250)
    assert early <= touch <= late
    (start_early, start_late), (end_early, end_late) = (crossing_bracket(time, travel, x) for x in (0.230, 0.250))
    assert 0.020 / (end_late - start_early) <= figures["zone_speed_m_per_s"] <= 0.020 / (end_early - start_late)
    assert figures["total_travel_m"] == pytest.approx(abs(travel[-1] - travel[0]), rel=1e-12)
    assert figures["overtravel_m"] == pytest.approx(max(0.0, np.max(travel - travel[-1])), rel=1e-12, abs=1e-15)
    assert figures["damping_duration_s"] > 0.0
    for label, value in (("time to contact touch", f"{touch * 1e3:.4g} ms"),
                         ("speed-zone average speed", f"{figures['zone_speed_m_per_s']:.4g} m/s"),
                         ("total travel", f"{figures['total_travel_m'] * 1e3:.4g} mm"),
                         ("overtravel", "mm"), ("rebound", "mm"),
                         ("damping-zone duration", f"{figures['damping_duration_s'] * 1e3:.4g} ms")):
        line = next((text for text in result.output.splitlines() if f"contact_displacement: {label}" in text), "")
        assert value in line, (label, result.output)


def test_a_run_with_an_envelope_says_where_the_curve_leaves_it(tmp_path):
    """The UHV stroke starts slower than the lower limit rises (3 mm/ms): it leaves the envelope at once."""
    lower, upper = [[0.0, 0.0], [0.040, 0.120]], [[0.0, 0.005], [0.040, 0.300]]
    config = with_travel(tmp_path, f"{ZONE}, envelope: {{lower: [[0 ms, 0 mm], [40 ms, 120 mm]], "
                                   "upper: [[0 ms, 5 mm], [40 ms, 300 mm]]}")
    out = tmp_path / "uhv.h5"
    result = runner.invoke(app, ["run", str(config), "-o", str(out), "--set", "solver.t_end=40ms"], terminal_width=200)
    assert result.exit_code == 0, result.output
    with h5py.File(out) as f:
        figures = json.loads(f.attrs["travel_figures"])
        time, travel = f["time"][()], f["sensors/contact_displacement"][()]
    assert figures["inside_envelope"] is False
    for key, value in envelope_check(time, travel, lower, upper).items():
        assert figures[key] == pytest.approx(value, rel=1e-12), key
    below = np.interp(time, *np.array(lower).T) - travel
    assert figures["envelope_largest_excursion_m"] == pytest.approx(below.max(), rel=1e-9)
    for label, value in (("within the envelope", "no"),
                         ("leaves the envelope at", f"{figures['envelope_first_outside_s'] * 1e3:.4g} ms"),
                         ("largest excursion", f"{figures['envelope_largest_excursion_m'] * 1e3:.4g} mm at "
                                               f"{figures['envelope_largest_excursion_at_s'] * 1e3:.4g} ms")):
        line = next(text for text in result.output.splitlines() if f"contact_displacement: {label}" in text)
        assert value in line, (label, result.output)


def test_a_run_ending_before_contact_touch_says_not_reached(tmp_path):
    config = with_travel(tmp_path, "sensor: contact_displacement, contact_touch: 250 mm, speed_zone: [230 mm, 250 mm]")
    out = tmp_path / "uhv.h5"
    result = runner.invoke(app, ["run", str(config), "-o", str(out), "--set", "solver.t_end=5ms"], terminal_width=200)
    assert result.exit_code == 0, result.output
    with h5py.File(out) as f:
        figures = json.loads(f.attrs["travel_figures"])
    assert figures["operating_time_s"] is None and figures["zone_speed_m_per_s"] is None
    assert "damping_duration_s" not in figures and "damping-zone duration" not in result.output  # none stated
    for label in ("time to contact touch", "speed-zone average speed"):
        line = next(text for text in result.output.splitlines() if f"contact_displacement: {label}" in text)
        assert "not reached" in line, result.output


def test_a_run_without_a_travel_block_has_no_travel_figures(tmp_path):
    out = tmp_path / "uhv.h5"
    result = runner.invoke(app, ["run", str(UHV), "-o", str(out), "--set", "solver.t_end=2ms"], terminal_width=200)
    assert result.exit_code == 0, result.output
    assert "time to contact touch" not in result.output
    with h5py.File(out) as f:
        assert "travel_figures" not in f.attrs


@pytest.mark.parametrize("block, place, message", [
    ("sensor: contact_displacment, contact_touch: 250 mm, speed_zone: [230 mm, 250 mm]", "travel → sensor",
     "unknown sensor 'contact_displacment'; did you mean 'contact_displacement'?"),
    ("sensor: contact_velocity, contact_touch: 250 mm, speed_zone: [230 mm, 250 mm]", "travel → sensor",
     "the travel sensor must be a point_displacement sensor; 'contact_velocity' is a point_velocity"),
    ("sensor: contact_displacement, contact_touch: 250 mm, speed_zone: [250 mm, 230 mm]", "travel → speed_zone",
     "the speed zone's two positions must be in the order the contact passes them"),
    (f"{ZONE}, envelope: {{lower: [[0 ms, 0 mm], [40 ms, 200 mm]], upper: [[0 ms, 5 mm], [40 ms, 150 mm]]}}",
     "travel → envelope", "the lower limit is above the upper one at 40 ms (200 mm > 150 mm)"),
    (f"{ZONE}, envelope: {{lower: [[0 ms, 0 mm], [40 ms, 100 mm], [30 ms, 200 mm]], upper: [[0 ms, 5 mm], [40 ms, 250 mm]]}}",
     "travel → envelope → lower", "the times of a limit curve must increase: point 3 (30 ms) does not come after point 2"),
    (f"{ZONE}, envelope: {{lower: [[0 ms, 0 mm], [40 ms, 100 mm]], upper: [[50 ms, 5 mm], [60 ms, 250 mm]]}}",
     "travel → envelope", "the lower limit (0 to 40 ms) and the upper limit (50 to 60 ms) share no time span"),
], ids=["unknown sensor", "not a displacement", "zone reversed", "envelope limits crossed", "envelope times back",
        "envelope limits apart"])
def test_a_bad_travel_block_exits_2_at_its_place(tmp_path, block, place, message):
    config = with_travel(tmp_path, block)
    line = next(number for number, text in enumerate(config.read_text().splitlines(), 1) if text.startswith("travel:"))
    result = runner.invoke(app, ["run", str(config), "-o", str(tmp_path / "bad.h5")], terminal_width=200)
    assert result.exit_code == 2, result.output
    assert f"{config}:{line}:" in result.output and place in result.output and message in result.output
    assert "Traceback" not in result.output and not (tmp_path / "bad.h5").exists()
