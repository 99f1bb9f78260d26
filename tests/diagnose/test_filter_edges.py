"""The comparison filter's start-up at each end of the record: there the filtered record holds the noise of its end
samples nearly unfiltered, so a noise-only residual would look like a disagreement. Gaps, χ² and the windows leave
it out alike."""

import numpy as np
import pytest

from clearsim.diagnose.align import chi_square, fit_at, lowpass, predict, prepare_record, residuals, scan_costs
from clearsim.diagnose.features import disagreement_windows

RATE, COUNT = 50e3, 1205
TIME = np.arange(COUNT) / RATE
STROKE = 0.05 * (1.0 - np.cos(2.0 * np.pi * 41.7 * TIME))


def noise_only_records(count: int):
    """Records of a smooth stroke plus noise through a 10 kHz bench filter, each compared with the stroke itself
    (in its 500 Hz comparison band): what remains is noise alone."""
    rng = np.random.default_rng(11)
    for _ in range(count):
        yield prepare_record(TIME, {"x": STROKE + lowpass(rng.normal(0.0, 1e-4, COUNT), 10e3, RATE)})


def test_a_noise_only_record_is_one_noise_level_from_its_model():
    """100 records: mean gap ≈ 1 and χ² ≈ n_eff (with the start-up counted: 1.08 and 1.22 n_eff), and no 1-ms window
    above the noise band (with it: 35 records flagged at their ends)."""
    gaps, chi_squares, windows = [], [], 0
    for record in noise_only_records(100):
        assert record.cutoff == 500.0
        fit = fit_at(record, TIME, {"x": STROKE}, 0.0)
        gaps.append(fit.gap)
        chi_squares.append(fit.chi_square / record.effective_samples)
        windows += bool(disagreement_windows(record, residuals(record, predict(record, TIME, {"x": STROKE}, 0.0))))
    assert 0.9 < np.mean(gaps) < 1.05
    assert 0.85 < np.mean(chi_squares) < 1.1
    assert windows <= 3


def test_the_offset_scan_scores_the_samples_the_fit_scores():
    """The scan filters the model over a span one sample wider: its start-up differs by up to 0.06 σ̂ inside the
    compared samples (0.6 % of χ²), by 2 σ̂ at the ends left out."""
    record = next(noise_only_records(1))
    scanned = scan_costs(record, TIME, {"x": STROKE}, np.array([0.0]))[0]
    assert scanned == pytest.approx(chi_square(record, residuals(record, predict(record, TIME, {"x": STROKE}, 0.0))),
                                    rel=0.02)
