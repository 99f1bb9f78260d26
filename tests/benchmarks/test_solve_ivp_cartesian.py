"""The Cartesian solve_ivp baseline is the same mechanism as the independent minimal-coordinate model."""

import numpy as np
import pytest

from benchmarks import solve_ivp_cartesian as cartesian
from tests.support.slider_crank_minimal import FRICTION, FRICTIONLESS
from tests.support.slider_crank_minimal import simulate as minimal

FIRST_EPISODE_END = 4e-4  # s: the first contact episode lasts from 0.227 to ~0.29 ms
RTOL = 1e-10
# Both models resolve the first impact to ~rtol (measured: onset 2e-16 s apart, impact speed 1e-12 and peak
# force 3e-10 relative). 1e-8 leaves 30× for the solvers; a formulation error is far larger: friction alone
# (μ_d = 0.01) moves the peak by 3.6e-4, and a wrong arm, mass or initial velocity moves the onset by µs.
# The time of the peak is not compared: at a flat maximum a force error ε moves it by ~√ε of the contact time.
AGREEMENT = 1e-8


def test_the_initial_state_is_on_the_constraints_with_the_journal_centred():
    p = FRICTIONLESS
    y = cartesian.initial_state(p)
    q, v = y[:cartesian.COORDINATES], y[cartesian.COORDINATES:]
    assert np.max(np.abs(cartesian.constraints(p, 0.0, q))) < 1e-16
    assert np.max(np.abs(cartesian.constraint_rate(p, cartesian.jacobian(p, q), v))) < 1e-12
    contact = cartesian.contact_kinematics(p, q, v)
    assert contact.penetration == pytest.approx(-p.clearance, abs=1e-16) and contact.rate == 0.0


@pytest.mark.parametrize("parameters", [FRICTIONLESS, FRICTION], ids=["frictionless", "friction"])
def test_first_impact_agrees_with_the_minimal_model(parameters):
    mine = cartesian.first_impact(parameters, FIRST_EPISODE_END, RTOL, cartesian.ATOL_PER_RTOL * RTOL)
    exact = minimal(parameters, t_end=FIRST_EPISODE_END, rtol=1e-11).episodes[0]
    assert mine["onset_s"] == pytest.approx(exact.onset, rel=AGREEMENT)
    assert mine["impact_speed"] == pytest.approx(exact.impact_speed, rel=AGREEMENT)
    assert mine["peak_normal_force"] == pytest.approx(exact.peak_normal_force, rel=AGREEMENT)


def test_the_matched_rtol_is_the_loosest_as_accurate_as_clearsim_in_both_figures_and_the_settled_one_stays_so():
    clearsim = {"error_max_contact_force": 6e-8, "error_peak_acceleration": 2e-8}
    rows = [{"rtol": 1e-6, "failed": "through the wall"},
            {"rtol": 3e-7, "error_max_contact_force": 5e-8, "error_peak_acceleration": 1e-8},  # as accurate, by luck
            {"rtol": 1e-7, "error_max_contact_force": 2e-8, "error_peak_acceleration": 6e-8},  # acceleration too coarse
            {"rtol": 1e-8, "error_max_contact_force": 1e-8, "error_peak_acceleration": 3e-10},
            {"rtol": 1e-9, "error_max_contact_force": 1e-9, "error_peak_acceleration": 3e-11}]
    assert cartesian.matched_row(rows, clearsim)["rtol"] == 3e-7
    assert cartesian.settled_row(rows, clearsim)["rtol"] == 1e-8  # every tighter rung is as accurate too
    assert cartesian.matched_row(rows[2:3], clearsim) is None and cartesian.settled_row(rows[:3], clearsim) is None


def test_the_output_history_is_the_per_sample_acceleration_on_the_whole_grid():
    """The equal-output timing computes the 100 kHz accelerations per segment; they must be those the figures read
    one sample at a time (slider_acceleration), on every point of the grid, switches included."""
    p, t_end = FRICTIONLESS, 6e-4  # two contact switches
    result = cartesian.simulate(p, t_end, 1e-8, cartesian.ATOL_PER_RTOL * 1e-8)
    assert len(result.segments) >= 3
    states, qdd = result.output_history(t_end)
    times = np.arange(0.0, t_end + 0.5 * cartesian.OUTPUT_PERIOD, cartesian.OUTPUT_PERIOD)
    assert qdd.shape == (times.size, cartesian.COORDINATES)
    one_by_one = np.array([result.slider_acceleration(t) for t in times])
    np.testing.assert_allclose(qdd[:, 6], one_by_one, rtol=1e-12, atol=1e-9)
    assert np.max(np.abs(qdd[:, 6])) == pytest.approx(result.peak_slider_acceleration(t_end), rel=1e-12)
