"""Where a first run's compile time goes: CPU seconds per kernel (docs/performance.md, *Compile time*).

    python -m benchmarks.compile_profile [config] [--top N] [--by-linked] [override ...]

runs a 1 ms run of the config (default: the bundled breaker) in a fresh process on an empty, throw-away
NUMBA_CACHE_DIR without the compile-ahead process, and prints for each kernel numba compiled the CPU seconds
(thread time, so the machine's other load counts less than in wall time) of its own compilation ("own": its
callees' compilations, nested inside it, subtracted), the part of it spent in LLVM (optimising and emitting
machine code of its library, the callees linked in included), and its time with its callees ("with callees",
counted where the callee was first compiled), and the number of compiled kernels whose library links it, directly or
through their callees (numba links a callee's code into every caller's library, which optimises it again).
From numba's event API: `numba:compile` and `numba:llvm_lock`; the links from each library's linking list.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

from clearsim.runner import BUNDLED_CONFIG

PROFILED_RUN = r"""
import collections, json, resource, sys, time
from numba.core import event

open_compiles = []  # [kernel, thread time at its start, its callees' time]
own, llvm, with_callees = collections.Counter(), collections.Counter(), collections.Counter()
llvm_started = []


class Compile(event.Listener):
    def on_start(self, compile_event):
        function = getattr(compile_event.data.get("dispatcher"), "py_func", None)
        name = f"{function.__module__}.{function.__qualname__}" if function is not None else "?"
        open_compiles.append([name, time.thread_time(), 0.0])

    def on_end(self, compile_event):
        name, started, callees = open_compiles.pop()
        spent = time.thread_time() - started
        own[name] += spent - callees
        if all(entry[0] != name for entry in open_compiles):
            with_callees[name] += spent
        if open_compiles:
            open_compiles[-1][2] += spent


class Llvm(event.Listener):
    def on_start(self, llvm_event):
        llvm_started.append(time.thread_time())

    def on_end(self, llvm_event):
        spent = time.thread_time() - llvm_started.pop()
        if open_compiles:
            llvm[open_compiles[-1][0]] += spent


event.register("numba:compile", Compile())
event.register("numba:llvm_lock", Llvm())
from clearsim.runner import simulate_config
simulate_config(sys.argv[1], ["solver.t_end=1ms", *sys.argv[3:]], sys.argv[2])
usage = resource.getrusage(resource.RUSAGE_SELF)


def linked_libraries(library, found):  # the libraries linked into this one's code, directly or through others
    for callee in library._linking_libraries:
        if callee not in found:
            found.add(callee)
            linked_libraries(callee, found)
    return found


import gc
from numba.core.dispatcher import Dispatcher
kernel_of = {}  # library -> kernel name
for dispatcher in (item for item in gc.get_objects() if isinstance(item, Dispatcher)):
    function = dispatcher.py_func
    for compiled in dispatcher.overloads.values():
        kernel_of[compiled.library] = f"{function.__module__}.{function.__qualname__}"
linked = collections.Counter(kernel_of[callee] for library in kernel_of
                             for callee in linked_libraries(library, set()) if callee in kernel_of)
print(json.dumps({"process_cpu_s": usage.ru_utime + usage.ru_stime, "libraries": len(kernel_of),
                  "kernels": {name: [own[name], llvm[name], with_callees[name], linked[name]] for name in own}}))
"""


def profile(config, overrides=()) -> dict:
    """{"process_cpu_s": s, "kernels": {kernel: [own s, LLVM s, with callees s]}} of a run on an empty cache."""
    with tempfile.TemporaryDirectory() as folder:
        environment = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(folder, "cache"), CLEARSIM_COMPILE_AHEAD="0")
        done = subprocess.run([sys.executable, "-c", PROFILED_RUN, str(config), os.path.join(folder, "run.h5"),
                               *overrides], env=environment, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.splitlines()[-1])


def table(result: dict, top: int, by_linked: bool = False) -> str:
    """The kernels by their own compile time, or by it times the libraries linking them (`by_linked`)."""
    kernels = result["kernels"]
    total_own, total_llvm = sum(v[0] for v in kernels.values()), sum(v[1] for v in kernels.values())
    lines = [f"process CPU {result['process_cpu_s']:.1f} s; compiling {total_own:.1f} s ({total_llvm:.1f} s in LLVM), "
             f"{len(kernels)} kernels, {result['libraries']} libraries",
             "   own   LLVM  with callees  linked  linked x own  kernel"]
    def order(kernel):
        own, _, _, linked = kernels[kernel]
        return own * linked if by_linked else own

    for name in sorted(kernels, key=order, reverse=True)[:top]:
        own, llvm, with_callees, linked = kernels[name]
        lines.append(f"{own:6.2f} {llvm:6.2f} {with_callees:13.2f} {linked:7d} {linked * own:13.2f}  {name}")
    return "\n".join(lines)


def main(arguments: list[str]) -> None:
    top = 25
    if "--top" in arguments:
        at = arguments.index("--top")
        top, arguments = int(arguments[at + 1]), arguments[:at] + arguments[at + 2:]
    by_linked = "--by-linked" in arguments
    arguments = [argument for argument in arguments if argument != "--by-linked"]
    configs = [argument for argument in arguments if "=" not in argument]
    overrides = [argument for argument in arguments if "=" in argument]
    print(table(profile(configs[0] if configs else BUNDLED_CONFIG, overrides), top, by_linked))


if __name__ == "__main__":
    main(sys.argv[1:])
