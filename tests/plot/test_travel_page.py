"""The travel page of `clearsim plot`: a mechanism with a `travel:` block gets `<stem>-travel.png`, the sensor's
travel drawn inside the shaded envelope, the marks, and the figures in a text box."""

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from clearsim.plot.data import load_run
from clearsim.plot.figures import PlotRequest, build_figures, plot_results
from clearsim.runner import simulate_config

from .conftest import SHORT, SLIDER_CRANK

# the slider moves inwards (negative travel) by about 61 mm in 3 ms; the envelope's lower limit has a corner at 2 ms
TRAVEL = ("travel: {sensor: slider_displacement, contact_touch: -30 mm, speed_zone: [-20 mm, -40 mm], "
          "envelope: {lower: [[0 ms, -70 mm], [2 ms, -75 mm], [3 ms, -70 mm]], upper: [[0 ms, 2 mm], [3 ms, 2 mm]]}}")


@pytest.fixture(scope="module")
def travel_run(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("travel")
    config = folder / "sc_travel.yaml"
    config.write_text(SLIDER_CRANK.read_text().replace("output: {", f"{TRAVEL}\noutput: {{", 1))
    report = simulate_config(config, [SHORT], folder / "sc_travel.h5")
    assert report.complete, report.status
    return report.output


def test_the_travel_page_draws_the_curve_inside_the_shaded_envelope(travel_run, tmp_path):
    figures, _ = build_figures([load_run(travel_run)], PlotRequest([travel_run]))
    ax = figures["travel"].axes[0]
    band = next(c for c in ax.collections if isinstance(c, PolyCollection) and c.get_label() == "tolerance envelope")
    corners = band.get_paths()[0].vertices
    assert {(t, x) for t, x in np.round(corners, 9)} >= {(0.0, -70.0), (2.0, -75.0), (3.0, -70.0), (0.0, 2.0),
                                                          (3.0, 2.0)}  # ms, mm
    with h5py.File(travel_run) as f:
        time, travel = f["time"][()], f["sensors/slider_displacement"][()]
        stored = json.loads(f.attrs["travel_figures"])
    curve = next(line for line in ax.lines if line.get_label() == "sc_travel")
    np.testing.assert_allclose(curve.get_xdata(), time * 1e3, rtol=1e-12)
    np.testing.assert_allclose(curve.get_ydata(), travel * 1e3, rtol=1e-12)
    assert {line.get_label() for line in ax.lines} >= {"contact touch", "speed zone"}
    assert [line.get_ydata()[0] for line in ax.lines if line.get_linestyle() == ":"] == pytest.approx([-20.0, -40.0])
    text = next(t for t in ax.texts if t.get_gid() == "travel-figures").get_text()
    assert stored["inside_envelope"] is True and "within the envelope: yes" in text
    assert f"time to contact touch: {stored['operating_time_s'] * 1e3:.4g} ms" in text


def test_the_travel_page_is_written_by_its_name(travel_run, tmp_path):
    report = plot_results(PlotRequest([travel_run], out=tmp_path))
    assert tmp_path / "sc_travel-travel.png" in report.written
    assert (tmp_path / "sc_travel-travel.png").stat().st_size > 0


def test_a_run_without_a_travel_block_has_no_travel_page(runs):
    figures, _ = build_figures([load_run(runs["clearance"])], PlotRequest([runs["clearance"]]))
    assert "travel" not in figures


def test_many_overlaid_runs_have_their_figures_as_ranges(travel_run, tmp_path):
    """Four runs of the same file: the text box gives each figure's range and the count within the envelope, not
    four blocks of rows."""
    copies = []
    for number in range(4):
        copies.append(tmp_path / f"copy{number}.h5")
        copies[-1].write_bytes(travel_run.read_bytes())
    figures, _ = build_figures([load_run(path) for path in copies], PlotRequest(copies))
    ax = figures["travel"].axes[0]
    text = next(t for t in ax.texts if t.get_gid() == "travel-figures").get_text()
    with h5py.File(travel_run) as f:
        touch = json.loads(f.attrs["travel_figures"])["operating_time_s"] * 1e3
    assert text.startswith("4 runs") and f"time to contact touch: {touch:.4g} to {touch:.4g} ms" in text
    assert "within the envelope: 4 of 4" in text and text.count("overtravel") == 1
    assert len([line for line in ax.lines if line.get_label().startswith("copy")]) == 4
