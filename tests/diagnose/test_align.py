"""The data-only arithmetic of the diagnosis: noise level, effective samples, trigger offset, gap."""

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from clearsim.diagnose.align import (equivalent_bandwidth, estimate_noise, fit_offset, lowpass, prepare_record,
                                     scan_costs)
from clearsim.physics.motion import lagged, stroke_law

RATE = 15_000.0
TIME = np.arange(1276) / RATE
STROKE = 0.2 * (TIME / 0.085) ** 2 * (3 - 2 * TIME / 0.085)


def filtered_noise(std, cutoff, seed):
    noise = np.random.default_rng(seed).normal(0.0, std, len(TIME))
    return sosfiltfilt(butter(4, cutoff, fs=RATE, output="sos"), noise) if cutoff else noise


@pytest.mark.parametrize("cutoff", [None, 4000.0, 2000.0, 1000.0])
def test_noise_level_and_effective_samples_of_a_smooth_stroke_with_noise(cutoff):
    for seed in range(3):
        noise = filtered_noise(2e-3, cutoff, seed)
        estimate = estimate_noise(STROKE + noise, RATE)
        assert estimate.std == pytest.approx(np.std(noise), rel=0.15)
        expected = 1.0 if cutoff is None else 2.0 * equivalent_bandwidth(cutoff) / RATE
        assert estimate.effective_samples / estimate.samples == pytest.approx(expected, rel=0.35)
        if cutoff is not None:
            assert estimate.bandwidth == pytest.approx(cutoff, rel=0.3)


def test_the_trigger_offset_of_a_shifted_record_is_recovered_to_a_tenth_of_a_sample():
    offset = 0.7e-3
    model_time = np.linspace(0.0, 0.085, 8501)
    model = 0.2 * (model_time / 0.085) ** 2 * (3 - 2 * model_time / 0.085)
    measured = np.interp(TIME - offset, model_time, model) + filtered_noise(1e-4, 2000.0, 7)
    record = prepare_record(TIME, {"x": measured})
    fit = fit_offset(record, model_time, {"x": model})
    assert abs(fit.offset - offset) < 0.1 / RATE
    assert fit.gap == pytest.approx(1.0, abs=0.2)  # the right model is explained down to the noise
    wrong = fit_offset(record, model_time, {"x": 1.01 * model})
    assert wrong.gap > 5.0



def test_the_offset_scan_is_the_chi_square_of_the_filtered_model_read_at_each_shifted_instant():
    """Each offset's window of the once-filtered model is that model interpolated at t_k − τ (what the scan was
    before the windows), over the compared samples: the same numbers, offset by offset."""
    model_time = np.linspace(0.0, 0.085, 8501)
    model = {"x": 0.2 * (model_time / 0.085) ** 2 * (3 - 2 * model_time / 0.085),
             "v": np.sin(2 * np.pi * 300.0 * model_time) + 0.1 * np.sin(2 * np.pi * 3000.0 * model_time)}
    measured = {s: np.interp(TIME - 0.7e-3, model_time, m) + filtered_noise(1e-3, 2000.0, 5) for s, m in model.items()}
    record = prepare_record(TIME, measured)
    step = 1.0 / record.rate
    offsets = np.arange(-3e-3, 3e-3 + 0.5 * step, step)
    widened = np.arange(record.time[0] - offsets.max() - step, record.time[-1] - offsets.min() + 1.5 * step, step)
    filtered = {s: lowpass(np.interp(widened, model_time, m), record.cutoff, record.rate) for s, m in model.items()}
    expected = [sum(record.weights[s] * np.sum(((record.values[s] - np.interp(record.time - offset, widened, filtered[s]))
                                                [record.compared]) ** 2) for s in model) for offset in offsets]
    costs = scan_costs(record, model_time, model, offsets)
    assert costs == pytest.approx(expected, rel=1e-12)
    assert offsets[np.argmin(costs)] == pytest.approx(0.7e-3, abs=step)

def test_the_lagged_stroke_law_solves_the_first_order_lag():
    from scipy.integrate import solve_ivp

    law, lag = stroke_law(-0.23, 0.085), 3e-3
    seen = lagged(law, lag)
    t = np.linspace(0.0, 0.2, 4001)
    reference = solve_ivp(lambda tt, y: (law(np.array([tt]))[0] - y) / lag, (0.0, 0.2), [0.0], t_eval=t,
                          rtol=1e-11, atol=1e-14, max_step=1e-4).y[0]
    assert np.max(np.abs(seen(t) - reference)) < 1e-7 * 0.23
    assert seen(np.array([-1.0]))[0] == 0.0 and seen(np.array([10.0]))[0] == pytest.approx(-0.23, abs=1e-12)


def test_the_comparison_filter_is_a_zero_phase_4th_order_butterworth_designed_once_per_band():
    """The low-pass applied to model and record alike: a 1 kHz sine at a 2 kHz cut-off passes with the gain of a
    4th-order Butterworth applied twice, |H|² = 1/(1 + (f/f_c)^8), without a phase shift; the design is reused."""
    from clearsim.diagnose.align import comparison_filter, lowpass

    rate, cutoff, frequency = 50_000.0, 2_000.0, 1_000.0
    t = np.arange(0, 0.05, 1 / rate)
    comparison_filter.cache_clear()
    filtered = lowpass(np.sin(2 * np.pi * frequency * t), cutoff, rate)
    middle = slice(len(t) // 4, 3 * len(t) // 4)  # away from the ends' start-up
    expected = np.sin(2 * np.pi * frequency * t) / (1 + (frequency / cutoff) ** 8)
    np.testing.assert_allclose(filtered[middle], expected[middle], atol=2e-3)
    lowpass(np.cos(2 * np.pi * frequency * t), cutoff, rate)
    assert comparison_filter.cache_info().hits == 1 and comparison_filter.cache_info().misses == 1
