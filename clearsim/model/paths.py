"""Walking YAML paths through the schema's types: which model, field or union member a path reaches.

Used to turn pydantic error locations into YAML paths (pydantic inserts the tag
of a union member into its locations) and to check `--set` paths before they
are applied.
"""

from __future__ import annotations

import types
import typing
from dataclasses import dataclass, field
from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel
from pydantic.fields import FieldInfo

DISCRIMINATORS = ("type", "law")


def strip_type(annotation: Any) -> Any:
    """The type without `Annotated[...]` and without an optional `None`."""
    while True:
        origin = typing.get_origin(annotation)
        if origin is Annotated:
            annotation = typing.get_args(annotation)[0]
        elif origin in (Union, types.UnionType):
            members = [a for a in typing.get_args(annotation) if a is not type(None)]
            if len(members) != 1:
                return annotation
            annotation = members[0]
        else:
            return annotation


def is_model(annotation: Any) -> bool:
    return isinstance(annotation, type) and issubclass(annotation, BaseModel)


def union_members(annotation: Any) -> list[Any]:
    """The members of a union type (after stripping), or [] for any other type."""
    annotation = strip_type(annotation)
    if typing.get_origin(annotation) in (Union, types.UnionType):
        return [strip_type(a) for a in typing.get_args(annotation) if a is not type(None)]
    return []


def tags_of(model: type[BaseModel]) -> tuple[str, ...]:
    """The values of the model's discriminator field (`type:` or `law:`)."""
    for key in DISCRIMINATORS:
        info = model.model_fields.get(key)
        if info is not None and typing.get_origin(strip_type(info.annotation)) is Literal:
            return typing.get_args(strip_type(info.annotation))
    return ()


def union_tags(annotation: Any) -> list[str]:
    return [tag for member in union_members(annotation) if is_model(member) for tag in tags_of(member)]


def member_for_tag(annotation: Any, tag: Any) -> Any:
    """The union member a discriminator value selects, or None."""
    return next((m for m in union_members(annotation) if is_model(m) and tag in tags_of(m)), None)


def member_for_data(annotation: Any, node: Any) -> Any:
    """The model a YAML mapping is validated as: the type itself, or the union member its tag selects."""
    annotation = strip_type(annotation)
    if is_model(annotation):
        return annotation
    if not isinstance(node, dict):
        return None
    for key in DISCRIMINATORS:
        member = member_for_tag(annotation, node.get(key))
        if member is not None:
            return member
    return None


def is_model_union(annotation: Any) -> bool:
    members = union_members(annotation)
    return bool(members) and all(is_model(m) for m in members)


def element_type(annotation: Any, component: Any) -> Any:
    """The type of `annotation[component]` for a list, tuple or dict type (None when unknown)."""
    annotation = strip_type(annotation)
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is list and args:
        return args[0]
    if origin is dict and len(args) == 2:
        return args[1]
    if origin is tuple and args:
        if len(args) == 2 and args[1] is Ellipsis:
            return args[0]
        return args[component] if isinstance(component, int) and 0 <= component < len(args) else None
    return None


@dataclass
class Location:
    """A pydantic location as a YAML path, with what the schema says about its end."""

    path: tuple = ()
    branches: list = field(default_factory=list)  # (path, member tag) of plain unions passed through
    owner: type[BaseModel] | None = None  # the model whose field the path ends on
    field_info: FieldInfo | None = None
    annotation: Any = None  # the type at the end of the path


def locate_error(loc: tuple, root: type[BaseModel]) -> Location:
    """Walk a pydantic error location through the schema, dropping union member tags."""
    result, annotation = Location(), root
    for component in loc:
        annotation = strip_type(annotation) if annotation is not None else None
        if annotation is not None and is_model_union(annotation):
            annotation = member_for_tag(annotation, component)
            continue
        if annotation is not None and union_members(annotation):
            result.branches.append((result.path, component))
            annotation = None
            continue
        result.path += (component,)
        annotation = _child(result, annotation, component)
    result.annotation = annotation
    return result


def _child(result: Location, annotation: Any, component: Any) -> Any:
    if is_model(annotation):
        info = annotation.model_fields.get(component)
        result.owner, result.field_info = annotation, info
        return info.annotation if info is not None else None
    result.owner, result.field_info = None, None
    return element_type(annotation, component) if annotation is not None else None


def model_at(path: tuple, document: Any, root: type[BaseModel]) -> type[BaseModel] | None:
    """The model that validates the mapping at `path` of a YAML document, or None."""
    annotation, node = root, document
    for component in path:
        model = member_for_data(annotation, node)
        if model is not None:
            info = model.model_fields.get(component)
            annotation = info.annotation if info is not None else None
        else:
            annotation = element_type(annotation, component) if annotation is not None else None
        node = _get(node, component)
        if annotation is None:
            return None
    return member_for_data(annotation, node)


def _get(node: Any, component: Any) -> Any:
    if isinstance(node, dict):
        return node.get(component)
    if isinstance(node, list) and isinstance(component, int) and 0 <= component < len(node):
        return node[component]
    return None
