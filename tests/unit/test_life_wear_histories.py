"""The per-sample wear histories of a result file (clearsim/io/wear_results.py), as a life's operations write them:
the depths of a chunk's profiles in one product equal the series evaluated profile by profile."""

import math

import numpy as np

from clearsim.io.wear_results import HISTORY_ANGLES, profile_basis
from clearsim.physics.wear import evaluate_profile


def test_the_depths_of_many_profiles_at_once_are_each_profiles_series():
    grid = np.linspace(0.0, 2.0 * math.pi, HISTORY_ANGLES, endpoint=False)
    coefficients = np.random.default_rng(26).normal(scale=1e-6, size=(50, 2 * 32 + 1))
    depth = coefficients @ profile_basis(32, grid)
    expected = np.stack([evaluate_profile(row, grid) for row in coefficients])
    np.testing.assert_allclose(depth, expected, rtol=0, atol=1e-18)  # 1e-13 of the ~1e-5 m depths: round-off of the sum order
    assert profile_basis(0, grid).shape == (1, HISTORY_ANGLES)  # a mean depth alone
    assert (np.zeros((0, 65)) @ profile_basis(32, grid)).shape == (0, HISTORY_ANGLES)  # an empty chunk
