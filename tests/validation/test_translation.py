"""Where the drawing's origin is must not matter: the slider-crank drawn 10 m away moves the same way."""

import numpy as np
import pytest

from clearsim.model.loader import load_mechanism
from clearsim.runner import prepare
from clearsim.solver.simulate import simulate

from tests.validation.conftest import CONFIGS

SHIFT = 10.0  # m along x and y


def drawn_at(offset: float) -> list[str]:
    """The slider-crank's points and body positions moved by (offset, offset) m, 8 ms (20 contact episodes)."""
    return [f"points.O=[{offset} m, {offset} m]", f"points.A=[{0.05 + offset} m, {offset} m]",
            f"points.B=[{0.17 + offset} m, {offset} m]", f"bodies.crank.position=[{0.025 + offset} m, {offset} m]",
            f"bodies.rod.position=[{0.11 + offset} m, {offset} m]",
            f"bodies.slider.position=[{0.17 + offset} m, {offset} m]", "solver.t_end=8ms"]


def test_the_motion_impacts_and_forces_do_not_depend_on_the_origin():
    """Accelerations, contact episodes and the peak contact force of the translated drawing equal the original's
    (the error norm weighs positions by their size, and 10 m coordinates loosen the position terms ~60×; the
    velocities' terms set the steps, so nothing may move beyond the solver tolerance)."""
    config = CONFIGS / "slider_crank_flores.yaml"
    here, there = (simulate(prepare(load_mechanism(config, drawn_at(d)))) for d in (0.0, SHIFT))
    assert len(there.episodes.onset) == len(here.episodes.onset) >= 10
    np.testing.assert_allclose(there.episodes.onset, here.episodes.onset, rtol=0, atol=1e-9)
    assert there.statistics.peak_normal_force == pytest.approx(here.statistics.peak_normal_force, rel=1e-6)
    np.testing.assert_array_equal(there.chunk.times, here.chunk.times)
    scale = np.max(np.abs(here.chunk.accelerations))
    np.testing.assert_allclose(there.chunk.accelerations, here.chunk.accelerations, rtol=0, atol=1e-5 * scale)
    positions = here.chunk.states[:, :9].reshape(-1, 3, 3)
    moved = there.chunk.states[:, :9].reshape(-1, 3, 3)
    np.testing.assert_allclose(moved[:, :, :2] - SHIFT, positions[:, :, :2], rtol=0, atol=1e-8)
    np.testing.assert_allclose(moved[:, :, 2], positions[:, :, 2], rtol=0, atol=1e-8)
