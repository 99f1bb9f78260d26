"""The figures of `clearsim diagnose`: every candidate report.md ranks, labels that do not run together, a title,
legends beside the data."""

import math
from types import SimpleNamespace

import numpy as np

from clearsim.diagnose.report import SensorComparison, comparison_figure, ranked_rows, ranking_figure


def scored(label: str, delta_bic: float, fitted: bool = True):
    return SimpleNamespace(candidate=SimpleNamespace(label=label), delta_bic=delta_bic, fitted=fitted)


RANKED = [scored(f"axial compliance of link_{k}", -20.0 + 3 * k, fitted=k < 3) for k in range(14)]
RANKED.append(scored("friction in joint J", math.inf))  # its runs failed: ranked last, ΔBIC "—" in report.md


def test_the_ranking_shows_every_candidate_report_md_ranks():
    rows = ranked_rows(RANKED)
    figure = ranking_figure(rows, [("as given", 3.0)], "title")
    rank_ax = figure.axes[0]
    names = [label.get_text() for label in rank_ax.get_yticklabels()][::-1]  # barh draws the first at the bottom
    assert names == [name for name, _ in rows] and len(names) == 15
    assert names[-1] == "friction in joint J" and names[3] == "axial compliance of link_3 (screened)"
    assert any("runs failed" in text.get_text() for text in rank_ax.texts)
    assert figure.get_suptitle() == "title"


def test_gap_tick_labels_do_not_run_together():
    effects = [("as given", 3.0), ("clearance in joint slider_pin", 2.0), ("axial compliance of crank", 1.4),
               ("drive of crank_drive (lag)", 1.1)]
    figure = ranking_figure(ranked_rows(RANKED[:3]), effects, "title")
    gap_ax = figure.axes[1]
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    boxes = [label.get_window_extent(renderer) for label in gap_ax.get_xticklabels()]
    assert len(boxes) == 4
    for a, b in zip(boxes, boxes[1:]):
        assert not a.overlaps(b), (a, b)


def test_comparison_figure_has_a_title_and_legends_beside_the_data():
    time = np.linspace(0.0, 5.0, 200)
    comparison = SensorComparison("slider_displacement", "m", np.sin(time), np.sin(time) + 0.1, np.sin(time),
                                  10 * np.cos(time), np.cos(time), 3.9, 1.0)
    figure = comparison_figure(time, [comparison, comparison], "model against record")
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    assert figure.get_suptitle() == "model against record"
    legends = [ax.get_legend() for ax in figure.axes]
    assert all(legends)
    for legend in legends:
        box = legend.get_window_extent(renderer)
        assert not any(box.overlaps(ax.get_window_extent(renderer)) for ax in figure.axes)
