"""The block size control of a life: wear per operation integrated over operations with error control.

The worn profile of every wearing joint (its Fourier coefficients, m) is a state H that grows with the number of
operations n as dH/dn = r(H): r is the wear of one operation simulated with the bores worn to H. A block of N
operations is one step of Heun's method (the explicit trapezoidal rule, order 2):

    H* = H + N r(H)                    (Euler predictor)
    H' = H + N (r(H) + r(H*)) / 2      (trapezoidal corrector)

and the difference of the two, N |r(H*) − r(H)| / 2 taken as the largest depth over the bore's angle, estimates the
block's error (Hairer, Nørsett & Wanner, Solving ODEs I, §II.4: embedded pair of orders 1 and 2). A block is kept
when that error is at most `tolerance` × the joint's clearance for every joint; the next block's size is
N · min(growth, max(shrink, safety · (1/ratio)^(1/2))) with ratio the error over its allowance. A kept block costs two
operations simulated: r(H*) and r(H') (the latter is the next block's start, and the operation whose figures are
recorded for the block); a refused one costs one. A block whose predicted or corrected bores cannot be simulated
(OperationFailed: the solver could not continue) is refused too, and shrunk by `shrink`; at one operation the failure
stops the life. A rate that does not change with the profile gives zero error: the
blocks then grow by `growth` each time, and the result is exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from clearsim.physics.wear import evaluate_profile

PROFILE_ANGLES = 720  # the depth norm's grid: every 0.5°


class OperationFailed(Exception):
    """An operation that could not be simulated with the bores worn to a state (the solver could not continue)."""


@dataclass(frozen=True)
class BlockControl:
    tolerance: float = 0.02  # a block's error estimate allowed per joint, as a fraction of its clearance
    growth: float = 4.0  # largest ratio of a block to the one before
    shrink: float = 0.2  # smallest ratio after a refused block
    safety: float = 0.9


@dataclass
class Operation:
    """One operation simulated with the bores worn to a state: its wear (coefficients, m, per joint) and figures."""

    wear: dict[str, np.ndarray]
    figures: dict[str, float] = field(default_factory=dict)


@dataclass
class Block:
    """A kept block: `size` operations ending at `operations` done, the state there and the operation simulated at
    it (the next block's start), the error estimate over its allowance, and the blocks refused before it."""

    operations: int
    size: int
    state: dict[str, np.ndarray]
    operation: Operation
    error_ratio: float
    refused: int


def largest_depth(coefficients: np.ndarray) -> float:
    """max over θ of |h(θ)| on a 0.5° grid."""
    angles = np.linspace(0.0, 2.0 * math.pi, PROFILE_ANGLES, endpoint=False)
    return float(np.max(np.abs(evaluate_profile(coefficients, angles))))


def error_ratio(start: Operation, predicted: Operation, size: int, allowances: dict[str, float]) -> float:
    """max over joints of N |r(H*) − r(H)| / 2 (largest depth over θ) / (tolerance × clearance)."""
    return max(size * largest_depth(predicted.wear[joint] - start.wear[joint]) / 2.0 / allowance
               for joint, allowance in allowances.items())


def next_size(size: int, ratio: float, control: BlockControl) -> int:
    """The next block's size after one of `size` with this error ratio (order 2: exponent 1/2)."""
    factor = control.growth if ratio == 0.0 else min(control.growth, max(control.shrink, control.safety / math.sqrt(ratio)))
    return max(1, int(size * factor))


def first_size(start: Operation, allowances: dict[str, float]) -> int:
    """A first block whose wear alone stays within the allowance: allowance / (wear of one operation)."""
    per_operation = max(largest_depth(start.wear[joint]) / allowance for joint, allowance in allowances.items())
    return max(1, int(1.0 / per_operation)) if per_operation > 0.0 else 1


def advanced(state: dict[str, np.ndarray], rates: list[Operation], weights: list[float], size: int) -> dict[str, np.ndarray]:
    """H + N Σ w_i r_i, joint by joint."""
    return {joint: value + size * sum(weight * rate.wear[joint] for weight, rate in zip(weights, rates))
            for joint, value in state.items()}


def live(simulate: Callable[[dict[str, np.ndarray]], Operation], start: Block, operations: int,
         clearances: dict[str, float], control: BlockControl, size: int | None = None,
         kept: Callable[[Block, int], None] = lambda block, next_size: None,
         simulate_end: Callable[[dict[str, np.ndarray], int], Operation] | None = None) -> Block:
    """Blocks from `start` (operations done, state, the operation simulated at it) until `operations` are done;
    `kept(block, next size)` after each kept block (the life file's row, resumable from it); the operation at a kept
    block's end is simulate_end(state, operations done) (default: simulate). → the last block."""
    simulate_end = simulate_end or (lambda state, done: simulate(state))
    allowances = {joint: control.tolerance * clearance for joint, clearance in clearances.items()}
    block = start
    size = size or first_size(block.operation, allowances)
    refused = 0
    while block.operations < operations:
        size = min(size, operations - block.operations)
        try:
            predicted = simulate(advanced(block.state, [block.operation], [1.0], size))
            ratio = error_ratio(block.operation, predicted, size, allowances)
            if ratio > 1.0 and size > 1:
                refused += 1
                size = next_size(size, ratio, control)
                continue
            state = advanced(block.state, [block.operation, predicted], [0.5, 0.5], size)
            end = simulate_end(state, block.operations + size)
        except OperationFailed:
            if size == 1:
                raise
            refused += 1
            size = max(1, int(size * control.shrink))
            continue
        block = Block(block.operations + size, size, state, end, ratio, refused)
        refused = 0
        size = next_size(size, ratio, control)
        kept(block, size)
    return block
