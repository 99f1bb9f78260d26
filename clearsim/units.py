"""Unit strings ("0.01 mm", "5000 rpm", "30 deg") to SI floats, once, at load time.

In a mechanism file a bare number on a dimensional key means what the file's `units:` block declares
(UnitSystem); a file that declares none must write every non-zero dimensional value with its unit. The
validation context {"units": UnitSystem | None} carries that choice into the schema's quantity types;
without a context (Python code building a Mechanism) a bare number is SI (metre, kilogram, second,
radian, newton). Angles are dimensionless in SI, so "5000 rpm" converts to rad/s.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any

from pydantic import BeforeValidator, ValidationInfo, WithJsonSchema

from clearsim import cache_home


class UnitError(ValueError):
    """A value whose unit is unknown or of the wrong kind."""


@lru_cache(maxsize=1)
def registry():
    """The shared pint registry, created on first use from pint's definitions as parsed by an earlier process."""
    return new_registry(_pint_cache_folder())


def _pint_cache_folder() -> Path:
    return cache_home() / "pint"


def new_registry(cache_folder: Path | None):
    """A pint registry; parsing pint's unit definitions takes 0.15 s per process (every run, sweep worker and test
    subprocess), loading them as pint cached them in cache_folder 0.02 s. A folder that cannot be written or a damaged
    cache only costs that time again."""
    pint = _import_pint()
    if cache_folder is not None:
        try:
            return pint.UnitRegistry(cache_folder=cache_folder)
        except Exception:  # noqa: BLE001 — any failure of the cache: parse the definitions as without one
            pass
    return pint.UnitRegistry()


def _import_pint():
    """pint, imported without dask: pint imports dask, when installed, for dask arrays of quantities, which
    clearsim never makes (6.5 MB and 80 ms per process). dask itself stays importable afterwards."""
    import sys

    if "pint" in sys.modules or "dask" in sys.modules:
        import pint

        return pint
    sys.modules["dask"] = None  # makes `import dask` fail inside pint, which then goes without it
    try:
        import pint
    finally:
        del sys.modules["dask"]
    return pint


@dataclass(frozen=True)
class Dimension:
    """A physical kind, named for messages, with its SI unit and pint dimensionality."""

    name: str
    si_unit: str
    exponents: tuple[tuple[str, float], ...]
    example: str


def _dims(**exponents: float) -> tuple[tuple[str, float], ...]:
    return tuple(sorted((f"[{k}]", float(v)) for k, v in exponents.items() if v))


DIMENSIONS = {
    "length": Dimension("length", "m", _dims(length=1), "0.01 mm"),
    "mass": Dimension("mass", "kg", _dims(mass=1), "3.67 kg"),
    "inertia": Dimension("moment of inertia", "kg*m^2", _dims(mass=1, length=2), "0.044 kg*m^2"),
    "time": Dimension("time", "s", _dims(time=1), "85 ms"),
    "frequency": Dimension("frequency", "Hz", _dims(time=-1), "100 kHz"),
    "speed": Dimension("speed", "m/s", _dims(length=1, time=-1), "1e-4 m/s"),
    "acceleration": Dimension("acceleration", "m/s^2", _dims(length=1, time=-2), "-9.81 m/s^2"),
    "angle": Dimension("angle", "rad", (), "30 deg"),
    "angular_speed": Dimension("angular speed", "rad/s", _dims(time=-1), "5000 rpm"),
    "force": Dimension("force", "N", _dims(mass=1, length=1, time=-2), "100 N"),
    "torque": Dimension("torque", "N*m", _dims(mass=1, length=2, time=-2), "20 N*m"),
    "area": Dimension("area", "m^2", _dims(length=2), "3.1e-3 m^2"),
    "volume": Dimension("volume", "m^3", _dims(length=3), "0.5 L"),
    "density": Dimension("density", "kg/m^3", _dims(mass=1, length=-3), "850 kg/m^3"),
    "pressure": Dimension("pressure (modulus)", "Pa", _dims(mass=1, length=-1, time=-2), "207 GPa"),
    "spring_stiffness": Dimension("spring stiffness", "N/m", _dims(mass=1, time=-2), "1e5 N/m"),
    "damping": Dimension("damping coefficient", "N*s/m", _dims(mass=1, time=-1), "50 N*s/m"),
    "viscosity": Dimension("dynamic viscosity", "Pa*s", _dims(mass=1, length=-1, time=-1), "0.1 Pa*s"),
    "second_moment": Dimension("second moment of area", "m^4", _dims(length=4), "8.3e-9 m^4"),
    "rotational_stiffness": Dimension("rotational stiffness", "N*m/rad", _dims(mass=1, length=2, time=-2), "1400 N*m/rad"),
    "rotational_damping": Dimension("rotational damping", "N*m*s/rad", _dims(mass=1, length=2, time=-1), "0.5 N*m*s/rad"),
    "dimensionless": Dimension("dimensionless number", "1", (), "0.2"),
}


BASE_UNITS = {"length": "m", "mass": "kg", "time": "s", "angle": "rad", "force": "N"}  # a `units:` block's base kinds
DERIVED_UNITS = {  # the other kinds, built from the base ones unless the block names them too
    "speed": "{length}/{time}",
    "acceleration": "{length}/{time}^2",
    "angular_speed": "{angle}/{time}",
    "frequency": "1/{time}",
    "inertia": "{mass}*{length}^2",
    "torque": "{force}*{length}",
    "area": "{length}^2",
    "volume": "{length}^3",
    "density": "{mass}/{length}^3",
    "pressure": "{force}/{length}^2",
    "spring_stiffness": "{force}/{length}",
    "damping": "{force}*{time}/{length}",
    "viscosity": "{force}*{time}/{length}^2",
    "second_moment": "{length}^4",
    "rotational_stiffness": "{force}*{length}/{angle}",
    "rotational_damping": "{force}*{length}*{time}/{angle}",
}
CONTACT_STIFFNESS_UNIT = "{force}/{length}^{exponent:g}"  # K of F = K δⁿ


def _dimensionality(quantity) -> tuple[tuple[str, float], ...]:
    return tuple(sorted((k, float(v)) for k, v in dict(quantity.dimensionality).items() if v))


def parse_quantity(value: Any):
    """A pint quantity from a number or a "value unit" string; UnitError names what is wrong (a unit with no
    number, 'kg', is not 1 kg)."""
    if isinstance(value, bool):
        raise UnitError(f"expected a number with a unit, got {value!r}")
    if isinstance(value, (int, float)):
        return registry().Quantity(_check_finite(value, value))
    if not isinstance(value, str):
        raise UnitError(f"expected a number or a 'value unit' string, got {value!r}")
    return _quantity_of_text(value)


@lru_cache(maxsize=4096)
def _quantity_of_text(value: str):
    """parse_quantity of a text, kept: a mechanism names the same few dozen quantities in every load (a sweep loads it
    once per case, where pint's parsing took 60 % of the time); a quantity of a float magnitude is not changed in
    place, so one object serves every caller. A text that fails is parsed again (and fails again) each time."""
    pint = _import_pint()
    _number_first(value)
    _one_number(value)
    try:
        quantity = registry().Quantity(value.strip())
    except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError) as exc:
        raise UnitError(f"unknown unit in {value!r} ({exc})") from None
    except Exception:
        raise UnitError(f"cannot read {value!r} as 'value unit' (e.g. '0.01 mm')") from None
    if not hasattr(quantity, "magnitude") or not isinstance(quantity.magnitude, (int, float)):
        raise UnitError(f"cannot read {value!r} as a number with a unit")
    _check_finite(quantity.magnitude, value)
    return quantity


LEADING_NUMBER = re.compile(r"\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
NOT_FINITE = re.compile(r"\s*[-+]?(?:nan|inf)", re.IGNORECASE)  # left to the finiteness check


def _number_first(value: str) -> None:
    """A unit alone is no value: pint reads 'kg' as 1 kg, which no one writing it means."""
    unit = value.strip()
    if not unit:
        raise UnitError("expected a number with a unit, got an empty text")
    if LEADING_NUMBER.match(value) or NOT_FINITE.match(value):
        return
    try:
        registry().parse_units(unit)
    except Exception:  # noqa: BLE001 — not a unit alone: pint's own reading and message follow
        return
    raise UnitError(f"expected a number with a unit, got {value!r}: a unit alone is no value; write the number "
                    f"before it, e.g. '1 {unit}'")


def _one_number(value: str) -> None:
    """One number and a unit: pint multiplies whatever it is given ('0.8 0.9' is 0.72, '0.01;0.02' 0.0002,
    '0.01 mm 2' 0.02 mm), which no one writing a value means. A unit alone ('rpm'), nan and inf are left to pint and
    to the finiteness check."""
    lead = LEADING_NUMBER.match(value)
    if lead is None:
        return
    unit = value[lead.end():].strip()
    if not unit:
        return
    try:
        registry().parse_units(unit)
    except Exception:  # noqa: BLE001 — a number in the unit part (a factor) or no unit at all
        if re.search(r"\d", unit):  # a unit without digits that pint does not know: its own message below
            word = re.match(r"[^\W\d_]\w*", unit)
            example = f"{value[:lead.end()].strip()} {word.group(0)}" if word else value[:lead.end()].strip()
            raise UnitError(f"expected one number with a unit, got {value!r}; write one value, e.g. '{example}'") from None


def _check_finite(number: float | int, value: Any) -> float:
    """The number as a float, unless it is NaN or infinite (written as nan or inf, or beyond ±1.8e308)."""
    try:
        number = float(number)
    except OverflowError:  # an integer too large for a float
        number = math.inf
    if not math.isfinite(number):
        shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
        raise UnitError(f"expected a finite number, got {shown}")
    return number


def _has_unit(quantity) -> bool:
    return str(quantity.units) != "dimensionless"


def to_si(value: Any, kind: str) -> float:
    """The SI magnitude of `value`, which must be of physical kind `kind` (a key of DIMENSIONS)."""
    if isinstance(value, str):  # a file's unit strings come back with every load of it (sweeps, diagnose)
        return _string_to_si(value, kind)
    return _to_si(value, kind)


@lru_cache(maxsize=4096)
def _string_to_si(value: str, kind: str) -> float:
    return _to_si(value, kind)


def _to_si(value: Any, kind: str) -> float:
    dimension = DIMENSIONS[kind]
    quantity = parse_quantity(value)
    if not _dimensionality(quantity) and not _has_unit(quantity):
        return float(quantity.magnitude)  # a bare number is SI
    if _dimensionality(quantity) != dimension.exponents:
        found = f"{quantity.units:~}" or "no unit"
        raise UnitError(
            f"expected a {dimension.name} (e.g. '{dimension.example}'), got {value!r} [{found}]"
        )
    return _check_finite(quantity.to_base_units().magnitude, value)


def contact_stiffness_to_si(value: Any, exponent: float) -> float:
    """SI magnitude of a contact stiffness K of F = K δⁿ, in N/m^n (dimension checked against n)."""
    quantity = parse_quantity(value)
    expected = _dims(mass=1, length=1 - exponent, time=-2)
    if _has_unit(quantity) and _dimensionality(quantity) != expected:
        raise UnitError(
            f"expected a contact stiffness in N/m^{exponent:g} for exponent n = {exponent:g}, got {value!r}"
        )
    return _check_finite(quantity.to_base_units().magnitude, value)


def unit_name(value: str) -> str:
    """A unit written alone, as a table's `time_unit` (pint's unit syntax, no number: '2 s' would scale the column)."""
    try:
        registry().parse_units(value)
    except Exception:  # pint raises ValueError for a factor, UndefinedUnitError and syntax errors otherwise
        if any(character.isdigit() for character in value.replace("^", "").replace("**", "")):
            raise ValueError(f"expected a unit alone, such as 'ms', got {value!r}: a number in it would scale "
                             "the column") from None
        raise ValueError(f"unknown unit {value!r}; e.g. 's', 'ms', 'mm', 'kN'") from None
    return value


# --- what bare numbers mean: a file's `units:` block -----------------------------------------------


@dataclass(frozen=True)
class UnitSystem:
    """The unit of every kind that a bare number of a mechanism file is read in; SI for kinds not declared."""

    units: tuple[tuple[str, str], ...]  # (kind, unit) for every kind of BASE_UNITS and DERIVED_UNITS

    def unit(self, kind: str) -> str:
        return dict(self.units)[kind]

    def to_si(self, number: float, kind: str) -> float:
        return _check_finite(number * _si_factor(self.unit(kind), kind), number)

    def contact_stiffness_unit(self, exponent: float) -> str:
        return CONTACT_STIFFNESS_UNIT.format(force=self.unit("force"), length=self.unit("length"), exponent=exponent)


def unit_system(declared: dict[str, str]) -> UnitSystem:
    """The units of a `units:` block (kind → unit, already checked by declared_unit); kinds left out are SI for
    the base kinds and built from the base units for the derived ones."""
    base = {kind: declared.get(kind, si) for kind, si in BASE_UNITS.items()}
    derived = {kind: declared.get(kind, _grouped(formula, base)) for kind, formula in DERIVED_UNITS.items()}
    return UnitSystem(tuple({**base, **derived}.items()))


def _grouped(formula: str, base: dict[str, str]) -> str:
    return formula.format(**{kind: f"({unit})" if re.search(r"[*/^ ]", unit) else unit for kind, unit in base.items()})


SI = unit_system({})


@lru_cache(maxsize=256)
def _si_factor(unit: str, kind: str) -> float:
    return to_si(f"1 {unit}", kind)


def declared_unit(unit: Any, kind: str) -> str:
    """A unit of a `units:` block, checked to be a unit alone of `kind`; ValueError names what is wrong."""
    try:
        if not isinstance(unit, str) or not unit.strip():
            raise ValueError(unit)
        unit_name(unit)
    except ValueError:
        raise ValueError(f"expected a unit alone, such as '{_example_unit(kind)}', got {unit!r}") from None
    try:
        to_si(f"1 {unit}", kind)
    except UnitError:
        raise ValueError(f"'{unit}' is not a unit of {DIMENSIONS[kind].name} (e.g. '{_example_unit(kind)}', "
                         f"SI '{DIMENSIONS[kind].si_unit}')") from None
    return unit


def _example_unit(kind: str) -> str:
    return DIMENSIONS[kind].example.split(" ", 1)[1]


UNITS_CONTEXT = "units"  # the validation context's key: a UnitSystem, or None for a file that declares none


def bare_to_si(number: float, kind: str, context: dict | None) -> float:
    """A bare number of kind `kind`: in the declared units; SI without a context (Python code); an error in a
    file that declares none, unless it is 0 (0 is 0 in every unit)."""
    if context is None or UNITS_CONTEXT not in context:
        return to_si(number, kind)
    system = context[UNITS_CONTEXT]
    if system is not None:
        return system.to_si(_check_finite(number, number), kind)
    if _check_finite(number, number) == 0.0:
        return 0.0
    raise UnitError(bare_number_message(number, kind))


def declares_no_units(context: dict | None) -> bool:
    """True while validating a file that has no `units:` block (no context: Python code, SI)."""
    return context is not None and UNITS_CONTEXT in context and context[UNITS_CONTEXT] is None


def declared_system(context: dict | None) -> UnitSystem | None:
    """The declared units of the file being validated, None when it declares none or for Python code."""
    return context.get(UNITS_CONTEXT) if context is not None else None


def bare_number_message(number: float, kind: str, examples: tuple[str, ...] = (), block: str | None = None) -> str:
    """The error of a bare number of kind `kind` in a file without `units:`: write the unit (one of `examples`,
    default the kind's usual and SI units), or declare the file's units (`block`, default {kind: unit})."""
    examples = examples or tuple(dict.fromkeys((_example_unit(kind), DIMENSIONS[kind].si_unit)))
    written = [f"'{number:g} {unit}'" for unit in examples]
    shown = " or ".join([", ".join(written[:-1]), written[-1]] if len(written) > 2 else written)
    block = block or f"{{{kind}: {examples[0]}}}"
    return (f"the bare number {number:g} has no unit and this file declares none: write {shown}, or declare what "
            f"the file's bare numbers mean, e.g. `units: {block}` or `units: SI` at its top")


def si_text(value: float, kind: str) -> str:
    """An SI value as text with its SI unit ('1e-05 m'): what code writes into a mechanism document, read the same
    whatever the file's `units:` declare."""
    return f"{float(value)!r} {DIMENSIONS[kind].si_unit}"


def bare_number(value: Any) -> float | None:
    """The number a value is when it has no unit: 10, or text such as '1e-2' (YAML 1.1 reads a number with an
    exponent and no dot as text), '10' or '(0.005)'; None for a value with a unit, a word or a boolean."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return value
    if not isinstance(value, str) or re.search(r"[^\W\deE_]", value):  # a letter: a unit, or a word such as auto
        return None
    if LEADING_NUMBER.fullmatch(value.strip()):
        return float(value)
    try:
        quantity = parse_quantity(value)
    except UnitError:
        return None
    return None if _has_unit(quantity) else float(quantity.magnitude)


def _si_validator(kind: str):
    def convert(value: Any, info: ValidationInfo) -> float:
        number = bare_number(value) if kind != "dimensionless" else None
        try:
            if number is not None:
                return bare_to_si(number, kind, info.context)
            return to_si(value, kind)
        except UnitError as exc:
            raise ValueError(str(exc)) from None

    return convert


def _quantity_type(kind: str):
    dimension = DIMENSIONS[kind]
    return Annotated[
        float,
        BeforeValidator(_si_validator(kind)),
        WithJsonSchema(
            {
                "anyOf": [{"type": "number"}, {"type": "string"}],
                "description": f"{dimension.name}: a string with a unit, e.g. '{dimension.example}', or a number in "
                               f"the file's `units:` ({dimension.si_unit} for `units: SI`)",
                "examples": [dimension.example],  # kept when a field's own description replaces the text above
                "x-unit": dimension.si_unit,
            }
        ),
    ]


Length = _quantity_type("length")
Mass = _quantity_type("mass")
Inertia = _quantity_type("inertia")
Time = _quantity_type("time")
Frequency = _quantity_type("frequency")
Speed = _quantity_type("speed")
Acceleration = _quantity_type("acceleration")
Angle = _quantity_type("angle")
AngularSpeed = _quantity_type("angular_speed")
Force = _quantity_type("force")
Torque = _quantity_type("torque")
Area = _quantity_type("area")
Pressure = _quantity_type("pressure")
Volume = _quantity_type("volume")
Density = _quantity_type("density")
SpringStiffness = _quantity_type("spring_stiffness")
Damping = _quantity_type("damping")
Viscosity = _quantity_type("viscosity")
SecondMoment = _quantity_type("second_moment")
RotationalStiffness = _quantity_type("rotational_stiffness")
RotationalDamping = _quantity_type("rotational_damping")
Number = _quantity_type("dimensionless")
