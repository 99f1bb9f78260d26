"""The cases of a grid sweep: value lists, the product of the swept axes, the ideal references.

    --clearance 0.01,0.1 --joints A,J      one axis "clearance": each value sets every named joint
    --set joints.J.friction.mu_d=0.1,0.16  one axis per path with several values
    --set solver.t_end=4ms                 a single value: applied to every case, the ideal ones too

Cases are the product of the axes. The ideal reference sets every clearance joint of the file,
and every joint whose clearance is swept, to clearance 0. An axis that cannot change the ideal
mechanism (the clearance itself, a key of a joint that the ideal case makes ideal, `defaults.`,
which only clearance joints read) is left out of it; any other axis (a mass, the driver, the
solver) gives one ideal case per value, and each case is compared with the ideal case of its own
values.
"""

from __future__ import annotations

import hashlib
import itertools
import re
from dataclasses import dataclass, field

from clearsim.errors import ClearsimError, did_you_mean
from clearsim.model.resolve import is_clearance_joint
from clearsim.units import LEADING_NUMBER, UnitError, to_si

CLEARANCE = "clearance"
IDEAL = "ideal"
MAX_NAME = 100
_UNSAFE = re.compile(r"[^A-Za-z0-9._+-]+")
_OPEN, _CLOSE = "[{(", "]})"
_ONE_LENGTH = re.compile(LEADING_NUMBER.pattern + r"\s*[^\W\d_]+\s*$")  # 0.01 mm, 50um, 1e-3 in


class SweepOptionError(ClearsimError):
    """A sweep option that cannot be read (the message names the option and the fix)."""


@dataclass(frozen=True)
class Axis:
    """One swept quantity: its column label, the values as written, the overrides each value applies."""

    label: str
    values: tuple[str, ...]
    overrides: tuple[tuple[str, ...], ...]
    affects_ideal: bool


@dataclass(frozen=True)
class Case:
    """One run of the sweep: its file stem, swept values (label → text), every `--set` it applies."""

    name: str
    values: dict[str, str]
    overrides: tuple[str, ...]
    ideal: bool = False
    reference: str | None = None  # the ideal case its figures are read against
    group: tuple[str, ...] = field(default=(), compare=False)  # values of the axes that affect the ideal


def split_values(text: str) -> list[str]:
    """'0.01,0.1mm' → ['0.01', '0.1mm']; commas inside [..], {..} or quotes do not split."""
    parts, depth, quote, current = [], 0, None, ""
    for char in text:
        if quote:
            quote = None if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char in _OPEN:
            depth += 1
        elif char in _CLOSE:
            depth -= 1
        elif char == "," and depth == 0:
            parts.append(current.strip())
            current = ""
            continue
        current += char
    parts.append(current.strip())
    return parts


def clearance_text(value: str) -> str:
    """A --clearance value with its unit: a bare number is in millimetres."""
    try:
        float(value)
        text = f"{value} mm"
    except ValueError:
        text = value
    one_length = _ONE_LENGTH.match(text)  # pint reads '0.01;0.02' as 0.0002 and '(0.01)' as metres: never a clearance
    if LEADING_NUMBER.match(text) and not one_length:
        raise _not_one_clearance(value)
    try:
        metres = to_si(text, "length")
    except UnitError as exc:
        raise SweepOptionError(f"--clearance: {exc}\n  hint: write millimetres as plain numbers "
                               "(--clearance 0.01,0.05) or give a unit (50um)") from None
    if not one_length:
        raise _not_one_clearance(value)
    if metres < 0:
        raise SweepOptionError(f"--clearance: a clearance cannot be negative, got {value!r}")
    return text


def _not_one_clearance(value: str) -> SweepOptionError:
    return SweepOptionError(f"--clearance: cannot read {value!r} as one clearance (a number, in mm unless a unit "
                            "follows it)\n  hint: separate values by commas: --clearance 0.01,0.05 or 10um,50um")


def _values(option: str, text: str) -> list[str]:
    values = split_values(text)
    if not all(values):
        raise SweepOptionError(f"{option}: an empty value in {text!r}\n  hint: separate values by single commas")
    if len(set(values)) != len(values):
        raise SweepOptionError(f"{option}: a value is given twice in {text!r}")
    return values


def clearance_joints(mechanism) -> list[str]:
    return [joint.name for joint in mechanism.joints if is_clearance_joint(joint)]


def target_joints(mechanism, joints: str | None) -> list[str]:
    """The joints --clearance applies to: --joints A,J (revolute), else the file's clearance joints."""
    if joints is None:
        found = clearance_joints(mechanism)
        if not found:
            raise SweepOptionError("--clearance: the file has no clearance joint\n"
                                   "  hint: name the revolute joints to give a clearance: --joints A,J")
        return found
    revolute = [j.name for j in mechanism.joints if j.type == "revolute"]
    kinds = {j.name: j.type for j in mechanism.joints}
    names = _values("--joints", joints)
    for name in names:
        if name in kinds and name not in revolute:
            raise SweepOptionError(f"--joints: '{name}' is a {kinds[name]} joint; only revolute joints "
                                   f"take a clearance\n  hint: revolute joints in the file: {', '.join(revolute)}")
        if name not in revolute:
            raise SweepOptionError(f"--joints: no revolute joint named '{name}'{did_you_mean(name, revolute)}\n"
                                   f"  hint: revolute joints in the file: {', '.join(revolute) or 'none'}")
    return names


def clearance_axis(values: str, joints: list[str]) -> Axis:
    texts = tuple(clearance_text(v) for v in _values("--clearance", values))
    overrides = tuple(tuple(f"joints.{j}.clearance={text}" for j in joints) for text in texts)
    return Axis(CLEARANCE, texts, overrides, affects_ideal=False)


def split_overrides(overrides: list[str]) -> tuple[list[str], list[tuple[str, list[str]]]]:
    """(single-valued overrides, [(path, values)] of those with several comma-separated values)."""
    fixed, swept = [], []
    for text in overrides:
        path, separator, raw = text.partition("=")
        values = split_values(raw) if separator else [raw]
        if len(values) > 1:
            swept.append((path.strip(), _values(f"--set {path.strip()}", raw)))
        else:
            fixed.append(text)
    paths = [path for path, _ in swept]
    for path in paths:
        if paths.count(path) > 1:
            raise SweepOptionError(f"--set {path}: swept twice\n  hint: give all its values in one --set")
    return fixed, swept


def joint_of(path: str) -> str | None:
    parts = path.split(".")
    return parts[1] if len(parts) > 2 and parts[0] == "joints" else None


def set_axes(swept: list[tuple[str, list[str]]], zeroed: set[str]) -> list[Axis]:
    axes = []
    for path, values in swept:
        cannot_change_ideal = path.startswith("defaults.") or joint_of(path) in zeroed
        axes.append(Axis(path, tuple(values), tuple((f"{path}={v}",) for v in values), not cannot_change_ideal))
    return axes


def zeroed_joints(mechanism, targets: list[str], swept: list[tuple[str, list[str]]]) -> list[str]:
    """Joints the ideal case sets to clearance 0: the file's clearance joints and every swept one."""
    names = clearance_joints(mechanism) + targets
    names += [joint_of(path) for path, _ in swept if path.endswith(".clearance") and joint_of(path)]
    return list(dict.fromkeys(names))


def safe_name(text: str) -> str:
    """A stable, filesystem-safe file stem; long ones keep a hash of the full text."""
    name = _UNSAFE.sub("_", text).strip("_.") or "case"
    if len(name) > MAX_NAME:
        digest = hashlib.sha1(text.encode()).hexdigest()[:8]
        name = f"{name[:MAX_NAME - 9]}-{digest}"
    return name


def _stem(pairs) -> str:
    return safe_name("__".join(f"{label}-{value}" for label, value in pairs))


def grid_cases(axes: list[Axis], fixed: list[str], zeroed: list[str], with_ideal: bool = True) -> list[Case]:
    """The ideal references, then the product of the axes in the order given."""
    ideal_axes = [axis for axis in axes if axis.affects_ideal]
    zero = tuple(f"joints.{j}.clearance=0" for j in zeroed)
    ideals = {}
    for group in itertools.product(*[range(len(axis.values)) for axis in ideal_axes]):
        pairs = [(axis.label, axis.values[k]) for axis, k in zip(ideal_axes, group)]
        extra = tuple(o for axis, k in zip(ideal_axes, group) for o in axis.overrides[k])
        name = IDEAL + ("__" + _stem(pairs) if pairs else "")
        ideals[tuple(v for _, v in pairs)] = Case(name, dict(pairs), (*fixed, *zero, *extra), True, None,
                                                  tuple(v for _, v in pairs))
    cases = list(ideals.values()) if with_ideal else []
    for choice in itertools.product(*[range(len(axis.values)) for axis in axes]):
        pairs = [(axis.label, axis.values[k]) for axis, k in zip(axes, choice)]
        group = tuple(axis.values[k] for axis, k in zip(axes, choice) if axis.affects_ideal)
        overrides = tuple(o for axis, k in zip(axes, choice) for o in axis.overrides[k])
        reference = ideals[group].name if with_ideal else None
        cases.append(Case(_stem(pairs), dict(pairs), (*fixed, *overrides), False, reference, group))
    return cases
