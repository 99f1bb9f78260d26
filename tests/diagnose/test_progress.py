"""A diagnosis reports its progress: runs done of those planned so far, the best gap so far and its model."""

from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.evaluate import Evaluator
from clearsim.diagnose.align import Fit
from clearsim.diagnose.search import Ensembled, Point, Tracked
from clearsim.diagnose.workflow import DiagnoseRequest, diagnose
from tests.diagnose.test_evaluate import ReversedExecutor, documents

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
IDEAL = ["joints.slider_pin.clearance=0"]


def test_tracked_counts_planned_and_finished_runs_and_keeps_the_best_gap(tmp_path):
    """Runs finish last first; a failed run (negative value) counts as done but has no fit; a repeated document is
    planned and done twice (it is one run); the best gap is the lowest of the finished runs, with its label."""
    states = []
    tracked = Tracked(Evaluator(tmp_path / "runs", "model.yaml", tmp_path, ReversedExecutor(), 100.0),
                      lambda progress: states.append(replace(progress)))
    tracked.stage("screening")

    def fitted(i, prediction):
        return SimpleNamespace(fit=SimpleNamespace(gap=float(prediction.sensors["x"][0])) if prediction.ok else None)

    tracked.evaluate(documents(3.0, 2.0, -1.0, 2.0), fitted, ["a", "b", "failed", "b again"])
    assert [(s.stage, s.planned, s.done) for s in states] == [("screening", 0, 0), ("screening", 4, 0)] + [
        ("screening", 4, done) for done in (1, 2, 3, 4)]
    assert [s.best_gap for s in states[2:]] == [np.inf, 2.0, 2.0, 2.0]  # the failed run, then 2.0 (×2), then 3.0
    assert states[-1].best_label in ("b", "b again")
    tracked.evaluate(documents(1.0), fitted, ["c"])
    assert (states[-1].planned, states[-1].done, states[-1].best_gap, states[-1].best_label) == (5, 5, 1.0, "c")
    assert tracked.simulations == 4  # 3.0, 2.0, −1.0 and 1.0 ran; the repeated 2.0 did not


def test_a_diagnosis_reports_every_run_it_plans_and_its_best_model(tmp_path, monkeypatch):
    bench = tmp_path / "bench.csv"
    made = CliRunner().invoke(app, ["synthesize", str(SLIDER_CRANK), "--set", IDEAL[0], "--set", "bodies.slider.mass=0.2kg",
                                    "--sensors", "slider_displacement,pin_normal_force", "--rate", "20kHz",
                                    "--noise", "0.5%", "-o", str(bench)])
    assert made.exit_code == 0, made.output
    asked = []
    evaluate = Evaluator.evaluate
    monkeypatch.setattr(Evaluator, "evaluate",
                        lambda self, docs, then=None: asked.append(len(docs)) or evaluate(self, docs, then))
    states = []
    result = diagnose(DiagnoseRequest(SLIDER_CRANK, bench, IDEAL, candidates="mass", out=tmp_path / "report",
                                      workers=1, fit_top=1), progress=lambda state: states.append(replace(state)))
    final = states[-1]
    assert final.planned == sum(asked) and final.done == final.planned  # every run asked for, and each finished
    assert all(a.done <= a.planned for a in states)
    assert [s.done for s in states] == sorted(s.done for s in states)
    stages = list(dict.fromkeys(s.stage for s in states))
    assert stages[0] == "estimating the noise"  # the model as given runs first: σ̂ from the residual against it
    assert stages[1].startswith("iteration 1: screening") and stages[2].startswith("iteration 1: fitting")
    best = min((p for s in result.iterations[0].ranked for p in s.points if p.fit is not None),
               key=lambda p: p.fit.gap)
    assert np.isclose(final.best_gap, min(best.fit.gap, result.before.gap))
    assert final.best_label.startswith("mass of ")


def test_an_ensemble_scores_each_document_by_its_median_member_and_counts_every_run():
    """Three copies per document: a lucky copy (χ² 1) among typical ones (10, 11) is outvoted; the progress counts
    every copy as a run planned and done."""
    chi = {("a", 0): 10.0, ("a", 1): 1.0, ("a", 2): 11.0, ("b", 0): 5.0, ("b", 1): 7.0, ("b", 2): 6.0}
    states = []

    class Runs:
        simulations = 0

        def evaluate(self, documents, then):
            return [then(i, d) for i, d in enumerate(documents)]

    tracked = Tracked(Runs(), lambda state: states.append(replace(state)))
    ensemble = Ensembled(tracked, lambda document: [(document, k) for k in range(3)])
    points = ensemble.evaluate(["a", "b"], lambda i, copy: Point(copy, Fit(0.0, chi[copy], {}, chi[copy]), None),
                               ["a", "b"])
    assert [p.chi_square for p in points] == [10.0, 6.0]
    assert (states[-1].planned, states[-1].done) == (6, 6)
    assert ensemble.simulations == 0 and ensemble.progress is tracked.progress
