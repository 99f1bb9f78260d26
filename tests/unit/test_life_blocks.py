"""The block size control of `clearsim life` (clearsim/life/blocks.py) on wear laws with closed-form lives."""

import math

import numpy as np
import pytest

from clearsim.life.blocks import Block, BlockControl, Operation, largest_depth, live

CLEARANCE = 1e-4  # m
OPERATIONS = 10_000


def start_of(simulate, harmonics=2):
    state = {"J": np.zeros(2 * harmonics + 1)}
    return Block(0, 0, state, simulate(state), 0.0, 0)


def counting(law):
    calls = []

    def simulate(state):
        calls.append(state)
        return Operation({"J": law(state["J"])})

    return simulate, calls


def test_the_error_norm_is_the_largest_depth_over_the_bore():
    assert largest_depth(np.array([0.0, 0.0, 0.0, -3.0, 4.0])) == pytest.approx(5.0, rel=1e-4)  # on the 0.5° grid
    assert largest_depth(np.array([0.0, 0.0, 0.0, 3.0, 4.0])) == pytest.approx(5.0, rel=1e-4)  # on the 0.5° grid


def test_a_wear_that_does_not_change_with_the_profile_is_integrated_exactly_in_few_blocks():
    per_operation = np.array([2e-9, 1e-9, -0.5e-9, 0.0, 0.0])
    simulate, calls = counting(lambda depth: per_operation)
    last = live(simulate, start_of(simulate), OPERATIONS, {"J": CLEARANCE}, BlockControl())
    assert last.operations == OPERATIONS
    assert np.allclose(last.state["J"], OPERATIONS * per_operation, rtol=1e-12, atol=0)
    assert len(calls) < 25  # blocks grow ×4 when the error estimate is 0: 1 + 2 per block


def uniform_wear_growing_with_clearance(rate):
    """dh/dn = rate (1 + h/c): a uniform depth h (a_0) that wears faster as the clearance opens;
    h(n) = c (exp(rate n / c) − 1)."""
    def law(depth):
        wear = np.zeros_like(depth)
        wear[0] = rate * (1.0 + depth[0] / CLEARANCE)
        return wear
    return law


def life_depth(tolerance, rate):
    simulate, calls = counting(uniform_wear_growing_with_clearance(rate))
    blocks = []
    last = live(simulate, start_of(simulate), OPERATIONS, {"J": CLEARANCE}, BlockControl(tolerance=tolerance),
                kept=lambda block, size: blocks.append(block))
    return last.state["J"][0], blocks, calls


def test_a_wear_that_grows_with_the_clearance_follows_its_closed_form():
    rate = CLEARANCE / OPERATIONS  # the clearance grows by e − 1 over the life
    exact = CLEARANCE * (math.e - 1.0)
    depth, blocks, _ = life_depth(0.02, rate)
    assert abs(depth - exact) < 0.02 * CLEARANCE, (depth, exact)
    assert all(block.error_ratio <= 1.0 for block in blocks)


def test_doubling_the_blocks_changes_the_life_by_less_than_the_tolerance():
    """Heun's method is of order 2: a quarter of the tolerance takes about twice the blocks."""
    rate = CLEARANCE / OPERATIONS
    coarse, coarse_blocks, _ = life_depth(0.02, rate)
    fine, fine_blocks, _ = life_depth(0.005, rate)
    assert 1.5 <= len(fine_blocks) / len(coarse_blocks) <= 3.0, (len(coarse_blocks), len(fine_blocks))
    assert abs(fine - coarse) < 0.02 * CLEARANCE, (coarse, fine)
    exact = CLEARANCE * (math.e - 1.0)
    assert abs(fine - exact) < abs(coarse - exact)  # and closer to the closed form


def test_a_sudden_change_of_the_wear_refuses_the_block_that_crosses_it():
    """The wear per operation doubles once the depth passes 0.3 c (e.g. the contact moves onto a worn flat)."""
    def law(depth):
        wear = np.zeros_like(depth)
        wear[0] = 1e-8 * (2.0 if depth[0] > 0.3 * CLEARANCE else 1.0)
        return wear

    simulate, _ = counting(law)
    blocks = []
    live(simulate, start_of(simulate), OPERATIONS, {"J": CLEARANCE}, BlockControl(),
         kept=lambda block, size: blocks.append(block))
    assert sum(block.refused for block in blocks) >= 1
    assert all(block.error_ratio <= 1.0 or block.size == 1 for block in blocks)


def test_a_life_resumed_from_a_kept_block_is_the_same_life():
    law = uniform_wear_growing_with_clearance(CLEARANCE / OPERATIONS)
    simulate, _ = counting(law)
    rows = []
    whole = live(simulate, start_of(simulate), OPERATIONS, {"J": CLEARANCE}, BlockControl(),
                 kept=lambda block, size: rows.append((block, size)))
    block, size = rows[2]
    resumed = live(simulate, block, OPERATIONS, {"J": CLEARANCE}, BlockControl(), size=size)
    assert resumed.operations == whole.operations
    assert np.array_equal(resumed.state["J"], whole.state["J"])


def test_a_block_whose_worn_bores_cannot_be_simulated_is_refused_and_shrunk():
    """Beyond 0.5 c of wear the operation fails (OperationFailed): blocks that would cross it are refused; at one
    operation the failure ends the life."""
    from clearsim.life.blocks import OperationFailed

    def simulate(state):
        if state["J"][0] > 0.5 * CLEARANCE:
            raise OperationFailed("the solver could not continue")
        return Operation({"J": np.array([1e-8, 0.0, 0.0])})

    blocks = []
    with pytest.raises(OperationFailed):
        live(simulate, start_of(simulate, 1), OPERATIONS, {"J": CLEARANCE}, BlockControl(),
             kept=lambda block, size: blocks.append(block))
    assert blocks[-1].state["J"][0] <= 0.5 * CLEARANCE < blocks[-1].state["J"][0] + 1e-8  # one operation short
    assert sum(block.refused for block in blocks) >= 1
