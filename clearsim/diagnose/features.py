"""What engineers read off a record, measured beside modelled, and where the residual leaves the noise band."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import savgol_filter

from clearsim.diagnose.align import Record, SMOOTHER_ORDER, smoother_window

START_FRACTION = 0.05  # a signal has started when it has moved 5 % of its range
SETTLE_BAND = 0.02  # settled: within ±2 % of the range around the final value
WINDOW_SECONDS = 1e-3  # moving RMS of the residual over 1 ms
POSITIONS = ("m", "rad")  # units of displacement and angle sensors
BAND = 3.0  # a window disagrees where the moving RMS exceeds 3 σ̂


@dataclass(frozen=True)
class Feature:
    sensor: str
    name: str
    measured: float
    model: float
    unit: str

    @property
    def difference(self) -> float:
        return self.measured - self.model


def start_time(time: np.ndarray, values: np.ndarray) -> float:
    """First time the signal has moved START_FRACTION of its range from its initial value."""
    moved = np.abs(values - values[0]) >= START_FRACTION * np.ptp(values)
    return float(time[np.argmax(moved)]) if np.any(moved) else np.nan


def settling_time(time: np.ndarray, values: np.ndarray) -> float:
    """Last time the signal is outside ±SETTLE_BAND of its range around its final value."""
    outside = np.abs(values - values[-1]) > SETTLE_BAND * np.ptp(values)
    return float(time[np.nonzero(outside)[0][-1]]) if np.any(outside) else float(time[0])


def overshoot(values: np.ndarray) -> float:
    """How far the signal goes beyond its final value, in the direction of travel, as a fraction of its range."""
    travel = np.sign(values[-1] - values[0]) or 1.0
    return float(max(0.0, np.max(travel * (values - values[-1]))) / (np.ptp(values) or 1.0))


def shaking(values: np.ndarray, rate: float) -> float:
    """RMS of the signal above the local cubic trend (the smoother of the noise estimate): high-frequency content."""
    window = smoother_window(len(values))
    if window <= SMOOTHER_ORDER + 1:
        return 0.0
    return float(np.sqrt(np.mean((values - savgol_filter(values, window, SMOOTHER_ORDER, mode="interp")) ** 2)))


def features(record: Record, prediction: dict[str, np.ndarray], units: dict[str, str]) -> list[Feature]:
    """Start, peak, end value and shaking of every sensor, overshoot and settling of travels; measured vs model."""
    out = []
    for sensor, measured in record.values.items():
        model, unit, t = prediction[sensor], units.get(sensor, ""), record.time
        tail = max(len(t) // 50, 1)
        pairs = {
            "start time": (start_time(t, measured), start_time(t, model), "s"),
            "peak |value|": (float(np.max(np.abs(measured))), float(np.max(np.abs(model))), unit),
            "end value": (float(np.mean(measured[-tail:])), float(np.mean(model[-tail:])), unit),
            "shaking (RMS above trend)": (shaking(measured, record.rate), shaking(model, record.rate), unit),
        }
        if unit in POSITIONS:  # a travel: it overshoots its end position and settles
            pairs["overshoot"] = (overshoot(measured), overshoot(model), "of range")
            pairs["settling time"] = (settling_time(t, measured), settling_time(t, model), "s")
        out += [Feature(sensor, name, m, p, u) for name, (m, p, u) in pairs.items()]
    return out


@dataclass(frozen=True)
class Window:
    sensor: str
    start: float
    end: float
    peak: float  # largest moving RMS in the window, in noise levels


def disagreement_windows(record: Record, residual: dict[str, np.ndarray]) -> list[Window]:
    """Time windows where the 1-ms moving RMS of the residual over the compared samples exceeds BAND noise levels."""
    width = max(int(round(WINDOW_SECONDS * record.rate)), 3)
    kernel = np.ones(width) / width
    time = record.time[record.compared]
    out = []
    for sensor, r in residual.items():
        level = np.sqrt(np.convolve(r[record.compared] ** 2, kernel, mode="same")) / record.noise[sensor].std
        flagged = level > BAND
        edges = np.diff(np.concatenate([[0], flagged.astype(int), [0]]))
        for start, stop in zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]):
            out.append(Window(sensor, float(time[start]), float(time[stop - 1]),
                              float(level[start:stop].max())))
    return sorted(out, key=lambda w: -w.peak)


RESONANCE_CYCLES = 3.0  # a resonance rings at least 3 cycles over the record; slower content is the quasi-static part
SPECTRUM_PADDING = 16  # zero padding of the spectrum: peaks located to 1/16 of the record's frequency resolution


def dominant_frequency(record: Record, signals: dict[str, np.ndarray]) -> float | None:
    """Frequency of the highest peak of the summed spectra of `signals` (each in noise levels, Hann window)
    between RESONANCE_CYCLES per record and the comparison band: the ringing a stiffness sets. None: no content."""
    n = len(record.time)
    frequencies = np.fft.rfftfreq(SPECTRUM_PADDING * n, 1.0 / record.rate)
    window = np.hanning(n)
    power = sum(np.abs(np.fft.rfft(window * (v - v.mean()) / record.noise[s].std, SPECTRUM_PADDING * n)) ** 2
                for s, v in signals.items())
    duration = record.time[-1] - record.time[0]
    keep = np.flatnonzero((frequencies > RESONANCE_CYCLES / duration) & (frequencies < (record.cutoff or record.rate / 2)))
    if keep.size == 0 or not np.any(power[keep] > 0.0):
        return None
    return float(frequencies[keep[np.argmax(power[keep])]])
