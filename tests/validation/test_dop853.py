"""solver.method: dop853 (docs/model.md §4) through the whole integration loop: its fixed steps and the samples read
from their continuous extension converge with the method's order on an oscillator with a closed form (and dopri5's
with its own)."""

import numpy as np
import pytest

from tests.validation.test_rosenbrock import BLOCK


def slope(errors):
    """log2 of the ratio of the last two errors, at halved steps."""
    return np.log2(errors[-2] / errors[-1])


# the overdamped block of the rosenbrock tests, undamped and softer: ω = 100 rad/s, 10 kHz samples over 100 ms
OSCILLATOR = (BLOCK.replace("stiffness: 1e6 N/m, damping: 2e5 N*s/m", "stiffness: 1e4 N/m, damping: 0 N*s/m")
              .replace("t_end: 200 ms, output_rate: 1 kHz", "t_end: 100 ms, output_rate: 10 kHz"))
STRETCH, OMEGA = 1e-3, 100.0  # m, rad/s: x(t) = −STRETCH (1 − cos ω t)


@pytest.mark.parametrize("method, order, steps", [("dop853", 8, ("16", "8", "4")), ("dopri5", 5, ("8", "4", "2"))])
def test_fixed_steps_and_their_samples_converge_with_the_methods_order(simulate, method, order, steps):
    """Fixed steps (hω down to 0.4 and 0.2) with samples every 0.1 ms read from each step's continuous extension: the
    largest error of the samples falls by 2^order per halving (the extension's local error is O(h^order))."""
    errors = []
    for step in steps:
        result = simulate(OSCILLATOR.format(step=step, method=method))
        t, x = result["time"], result["bodies/block/q"][:, 0]
        assert t[-1] == pytest.approx(0.1)
        errors.append(np.abs(x + STRETCH * (1.0 - np.cos(OMEGA * t))).max())
    assert errors[-1] > 1e-13  # precondition: above round-off
    assert slope(errors) == pytest.approx(order, abs=0.2), errors
