"""Ideal slider-crank against its closed-form kinematics (the clearance joint made ideal by override)."""

import numpy as np
import pytest

CRANK, ROD, OMEGA = 0.05, 0.12, 5000 * 2 * np.pi / 60


def closed_form(t):
    """Slider position, velocity, acceleration of the centred slider-crank, θ = ω t."""
    s, c = np.sin(OMEGA * t), np.cos(OMEGA * t)
    root = np.sqrt(ROD**2 - CRANK**2 * s**2)
    x = CRANK * c + root
    v = -CRANK * OMEGA * s - CRANK**2 * OMEGA * s * c / root
    a = (-CRANK * OMEGA**2 * c - CRANK**2 * OMEGA**2 * (c**2 - s**2) / root
         - CRANK**4 * OMEGA**2 * s**2 * c**2 / root**3)
    return x, v, a


@pytest.mark.parametrize("method", ["dopri5", "dop853"])
def test_ideal_slider_crank_matches_closed_form(simulate, method):
    result = simulate("slider_crank_flores.yaml", "joints.slider_pin.clearance=0", "solver.t_end=12ms",
                      f"solver.method={method}")
    t = result["time"]
    x, v, a = closed_form(t)
    assert t[-1] == 0.012 and len(t) == 1201
    # relative to each signal's amplitude; a 0-DOF driven chain is solved algebraically at every
    # sample (projection + constrained accelerations), so only round-off separates it from the formula
    assert np.max(np.abs(result["sensors/slider_displacement"] - (x - x[0]))) <= 1e-6 * np.ptp(x)
    assert np.max(np.abs(result["sensors/slider_velocity"] - v)) <= 1e-6 * np.max(np.abs(v))
    assert np.max(np.abs(result["sensors/slider_acceleration"] - a)) <= 1e-6 * np.max(np.abs(a))
    assert np.max(result["constraints/violation"]) <= 1e-9
