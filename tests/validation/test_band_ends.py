"""solver.band_ends: located (docs/model.md §4): a try rejected across an end of a sliding joint's friction band is
tried again no longer than up to it; controlled, the default, leaves the steps to the controller alone."""

import numpy as np
import pytest

import clearsim.solver.integrator as ig
from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare
from clearsim.solver.simulate import Run

FIRST_MS = "solver.t_end=10ms"  # the bundled breaker's first 10 ms: A and J slide through v_d = 1e-2 m/s


def finished_run(*overrides):
    run = Run(prepare(load_mechanism(BUNDLED_CONFIG, [FIRST_MS, *overrides])))
    return run, list(run.chunks())


@pytest.fixture(scope="module")
def runs():
    return {setting: finished_run(*([f"solver.band_ends={setting}"] if setting else []))
            for setting in ("", "controlled", "located")}


def test_located_band_ends_shorten_the_tries_that_failed_across_them(runs):
    run, _ = runs["located"]
    assert run.ints[ig.I_BAND_END_TRIES] > 0
    assert run.statistics().rejected_steps <= runs[""][0].statistics().rejected_steps


def test_controlled_is_the_default_and_shortens_nothing(runs):
    default, controlled = runs[""], runs["controlled"]
    assert controlled[0].ints[ig.I_BAND_END_TRIES] == 0
    assert controlled[0].statistics().steps == default[0].statistics().steps
    # chunks end where the wall time says (simulate.chunk_span): compare the samples joined
    states = [np.concatenate([chunk.states for chunk in run[1]]) for run in (controlled, default)]
    assert np.array_equal(states[0], states[1])


def test_located_band_ends_keep_the_output_acceleration_peak(runs):
    """The steps move, the physics does not: the peak output acceleration within 1e-3 of the default's."""
    peaks = [runs[key][0].real[ig.R_PEAK_ACCELERATION] for key in ("", "located")]
    assert peaks[0] > 0.0
    assert peaks[1] == pytest.approx(peaks[0], rel=1e-3)
