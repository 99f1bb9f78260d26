"""flexible.chain_ordered: the joints of an expanded document along the chain, from the end of the file's first
joint, whatever order the expansion appended them in; in the factor of S each joint's constraint rows together in
that order (build.ConstraintRows.places, arrays.row_place), for a flexible model only."""

from pathlib import Path

import numpy as np
import pytest
from numba import njit

from clearsim.assembly.build import ConstraintRows
from clearsim.model.flexible import chain_ordered


def joint(name: str, first: str, second: str) -> dict:
    return {"name": name, "type": "revolute", "bodies": [first, second]}


def test_joints_appended_out_of_order_come_back_along_the_chain():
    """ground -a- p -b- q -c- r -d- s, with c and b appended last (as a split link's slide or a beam's hinges)."""
    joints = [joint("a", "ground", "p"), joint("d", "r", "s"), joint("c", "q", "r"), joint("b", "p", "q")]
    assert [j["name"] for j in chain_ordered(joints)] == ["a", "b", "c", "d"]


def test_the_chain_is_numbered_from_the_end_of_the_file_s_first_joint():
    """Each joint at its bodies' highest number: a (p alone) ties with b (p, q), and keeps its place before b."""
    joints = [joint("d", "r", "s"), joint("a", "ground", "p"), joint("c", "q", "r"), joint("b", "p", "q")]
    assert [j["name"] for j in chain_ordered(joints)] == ["d", "c", "a", "b"]


def test_no_bodies_no_reordering():
    grounded = [joint("x", "ground", "ground")]
    assert chain_ordered([]) == [] and chain_ordered(grounded) == grounded


# --- the constraint rows of a flexible model: joint by joint along the chain in the factor of S -----------------

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
RIGID_BREAKER_ENVELOPE = 535  # Σ (row − first column)² of the rigid breaker's factor (23 rows)


@njit
def _envelope_starts(kernel_arrays):
    return kernel_arrays.solve_envelope.copy()


def factor_at_start(system, arrays=None, sticking=False):
    """(q̈, λ, envelope work Σ (i − first[i])² of the factor of S) at the system's start, with a unit force on every
    coordinate; `arrays`: the system's arrays, or others of the same system; `sticking`: every clearance joint
    sticks (a stick row each, after the constraint rows)."""
    from clearsim.assembly.arrays import for_kernels
    from clearsim.assembly.dynamics import STICK, accelerations

    kernel_arrays = for_kernels(system.arrays if arrays is None else arrays)
    modes = np.full(len(system.clearance_joints), STICK if sticking else 0, np.int64)
    acceleration, multipliers = accelerations(kernel_arrays, 0.0, system.q0, system.qd0, np.ones(system.q0.size),
                                              modes)
    rows = multipliers.size
    work = int(np.sum((np.arange(rows) - _envelope_starts(kernel_arrays)[:rows]) ** 2))
    return acceleration, multipliers, work


@pytest.fixture(scope="module")
def flexible_breaker():
    from clearsim.assembly.system import assemble
    from clearsim.model.loader import load_mechanism

    loaded = load_mechanism(CONFIGS / "uhv_breaker_flexible.yaml")
    return assemble(loaded.mechanism, loaded.base_dir)


def test_each_joints_rows_lie_together_in_chain_order():
    """Pins, offsets, angles in the arrays; in the factor the joints' and drivers' rows together, in `names` order."""
    rows = ConstraintRows(pins=[(0, 1, None, None, "a"), (1, 2, None, None, "c")],
                          offsets=[(1, 2, None, None, None, 0.0, -1, "b"), (-1, 0, None, None, None, 0.0, 0, "drive")],
                          angles=[(1, 2, 0.0, -1, "b")])
    # rows: a a c c b(offset) drive b(angle) → places: a a, b b, c c, drive
    assert rows.places(["a", "b", "c", "drive"]).tolist() == [0, 1, 4, 5, 2, 6, 3]


def test_the_flexible_breakers_factor_is_narrower_than_the_rigid_ones(flexible_breaker):
    """The slides' offset and angle rows after every pin row gave the flexible breaker's factor an envelope work of
    6 159 (43 rows); each joint's rows in their place along the chain, 380: below the rigid breaker's 535."""
    assert factor_at_start(flexible_breaker)[2] < RIGID_BREAKER_ENVELOPE


@pytest.mark.parametrize("sticking", [False, True], ids=["no joint sticks", "A and J stick"])
def test_the_rows_places_change_neither_the_accelerations_nor_the_multipliers(flexible_breaker, sticking):
    """λ stays in the rows' order (pins, offsets, angles, stick rows) whatever their places in the factor: the same
    q̈ and λ as with every row in its own place, to round-off (7e-14 measured; 3e-15 with both stick rows). The stick
    rows stay last, in their own places: the envelope work 6 505 → 2 265 with A and J sticking (6 159 → 380 without)."""
    assert flexible_breaker.arrays.row_place.size == 43
    placed = factor_at_start(flexible_breaker, sticking=sticking)
    own = factor_at_start(flexible_breaker, flexible_breaker.arrays._replace(row_place=np.zeros(0, np.int64)),
                          sticking)
    assert placed[1].size == 43 + 2 * sticking
    assert own[2] > 2 * placed[2]
    for with_places, in_own_places in zip(placed[:2], own[:2]):
        assert np.max(np.abs(with_places - in_own_places)) <= 1e-11 * np.max(np.abs(in_own_places))


def test_a_rigid_model_keeps_every_row_in_its_own_place():
    """Rigid models' results stay bitwise what they were: no row is moved."""
    from clearsim.assembly.system import assemble
    from clearsim.model.loader import load_mechanism

    loaded = load_mechanism(CONFIGS / "uhv_breaker.yaml")
    assert not loaded.mechanism.rows_along_the_chain
    assert assemble(loaded.mechanism, loaded.base_dir).arrays.row_place.size == 0
