"""Travel-curve figures of merit of a breaker operation, from a travel history x(t) (m, s).

The figures a breaker travel analyser reports (docs/plotting.md "Travel curve"): operating time to contact touch,
average speed over a contact zone, total travel, overtravel, rebound and the damping-zone duration. Positions are
the sensor's signed displacement from t = 0; crossings are interpolated linearly between samples. A figure the
history does not reach (a position never crossed) is None. An optional tolerance envelope (a lower and an upper
limit curve) is checked against the whole curve: inside or not, where it first leaves, how far it goes beyond.
"""

from __future__ import annotations

import numpy as np


def first_crossing(time: np.ndarray, travel: np.ndarray, position: float, after: float = -np.inf) -> float | None:
    """The first time at or after `after` at which the travel reaches `position`, interpolated linearly; None if never."""
    offset, time = np.asarray(travel, dtype=float) - position, np.asarray(time, dtype=float)
    at_sample = np.flatnonzero(offset == 0.0)
    between = np.flatnonzero(offset[:-1] * offset[1:] < 0.0)  # strictly between sample i and i + 1
    share = offset[between] / (offset[between] - offset[between + 1])
    times = np.sort(np.concatenate([time[at_sample], time[between] + share * np.diff(time)[between]]))
    times = times[times >= after]
    return float(times[0]) if len(times) else None


def operating_time(time: np.ndarray, travel: np.ndarray, contact_touch: float, command_time: float = 0.0) -> float | None:
    """Closing (or opening) time: from the command to the first time the travel reaches the contact-touch position."""
    touch = first_crossing(time, travel, contact_touch, command_time)
    return None if touch is None else touch - command_time


def zone_speed(time: np.ndarray, travel: np.ndarray, zone: tuple[float, float]) -> float | None:
    """Average speed over the zone: |x₂ − x₁| / (t₂ − t₁), t₁, t₂ the first times the travel reaches x₁, then x₂."""
    start = first_crossing(time, travel, zone[0])
    end = None if start is None else first_crossing(time, travel, zone[1], start)
    if end is None or end == start:
        return None
    return abs(zone[1] - zone[0]) / (end - start)


def total_travel(travel: np.ndarray) -> float:
    """Total travel: |x_rest − x(0)|, x_rest the final rest position (the last sample)."""
    return float(abs(travel[-1] - travel[0]))


def _stroke_sign(travel: np.ndarray) -> float:
    return 1.0 if travel[-1] >= travel[0] else -1.0


def overtravel(travel: np.ndarray) -> float:
    """Overtravel: the largest travel beyond the final rest position, in the stroke direction (0 if none)."""
    sign = _stroke_sign(travel)
    return float(max(0.0, np.max(sign * (np.asarray(travel) - travel[-1]))))


def rebound(travel: np.ndarray) -> float:
    """Rebound: the travel back, against the stroke direction, from the farthest position to the lowest one after it."""
    along = _stroke_sign(travel) * np.asarray(travel, dtype=float)
    farthest = int(np.argmax(along))
    return float(along[farthest] - np.min(along[farthest:]))


def settling_time(time: np.ndarray, travel: np.ndarray, tolerance: float) -> float:
    """The time after which the travel stays within `tolerance` of the final rest position (band entry interpolated)."""
    offset = np.abs(np.asarray(travel, dtype=float) - travel[-1]) - tolerance
    outside = np.flatnonzero(offset > 0.0)
    if len(outside) == 0:
        return float(time[0])
    i = outside[-1]
    share = offset[i] / (offset[i] - offset[i + 1])
    return float(time[i] + share * (time[i + 1] - time[i]))


def damping_duration(time: np.ndarray, travel: np.ndarray, damping_start: float, tolerance: float) -> float | None:
    """Damping-zone duration: from the first time the travel reaches `damping_start` to the settling time."""
    start = first_crossing(time, travel, damping_start)
    return None if start is None else max(0.0, settling_time(time, travel, tolerance) - start)


def travel_figures(time: np.ndarray, travel: np.ndarray, spec) -> dict[str, float | None]:
    """Every figure of a `travel:` block (clearsim.model.schema.TravelCurve), SI, by name (the damping-zone duration
    only with a `damping_start`, the envelope check only with an `envelope`)."""
    time, travel = np.asarray(time, dtype=float), np.asarray(travel, dtype=float)
    finite = np.isfinite(travel) & np.isfinite(time)
    time, travel = time[finite], travel[finite]
    if len(travel) < 2:
        return {}
    figures = {
        "operating_time_s": operating_time(time, travel, spec.contact_touch, spec.command_time),
        "zone_speed_m_per_s": zone_speed(time, travel, spec.speed_zone),
        "total_travel_m": total_travel(travel),
        "overtravel_m": overtravel(travel),
        "rebound_m": rebound(travel),
    }
    if spec.damping_start is not None:  # no damping zone stated: no such figure
        figures["damping_duration_s"] = damping_duration(time, travel, spec.damping_start, spec.settle_tolerance)
    envelope = getattr(spec, "envelope", None)
    if envelope is not None:
        figures |= envelope_check(time, travel, envelope.lower, envelope.upper)
    return figures


# --- tolerance envelope: a lower and an upper limit curve, each straight between its [time, travel] points ---------


def envelope_span(lower: np.ndarray, upper: np.ndarray) -> tuple[float, float]:
    """The times both limit curves cover ([time, travel] rows, SI): the envelope holds there, nowhere else."""
    return max(lower[0, 0], upper[0, 0]), min(lower[-1, 0], upper[-1, 0])


def _knots(span: tuple[float, float], *times: np.ndarray) -> np.ndarray:
    """Every time in `times` within the span, and its two ends: between two of them all curves are straight."""
    every = np.concatenate([np.asarray(t, dtype=float) for t in times] + [np.array(span)])
    return np.unique(every[(every >= span[0]) & (every <= span[1])])


def _on(knots: np.ndarray, points: np.ndarray) -> np.ndarray:
    return np.interp(knots, points[:, 0], points[:, 1])


def limit_band(lower, upper) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(time, lower, upper) at every corner of either limit curve over the times both cover."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    knots = _knots(envelope_span(lower, upper), lower[:, 0], upper[:, 0])
    return knots, _on(knots, lower), _on(knots, upper)


def crossed_limits(lower, upper) -> tuple[float, float, float] | None:
    """(time, lower, upper) at the first corner where the lower limit lies above the upper one; None when it never
    does (the limits are straight between corners, so the corners decide)."""
    knots, low, high = limit_band(lower, upper)
    crossed = np.flatnonzero(low > high)
    return None if not len(crossed) else (float(knots[crossed[0]]), float(low[crossed[0]]), float(high[crossed[0]]))


def _zero_entry(start: float, end: float, before: float, after: float) -> float:
    """Where a straight line from `before` (≤ 0) at `start` to `after` (> 0) at `end` passes 0."""
    return start + (end - start) * (-before) / (after - before)


def envelope_check(time: np.ndarray, travel: np.ndarray, lower, upper) -> dict[str, bool | float | None]:
    """Whether the travel (straight between samples) stays within the limits over the times both cover, and if not
    the first time it leaves them and the largest excursion beyond a limit (with its time). Exact for the straight
    pieces: every sample time and every limit corner is a knot, between two knots the excursions are straight."""
    time, travel = np.asarray(time, dtype=float), np.asarray(travel, dtype=float)
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    start, end = envelope_span(lower, upper)
    span = (max(start, time[0]), min(end, time[-1]))
    inside = {"inside_envelope": True, "envelope_first_outside_s": None, "envelope_largest_excursion_m": 0.0,
              "envelope_largest_excursion_at_s": None}
    if span[0] > span[1]:  # the curve ends before the envelope begins: nothing to check
        return inside | {"inside_envelope": None}
    knots = _knots(span, time, lower[:, 0], upper[:, 0])
    position = np.interp(knots, time, travel)
    above, below = position - _on(knots, upper), _on(knots, lower) - position
    excursion = np.maximum(above, below)
    outside = np.flatnonzero(excursion > 0.0)
    if not len(outside):
        return inside
    i, largest = outside[0], int(np.argmax(excursion))
    first = knots[i] if i == 0 else min(_zero_entry(knots[i - 1], knots[i], side[i - 1], side[i])
                                        for side in (above, below) if side[i] > 0.0)
    return {"inside_envelope": False, "envelope_first_outside_s": float(first),
            "envelope_largest_excursion_m": float(excursion[largest]),
            "envelope_largest_excursion_at_s": float(knots[largest])}


def envelope_rows(figures: dict) -> list[tuple[str, str]]:
    """The envelope check of a `travel_figures` record as (label, value) rows: inside or not, and if not where the
    curve first leaves the envelope and its largest excursion beyond a limit."""
    inside = figures["inside_envelope"]
    if inside is None:
        return [("within the envelope", "not checked: the run ends before it begins")]
    if inside:
        return [("within the envelope", "yes")]
    return [("within the envelope", "no"),
            ("leaves the envelope at", f"{figures['envelope_first_outside_s'] * 1e3:.4g} ms"),
            ("largest excursion", f"{figures['envelope_largest_excursion_m'] * 1e3:.4g} mm at "
                                  f"{figures['envelope_largest_excursion_at_s'] * 1e3:.4g} ms")]


# figure of a `travel_figures` record → its label and how it is shown (SI value × scale, unit)
FIGURE_ROWS = {"operating_time_s": ("time to contact touch", 1e3, "ms"),
               "zone_speed_m_per_s": ("speed-zone average speed", 1.0, "m/s"),
               "total_travel_m": ("total travel", 1e3, "mm"), "overtravel_m": ("overtravel", 1e3, "mm"),
               "rebound_m": ("rebound", 1e3, "mm"), "damping_duration_s": ("damping-zone duration", 1e3, "ms")}


def figure_rows(figures: dict) -> list[tuple[str, str]]:
    """(label, value with its unit) of each figure of a `travel_figures` record ("not reached": a position the
    travel never crossed), and the envelope verdict when an envelope was given."""
    rows = [(label, "not reached" if figures[key] is None else f"{figures[key] * scale:.4g} {unit}")
            for key, (label, scale, unit) in FIGURE_ROWS.items() if key in figures]
    return rows + (envelope_rows(figures) if "inside_envelope" in figures else [])
