"""Pydantic validation errors → Problems with YAML paths and messages written for people.

No "Value error," prefixes, no URLs; unknown keys and unknown `type:`/`law:`
values come with the allowed choices and a did-you-mean.
"""

from __future__ import annotations

import re
from collections import defaultdict
from typing import Any

from pydantic import BaseModel, ValidationError

from clearsim.errors import Problem, did_you_mean
from clearsim.model.paths import Location, locate_error, model_at, union_tags

_BOUNDS = {
    "greater_than": ("gt", "must be greater than"),
    "greater_than_equal": ("ge", "must be at least"),
    "less_than": ("lt", "must be smaller than"),
    "less_than_equal": ("le", "must be at most"),
}

_EXPECTED = {
    "float_type": "a number", "float_parsing": "a number", "finite_number": "a finite number", "int_type": "a whole number",
    "int_parsing": "a whole number", "int_from_float": "a whole number", "string_type": "a name (text)",
    "bool_type": "true or false", "bool_parsing": "true or false", "tuple_type": "a list",
    "list_type": "a list", "dict_type": "a mapping (key: value)", "model_type": "a mapping (key: value)",
    "model_attributes_type": "a mapping (key: value)", "literal_error": "one of the listed values",
}


def show(value: Any) -> str:
    """A short rendering of a YAML value for a message."""
    text = repr(value) if isinstance(value, str) else str(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _quoted(text: str) -> list[str]:
    return re.findall(r"'([^']*)'", text)


def validation_problems(exc: ValidationError, document: Any, root: type[BaseModel]) -> list[Problem]:
    """One Problem per error (errors of the branches of a plain union merged into one)."""
    located = [(error, locate_error(tuple(error["loc"]), root)) for error in exc.errors()]
    located = _keep_deepest_branches(located)
    problems = _merge_type_mismatches(located)
    problems += [_problem(error, where, document, root) for error, where in located if not where.branches]
    return _unique(problems)


def _unique(problems: list[Problem]) -> list[Problem]:
    return list(dict.fromkeys(problems))


def _branch_site(where: Location) -> tuple | None:
    return where.branches[-1][0] if where.branches else None


def _keep_deepest_branches(located: list) -> list:
    """In a plain union (a point name or [x, y]), keep the errors of the member that got furthest."""
    depth: dict = defaultdict(int)
    for error, where in located:
        site = _branch_site(where)
        if site is not None:
            depth[site] = max(depth[site], len(where.path) - len(site))
    kept = []
    for error, where in located:
        site = _branch_site(where)
        if site is not None and depth[site] > 0:
            if len(where.path) - len(site) < depth[site]:
                continue
            where.branches = []  # a member that matched the shape: its error stands alone
        kept.append((error, where))
    return kept


def _merge_type_mismatches(located: list) -> list[Problem]:
    """All members of a plain union rejected the value's shape: one 'expected A or B' problem."""
    expected: dict = defaultdict(list)
    values: dict = {}
    for error, where in located:
        if where.branches:
            expected[where.path].append(_EXPECTED.get(error["type"], error["msg"].lower()))
            values[where.path] = error["input"]
    return [
        Problem(path, f"expected {' or '.join(dict.fromkeys(kinds))}, got {show(values[path])}")
        for path, kinds in expected.items()
    ]


def _description_hint(where: Location) -> str | None:
    return where.field_info.description if where.field_info is not None else None


def _problem(error: dict, where: Location, document: Any, root: type[BaseModel]) -> Problem:
    kind, path = error["type"], where.path
    if kind == "missing":
        return Problem(path[:-1], f"missing required key '{path[-1]}'", _description_hint(where))
    if kind == "extra_forbidden":
        return _unknown_key(path, document, root)
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        return _bad_tag(error, where)
    if kind == "literal_error":
        allowed = _quoted(error["ctx"]["expected"])
        name = path[-1] if path and isinstance(path[-1], str) else "value"
        message = f"unknown {name} {show(error['input'])}{did_you_mean(error['input'], allowed)}"
        return Problem(path, message, f"allowed: {', '.join(allowed)}")
    if kind in _BOUNDS:
        bound, phrase = _BOUNDS[kind]
        return Problem(path, f"{phrase} {error['ctx'][bound]:g}, got {show(error['input'])}", _description_hint(where))
    return Problem(path, _plain_message(error), _description_hint(where) if kind in _EXPECTED else None)


def _plain_message(error: dict) -> str:
    kind, message = error["type"], error["msg"]
    if kind in ("too_long", "too_short"):
        ctx = error.get("ctx", {})
        limit = ctx.get("max_length", ctx.get("min_length"))
        word = "many" if kind == "too_long" else "few"
        return f"too {word} items: expected {'at most' if kind == 'too_long' else 'at least'} {limit}, got {ctx.get('actual_length')}"
    if kind in _EXPECTED:
        return f"expected {_EXPECTED[kind]}, got {show(error['input'])}"
    for prefix in ("Value error, ", "Assertion failed, "):
        message = message.removeprefix(prefix)
    return message[:1].lower() + message[1:]


def _unknown_key(path: tuple, document: Any, root: type[BaseModel]) -> Problem:
    key = path[-1]
    model = model_at(path[:-1], document, root)
    allowed = list(model.model_fields) if model is not None else []
    hint = f"allowed keys here: {', '.join(allowed)}" if allowed else None
    return Problem(path, f"unknown key '{key}'{did_you_mean(key, allowed)}", hint)


def _bad_tag(error: dict, where: Location) -> Problem:
    key = error["ctx"]["discriminator"].strip("'")
    allowed = _quoted(error["ctx"].get("expected_tags", "")) or _tags_at(where)
    if error["type"] == "union_tag_not_found":
        return Problem(where.path, f"missing required key '{key}'", f"one of: {', '.join(allowed)}")
    tag = error["ctx"]["tag"]
    message = f"unknown {key} '{tag}'{did_you_mean(tag, allowed)}"
    return Problem(where.path + (key,), message, f"allowed: {', '.join(allowed)}")


def _tags_at(where: Location) -> list[str]:
    return union_tags(where.annotation) if where.annotation is not None else []
