"""Travel-curve figures (clearsim.travel) on a piecewise-linear travel whose figures are known in closed form.

The samples hold every kink of the curve, so linear interpolation between them is exact: each figure must match
its closed form to rounding (1e-12 relative)."""

from types import SimpleNamespace

import numpy as np
import pytest

from clearsim.travel import crossed_limits, envelope_check, first_crossing, travel_figures

MM, MS = 1e-3, 1e-3
# (time ms, travel mm): rest, 4 m/s to 160 mm, 5 m/s to 310 mm, back to 294 mm, settles at 300 mm
KINKS = [(0, 0), (10, 0), (50, 160), (80, 310), (84, 294), (86, 300), (100, 300)]
SPEC = SimpleNamespace(sensor="rod", command_time=2 * MS, contact_touch=250 * MM, speed_zone=(150 * MM, 250 * MM),
                       damping_start=280 * MM, settle_tolerance=1 * MM)
# closed forms: touch at 50 + (250 - 160)/5 = 68 ms; 150 mm at 10 + 150/4 = 47.5 ms; 280 mm at 50 + 120/5 = 74 ms;
# within 1 mm of 300 mm for good at 84 + (299 - 294)/3 ms
EXPECTED = {"operating_time_s": 66 * MS, "zone_speed_m_per_s": 100 * MM / (20.5 * MS), "total_travel_m": 300 * MM,
            "overtravel_m": 10 * MM, "rebound_m": 16 * MM, "damping_duration_s": (84 + 5 / 3 - 74) * MS}


def sampled(step_ms: float = 0.3):
    """The curve sampled every `step_ms` (crossings fall between samples) and at each kink."""
    kink_times, kink_travel = np.array(KINKS, dtype=float).T
    time = np.union1d(np.arange(0.0, 100.0, step_ms), kink_times)
    return time * MS, np.interp(time, kink_times, kink_travel) * MM


def test_each_figure_equals_its_closed_form():
    figures = travel_figures(*sampled(), SPEC)
    assert figures.keys() == EXPECTED.keys()
    for name, value in EXPECTED.items():
        assert figures[name] == pytest.approx(value, rel=1e-12, abs=1e-15), name


def test_an_opening_stroke_negative_along_the_sensor_gives_the_same_figures():
    time, travel = sampled()
    mirrored = SimpleNamespace(**(vars(SPEC) | {"contact_touch": -SPEC.contact_touch,
                                                "speed_zone": tuple(-x for x in SPEC.speed_zone),
                                                "damping_start": -SPEC.damping_start}))
    figures = travel_figures(time, -travel, mirrored)
    for name, value in EXPECTED.items():
        assert figures[name] == pytest.approx(value, rel=1e-12, abs=1e-15), name


def test_positions_never_reached_give_no_figure():
    spec = SimpleNamespace(**(vars(SPEC) | {"contact_touch": 400 * MM, "speed_zone": (250 * MM, 320 * MM),
                                            "damping_start": 311 * MM}))
    figures = travel_figures(*sampled(), spec)
    assert figures["operating_time_s"] is None and figures["zone_speed_m_per_s"] is None
    assert figures["damping_duration_s"] is None


def test_a_crossing_in_the_interval_holding_the_start_time_is_found():
    """Both zone positions between the same two samples: the second is found after the first, not skipped."""
    time, travel = np.array([0.0, 1.0]), np.array([0.0, 1.0])
    assert first_crossing(time, travel, 0.5, after=0.25) == pytest.approx(0.5)
    assert first_crossing(time, travel, 0.2, after=0.25) is None


def test_a_curve_without_overtravel_has_no_overtravel_nor_rebound():
    time = np.linspace(0.0, 1.0, 11)
    spec = SimpleNamespace(**(vars(SPEC) | {"command_time": 0.0, "contact_touch": 0.25, "speed_zone": (0.1, 0.3),
                                            "damping_start": None}))
    figures = travel_figures(time, np.minimum(time, 0.5), spec)
    assert figures["overtravel_m"] == 0.0 and figures["rebound_m"] == 0.0 and "damping_duration_s" not in figures
    assert figures["operating_time_s"] == pytest.approx(0.25) and figures["zone_speed_m_per_s"] == pytest.approx(1.0)


# --- tolerance envelope: limit curves whose crossings with the travel are known in closed form (ms, mm) ----------
LOWER = [(0, -5), (20, 0), (60, 150), (100, 290)]
UPPER = [(0, 5), (10, 5), (50, 200), (80, 320), (100, 320)]


def limits(points):
    return np.array(points, dtype=float) * MM


def test_a_travel_within_its_envelope_is_inside():
    spec = SimpleNamespace(**(vars(SPEC) | {"envelope": SimpleNamespace(lower=limits(LOWER), upper=limits(UPPER))}))
    figures = travel_figures(*sampled(), spec)
    assert figures["inside_envelope"] is True and figures["envelope_first_outside_s"] is None
    assert figures["envelope_largest_excursion_m"] == 0.0
    assert all(figures[name] == pytest.approx(value, rel=1e-12, abs=1e-15) for name, value in EXPECTED.items())


def test_a_travel_above_the_upper_limit_leaves_at_the_crossing_and_exceeds_it_at_its_peak():
    # upper 200 → 305 mm over 50 → 80 ms (3.5 mm/ms) against the travel 160 → 310 mm (5 mm/ms): crossed at
    # 50 + 40/1.5 ms; the travel peaks at 310 mm at 80 ms, 5 mm above
    upper = [(0, 5), (10, 5), (50, 200), (80, 305), (100, 305)]
    check = envelope_check(*sampled(), limits(LOWER), limits(upper))
    assert check["inside_envelope"] is False
    assert check["envelope_first_outside_s"] == pytest.approx((50 + 40 / 1.5) * MS, rel=1e-12)
    assert check["envelope_largest_excursion_m"] == pytest.approx(5 * MM, rel=1e-12)
    assert check["envelope_largest_excursion_at_s"] == pytest.approx(80 * MS, rel=1e-12)


def test_a_travel_below_a_lower_limit_whose_corner_falls_between_samples_is_found_exactly():
    # the lower limit's corner (84.05 ms, 297 mm) lies between the samples at 84 and 84.3 ms: the travel there is
    # 294 + 3 × 0.05 mm; it first drops below on its fall 310 − 4 s (s = t − 80 ms) against 150 + 147 (t − 60)/24.05
    lower = [(0, -5), (20, 0), (60, 150), (84.05, 297), (100, 290)]
    slope = 147 / 24.05
    entry = 80 + (310 - 150 - slope * 20) / (4 + slope)
    check = envelope_check(*sampled(), limits(lower), limits(UPPER))
    assert check["inside_envelope"] is False
    assert check["envelope_first_outside_s"] == pytest.approx(entry * MS, rel=1e-12)
    assert check["envelope_largest_excursion_m"] == pytest.approx((297 - 294.15) * MM, rel=1e-12)
    assert check["envelope_largest_excursion_at_s"] == pytest.approx(84.05 * MS, rel=1e-12)


def test_only_the_times_both_curves_cover_are_checked():
    time, travel = sampled()
    early = time <= 30 * MS  # the run ends at 30 ms: the curve above the upper limit later on is never reached
    upper = [(0, 5), (10, 5), (50, 200), (80, 305), (100, 305)]
    assert envelope_check(time[early], travel[early], limits(LOWER), limits(upper))["inside_envelope"] is True
    late = limits([(40, 0), (100, 400)]), limits([(40, 500), (100, 600)])
    assert envelope_check(time[early], travel[early], *late)["inside_envelope"] is None


def test_limits_crossing_between_their_corners_are_found_at_a_corner():
    assert crossed_limits(limits([(0, 0), (10, 10)]), limits([(0, 1), (5, 6), (10, 9)])) == (
        pytest.approx(10 * MS), pytest.approx(10 * MM), pytest.approx(9 * MM))
    assert crossed_limits(limits(LOWER), limits(UPPER)) is None
