"""The constrained solve's banded kernels (assembly/constraints.py schur_complement, assembly/dynamics.py factorize and
solve_factored): exact against numpy on random banded SPD systems, from bandwidth 0 to full; bit for bit the dense
algorithm they replace (every row scanned from column 0, S cleared whole, the back substitution over every later row)
on the bundled models' states; and touching S only inside its band, so that their cost is linear in the rows."""

import functools

import numpy as np
import pytest

from benchmarks.chain import pendulum_chain
from clearsim.assembly.arrays import WORKSPACE_FIELDS, SystemArrays, _workspace, packed
from clearsim.assembly.constraints import constraint_count, dense_jacobian, jacobian_blocks, schur_complement
from clearsim.assembly.dynamics import FACTOR_SINGULAR, FACTOR_SPD, accelerations, factored_jacobian, factorize, solve_factored
from clearsim.assembly.forces import CONTACT, STICK
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.runner import BUNDLED_CONFIG, prepare

LINKS = 24  # the scratch of a 24-link chain: 2 · 24 + 1 = 49 rows
CRANK = BUNDLED_CONFIG.parent / "slider_crank_flores.yaml"


class Scratch:
    """The kernels' arrays of a system (`system`, as for_kernels makes them) with each of them by name, the same
    memory, to write and read here (the kernels' object has no attributes in Python)."""

    def __init__(self, arrays: SystemArrays):
        fields = tuple(arrays) + _workspace(arrays)
        self.__dict__.update(zip(list(SystemArrays._fields) + WORKSPACE_FIELDS, fields))
        self.system = packed(fields, arrays.wear_harmonics)


@functools.cache
def chain_arrays(links: int = LINKS) -> SystemArrays:
    """The benchmarks' pendulum chain of `links` links, ideal joints: 2 links + 1 rows, the driver's last."""
    return prepare(load_mechanism_text(pendulum_chain(links, 0), "chain.yaml")).arrays


def chain_scratch() -> Scratch:
    """A fresh scratch of the chain's arrays."""
    return Scratch(chain_arrays())


def random_envelope_spd(size: int, bandwidth: int, long_rows: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """(A, first): a symmetric, strictly diagonally dominant (so positive definite) matrix whose row i is nonzero
    from first[i] to i, first[i] drawn in [i − bandwidth, i]; `long_rows` random rows reach column 0 (a driver)."""
    first = np.array([rng.integers(max(i - bandwidth, 0), i + 1) for i in range(size)])
    if size > 1:
        first[rng.choice(np.arange(1, size), size=min(long_rows, size - 1), replace=False)] = 0
    matrix = np.zeros((size, size))
    for i in range(size):
        matrix[i, first[i]:i] = rng.uniform(-1.0, 1.0, i - first[i])
        if first[i] < i:
            matrix[i, first[i]] = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.0)  # first[i] is the first nonzero
    matrix = matrix + matrix.T
    matrix[np.diag_indices(size)] = np.abs(matrix).sum(axis=1) + rng.uniform(0.1, 2.0, size)
    return matrix, first


def factor_and_solve(scratch, matrix: np.ndarray, band: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """factorize and solve_factored on `matrix` written into the scratch's S, its band in solve_band."""
    size = matrix.shape[0]
    scratch.solve_schur[:size, :size] = matrix
    scratch.solve_band[:size] = band
    scratch.factor_key[0] = FACTOR_SPD if factorize(scratch.system, size) else FACTOR_SINGULAR
    x = rhs.copy()
    solve_factored(scratch.system, x)
    return x


@pytest.mark.parametrize("size, bandwidth, long_rows", [
    (1, 0, 0), (7, 0, 0), (49, 0, 0),  # diagonal
    (2, 1, 0), (13, 1, 0), (49, 3, 0), (49, 3, 2), (30, 6, 1), (49, 10, 3),  # banded, with driver-like long rows
    (5, 4, 0), (20, 19, 0), (49, 48, 0),  # full
])
def test_banded_solve_matches_numpy(size, bandwidth, long_rows):
    rng = np.random.default_rng(1000 * size + 10 * bandwidth + long_rows)
    matrix, first = random_envelope_spd(size, bandwidth, long_rows, rng)
    scratch = chain_scratch()
    for _ in range(3):  # the same scratch, several right-hand sides (the solve keeps its list in the scratch)
        rhs = rng.normal(size=size)
        x = factor_and_solve(scratch, matrix, first, rhs)
        expected = np.linalg.solve(matrix, rhs)
        assert np.linalg.norm(x - expected) <= 1e-12 * np.linalg.norm(expected)
    assert np.array_equal(scratch.solve_envelope[:size], first)  # each row's envelope: from its first nonzero


def test_factorize_reads_no_entry_left_of_the_band():
    """Entries of S left of solve_band are not read: NaN there changes nothing (scanning each row from column 0, as a
    dense factorisation does, finds the NaN and returns NaN)."""
    rng = np.random.default_rng(5)
    matrix, first = random_envelope_spd(LINKS * 2 + 1, 3, 1, rng)
    rhs = rng.normal(size=matrix.shape[0])
    clean = factor_and_solve(chain_scratch(), matrix, first, rhs)
    poisoned = matrix.copy()
    for i, start in enumerate(first):
        poisoned[i, :start] = np.nan
    assert np.array_equal(factor_and_solve(chain_scratch(), poisoned, first, rhs), clean)


def test_a_band_wider_than_the_nonzeros_gives_the_same_factor_bit_for_bit():
    """solve_band is where a row of S may start; the factor starts each row at its first nonzero, from there."""
    rng = np.random.default_rng(6)
    matrix, first = random_envelope_spd(LINKS * 2 + 1, 4, 2, rng)
    rhs = rng.normal(size=matrix.shape[0])
    exact = factor_and_solve(chain_scratch(), matrix, first, rhs)
    assert np.array_equal(factor_and_solve(chain_scratch(), matrix, np.zeros_like(first), rhs), exact)


def test_a_matrix_that_is_not_positive_definite_gives_nan():
    matrix = np.array([[1.0, 2.0], [2.0, 1.0]])
    assert np.all(np.isnan(factor_and_solve(chain_scratch(), matrix, np.zeros(2, np.int64), np.ones(2))))


def test_schur_complement_writes_only_its_band_and_clears_the_last_one():
    """S = Φ_q M⁻¹ Φ_qᵀ inside the band (against numpy), exactly zero elsewhere after a call with other rows, and an
    entry outside both the last call's band and this one's left alone (a sentinel there survives)."""
    scratch = chain_scratch()
    rows = constraint_count(scratch.system)
    rng = np.random.default_rng(8)
    q = rng.normal(size=3 * LINKS)
    blocks, bodies = jacobian_blocks(scratch.system, q)
    wide_bodies = bodies.copy()
    wide_bodies[-1] = [LINKS - 1, 0]  # the last row couples the chain's two ends: a band of full width
    schur_complement(scratch.system, blocks, wide_bodies)
    assert scratch.solve_band[rows - 1] == 0
    schur_complement(scratch.system, blocks, bodies)  # now the last row reaches only body 0: rows 0–3 and itself
    jac = np.zeros((rows, 3 * LINKS))
    for row in range(rows):
        for slot in range(2):
            if bodies[row, slot] >= 0:
                jac[row, 3 * bodies[row, slot]:3 * bodies[row, slot] + 3] += blocks[row, slot]
    expected = jac @ np.diag(scratch.inverse_mass) @ jac.T
    schur = scratch.solve_schur[:rows, :rows]
    assert np.allclose(schur, expected, rtol=1e-13, atol=1e-13 * np.abs(expected).max())
    assert np.array_equal(schur == 0.0, expected == 0.0)
    band = scratch.solve_band[:rows]
    assert list(band[:6]) == [0, 0, 0, 0, 2, 2] and band[rows - 1] == 0  # rows of pins 0–1 share body 0
    outside = np.arange(rows)[None, :] < band[:, None]  # left of every row's band
    scratch.solve_schur[:rows, :rows][outside] = 7.0
    schur_complement(scratch.system, blocks, bodies)
    assert np.all(scratch.solve_schur[:rows, :rows][outside] == 7.0)  # not cleared: O(band), not O(rows²)


# --- bit for bit the dense algorithm, on the bundled models' states -----------------------------------------------

def dense_factor(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, L): the envelope Cholesky factor as the dense reference computes it, each row scanned from column 0."""
    size = matrix.shape[0]
    first = np.arange(size)
    lower = np.zeros((size, size))
    for i in range(size):
        nonzero = np.flatnonzero(matrix[i, :i] != 0.0)
        if nonzero.size:
            first[i] = nonzero[0]
    for i in range(size):
        for j in range(first[i], i + 1):
            acc = matrix[i, j]
            for k in range(max(first[i], first[j]), j):
                acc -= lower[i, k] * lower[j, k]
            lower[i, j] = np.sqrt(acc) if i == j else acc / lower[j, j]
    return first, lower


def dense_solve(first: np.ndarray, lower: np.ndarray, x: np.ndarray) -> np.ndarray:
    """S⁻¹ x with the dense reference's substitutions (the backward one over every later row, in ascending order)."""
    x = x.copy()
    size = x.shape[0]
    for i in range(size):
        for k in range(first[i], i):
            x[i] -= lower[i, k] * x[k]
        x[i] /= lower[i, i]
    for i in range(size - 1, -1, -1):
        for k in range(i + 1, size):
            if first[k] <= i:
                x[i] -= lower[k, i] * x[k]
        x[i] /= lower[i, i]
    return x


def model_states():
    """(name, system, q, q̇, modes): the bundled breaker (its stick rows on and off, in an order that moves them) and
    slider-crank, and the benchmarks' 16-link pendulum chain with 3 clearance joints (its driver row reaches column 0),
    at their initial states and nearby ones."""
    rng = np.random.default_rng(11)
    chain = load_mechanism_text(pendulum_chain(16, 3), "chain.yaml")
    for loaded, mode_sets in ((load_mechanism(BUNDLED_CONFIG), [(CONTACT, CONTACT), (STICK, CONTACT), (STICK, STICK),
                                                                 (CONTACT, STICK), (CONTACT, CONTACT)]),
                              (load_mechanism(CRANK), [(CONTACT,), (STICK,)]),
                              (chain, [(CONTACT,) * 3, (STICK, CONTACT, STICK), (CONTACT, STICK, CONTACT)])):
        system = prepare(loaded)
        scratch = Scratch(system.arrays)  # one scratch through all, as in a run
        for step, modes in enumerate(mode_sets):
            q = system.q0 + (1e-4 * step) * rng.normal(size=system.q0.size)
            yield loaded.mechanism.name, scratch, q, system.qd0, np.array(modes, np.int64)


def test_the_solve_is_the_dense_algorithm_bit_for_bit_on_the_models():
    rng = np.random.default_rng(12)
    checked = 0
    for name, scratch, q, qd, modes in model_states():
        rows = constraint_count(scratch.system) + int(np.sum(modes == STICK))
        curvature = np.zeros(rows)
        factored_jacobian(scratch.system, q, qd, modes, rows, curvature[constraint_count(scratch.system):])
        schur = scratch.solve_schur[:rows, :rows].copy()
        m = constraint_count(scratch.system)
        jac = dense_jacobian(scratch.system, q)
        expected = jac @ np.diag(scratch.inverse_mass) @ jac.T
        assert np.allclose(schur[:m, :m], expected, rtol=1e-13, atol=1e-13 * np.abs(expected).max()), name
        first, lower = dense_factor(schur)
        assert np.array_equal(scratch.solve_envelope[:rows], first), name
        for i in range(rows):
            assert np.array_equal(scratch.solve_lower[i, first[i]:i + 1], lower[i, first[i]:i + 1]), name
        rhs = rng.normal(size=rows)
        x = rhs.copy()
        solve_factored(scratch.system, x)
        assert np.array_equal(x, dense_solve(first, lower, rhs)), name
        force = rng.normal(size=q.size)
        qdd, lam = accelerations(scratch.system, 0.001, q, qd, force, modes)
        assert np.all(np.isfinite(qdd)) and lam.shape == (rows,)
        checked += 1
    assert checked == 10
