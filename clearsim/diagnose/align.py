"""Measurement and model side by side: noise level, bench bandwidth, trigger offset, residual, gap.

Everything here is data-only arithmetic (docs/diagnose.md §"The gap" and §"Noise"):

    noise       σ̂_s, S_n(f): the record's scatter about its local cubic trend, spectrum made
                whole below the smoother's cut-off by the flat floor just above it
    n_eff       N · S_white / S_n(0): independent samples the record is worth (coloured noise)
    offset      τ̂: the time shift of the model that fits the record best (a nuisance, not an effect)
    residual    r_s(t_k) = y_s(t_k) − m_s(t_k − τ̂)
    gap         g_s = RMS(r_s) / σ̂_s,  g = √(mean_s g_s²)
    χ²          Σ_s (n_eff,s / N_s) Σ_k r_sk² / σ̂_s²  (the Gaussian log-likelihood, coloured noise)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.signal import butter, savgol_filter, sosfiltfilt, welch

SMOOTHER_ORDER = 5
SMOOTHER_CUTOFF = 1.0 / 40.0  # of the sampling rate: the local cubic follows the signal below it
WELCH_SEGMENT = 256
PASSED = 0.8  # the smoother's high-pass passes at least 80 % of the power: noise seen there is whole
FLOOR_BINS = 5
FLAT_PART = 0.6  # of the bandwidth: below it a bench filter has not started to roll off
LINE_FACTOR = 3.0  # a spectral bin above 3× the floor holds signal (a Welch bin of noise rarely reaches it)
COMPARISON_FILTER_ORDER = 4
BANDWIDTH_DROP = 0.1  # the bench bandwidth ends where the noise floor has fallen to 10 % of its level
COMPARISON_BANDWIDTH = 500.0  # Hz: the motion and its lag, below the chaotic detail of single impacts
MAX_OFFSET_FRACTION = 0.1  # the trigger offset is searched within ±10 % of the record length
LOW_BAND_FACTOR = 0.4  # the screening band: 0.4 × the comparison band (frequency continuation, docs/diagnose.md §4)


@dataclass(frozen=True)
class NoiseEstimate:
    """The noise of one sensor's record, estimated from the record alone."""

    std: float  # σ̂, SI
    effective_samples: float  # n_eff
    samples: int  # N
    bandwidth: float | None  # Hz where the noise floor has dropped to 10 %, None: flat to Nyquist
    floor: float = 0.0  # one-sided noise density at low frequency, unit²/Hz

    def filtered(self, cutoff: float, rate: float) -> "NoiseEstimate":
        """The same noise after the comparison low-pass: σ² = S_n(0)·B_eq(cutoff) where that is below
        the record's own noise, n_eff = N·2 B_eq/rate."""
        band = equivalent_bandwidth(cutoff)
        if self.floor <= 0.0 or self.floor * band >= self.std ** 2:
            return self
        return NoiseEstimate(float(np.sqrt(self.floor * band)), self.samples * min(1.0, 2.0 * band / rate),
                             self.samples, cutoff, self.floor)


def smoother_window(rate_samples: int) -> int:
    """Odd Savitzky–Golay window whose cut-off is SMOOTHER_CUTOFF of the rate (Schafer 2011, eq. 11 inverted)."""
    half = int(np.ceil(((SMOOTHER_ORDER + 1) / SMOOTHER_CUTOFF + 4.6) / 3.2))
    return min(2 * half + 1, rate_samples - (1 - rate_samples % 2))


def smoother_response(window: int, frequencies: np.ndarray, rate: float) -> np.ndarray:
    """|H(f)| of the centred Savitzky–Golay smoother (its impulse response is the middle row's weights)."""
    from scipy.signal import savgol_coeffs

    weights = savgol_coeffs(window, SMOOTHER_ORDER)
    lags = np.arange(window) - window // 2
    return np.abs(np.exp(-2j * np.pi * np.outer(frequencies / rate, lags)) @ weights)


def estimate_noise(values: np.ndarray, rate: float) -> NoiseEstimate:
    """σ̂ and n_eff of a record: the high-pass scatter's median Welch spectrum, divided by the
    smoother's high-pass response and continued flat below its cut-off, integrated."""
    count = len(values)
    window = smoother_window(count)
    if window <= SMOOTHER_ORDER + 1:
        scatter = values - np.mean(values)
        return NoiseEstimate(float(np.std(scatter)), float(count), count, None)
    scatter = values - savgol_filter(values, window, SMOOTHER_ORDER, mode="interp")
    frequencies, density = welch(scatter, fs=rate, nperseg=min(WELCH_SEGMENT, count), average="median")
    passed = (1.0 - smoother_response(window, frequencies, rate)) ** 2
    valid = passed > PASSED
    if not np.any(valid):
        return NoiseEstimate(float(np.std(scatter)), float(count), count, None)
    noise = np.where(valid, density / np.where(valid, passed, 1.0), 0.0)
    level = _floor_level(frequencies, noise, valid)
    bandwidth = _bandwidth(frequencies, noise, level)
    noise = np.where(valid, np.minimum(noise, LINE_FACTOR * level), level)  # lines far above the floor are signal
    variance = float(np.trapezoid(noise, frequencies))
    white = 2.0 * variance / rate
    effective = count * min(1.0, white / level) if level > 0.0 else float(count)
    return NoiseEstimate(float(np.sqrt(max(variance, 0.0))), effective, count, bandwidth, level)


def equivalent_bandwidth(cutoff: float) -> float:
    """Noise-equivalent bandwidth of the zero-phase comparison filter: ∫ |H(f)|⁴ df, |H|² = 1/(1 + (f/f_c)^8)."""
    from scipy.integrate import quad

    return cutoff * quad(lambda x: 1.0 / (1.0 + x ** (2 * COMPARISON_FILTER_ORDER)) ** 2, 0.0, np.inf)[0]


def _floor_level(frequencies: np.ndarray, noise: np.ndarray, valid: np.ndarray) -> float:
    """The flat noise floor: the mean density over the flat part of the passband (up to FLAT_PART of
    the bandwidth), spectral lines above LINE_FACTOR × the median left out. Two rounds: the lowest
    valid bins give the bandwidth, the bandwidth gives the flat part."""
    first = np.nonzero(valid)[0][:FLOOR_BINS]
    bandwidth = _bandwidth(frequencies, noise, float(np.median(noise[first])))
    flat = valid & (frequencies <= FLAT_PART * (bandwidth or frequencies[-1] / FLAT_PART))
    if not np.any(flat):
        flat = valid
    typical = float(np.median(noise[flat]))
    kept = noise[flat][noise[flat] <= LINE_FACTOR * typical]
    return float(np.mean(kept)) if len(kept) else typical


def _bandwidth(frequencies: np.ndarray, noise: np.ndarray, level: float) -> float | None:
    """The first frequency above which the noise stays below BANDWIDTH_DROP of its floor level."""
    above = np.nonzero(noise >= BANDWIDTH_DROP * level)[0]
    if len(above) == 0 or above[-1] >= len(frequencies) - 2:
        return None
    return float(frequencies[above[-1] + 1])


def lowpass(values: np.ndarray, cutoff: float | None, rate: float) -> np.ndarray:
    """Zero-phase 4th-order Butterworth low-pass, the comparison filter applied to model and record alike."""
    if cutoff is None or cutoff >= 0.5 * rate or len(values) <= 3 * (2 * COMPARISON_FILTER_ORDER + 1):
        return values
    return sosfiltfilt(np.array(comparison_filter(cutoff, rate)), values)


@lru_cache(maxsize=64)
def comparison_filter(cutoff: float, rate: float) -> tuple:
    """The second-order sections of the comparison filter, designed once per cut-off and rate (a diagnosis filters
    thousands of predictions with a few filters, and the design cost more than the filtering)."""
    return tuple(map(tuple, butter(COMPARISON_FILTER_ORDER, cutoff, btype="low", fs=rate, output="sos")))


@dataclass
class Record:
    """A measured record prepared for comparison: filtered values and their noise, per sensor."""

    time: np.ndarray
    rate: float
    values: dict[str, np.ndarray]
    noise: dict[str, NoiseEstimate]
    cutoff: float | None  # comparison low-pass (Hz) applied to the model's prediction, None: none
    low_band: "Record | None" = None  # the same record in the screening band (LOW_BAND_FACTOR × cutoff)

    @property
    def weights(self) -> dict[str, float]:
        """χ² weight of one squared residual sample: (n_eff/N) / σ̂²."""
        return {s: (n.effective_samples / n.samples) / n.std ** 2 for s, n in self.noise.items()}

    @property
    def effective_samples(self) -> float:
        return float(sum(n.effective_samples for n in self.noise.values()))


def prepare_record(time: np.ndarray, values: dict[str, np.ndarray], cutoff: float | None = None) -> Record:
    """Resample onto a uniform grid (the record's median step), estimate each sensor's noise, and
    low-pass the record at the comparison bandwidth (model predictions get the same filter); the
    record in the screening band (LOW_BAND_FACTOR × that bandwidth) rides along as `low_band`.

    cutoff: the comparison bandwidth (Hz); None: COMPARISON_BANDWIDTH, or the record's own
    bandwidth where that is narrower.
    """
    step = float(np.median(np.diff(time)))
    grid = time[0] + step * np.arange(int(np.floor((time[-1] - time[0]) / step + 1e-9)) + 1)
    uniform = {s: np.interp(grid, time, v) for s, v in values.items()}
    rate = 1.0 / step
    noise = {s: estimate_noise(v, rate) for s, v in uniform.items()}
    if cutoff is None:
        seen = [n.bandwidth for n in noise.values() if n.bandwidth is not None]
        cutoff = min([COMPARISON_BANDWIDTH, *seen])
    for sensor, estimate in noise.items():
        if not estimate.std > 0.0:
            noise[sensor] = NoiseEstimate(_quantisation_floor(uniform[sensor]), estimate.effective_samples,
                                          estimate.samples, estimate.bandwidth)
    record = _in_band(grid, rate, uniform, noise, cutoff)
    record.low_band = _in_band(grid, rate, uniform, noise, LOW_BAND_FACTOR * (record.cutoff or 0.5 * rate))
    return record


def _in_band(grid: np.ndarray, rate: float, uniform: dict[str, np.ndarray], noise: dict[str, NoiseEstimate],
             cutoff: float) -> Record:
    """The record low-passed at `cutoff` (none at or above Nyquist), with its noise seen through that filter."""
    cutoff = cutoff if cutoff < 0.5 * rate else None
    if cutoff is None:
        return Record(grid, rate, dict(uniform), dict(noise), None)
    return Record(grid, rate, {s: lowpass(v, cutoff, rate) for s, v in uniform.items()},
                  {s: n.filtered(cutoff, rate) for s, n in noise.items()}, cutoff)


def _quantisation_floor(values: np.ndarray) -> float:
    """A noiseless record (synthetic, no --noise): one part in 1e6 of its range, so weights stay finite."""
    return max(float(np.ptp(values)) * 1e-6, 1e-300)


def predict(record: Record, model_time: np.ndarray, model: dict[str, np.ndarray], offset: float) -> dict[str, np.ndarray]:
    """m_s(t_k − τ) on the record's grid, held at its first/last value outside the run, through the comparison filter."""
    shifted = record.time - offset
    return {s: lowpass(np.interp(shifted, model_time, model[s]), record.cutoff, record.rate) for s in record.values}


def residuals(record: Record, prediction: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """r_s(t_k) = y_s(t_k) − m_s(t_k − τ̂)."""
    return {s: record.values[s] - prediction[s] for s in record.values}


def chi_square(record: Record, residual: dict[str, np.ndarray]) -> float:
    """χ² = Σ_s (n_eff,s/N_s) Σ_k r_sk²/σ̂_s² (docs/diagnose.md eq. D3)."""
    weights = record.weights
    return float(sum(weights[s] * np.sum(r ** 2) for s, r in residual.items()))


def chi_square_halves(record: Record, residual: dict[str, np.ndarray]) -> tuple[float, float]:
    """χ² (D3) of the first and of the second half of the record, for a check on data the other half fitted."""
    middle = len(record.time) // 2
    first = {s: r[:middle] for s, r in residual.items()}
    second = {s: r[middle:] for s, r in residual.items()}
    return chi_square(record, first), chi_square(record, second)


def sensor_gaps(record: Record, residual: dict[str, np.ndarray]) -> dict[str, float]:
    """g_s = RMS(r_s)/σ̂_s (docs/diagnose.md eq. D1)."""
    return {s: float(np.sqrt(np.mean(r ** 2)) / record.noise[s].std) for s, r in residual.items()}


def combined_gap(gaps: dict[str, float]) -> float:
    """g = √(mean_s g_s²) (docs/diagnose.md eq. D2)."""
    return float(np.sqrt(np.mean([g ** 2 for g in gaps.values()]))) if gaps else 0.0


@dataclass(frozen=True)
class Fit:
    """A model's prediction compared with the record at its best trigger offset."""

    offset: float
    chi_square: float
    gaps: dict
    gap: float


def fit_offset(record: Record, model_time: np.ndarray, model: dict[str, np.ndarray],
               max_offset: float | None = None) -> Fit:
    """τ̂ minimising χ²: a scan at the record's sample step, then a bounded Brent search around the best."""
    span = record.time[-1] - record.time[0]
    limit = MAX_OFFSET_FRACTION * span if max_offset is None else max_offset
    step = 1.0 / record.rate

    def cost(offset: float) -> float:
        return chi_square(record, residuals(record, predict(record, model_time, model, offset)))

    grid = np.arange(-limit, limit + 0.5 * step, step)
    best = int(np.argmin(scan_costs(record, model_time, model, grid)))
    low, high = grid[max(best - 1, 0)], grid[min(best + 1, len(grid) - 1)]
    offset = grid[best]
    if high > low:
        refined = minimize_scalar(cost, bounds=(low, high), method="bounded", options={"xatol": 1e-3 * step})
        if refined.fun < cost(offset):
            offset = float(refined.x)
    return fit_at(record, model_time, model, offset)


def scan_costs(record: Record, model_time: np.ndarray, model: dict[str, np.ndarray], offsets: np.ndarray) -> np.ndarray:
    """χ² (D3) at each of `offsets`, a grid in steps of the record's sample step (fit_offset's scan), with the model
    filtered once over the record's span widened by the offsets, and then shifted: the comparison filter commutes
    with a shift but for its start-up at the window's ends, so this finds the best offset's neighbourhood at a
    fraction of the cost of filtering every shifted copy. A shift by whole samples is a window of the filtered
    model, so every offset's residual comes from one strided view, without interpolation."""
    step = 1.0 / record.rate
    widened = np.arange(record.time[0] - offsets.max() - step, record.time[-1] - offsets.min() + 1.5 * step, step)
    starts = np.rint((record.time[0] - offsets - widened[0]) / step).astype(int)  # the window of each offset
    weights = record.weights
    costs = np.zeros(len(offsets))
    for s in record.values:
        filtered = lowpass(np.interp(widened, model_time, model[s]), record.cutoff, record.rate)
        windows = np.lib.stride_tricks.sliding_window_view(filtered, len(record.time))[starts]
        costs += weights[s] * np.sum((record.values[s] - windows) ** 2, axis=1)
    return costs


def fit_at(record: Record, model_time: np.ndarray, model: dict[str, np.ndarray], offset: float) -> Fit:
    """χ² and gaps of the model at trigger offset `offset`."""
    residual = residuals(record, predict(record, model_time, model, offset))
    gaps = sensor_gaps(record, residual)
    return Fit(float(offset), chi_square(record, residual), gaps, combined_gap(gaps))
