"""numba's inliner with one memo per inlined copy (clearsim.numba_inlining): the same IR, the same machine code."""

import copy
import re

import numpy as np
from numba import njit
from numba.core import inline_closurecall as inliner
from numba.core.compiler import run_frontend

from clearsim import numba_inlining
import clearsim.assembly.arrays  # noqa: F401  (installs it, as every kernel module does through arrays)


def _callee(x, n):
    total = 0.0
    for i in range(n):
        if x[i] > 0.0:
            total += x[i]
        else:
            total -= 2.0 * x[i]
    return total


def _caller(x):
    return _inlined(x, x.shape[0]) * _inlined(x[::-1].copy(), 3)


def _compiled_caller():
    """A new dispatcher of _caller, inlining a new dispatcher of _callee (compiled now, with the inliner as it is)."""
    global _inlined
    _inlined = njit(inline="always")(_callee)
    kernel = njit(_caller)
    kernel(np.linspace(-1.0, 1.0, 7))
    return next(iter(kernel.inspect_llvm().values()))


def _normalized(llvm_ir: str) -> str:
    """Block labels and numbered names come from numba's global counters, which every compilation advances."""
    return re.sub(r"[ \t]+", " ", re.sub(r"\d+", "N", llvm_ir))


def test_it_is_installed_for_the_kernels():
    assert numba_inlining.install()
    assert isinstance(inliner.copy, numba_inlining._MemoPerInlinedCopy)


def test_a_kernel_inlined_with_one_memo_has_the_llvm_ir_of_numbas_own_copy(monkeypatch):
    with_one_memo = _compiled_caller()
    monkeypatch.setattr(inliner, "copy", copy)
    monkeypatch.setattr(inliner.InlineWorker, "inline_ir", inliner.InlineWorker.inline_ir.__wrapped__)
    with_numbas_copy = _compiled_caller()
    assert "callee" in with_one_memo and with_one_memo != with_numbas_copy  # both inlined, labels renumbered
    assert _normalized(with_one_memo) == _normalized(with_numbas_copy)


def test_one_memo_copies_the_blocks_with_one_scope_equal_to_the_per_block_copies():
    """numba's per-block copies give each block a scope of its own (equal ones); one memo gives the one scope the
    interpreter built, and blocks equal to numba's copies."""
    blocks = run_frontend(_callee).blocks
    assert len(blocks) > 3
    per_block = {label: copy.deepcopy(block) for label, block in blocks.items()}
    shared = numba_inlining._MemoPerInlinedCopy()
    shared.memo = {}
    one_memo = {label: shared.deepcopy(block) for label, block in blocks.items()}
    assert len({id(block.scope) for block in per_block.values()}) == len(blocks)
    assert len({id(block.scope) for block in one_memo.values()}) == 1
    assert all(one_memo[label] == per_block[label] for label in blocks)
    assert all(one_memo[label] is not blocks[label] and one_memo[label].scope is not blocks[label].scope
               for label in blocks)
