"""numba's inliner copies the callee's IR with one memo per block; here, with one memo per inlined copy.

Compile time only: the IR each inlined copy gets is the same, and so is the machine code (results bitwise identical,
tests/unit/test_numba_inlining.py). numba's `InlineWorker.inline_ir` copies the callee's IR block by block with
`copy.deepcopy`, each block with a memo of its own; every variable holds its scope, so each block's copy copies the
scope with every variable of the function again: O(blocks × variables) per inlined copy (numba issues #8989 and
#9204; numba 0.68). With one memo for the blocks of one `inline_ir` call the copy is the deep copy of the whole IR,
with the aliasing the interpreter built (one scope, shared variables) instead of a scope per block, and costs
O(blocks + variables): `advance`'s 54 inlined copies took 1.8–2.0 s of a cold compile, now 0.5–0.6 s
(docs/performance.md, *Compile time*). Applied once per process, before any kernel compiles, where numba's inliner is
built as this expects (its module's `copy` and `InlineWorker.inline_ir`); elsewhere numba's own copy runs unchanged.
"""

from __future__ import annotations

import copy
import functools

_installed = False


class _MemoPerInlinedCopy:
    """Stands for the `copy` module inside numba's inliner: `deepcopy` without a memo of its own shares the memo of
    the `inline_ir` call in progress."""

    def __init__(self):
        self.memo: dict | None = None

    def deepcopy(self, value, memo=None):
        return copy.deepcopy(value, self.memo if memo is None else memo)

    def __getattr__(self, name):
        return getattr(copy, name)


def install() -> bool:
    """Route numba's inliner through _MemoPerInlinedCopy; False (nothing changed) where numba is built otherwise."""
    global _installed
    if _installed:
        return True
    try:
        from numba.core import inline_closurecall as inliner
    except ImportError:
        return False
    worker = getattr(inliner, "InlineWorker", None)
    if getattr(inliner, "copy", None) is not copy or not callable(getattr(worker, "inline_ir", None)):
        return False
    shared = _MemoPerInlinedCopy()
    inline_ir = worker.inline_ir

    @functools.wraps(inline_ir)
    def inline_ir_with_one_memo(self, *args, **kwargs):
        outer, shared.memo = shared.memo, {}  # an inline_ir inside another's (typing a callee) has a memo of its own
        try:
            return inline_ir(self, *args, **kwargs)
        finally:
            shared.memo = outer

    inliner.copy = shared
    worker.inline_ir = inline_ir_with_one_memo
    _installed = True
    return True
