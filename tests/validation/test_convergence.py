"""Convergence in the tolerance: the slider-crank's peak contact force and slider-acceleration RMS settle.

Point-by-point histories of many impacts diverge between tolerances (the damping divides by δ̇⁻,
so soft re-contacts amplify tiny differences): the first impact is compared exactly, the rest
statistically (docs/model.md, "Sensitivity").
"""

import numpy as np
import pytest


@pytest.mark.parametrize("config", ["slider_crank_flores.yaml", "slider_crank_flores_friction.yaml"])
def test_tightening_rtol_settles_peak_force_and_acceleration_rms(simulate, config):
    figures = []
    for rtol in ("1e-8", "1e-9", "1e-10"):
        result = simulate(config, f"solver.rtol={rtol}")
        acceleration = result["sensors/slider_acceleration"]
        figures.append((np.max(result["joints/slider_pin/normal_force"]), np.sqrt(np.mean(acceleration**2)),
                        result["joints/slider_pin/episodes/onset"][0]))
    (force_1, rms_1, onset_1), (force_2, rms_2, onset_2), (force_3, rms_3, onset_3) = figures
    assert abs(force_3 - force_2) < 0.02 * force_3
    assert abs(rms_3 - rms_2) < 0.02 * rms_3
    assert abs(onset_3 - onset_1) < 1e-9  # s: the first impact is located, not sampled
    assert force_3 > 1e4  # the run really has hard impacts (≈ 45 kN at 4.4 m/s)
