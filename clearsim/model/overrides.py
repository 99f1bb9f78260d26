"""`--set path=value` overrides applied to the YAML document before validation.

    joints.J.clearance=0.1mm           the joint named J (list items are selected by name)
    joints.J.contact.restitution=0.8   creates `contact:` when the joint has none
    solver.t_end=20ms                  values are read as YAML: 0, 1e-8, true; "0.1mm" stays text

Setting a joint's `clearance` keeps its bearing radius: a `journal_radius:` the
joint writes is dropped (R_J = R_B − c) when a bearing radius is known, so that
a clearance sweep works on joints described by their two radii.

Each path is checked against the schema (the right union member for a joint's
`type:` or a motion's `law:`) so that a misspelt key is an error, not a silent
new key.
"""

from __future__ import annotations

import typing
from dataclasses import dataclass
from typing import Any, Sequence

import yaml
from pydantic import BaseModel

from clearsim.errors import Problem, did_you_mean
from clearsim.model.messages import show
from clearsim.model.paths import element_type, is_model, member_for_data, strip_type
from clearsim.model.yaml_reading import MAX_VALUE_CHARACTERS, CheckedLoader

NAMED_LISTS = {"bodies": "body", "joints": "joint", "drivers": "driver", "forces": "force", "sensors": "sensor"}
EXAMPLE = "joints.J.clearance=0.1mm"


class OverrideError(ValueError):
    def __init__(self, message: str, hint: str | None = None):
        super().__init__(message)
        self.message, self.hint = message, hint


@dataclass
class _Cursor:
    """Where the walk along an override path is: the YAML node, its schema type, the path so far."""

    node: Any
    annotation: Any
    path: tuple = ()
    written: str = ""  # the dotted path as written, up to here


def apply_overrides(document: dict, overrides: Sequence[str], root: type[BaseModel]) -> tuple[dict, list[Problem]]:
    """Apply each override in order; (YAML path → override text, problems of those that failed)."""
    applied: dict = {}
    problems = []
    for text in overrides:
        try:
            path = apply_override(document, text, root)
            applied[path] = text
            _clearance_keeps_bearing(document, path)
        except OverrideError as exc:
            problems.append(Problem((), exc.message, exc.hint, override=text))
    return applied, problems


def apply_override(document: dict, text: str, root: type[BaseModel]) -> tuple:
    """Set one `dotted.path=value` in the document; returns the YAML path it set."""
    key, separator, raw_value = text.partition("=")
    segments = key.strip().split(".")
    if not separator or not all(s.strip() for s in segments):
        raise OverrideError("an override is written path=value", f"e.g. --set {EXAMPLE}")
    if not raw_value.strip():
        raise OverrideError("no value after '=': an empty value would silently unset the file's value",
                            f"write the value, e.g. --set {key.strip()}=<value>, or leave this --set out")
    value = parse_value(raw_value)
    cursor = _Cursor(document, root)
    for segment in segments[:-1]:
        cursor = _descend(cursor, segment.strip())
    return _assign(cursor, segments[-1].strip(), value)


def _clearance_keeps_bearing(document: dict, path: tuple) -> None:
    if len(path) != 3 or path[0] != "joints" or path[2] != "clearance":
        return
    joint = document["joints"][path[1]]
    defaults = document.get("defaults")
    bearing_known = "bearing_radius" in joint or (isinstance(defaults, dict) and "bearing_radius" in defaults)
    if bearing_known and joint.get("clearance") not in (None, 0):
        joint.pop("journal_radius", None)


def parse_value(raw: str) -> Any:
    """The override's value as YAML; numbers PyYAML keeps as text (1e-8) become floats."""
    if len(raw) > MAX_VALUE_CHARACTERS:
        raise OverrideError(f"a value of {len(raw)} characters, more than any setting takes ({MAX_VALUE_CHARACTERS})",
                            "write the number with its unit, e.g. 0.1mm, or the name")
    try:
        if any(isinstance(event, yaml.AliasEvent) for event in yaml.parse(raw, Loader=CheckedLoader)):
            raise OverrideError(f"an alias (*name) in the value {show(raw)}", "write the value out in full")
        value = yaml.load(raw, Loader=CheckedLoader)
    except yaml.YAMLError:
        raise OverrideError(f"cannot read the value {show(raw)}", "quote it, or write it as in the YAML file") from None
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value


def _descend(cursor: _Cursor, segment: str) -> _Cursor:
    """One step down the path; a missing mapping on the way (`contact:`) is created."""
    written = f"{cursor.written}.{segment}" if cursor.written else segment
    if isinstance(cursor.node, list):
        index = _list_index(cursor, segment)
        child_type = element_type(cursor.annotation, index) if cursor.annotation is not None else None
        return _Cursor(cursor.node[index], child_type, cursor.path + (index,), written)
    key, child_type = _key_and_type(cursor, segment)
    child = cursor.node.get(key)
    if child is None and _origin(child_type) is list:
        child = []  # an absent list has no items to select; _list_index says so
    elif not isinstance(child, (dict, list)):
        if child is not None or not _is_mapping_type(child_type):
            raise OverrideError(f"'{written}' holds a single value, not keys", f"write --set {written}=<value>")
        child = cursor.node[key] = {}
    return _Cursor(child, child_type, cursor.path + (key,), written)


def _origin(annotation: Any) -> Any:
    return typing.get_origin(strip_type(annotation)) if annotation is not None else None


def _is_mapping_type(annotation: Any) -> bool:
    return annotation is not None and (is_model(strip_type(annotation)) or _origin(annotation) is dict)


def _key_and_type(cursor: _Cursor, segment: str) -> tuple[str, Any]:
    """The mapping key a segment names and its schema type; an unknown key is an error."""
    if not isinstance(cursor.node, dict):
        raise OverrideError(f"'{cursor.written}' is a single value: it has no '{segment}'")
    annotation = strip_type(cursor.annotation)
    if _origin(annotation) is dict:
        return segment, element_type(annotation, segment)
    model = member_for_data(annotation, cursor.node)
    if model is None:
        return segment, None
    if segment not in model.model_fields:
        where = f" in {cursor.written}" if cursor.written else ""
        allowed = list(model.model_fields)
        raise OverrideError(f"unknown key '{segment}'{where}{did_you_mean(segment, allowed)}",
                            f"allowed keys here: {', '.join(allowed)}")
    return segment, model.model_fields[segment].annotation


def _list_index(cursor: _Cursor, segment: str) -> int:
    """A named list's item by its `name:`; a plain list's (a point's [x, y]) item by its index."""
    items = cursor.node if isinstance(cursor.node, list) else []
    list_key = cursor.path[-1] if cursor.path else None
    if list_key in NAMED_LISTS and len(cursor.path) == 1:
        names = [item.get("name") for item in items if isinstance(item, dict)]
        if segment in names:
            return names.index(segment)
        raise OverrideError(f"no {NAMED_LISTS[list_key]} named '{segment}'{did_you_mean(segment, names)}",
                            f"{list_key} in the file: {', '.join(map(str, names)) or 'none'}")
    if segment.isdigit() and int(segment) < len(items):
        return int(segment)
    raise OverrideError(f"'{cursor.written}' has no item '{segment}'", f"set the whole list: --set {cursor.written}=[...]")


def _assign(cursor: _Cursor, segment: str, value: Any) -> tuple:
    """Set the last segment's value; the YAML path that now holds it."""
    if isinstance(cursor.node, list):
        index = _list_index(cursor, segment)
        cursor.node[index] = value
        return cursor.path + (index,)
    key, _ = _key_and_type(cursor, segment)
    cursor.node[key] = value
    return cursor.path + (key,)
