"""Progress is reported at every return of the compiled loop, not only when it brings samples."""

from pathlib import Path

import numpy as np
import pytest

from clearsim.runner import simulate_config
from clearsim.solver import simulate as sim

SLIDER_CRANK = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"


def test_progress_moves_between_samples(tmp_path, monkeypatch):
    """At 1 kHz output a 0.5 ms run has one sample (t = 0) but the loop returns every t_end/100 at the finest
    (steps of at most 1 µs, so each hundredth holds several): the progress bar must follow the integration, not the
    samples (it stood still for minutes with a tiny max_step). PROGRESS_SECONDS = 0 asks for the finest chunks: this
    run is over long before a chunk at the default pace would end."""
    monkeypatch.setattr(sim, "PROGRESS_SECONDS", 0.0)
    seen = []
    report = simulate_config(SLIDER_CRANK, ["solver.t_end=0.5ms", "solver.output_rate=1kHz", "solver.max_step=1us"], tmp_path / "r.h5",
                             progress=seen.append)
    assert report.complete
    assert len(seen) >= sim.CHUNKS // 2, seen
    assert seen == sorted(seen) and seen[-1] == 0.5e-3
    assert len({round(t * 1e9) for t in seen}) >= sim.CHUNKS // 2  # distinct times: it moved


def test_chunk_span_follows_the_pace_within_its_limits():
    finest = 1e-4
    assert sim.chunk_span(finest, finest, 0.0, 0.0) == finest  # nothing measured yet
    pace = 1e-3 / 0.01  # 1 ms simulated in 10 ms of wall time
    assert sim.chunk_span(finest, 1.0, 1e-3, 0.01) == pytest.approx(pace * sim.PROGRESS_SECONDS)
    assert sim.chunk_span(finest, 1e-4, 1e-3, 0.01) == pytest.approx(sim.GROWTH * 1e-4)  # grows by GROWTH at most
    assert sim.chunk_span(finest, 1.0, 1e-9, 10.0) == finest  # a crawling pace: never below 1 % of t_end


@pytest.mark.parametrize("method", ["dopri5", "rosenbrock"])
def test_where_the_loop_returns_does_not_change_the_result(monkeypatch, method):
    """The loop pauses between steps, so returning every 1 % of t_end or once per full sample buffer gives the same
    run, bit for bit (3 ms of the slider-crank: its first impacts, contact episodes and their events), with either
    method (rosenbrock's Jacobian and its age live in the run's arrays)."""
    from dataclasses import fields

    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare

    loaded = load_mechanism(SLIDER_CRANK, ["solver.t_end=3ms", f"solver.method={method}"])
    runs = {}
    for pace in (0.0, 1e9):
        monkeypatch.setattr(sim, "PROGRESS_SECONDS", pace)
        calls = []
        runs[pace] = sim.simulate(prepare(loaded), progress=calls.append), len(calls)
    (finest, finest_calls), (coarsest, coarsest_calls) = runs[0.0], runs[1e9]
    assert finest_calls >= sim.CHUNKS // 2 and coarsest_calls < 10  # the two really returned differently
    for field in fields(finest.chunk):
        assert np.array_equal(getattr(finest.chunk, field.name), getattr(coarsest.chunk, field.name)), field.name
    for field in fields(finest.episodes):
        assert np.array_equal(getattr(finest.episodes, field.name), getattr(coarsest.episodes, field.name)), field.name
    assert finest.statistics.steps == coarsest.statistics.steps
    assert finest.statistics.rhs_evaluations == coarsest.statistics.rhs_evaluations
