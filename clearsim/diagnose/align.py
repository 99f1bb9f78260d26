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

from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.signal import butter, savgol_filter, sosfiltfilt, spectrogram
from scipy.stats import chi2

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
QUIET_SHARE = 0.3  # a segment is quiet where the model's own scatter is below 30 % of σ̂ (≤ 9 % of the noise variance)
QUIET_ROUNDS = 3  # σ̂ from the quiet segments, the quiet segments from σ̂: rounds from the trend estimate down
MIN_QUIET_SEGMENTS = 4  # fewer quiet Welch segments than this: the trend estimate stands
HANN_BINS = 1.5  # equivalent noise bandwidth of the Hann window, in bins: neighbouring bins are correlated
OVERLAP_VARIANCE = 1.056  # Welch (1967): variance of a 50 %-overlap Hann average over that of independent segments
MEDIAN_EFFICIENCY = 1.0 / (4.0 * np.log(2.0) ** 2)  # of a median of exponential (χ²₂) bins against their mean: 0.52
INTERVAL_LEVEL = 0.95  # the χ² interval reported on σ̂
PLATEAU_BINS = 9  # the running median of the noise spectrum whose lowest value is the rattle-free floor
PLATEAU_SEGMENTS = 6  # fewer Welch segments: white noise alone would pass RATTLE_EXCESS in a few % of records
RATTLE_EXCESS = 9.0  # the flat part's mean above this × the rattle-free floor: the flat part holds a rattle (σ̂ 3×)

TREND, QUIET, REPEATS = "trend", "quiet", "repeats"  # the noise estimators (docs/diagnose.md §1)


@dataclass(frozen=True)
class NoiseEstimate:
    """The noise of one sensor's record, estimated from the record alone."""

    std: float  # σ̂, SI
    effective_samples: float  # n_eff
    samples: int  # N
    bandwidth: float | None  # Hz where the noise floor has dropped to 10 %, None: flat to Nyquist
    floor: float = 0.0  # one-sided noise density at low frequency, unit²/Hz
    degrees_of_freedom: float = np.inf  # ν of the floor (σ̂² ~ σ² χ²_ν/ν): the χ² interval on σ̂
    estimator: str = TREND  # TREND: the record minus its trend; QUIET: the residual against the model where the
    # model is quiet; REPEATS: the difference of repeated records

    def filtered(self, cutoff: float, rate: float) -> "NoiseEstimate":
        """The same noise after the comparison low-pass: σ² = S_n(0)·B_eq(cutoff) where that is below
        the record's own noise, n_eff = N·2 B_eq/rate."""
        band = equivalent_bandwidth(cutoff)
        if self.floor <= 0.0 or self.floor * band >= self.std ** 2:
            return self
        return replace(self, std=float(np.sqrt(self.floor * band)),
                       effective_samples=self.samples * min(1.0, 2.0 * band / rate), bandwidth=cutoff)

    def interval(self, level: float = INTERVAL_LEVEL) -> tuple[float, float]:
        """The χ² interval on σ̂ at `level`: σ̂ √(ν/χ²_ν(1 − α/2)) … σ̂ √(ν/χ²_ν(α/2))."""
        if not np.isfinite(self.degrees_of_freedom):
            return self.std, self.std
        tail = 0.5 * (1.0 - level)
        nu = self.degrees_of_freedom
        return (float(self.std * np.sqrt(nu / chi2.ppf(1.0 - tail, nu))),
                float(self.std * np.sqrt(nu / chi2.ppf(tail, nu))))


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


def estimate_noise(values: np.ndarray | list[np.ndarray], rate: float, quiet: np.ndarray | None = None,
                   estimator: str = TREND) -> NoiseEstimate:
    """σ̂ and n_eff of a record: the high-pass scatter's median Welch spectrum, divided by the
    smoother's high-pass response and continued flat below its cut-off, integrated.

    values: one signal, or several of one length whose segments all count (the scaled differences of repeats).
    quiet: per sample, True where the scatter is noise alone; only Welch segments wholly inside it count
    (fewer than MIN_QUIET_SEGMENTS: all count, and the estimator is TREND)."""
    signals = [np.asarray(v, dtype=float) for v in (values if isinstance(values, list) else [values])]
    count = len(signals[0])
    window = smoother_window(count)
    if window <= SMOOTHER_ORDER + 1:
        scatter = signals[0] - np.mean(signals[0])
        return NoiseEstimate(float(np.std(scatter)), float(count), count, None, degrees_of_freedom=count - 1.0)
    scatters = [v - savgol_filter(v, window, SMOOTHER_ORDER, mode="interp") for v in signals]
    frequencies, segments = segment_spectra(scatters, rate, quiet)
    if quiet is not None and len(segments) < MIN_QUIET_SEGMENTS:
        frequencies, segments = segment_spectra(scatters, rate, None)
        estimator = TREND
    density = np.median(segments, axis=0) / _median_bias(len(segments))
    passed = (1.0 - smoother_response(window, frequencies, rate)) ** 2
    valid = passed > PASSED
    if not np.any(valid):
        return NoiseEstimate(float(np.std(scatters[0])), float(count), count, None, estimator=estimator)
    noise = np.where(valid, density / np.where(valid, passed, 1.0), 0.0)
    level, bins = _floor_level(frequencies, noise, valid, len(segments))
    bandwidth = _bandwidth(frequencies, noise, level)
    noise = np.where(valid, np.minimum(noise, LINE_FACTOR * level), level)  # lines far above the floor are signal
    variance = float(np.trapezoid(noise, frequencies))
    white = 2.0 * variance / rate
    effective = count * min(1.0, white / level) if level > 0.0 else float(count)
    return NoiseEstimate(float(np.sqrt(max(variance, 0.0))), effective, count, bandwidth, level,
                         floor_degrees_of_freedom(len(segments), bins), estimator)


def floor_degrees_of_freedom(segments: int, bins: int) -> float:
    """ν of the noise floor, the mean over `bins` Hann bins of each bin's median over `segments` Welch segments:
    2 per bin and segment, the segments' overlap (OVERLAP_VARIANCE), the median's efficiency (MEDIAN_EFFICIENCY)
    and the correlation of neighbouring bins (HANN_BINS) taken off."""
    return 2.0 * segments / OVERLAP_VARIANCE * MEDIAN_EFFICIENCY * max(bins, 1) / HANN_BINS


def segment_spectra(scatters: list[np.ndarray], rate: float, quiet: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """One-sided density of every Welch segment (WELCH_SEGMENT-sample Hann, half overlapping, mean removed) of each
    scatter signal; with `quiet`, only the segments whose samples are all quiet."""
    length = min(WELCH_SEGMENT, len(scatters[0]))
    rows = []
    for scatter in scatters:
        frequencies, _, density = spectrogram(scatter, fs=rate, window="hann", nperseg=length, noverlap=length // 2,
                                              detrend="constant", scaling="density", mode="psd")
        starts = np.arange(density.shape[1]) * (length - length // 2)
        keep = [quiet is None or bool(np.all(quiet[k:k + length])) for k in starts]
        rows += [density[:, j] for j in np.flatnonzero(keep)]
    return frequencies, np.array(rows).reshape(len(rows), len(frequencies))


def _median_bias(count: int) -> float:
    """Median of `count` χ²₂ variables over their mean (scipy's Welch median correction): 1 − 1/2 + 1/3 − …"""
    odd = 2.0 * np.arange(1.0, (count - 1) // 2 + 1)
    return float(1.0 + np.sum(1.0 / (odd + 1.0) - 1.0 / odd))


def repeat_noise(records: list[np.ndarray], rate: float) -> NoiseEstimate:
    """σ̂ from repeated records of one test on one grid: the deviations from their mean, y_i − ȳ, scaled by
    √(n/(n − 1)) to the noise of one record, hold the noise alone wherever the repeats agree (whatever the model);
    their segments together give the estimate (ν grows with the n − 1 independent deviations)."""
    stacked = np.array(records, dtype=float)
    count = len(stacked)
    scale = np.sqrt(count / (count - 1.0))
    deviations = [scale * (row - stacked.mean(axis=0)) for row in stacked]
    estimate = estimate_noise(deviations, rate, estimator=REPEATS)
    return replace(estimate, degrees_of_freedom=estimate.degrees_of_freedom * (count - 1) / count)


def quiet_samples(model: np.ndarray, rate: float, level: float) -> np.ndarray:
    """Per sample, True where the model's own scatter about its trend, RMS over the surrounding Welch segment, is
    below QUIET_SHARE × `level` (σ̂): no rattle or ringing of the model there."""
    window = smoother_window(len(model))
    if window <= SMOOTHER_ORDER + 1:
        return np.ones(len(model), dtype=bool)
    scatter = model - savgol_filter(model, window, SMOOTHER_ORDER, mode="interp")
    length = min(WELCH_SEGMENT, len(model))
    local = np.sqrt(np.convolve(scatter ** 2, np.ones(length) / length, mode="same"))
    return local < QUIET_SHARE * level


def model_quiet_noise(record: np.ndarray, model: np.ndarray, rate: float, start: NoiseEstimate) -> NoiseEstimate:
    """σ̂ from the residual against the model (record − model, both unfiltered) where the model is quiet
    (`quiet_samples`): rattle and ringing the model predicts are left out, the residual there is the noise. The quiet
    part is found from σ̂ and σ̂ from the quiet part, QUIET_ROUNDS rounds from `start` (the trend estimate, which a
    rattle raises); too few quiet segments: `start` stands."""
    estimate = start
    for _ in range(QUIET_ROUNDS):
        quiet = quiet_samples(model, rate, estimate.std)
        found = estimate_noise(record - model, rate, quiet, QUIET)
        if found.estimator != QUIET:
            return start
        estimate = found
    return estimate


def equivalent_bandwidth(cutoff: float) -> float:
    """Noise-equivalent bandwidth of the zero-phase comparison filter: ∫ |H(f)|⁴ df, |H|² = 1/(1 + (f/f_c)^8)."""
    from scipy.integrate import quad

    return cutoff * quad(lambda x: 1.0 / (1.0 + x ** (2 * COMPARISON_FILTER_ORDER)) ** 2, 0.0, np.inf)[0]


def _floor_level(frequencies: np.ndarray, noise: np.ndarray, valid: np.ndarray, segments: int) -> tuple[float, int]:
    """The flat noise floor and the number of bins it is the mean of: the mean density over the flat part of the
    passband (up to FLAT_PART of the bandwidth), spectral lines above LINE_FACTOR × the median left out. Two rounds:
    the lowest valid bins give the bandwidth, the bandwidth gives the flat part. Where that mean exceeds the
    rattle-free floor (`rattle_free_floor`) by more than RATTLE_EXCESS, the flat part holds a rattle (its spectrum
    falls with frequency, the noise's does not) and the rattle-free floor is the level; not from fewer than
    PLATEAU_SEGMENTS Welch segments, whose bins scatter too much for their lowest median to mean anything."""
    first = np.nonzero(valid)[0][:FLOOR_BINS]
    bandwidth = _bandwidth(frequencies, noise, float(np.median(noise[first])))
    flat = valid & (frequencies <= FLAT_PART * (bandwidth or frequencies[-1] / FLAT_PART))
    if not np.any(flat):
        flat = valid
    typical = float(np.median(noise[flat]))
    kept = noise[flat][noise[flat] <= LINE_FACTOR * typical]
    level, bins = (float(np.mean(kept)), len(kept)) if len(kept) else (typical, 1)
    plateau = rattle_free_floor(frequencies, noise, valid) if segments >= PLATEAU_SEGMENTS else None
    return (plateau, PLATEAU_BINS) if plateau is not None and level > RATTLE_EXCESS * plateau else (level, bins)


def rattle_free_floor(frequencies: np.ndarray, noise: np.ndarray, valid: np.ndarray) -> float | None:
    """The lowest running median (PLATEAU_BINS valid bins) of the noise spectrum that is the lowest one of its own flat
    part (up to FLAT_PART of the bandwidth it gives as a floor, as in `_floor_level`): an upper bound of a white noise's
    density that a rattle's spectrum, falling with frequency, reaches only where it has fallen below the noise. A
    level in the bench filter's roll-off lies beyond its own flat part, so it is not one; nor is a level the spectrum
    stays above to the Nyquist frequency (no bench filter: no roll-off tells the passband's end). None: too few valid
    bins, or no such level."""
    where = np.nonzero(valid)[0]
    if len(where) < 2 * PLATEAU_BINS:
        return None
    medians = np.median(np.lib.stride_tricks.sliding_window_view(noise[where], PLATEAU_BINS), axis=1)
    centres = frequencies[where][PLATEAU_BINS // 2: PLATEAU_BINS // 2 + len(medians)]
    for level in np.sort(medians[medians > 0.0]):
        bandwidth = _bandwidth(frequencies, noise, float(level))
        flat = medians[centres <= FLAT_PART * bandwidth] if bandwidth is not None else []
        if len(flat) and np.min(flat) == level:
            return float(level)
    return None


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
    unfiltered: dict[str, np.ndarray] = field(default_factory=dict)  # the record on the grid, before any low-pass

    @property
    def weights(self) -> dict[str, float]:
        """χ² weight of one squared residual sample: (n_eff/N) / σ̂²."""
        return {s: (n.effective_samples / n.samples) / n.std ** 2 for s, n in self.noise.items()}

    @property
    def effective_samples(self) -> float:
        """n_eff of the compared samples, all sensors together: χ²'s expectation on noise alone."""
        kept = len(range(*self.compared.indices(len(self.time)))) / max(len(self.time), 1)
        return float(kept * sum(n.effective_samples for n in self.noise.values()))

    @property
    def compared(self) -> slice:
        """The samples every comparison uses: all but the comparison filter's start-up at each end (1/f_c). There the
        filtered record holds the noise of its first or last sample nearly unfiltered (the filter's odd padding
        repeats it): 57 σ̂² at the end sample, still 2 σ̂² half a start-up in (4th-order Butterworth run forward and
        backward), so gaps, χ², the noise test and the disagreement windows all leave it out."""
        if self.cutoff is None:
            return slice(None)
        edge = int(np.ceil(self.rate / self.cutoff))
        return slice(edge, len(self.time) - edge) if len(self.time) > 4 * edge else slice(None)


def uniform_grid(time: np.ndarray) -> np.ndarray:
    """The record's uniform grid: its first time in steps of its median step."""
    step = float(np.median(np.diff(time)))
    return time[0] + step * np.arange(int(np.floor((time[-1] - time[0]) / step + 1e-9)) + 1)


def prepare_record(time: np.ndarray, values: dict[str, np.ndarray], cutoff: float | None = None,
                   noise: dict[str, NoiseEstimate] | None = None) -> Record:
    """Resample onto a uniform grid (`uniform_grid`), estimate each sensor's noise, and
    low-pass the record at the comparison bandwidth (model predictions get the same filter); the
    record in the screening band (LOW_BAND_FACTOR × that bandwidth) rides along as `low_band`.

    cutoff: the comparison bandwidth (Hz); None: COMPARISON_BANDWIDTH, or the record's own
    bandwidth where that is narrower.
    noise: the noise of each sensor on that grid (repeats, or the residual against a model); None: the record
    minus its trend (TREND).
    """
    grid = uniform_grid(time)
    uniform = {s: np.interp(grid, time, v) for s, v in values.items()}
    rate = 1.0 / (grid[1] - grid[0])
    noise = dict(noise) if noise is not None else {s: estimate_noise(v, rate) for s, v in uniform.items()}
    if cutoff is None:
        seen = [n.bandwidth for n in noise.values() if n.bandwidth is not None]
        cutoff = min([COMPARISON_BANDWIDTH, *seen])
    for sensor, estimate in noise.items():
        if not estimate.std > 0.0:
            noise[sensor] = replace(estimate, std=_quantisation_floor(uniform[sensor]), floor=0.0)
    record = _in_band(grid, rate, uniform, noise, cutoff)
    record.low_band = _in_band(grid, rate, uniform, noise, LOW_BAND_FACTOR * (record.cutoff or 0.5 * rate))
    return record


def _in_band(grid: np.ndarray, rate: float, uniform: dict[str, np.ndarray], noise: dict[str, NoiseEstimate],
             cutoff: float) -> Record:
    """The record low-passed at `cutoff` (none at or above Nyquist), with its noise seen through that filter."""
    cutoff = cutoff if cutoff < 0.5 * rate else None
    if cutoff is None:
        return Record(grid, rate, dict(uniform), dict(noise), None, unfiltered=uniform)
    return Record(grid, rate, {s: lowpass(v, cutoff, rate) for s, v in uniform.items()},
                  {s: n.filtered(cutoff, rate) for s, n in noise.items()}, cutoff, unfiltered=uniform)


def residual_noise(record: Record, model_time: np.ndarray, model: dict[str, np.ndarray],
                   offset: float) -> dict[str, NoiseEstimate]:
    """Per sensor, the lower of two estimates that each hold the noise and something more: the record minus its trend
    (TREND: and the record's own rattle) and the residual against the model at trigger offset `offset`, low-passed at
    the record's bandwidth, where the model is quiet if enough of it is, else all of it (QUIET: and what the model
    misses). The model's dynamics, rattle included, are left out of the second."""
    trend = {s: estimate_noise(v, record.rate) for s, v in record.unfiltered.items()}
    chosen = {}
    for sensor, values in record.unfiltered.items():
        prediction = lowpass(np.interp(record.time - offset, model_time, model[sensor]), trend[sensor].bandwidth,
                             record.rate)  # the bench's filter, as far as the record shows it
        against = model_quiet_noise(values, prediction, record.rate, trend[sensor])
        if against.estimator != QUIET:
            against = estimate_noise(values - prediction, record.rate, estimator=QUIET)
        chosen[sensor] = min(trend[sensor], against, key=lambda estimate: estimate.std)
    return chosen


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
    """χ² = Σ_s (n_eff,s/N_s) Σ_k r_sk²/σ̂_s² over the compared samples (docs/diagnose.md eq. D3)."""
    return _weighted_squares(record, {s: r[record.compared] for s, r in residual.items()})


def _weighted_squares(record: Record, residual: dict[str, np.ndarray]) -> float:
    weights = record.weights
    return float(sum(weights[s] * np.sum(r ** 2) for s, r in residual.items()))


def chi_square_halves(record: Record, residual: dict[str, np.ndarray]) -> tuple[float, float]:
    """χ² (D3) of the first and of the second half of the compared samples, for a check on data the other half
    fitted."""
    compared = {s: r[record.compared] for s, r in residual.items()}
    middle = len(next(iter(compared.values()), [])) // 2
    first = {s: r[:middle] for s, r in compared.items()}
    second = {s: r[middle:] for s, r in compared.items()}
    return _weighted_squares(record, first), _weighted_squares(record, second)


def sensor_gaps(record: Record, residual: dict[str, np.ndarray]) -> dict[str, float]:
    """g_s = RMS(r_s)/σ̂_s over the compared samples (docs/diagnose.md eq. D1)."""
    return {s: float(np.sqrt(np.mean(r[record.compared] ** 2)) / record.noise[s].std) for s, r in residual.items()}


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
        costs += weights[s] * np.sum(((record.values[s] - windows)[:, record.compared]) ** 2, axis=1)
    return costs


def fit_at(record: Record, model_time: np.ndarray, model: dict[str, np.ndarray], offset: float) -> Fit:
    """χ² and gaps of the model at trigger offset `offset`."""
    residual = residuals(record, predict(record, model_time, model, offset))
    gaps = sensor_gaps(record, residual)
    return Fit(float(offset), chi_square(record, residual), gaps, combined_gap(gaps))


UNEXPLAINED_LEVEL = 0.01  # false-alarm rate of the "unexplained" test over all sensors together (Bonferroni)
DECAYED_LAGS = 10  # the residual's autocorrelation has decayed where it stays within its noise for this many lags


@dataclass(frozen=True)
class ChaoticSpread:
    """What the model's own realisations of a chaotic impact sequence add to a residual (docs/diagnose.md §5b): per
    sensor, the variance D_k at each compared sample of a re-rolled twin's prediction about the reported one (the mean
    over the twins of their squared differences, moving-averaged), and the degrees of freedom of that estimate."""

    variance: dict  # sensor → D_k over the compared samples (the sensor's unit squared)
    degrees_of_freedom: dict  # sensor → ν_D
    twins: int  # the twins it is estimated from

    def in_noise_levels(self, record: Record) -> dict[str, float]:
        """√(mean D_k)/σ̂ per sensor: how far, RMS, the twins stray from the reported run, in noise levels."""
        return {s: float(np.sqrt(np.mean(d)) / record.noise[s].std) for s, d in self.variance.items()}


@dataclass(frozen=True)
class NoiseTest:
    """Is a residual consistent with the noise (and the chaotic spread, when given)? Per sensor,
    gap² = mean(r_k²/(σ̂² + D_k)) against F(n_eff, ν): the standardised residual's squares are worth n_eff independent
    ones (from its autocorrelation), σ̂² + D̄ has ν degrees of freedom (Welch–Satterthwaite)."""

    gaps: dict  # sensor → gap (RMS residual / σ̂; standardised by σ̂² + D_k where a spread is given)
    effective_samples: dict  # sensor → n_eff of the (standardised) residual
    p_values: dict  # sensor → P(gap this large | noise and spread alone)
    level: float = UNEXPLAINED_LEVEL
    spread: dict = field(default_factory=dict)  # sensor → the twins' stray in noise levels (ChaoticSpread); {}: none

    @property
    def failing(self) -> list[str]:
        """The sensors whose residual is beyond the noise at `level` (shared among the sensors)."""
        return [s for s, p in self.p_values.items() if p < self.level / len(self.p_values)]

    @property
    def consistent(self) -> bool:
        return not self.failing


def residual_effective_samples(residual: np.ndarray) -> float:
    """n_eff = N / (1 + 2 Σ_k (1 − k/N) ρ_k²): the independent samples whose squares vary as much as the residual's
    (Var Σ r² = 2σ⁴ N (1 + 2 Σ_k (1 − k/N) ρ_k²) for a Gaussian sequence), ρ_k its sample autocorrelation, summed up
    to the first lag from which |ρ_k| stays below 2/√N for DECAYED_LAGS lags (beyond it the sample ρ_k is its own
    noise; a band-limited residual's ρ_k crosses zero between its lobes, so one lag below is not enough)."""
    count = len(residual)
    centred = residual - np.mean(residual)
    spectrum = np.fft.rfft(centred, 2 * count)
    correlation = np.fft.irfft(np.abs(spectrum) ** 2)[:count]
    if correlation[0] <= 0.0:
        return float(count)
    rho = correlation / correlation[0]
    quiet = np.abs(rho) < 2.0 / np.sqrt(count)
    runs = np.convolve(quiet.astype(float), np.ones(DECAYED_LAGS), mode="valid") >= DECAYED_LAGS
    last = int(np.argmax(runs[1:])) + 1 if np.any(runs[1:]) else count
    lags = np.arange(1, last)
    return float(count / (1.0 + 2.0 * np.sum((1.0 - lags / count) * rho[1:last] ** 2)))


def combined_degrees_of_freedom(noise_variance: float, noise_dof: float, spread_variance: float,
                                spread_dof: float) -> float:
    """ν of σ̂² + D̄ from those of its two terms (Welch–Satterthwaite): (σ̂² + D̄)² / (σ̂⁴/ν_σ + D̄²/ν_D)."""
    if spread_variance <= 0.0:
        return noise_dof
    return float((noise_variance + spread_variance) ** 2
                 / (noise_variance ** 2 / noise_dof + spread_variance ** 2 / spread_dof))


def noise_test(record: Record, residual: dict[str, np.ndarray], spread: ChaoticSpread | None = None) -> NoiseTest:
    """The residual (in the comparison band, its compared samples) against the noise, per sensor:
    p = P(F(n_eff, ν) ≥ gap²); with a chaotic spread, each sample's residual against σ̂² + D_k (docs/diagnose.md D5)."""
    from scipy.stats import f as fisher

    gaps, effective, p_values = {}, {}, {}
    for s, r in residual.items():
        noise = record.noise[s]
        spread_variance = spread.variance[s] if spread is not None else np.zeros(1)
        standardised = r[record.compared] / np.sqrt(noise.std ** 2 + spread_variance)
        gaps[s] = float(np.sqrt(np.mean(standardised ** 2)))
        effective[s] = residual_effective_samples(standardised)
        dof = (combined_degrees_of_freedom(noise.std ** 2, noise.degrees_of_freedom, float(np.mean(spread_variance)),
                                           spread.degrees_of_freedom[s]) if spread is not None
               else noise.degrees_of_freedom)
        p_values[s] = float(fisher.sf(gaps[s] ** 2, effective[s], min(dof, 1e9)))
    return NoiseTest(gaps, effective, p_values, spread=spread.in_noise_levels(record) if spread is not None else {})
