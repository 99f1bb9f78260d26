"""Figures an engineer can read: legends beside the data, one unit per quantity, small cases visible, informative
axis limits, a title on every figure. Checked on the figures' data (Agg canvas), not on pixels."""

import numpy as np

from clearsim.plot import PlotRequest, load_run, plot_spectrum, read_summary
from clearsim.plot.figures import build_figures
from clearsim.plot.history import SPECTRUM_RANGE, signals_figure
from clearsim.plot.journal import joint_figure
from clearsim.plot.labels import run_labels
from clearsim.plot.style import new_figure
from clearsim.plot.sweep import merit_figure

JOINT = "slider_pin"


def overlay(runs, *names):
    """The runs, labelled and numbered as `clearsim plot` does for several files."""
    loaded = [load_run(runs[name]) for name in names]
    for index, (run, label) in enumerate(zip(loaded, run_labels(loaded))):
        run.label, run.index = label, index
    return loaded


def legends(figure) -> list:
    return [ax.get_legend() for ax in figure.axes if ax.get_legend()] + list(figure.legends)


def overlaps(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def test_no_legend_covers_the_data_of_any_figure(runs):
    figures, _ = build_figures(overlay(runs, "ideal", "small", "clearance"), PlotRequest([]))
    for kind, figure in figures.items():
        renderer = figure.canvas.get_renderer()
        figure.canvas.draw()
        boxes = [legend.get_window_extent(renderer) for legend in legends(figure)]
        assert boxes, kind
        for ax in figure.axes:
            data = ax.get_window_extent(renderer)
            assert not any(overlaps(box, data) for box in boxes), f"{kind}: a legend covers {ax.get_ylabel()!r}"


def test_every_figure_has_a_title(runs):
    figures, _ = build_figures(overlay(runs, "ideal", "clearance"), PlotRequest([]))
    assert all(figure.get_suptitle() for figure in figures.values())


def test_merit_figure_of_a_summary_with_a_warnings_column_has_no_bogus_legend(tmp_path):
    csv = tmp_path / "summary.csv"
    csv.write_text("case,reference,clearance,status,peak_acceleration_m_s2,start_delay_ms,max_contact_force_N[A],"
                   "warnings\n"
                   "ideal,,,complete,2000.0,0.0,,\n"
                   "c1,ideal,0.01 mm,complete,4000.0,0.2,20000.0,\n"
                   "c2,ideal,0.02 mm,complete,5000.0,0.1,30000.0,step size below the minimum\n")
    summary = read_summary(csv)
    assert summary.parameters == ["clearance"]
    figure = merit_figure(summary, "sweep")
    texts = [text.get_text() for legend in legends(figure) for text in legend.get_texts()]
    assert texts == ["ideal"]  # one swept quantity: no line label, only the ideal case's dashed line


def test_journal_paths_and_penetration_share_one_length_unit(runs):
    figure = joint_figure(overlay(runs, "tiny", "clearance"), JOINT)
    labels = [label for ax in figure.axes for label in (ax.get_xlabel(), ax.get_ylabel())
              if label.startswith(("$e", "penetration"))]
    units = {label[label.rindex("(") + 1:-1] for label in labels}
    assert len(labels) == 5 and units == {"mm"}, labels  # e_x, e_y of two paths, δ; 0.5 mm sets the unit


def test_an_ideal_runs_numerical_floor_does_not_set_the_spectrum_axis(runs):
    ax = new_figure((6.0, 4.0)).add_subplot()
    plot_spectrum(overlay(runs, "ideal", "clearance"), "slider_acceleration", ax)
    ideal, clearance = (line.get_ydata() for line in ax.lines)
    bottom, top = ax.get_ylim()
    assert bottom >= top / 2.0 * SPECTRUM_RANGE
    assert bottom > np.min(ideal) and bottom <= np.percentile(clearance, 1.0)  # the clearance run is all shown
    assert top >= np.max(clearance)


def test_the_largest_case_is_drawn_under_the_smaller_ones(runs):
    loaded = overlay(runs, "clearance", "small", "tiny")
    figure = signals_figure(loaded, ["slider_acceleration"])
    lines = figure.axes[0].lines
    spans = [np.ptp(line.get_ydata()) for line in lines]
    order = np.argsort(spans)[::-1]  # largest first
    zorders = [lines[k].get_zorder() for k in order]
    assert zorders == sorted(zorders) and len(set(zorders)) == 3
