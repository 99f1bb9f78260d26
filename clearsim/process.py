"""What a clearsim process does once, for itself: a quick exit.

A process that has loaded the compiled kernels spends ~0.25 s of its exit in the garbage collector (interpreter
finalisation walks numba's object graph), after the command's work is done and its files are closed: a
`clearsim run` seems to hang that long after its summary, and a sweep waits that long for its pool's processes to
end before it writes the summary. Frozen objects are left to the operating system instead (gc.freeze): atexit
handlers still run, files are closed by the code that opened them, before.
"""

from __future__ import annotations

import atexit
import gc

_registered = False


def exit_without_final_collection() -> None:
    """Freeze the heap at exit, once per process: the final collection skips what exists then."""
    global _registered
    if not _registered:
        atexit.register(gc.freeze)  # registered early, so it runs after the handlers registered later
        _registered = True
