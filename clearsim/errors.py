"""Errors a user sees as one message (exit code 2 in the CLI, no traceback).

An `InputError` gathers every `Problem` of a mechanism file and writes them in
file order, each located by its YAML path:

    uhv_breaker.yaml:88:31  joints[9] 'J' → bodies[1]
      unknown body 'moving_contakt'; did you mean 'moving_contact'?
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

Path_ = tuple[str | int, ...]

MAX_PROBLEMS_SHOWN = 20  # the first ones in file order; the others usually repeat them (an alias, a copied block)
MAX_LINE = 1000  # characters of a line of a message, with every value quoted in it (a long path or hint fits)
MAX_LINES = 100  # lines of any message


def clipped(text: str, limit: int = MAX_LINE) -> str:
    """`text`, cut to `limit` characters ("..." at the end when cut)."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


def bounded(message: str) -> str:
    """A message of at most MAX_LINES lines of at most MAX_LINE characters: a value of megabytes quoted in it, or
    thousands of problems, cannot flood the terminal."""
    lines = [clipped(line) for line in message.splitlines()]
    if len(lines) > MAX_LINES:
        lines = lines[:MAX_LINES] + [f"... ({len(lines) - MAX_LINES} more lines)"]
    return "\n".join(lines)


class ClearsimError(Exception):
    """Base of every error that is reported to the user as one message."""


@dataclass(frozen=True)
class Problem:
    """One thing wrong with the input, at a YAML path.

    `position` (line, column) locates problems that have no path, such as YAML
    syntax errors; `override` names the `--set` text a problem comes from when
    the override itself cannot be applied.
    """

    path: Path_
    message: str
    hint: str | None = None
    position: tuple[int, int] | None = None
    override: str | None = None


def did_you_mean(word: object, candidates: Iterable[object]) -> str:
    """"; did you mean 'x'?" for the closest candidate, or "" when none is close."""
    names = [str(c) for c in candidates]
    matches = difflib.get_close_matches(str(word), names, n=1, cutoff=0.6)
    return f"; did you mean '{matches[0]}'?" if matches else ""


def format_path(path: Path_, names: dict | None = None) -> str:
    """("joints", 9, "bodies", 1) → "joints[9] 'J' → bodies[1]" (names: path → item name)."""
    names = names or {}
    parts: list[str] = []
    for depth, component in enumerate(path):
        if isinstance(component, int) and parts:
            parts[-1] += f"[{component}]"
            name = names.get(path[: depth + 1])
            if name is not None:
                parts[-1] += f" '{name}'"
        else:
            parts.append(str(component))
    return " → ".join(parts) if parts else "(top level)"


class InputError(ClearsimError):
    """All problems found in one mechanism file (and its `--set` overrides)."""

    def __init__(self, problems: Sequence[Problem], file: str | Path | None = None, source=None):
        self.problems = list(problems)
        self.file = file
        self.source = source
        super().__init__(self.report())

    def report(self) -> str:
        ordered = sorted(self.problems, key=self._order)
        blocks = [self._block(problem) for problem in ordered[:MAX_PROBLEMS_SHOWN]]
        if len(ordered) > MAX_PROBLEMS_SHOWN:
            blocks.append(f"... and {len(ordered) - MAX_PROBLEMS_SHOWN} more problems: fix the first "
                          f"{MAX_PROBLEMS_SHOWN} and check again")
        return "\n".join(blocks)

    def __str__(self) -> str:
        return self.report()

    def _order(self, problem: Problem) -> tuple:
        if problem.override is not None or self._override_of(problem) is not None:
            return (2, 0, 0)
        position = problem.position or self._located(problem.path)[0]
        if position is None:
            return (0, 0, 0)
        return (1, *position)

    def _override_of(self, problem: Problem) -> str | None:
        if problem.override is not None:
            return problem.override
        if self.source is None or problem.position is not None:
            return None
        return self.source.override_for(problem.path)

    def _located(self, path: Path_):
        """((line, column) or None, the path actually found in the file)."""
        if self.source is None:
            return None, path
        return self.source.locate(path)

    def _names(self) -> dict:
        return self.source.names if self.source is not None else {}

    def _header(self, problem: Problem) -> str:
        file = str(self.file) if self.file is not None else "<input>"
        where = format_path(problem.path, self._names()) if problem.path else ""
        override = self._override_of(problem)
        if override is not None:
            return f"in --set {clipped(override, MAX_LINE // 2)}" + (f"  {where}" if where else "")
        if problem.position is not None:
            line, column = problem.position
            return f"{file}:{line}:{column}" + (f"  {where}" if where else "")
        position, found = self._located(problem.path)
        if position is None:
            return file + (f"  {where}" if where else "")
        note = "" if found == problem.path else f"  (not in the file; shown at {format_path(found, self._names())})"
        return f"{file}:{position[0]}:{position[1]}  {format_path(problem.path, self._names())}{note}"

    def _block(self, problem: Problem) -> str:
        lines = [clipped(self._header(problem)), clipped(f"  {problem.message}")]
        if problem.hint:
            lines.append(clipped(f"  hint: {problem.hint}"))
        return "\n".join(lines)


class SolverError(ClearsimError):
    """The integration could not go on; says when, in which element, and what to try."""

    def __init__(self, message: str, time: float, element: str | None = None, hint: str | None = None,
                 kind: str = "joint"):
        self.message = message
        self.time = time
        self.element = element
        self.kind = kind  # what the element is: joint, force
        self.hint = hint
        self.place: str | None = None  # "file:line:column  joints[k] 'name'" of the element, when known
        super().__init__(str(self))

    def __str__(self) -> str:
        where = f"at t = {self.time * 1e3:.4g} ms"
        if self.element:
            where += f", {self.kind} {self.element}"
        text = f"{where}: {self.message.rstrip('.')}."
        text = f"{self.place}: {text}" if self.place else text
        return f"{text} {self.hint}" if self.hint else text
