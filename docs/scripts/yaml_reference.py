"""Write the key tables of docs/yaml.md from the schema (clearsim/model/schema.py).

Run from the repository root: python3 docs/scripts/yaml_reference.py [--check]
Only the region between the GENERATED KEYS markers is rewritten; the prose around it is
hand-written. --check exits with 1 instead of writing when the region is out of date.
A field without `description=` gets a short italic text derived from its type.
"""

import inspect
import sys
import types
import typing
from pathlib import Path
from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, WithJsonSchema
from pydantic.fields import FieldInfo

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the script lives outside the package

from clearsim.model.paths import is_model  # noqa: E402
from clearsim.model.schema import Mechanism  # noqa: E402

DOC = Path(__file__).resolve().parents[1] / "yaml.md"
BEGIN, END = "<!-- BEGIN GENERATED KEYS -->", "<!-- END GENERATED KEYS -->"
DISCRIMINATORS = ("type", "law")
SIMPLE_TYPES = {str: "string", float: "number", int: "integer", bool: "boolean"}
LIMITS = {"gt": ">", "ge": "≥", "lt": "<", "le": "≤"}
HEADER = "| key | type | unit | default | meaning |\n|---|---|---|---|---|"


# --- types ----------------------------------------------------------------------------------------


def _parts(annotation: Any) -> tuple[Any, list]:
    """(bare type, metadata) of a possibly `Annotated` type."""
    if typing.get_origin(annotation) is Annotated:
        bare, *metadata = typing.get_args(annotation)
        return bare, metadata
    return annotation, []


def _members(bare: Any) -> list:
    """The non-None members of a union, or [] for any other type."""
    if typing.get_origin(bare) in (Union, types.UnionType):
        return [a for a in typing.get_args(bare) if a is not type(None)]
    return []


def anchor(model: type[BaseModel]) -> str:
    return f"key-{model.__name__.lower()}"


def field_type(info: FieldInfo) -> Any:
    """The field's type with its metadata (unit, limits) put back, as it was written."""
    return Annotated[(info.annotation, *info.metadata)] if info.metadata else info.annotation


def units_of(annotation: Any) -> list[str]:
    """The unit kinds ("length: a number in m or ...") of the quantities inside a type."""
    bare, metadata = _parts(annotation)
    found = [(m.json_schema or {}).get("description") for m in metadata if isinstance(m, WithJsonSchema)]
    for argument in typing.get_args(bare):
        found += units_of(argument)
    return list(dict.fromkeys(text for text in found if text))


def _pair_text(arguments: tuple) -> str:
    items = [type_text(a) for a in arguments]
    if len(set(items)) == 1 and " " in items[0]:
        return f"pair of ({items[0]})"
    return "[" + ", ".join(items) + "]"


def type_text(annotation: Any) -> str:
    """The type as a reader of the YAML sees it: quantity, string, [x, y], list of a model, ..."""
    bare, metadata = _parts(annotation)
    origin, arguments = typing.get_origin(bare), typing.get_args(bare)
    if any(isinstance(m, WithJsonSchema) and "x-unit" in (m.json_schema or {}) for m in metadata):
        return "quantity"
    if _members(bare):
        return " or ".join(type_text(a) for a in _members(bare))
    if origin is Literal:
        values = ", ".join(f"`{a}`" for a in arguments)
        return values if len(arguments) == 1 else f"one of {values}"
    if origin is tuple:
        return _pair_text(arguments)
    if origin is list:
        return f"list of {type_text(arguments[0])}"
    if origin is dict:
        return f"mapping {type_text(arguments[0])} → {type_text(arguments[1])}"
    if is_model(bare):
        return f"[{bare.__name__}](#{anchor(bare)})"
    return SIMPLE_TYPES.get(bare, getattr(bare, "__name__", str(bare)))


def limits_text(info: FieldInfo) -> str:
    """", > 0, ≤ 1" from the field's constraints (min_length of a list: ", at least 1 item")."""
    parts = []
    for constraint in info.metadata:
        parts += [f"{sign} {number(getattr(constraint, key))}" for key, sign in LIMITS.items()
                  if getattr(constraint, key, None) is not None]
        if getattr(constraint, "min_length", None) is not None:
            parts.append(f"at least {constraint.min_length} item(s)")
    return "".join(f", {part}" for part in parts)


# --- values ---------------------------------------------------------------------------------------


def number(value: float) -> str:
    """1e-07 → 1e-7, 207000000000.0 → 2.07e11, 0.0 → 0."""
    text = f"{value:g}"
    mantissa, _, exponent = text.partition("e")
    return f"{mantissa}e{int(exponent)}" if exponent else mantissa


def flow(value: Any) -> str:
    """A value as YAML flow text; a model as the keys it sets."""
    if isinstance(value, BaseModel):
        value = value.model_dump(exclude_none=True)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{key}: {flow(item)}" for key, item in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(flow(item) for item in value) + "]"
    if isinstance(value, float):
        return number(value)
    return str(value)


def default_text(info: FieldInfo) -> str:
    if info.is_required():
        return "required"
    value = info.get_default(call_default_factory=True)
    if value is None:
        return "—"
    if isinstance(value, BaseModel) and value == type(value)():
        return "the keys' defaults"
    return f"`{flow(value)}`"


def meaning_text(info: FieldInfo) -> str:
    """The field's description; without one, a short italic text derived from its type."""
    if info.description:
        return info.description
    models = _models_in(info.annotation)
    if models:
        return "see " + ", ".join(type_text(model) for model in models)
    return f"*{_type_summary(field_type(info))}*"


def _type_summary(annotation: Any) -> str:
    """"mass" for a quantity, "selects this kind" for a `type:`/`law:` tag, else the type."""
    units = units_of(annotation)
    if units:
        return units[0].split(":")[0]
    bare, _ = _parts(annotation)
    bare = (_members(bare) or [bare])[0]
    if typing.get_origin(bare) is Literal:
        return "selects this kind" if len(typing.get_args(bare)) == 1 else "one of the values listed"
    return type_text(annotation)


# --- tables ---------------------------------------------------------------------------------------


def cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def field_row(name: str, info: FieldInfo) -> str:
    annotation = field_type(info)
    units = "; ".join(units_of(annotation)) or "—"
    cells = [f"`{name}`", type_text(annotation) + limits_text(info), units, default_text(info), meaning_text(info)]
    return "| " + " | ".join(cell(c) for c in cells) + " |"


def _tag(model: type[BaseModel]) -> str:
    """" with `type: revolute`" for a member of a union told apart by `type:` or `law:`."""
    for key in DISCRIMINATORS:
        info = model.model_fields.get(key)
        if info is not None and typing.get_origin(info.annotation) is Literal:
            values = " / ".join(typing.get_args(info.annotation))
            return f" with `{key}: {values}`"
    return ""


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    bare, _ = _parts(annotation)
    if is_model(bare):
        return [bare]
    return [model for argument in typing.get_args(bare) for model in _models_in(argument)]


def _child_path(path: str, name: str, annotation: Any) -> str:
    bare, _ = _parts(annotation)
    bare = (_members(bare) or [bare])[0]
    suffix = "[]" if typing.get_origin(bare) is list else ""
    return f"{path}.{name}{suffix}" if path else f"{name}{suffix}"


def model_locations(model: type[BaseModel] = Mechanism, path: str = "", found: dict | None = None) -> dict:
    """Every model reachable from `model` → where it is written in the file, top-down (depth first)."""
    found = {model: ["the top level of the file"]} if found is None else found
    for name, info in model.model_fields.items():
        child_path = _child_path(path, name, info.annotation)
        for child in _models_in(info.annotation):
            first_visit = child not in found
            found.setdefault(child, []).append(f"`{child_path}`{_tag(child)}")
            if first_visit:
                model_locations(child, child_path, found)
    return found


def model_section(model: type[BaseModel], locations: list[str]) -> str:
    intro = "Written at " + ", ".join(locations) + "."
    if model.__doc__:
        intro += " " + " ".join(inspect.cleandoc(model.__doc__).split())
    rows = [field_row(name, info) for name, info in model.model_fields.items()]
    return "\n".join([f'<a id="{anchor(model)}"></a>', f"### {model.__name__}", "", intro, "", HEADER, *rows])


def reference_markdown() -> str:
    """The generated region: one table per schema model, in the order the file is read."""
    sections = [model_section(model, where) for model, where in model_locations().items()]
    return "\n\n".join(sections) + "\n"


# --- the document ---------------------------------------------------------------------------------


def generated_region(text: str) -> str:
    """The text between the markers (without the newlines that follow BEGIN and precede END)."""
    start, end = text.index(BEGIN) + len(BEGIN), text.index(END)
    return text[start:end].strip("\n") + "\n"


def splice(text: str, generated: str) -> str:
    start, end = text.index(BEGIN) + len(BEGIN), text.index(END)
    return text[:start] + "\n" + generated + text[end:]


def main(argv: list[str]) -> int:
    text = DOC.read_text(encoding="utf-8")
    generated = reference_markdown()
    if generated_region(text) == generated:
        print(f"{DOC.name}: up to date")
        return 0
    if "--check" in argv:
        print(f"{DOC.name}: out of date; run python3 docs/scripts/yaml_reference.py")
        return 1
    DOC.write_text(splice(text, generated), encoding="utf-8")
    print(f"{DOC.name}: tables rewritten")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
