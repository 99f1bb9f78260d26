"""A revolute joint's clearance description → the numbers of its contact model (SI floats).

A joint is a clearance joint when its radial clearance is positive: `clearance:`
written and > 0, or left out with `journal_radius:` given (the clearance is then
R_B − R_J). Any two of clearance / bearing radius / journal radius give the third;
the bearing radius falls back to `defaults.bearing_radius`.

Contact and friction merge field by field: built-in defaults, then the file's
`defaults:`, then the joint. A layer that changes the friction `law` starts that
law afresh: it does not inherit parameters of another law from the layers below.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearsim.model.schema import (
    DEFAULT_CONTACT, DEFAULT_LUBRICATION, FRICTION_OPTIONS, FRICTION_PARAMETERS, ContactSpec, Defaults, FrictionSpec,
    LubricationSpec,
)
from clearsim.physics import wear
from clearsim.units import UnitError, contact_stiffness_to_si

BUILTIN_FRICTION = FrictionSpec(law="none")
AUTO_STIFFNESS_EXPONENT = 1.5  # the Hertz-type generalised stiffness is K in N/m^1.5


class ResolveError(ValueError):
    """A clearance joint that cannot be turned into numbers.

    `path_suffix` is relative to the joint, or to `defaults:` when `in_defaults`.
    """

    def __init__(self, path_suffix: tuple, message: str, hint: str | None = None, in_defaults: bool = False):
        super().__init__(message)
        self.path_suffix, self.message, self.hint, self.in_defaults = tuple(path_suffix), message, hint, in_defaults


@dataclass(frozen=True)
class ClearanceParameters:
    bearing_radius: float  # m
    journal_radius: float  # m
    clearance: float  # m, c = R_B − R_J
    law: str
    restitution: float
    exponent: float
    stiffness: float  # N/m^n
    min_impact_speed: float  # m/s
    friction_law: str
    mu_s: float
    mu_d: float
    v_low: float  # m/s: v_s (stiction_step) or v_0 (ambrosio); 0 when unused
    v_high: float  # m/s: v_d (stiction_step) or v_1 (ambrosio); 0 when unused
    stick: str  # "exact" (a constraint while sticking) or "smooth" (the law as written)
    initial_eccentricity: tuple[float, float] = (0.0, 0.0)  # m, journal centre − bearing centre, t = 0
    initial_velocity: tuple[float, float] = (0.0, 0.0)  # m/s, its rate at t = 0
    elastic: str = "point_hertz"  # the elastic law (clearsim.physics.cylindrical); stiffness, exponent are its K, n
    length: float = 0.0  # m, the pin's axial length L (0: not given)
    viscosity: float = 0.0  # Pa·s, oil film; 0: a dry joint
    film_length: float = 0.0  # m, pin length wetted by the film
    film_model: str = "short_bearing"
    dry_below: float = 0.0  # m, film thickness below which the dry laws act (0 for a dry joint)
    wear_profile: tuple[float, ...] = ()  # m, the worn bore's Fourier coefficients [a_0, a_1, b_1, ...]; (): circular
    archard: ArchardNumbers | None = None  # Archard wear accumulated during the run; None: none


@dataclass(frozen=True)
class ArchardNumbers:
    """Archard wear of a joint (physics/wear.py), SI."""

    coefficient: float  # k_w, dimensionless
    hardness: float  # Pa
    length: float  # m, axial length of the worn band
    width: float  # m, the kernel's width w = R_B/K(0) (the stated one, or the narrowest the harmonics carry)
    harmonics: int
    sigma: float  # rad, the kernel's σ
    line_stiffness: float = 0.0  # N/m, S = π L E* of the load-following band (physics/wear.py); 0: a stated width


def is_clearance_joint(joint) -> bool:
    if getattr(joint, "type", None) != "revolute":
        return False
    if joint.clearance is not None:
        return joint.clearance > 0.0
    return joint.journal_radius is not None


def resolve_clearance(joint, defaults: Defaults) -> ClearanceParameters | None:
    """The clearance joint's parameters, or None for an ideal joint; ResolveError when inconsistent."""
    if not is_clearance_joint(joint):
        return None
    bearing, journal, clearance = _radii(joint, defaults)
    contact, contact_origin = _merged_contact(joint, defaults)
    friction, friction_origin = _merged_friction(joint, defaults)
    _check_friction(friction, friction_origin)
    stiffness, exponent = _elastic_coefficients(contact, contact_origin, bearing, journal, clearance,
                                                joint.material or defaults.material)
    return ClearanceParameters(
        bearing_radius=bearing, journal_radius=journal, clearance=clearance,
        law=contact["law"], restitution=contact["restitution"], exponent=exponent,
        stiffness=stiffness, min_impact_speed=contact["min_impact_speed"],
        elastic=contact["elastic"], length=contact.get("length", 0.0),
        friction_law=friction["law"], **_friction_numbers(friction),
        initial_eccentricity=_initial_eccentricity(joint, clearance),
        initial_velocity=tuple(map(float, getattr(joint, "initial_velocity", None) or (0.0, 0.0))),
        **_film_numbers(*_merged_lubrication(joint, defaults), clearance, contact.get("length")),
        **_wear_numbers(getattr(joint, "wear", None), bearing, contact.get("length"),
                        bool(_merged_lubrication(joint, defaults)[0].get("viscosity")),
                        joint.material or defaults.material),
    )


def _wear_numbers(spec, bearing_radius: float, pin_length: float | None, lubricated: bool, material) -> dict:
    """The worn profile's coefficients (an all-zero profile is the circular bore) and the Archard numbers."""
    if spec is None:
        return {}
    numbers = {}
    if spec.profile is not None:
        coefficients = spec.profile.coefficients()
        if lubricated and coefficients.any():
            raise ResolveError(("wear", "profile"), "a worn profile is not modelled under an oil film (the film "
                               "laws assume a circular bore)", "remove the joint's lubrication or its wear profile")
        if coefficients.any():
            numbers["wear_profile"] = tuple(float(c) for c in coefficients)
    if spec.archard is not None:
        numbers["archard"] = _archard_numbers(spec.archard, bearing_radius, pin_length, material)
    return numbers


def _archard_numbers(archard, bearing_radius: float, pin_length: float | None, material) -> ArchardNumbers:
    """A stated `width` fixes the kernel; without one the band follows the load (S = π L E*) over the narrowest
    kernel the harmonics carry."""
    from clearsim.physics.cylindrical import effective_modulus

    length = archard.length if archard.length is not None else pin_length
    if length is None:
        raise ResolveError(("wear", "archard", "length"), "Archard wear needs the length L of the worn band",
                           "add `length: 40 mm` to the joint's wear.archard or its contact (the pin's length)")
    narrowest = wear.narrowest_width(archard.harmonics, bearing_radius)
    width = max(archard.width or narrowest, narrowest)
    if width >= 2.0 * math.pi * bearing_radius:
        raise ResolveError(("wear", "archard", "width"), f"the wear width {_mm(width)} is not shorter than the "
                           f"bore's circumference {_mm(2.0 * math.pi * bearing_radius)}",
                           "the width is the contact's, along the bore: a fraction of it, e.g. 2 mm")
    line_stiffness = 0.0 if archard.width else math.pi * length * effective_modulus(
        material.youngs_modulus, material.poisson_ratio, material.youngs_modulus, material.poisson_ratio)
    return ArchardNumbers(archard.coefficient, archard.hardness, length, width, archard.harmonics,
                          wear.kernel_sigma(width, archard.harmonics, bearing_radius), line_stiffness)


# --- geometry -------------------------------------------------------------------------------------


def _radii(joint, defaults: Defaults) -> tuple[float, float, float]:
    """(R_B, R_J, c): any two give the third; the joint's own values come before defaults."""
    bearing, journal, clearance = joint.bearing_radius, joint.journal_radius, joint.clearance
    if clearance is not None and journal is not None and bearing is None:
        bearing = journal + clearance
    bearing = bearing if bearing is not None else defaults.bearing_radius
    where = ("clearance",) if clearance is not None else ("journal_radius",)
    if bearing is None:
        raise ResolveError(where, "a clearance joint needs a bearing radius",
                           "add `bearing_radius: 50 mm` to the joint or to defaults")
    if clearance is None:
        clearance = bearing - journal
        if clearance <= 0.0:
            raise ResolveError(("journal_radius",), f"journal radius {_mm(journal)} must be smaller than "
                               f"the bearing radius {_mm(bearing)}", "the radial clearance is R_B − R_J > 0")
    elif journal is None:
        journal = bearing - clearance
    elif not math.isclose(bearing - journal, clearance, rel_tol=1e-9, abs_tol=1e-12):
        raise ResolveError(("clearance",), f"clearance {_mm(clearance)} differs from bearing radius − journal "
                           f"radius = {_mm(bearing - journal)}", "give only two of the three")
    if clearance >= bearing:
        raise ResolveError(("clearance",), f"clearance {_mm(clearance)} must be smaller than the bearing radius "
                           f"{_mm(bearing)}", "the clearance is radial, R_B − R_J: check its unit (e.g. 0.01 mm)")
    return bearing, journal, clearance


def _mm(length: float) -> str:
    return f"{length * 1e3:.6g} mm"


INITIAL_PRELOAD = 0.1  # a journal may start pressed into the wall (its static load) by up to 10 % of c


def _initial_eccentricity(joint, clearance: float) -> tuple[float, float]:
    if joint.initial_eccentricity is None:
        return (0.0, 0.0)
    x, y = joint.initial_eccentricity
    if math.hypot(x, y) > clearance * (1.0 + INITIAL_PRELOAD):
        raise ResolveError(("initial_eccentricity",), f"initial eccentricity |e| = {_mm(math.hypot(x, y))} "
                           f"lies outside the clearance circle (c = {_mm(clearance)})",
                           f"the journal centre starts within c of the bearing centre (pressed into the wall "
                           f"by at most {INITIAL_PRELOAD:.0%} of c)")
    return (float(x), float(y))


# --- merging joint over defaults ------------------------------------------------------------------


def _layers(joint, defaults: Defaults, key: str, builtin) -> list:
    """(spec, origin) from the bottom up; origin is (in_defaults, path prefix)."""
    layers = [(builtin, None), (getattr(defaults, key), (True, (key,)))]
    if getattr(joint, key) is not None:
        layers.append((getattr(joint, key), (False, (key,))))
    return layers


def _merged_contact(joint, defaults: Defaults) -> tuple[dict, dict]:
    """Contact fields merged field by field; where each one was written (None: built in)."""
    values, origin = {}, {}
    for spec, where in _layers(joint, defaults, "contact", DEFAULT_CONTACT):
        for name in ContactSpec.model_fields:
            if getattr(spec, name) is not None:
                values[name], origin[name] = getattr(spec, name), where
    return values, origin


def _merged_lubrication(joint, defaults: Defaults) -> tuple[dict, dict]:
    """Lubrication fields merged field by field over the built-in film defaults; {} when no layer has a film."""
    layers = [(spec, where) for spec, where in _layers(joint, defaults, "lubrication", DEFAULT_LUBRICATION)
              if spec is not None]
    if len(layers) == 1:
        return {}, {}
    values, origin = {}, {}
    for spec, where in layers:
        for name in LubricationSpec.model_fields:
            if getattr(spec, name) is not None:
                values[name], origin[name] = getattr(spec, name), where
    return values, origin


def _merged_friction(joint, defaults: Defaults) -> tuple[dict, dict]:
    """Friction fields merged; a layer that names another law drops the parameters below it."""
    values, origin = {}, {}
    for spec, where in _layers(joint, defaults, "friction", BUILTIN_FRICTION):
        if spec.law is not None and spec.law != values.get("law"):
            values, origin = {}, {}
        for name in FrictionSpec.model_fields:
            if getattr(spec, name) is not None:
                values[name], origin[name] = getattr(spec, name), where
    return values, origin


def _error_at(origin: dict, name: str, message: str, hint: str | None, block: str = "friction") -> ResolveError:
    """The error located where `name` was written, else at the `law:` it belongs to, else at the block."""
    for key in (name, "law"):
        where = origin.get(key)
        if where is not None:
            in_defaults, prefix = where
            return ResolveError(prefix + (key,), message, hint, in_defaults=in_defaults)
    return ResolveError((block,), message, hint)


# --- friction -------------------------------------------------------------------------------------


def _check_friction(friction: dict, origin: dict) -> None:
    law = friction["law"]
    needed = FRICTION_PARAMETERS[law]
    missing = [name for name in needed if name not in friction]
    if missing:
        example = " and ".join(f"`{name}: ...`" for name in missing)
        raise _error_at(origin, "law", f"friction law '{law}' needs {', '.join(missing)}",
                        f"add {example} to the joint's friction or to defaults.friction")
    for name in friction:
        if name != "law" and name not in needed and name not in FRICTION_OPTIONS.get(law, {}):
            users = [other for other in FRICTION_PARAMETERS
                     if name in FRICTION_PARAMETERS[other] or name in FRICTION_OPTIONS.get(other, {})]
            raise _error_at(origin, name, f"friction law '{law}' does not use {name}",
                            f"remove it, or choose a law that does: {', '.join(users)}")
    _check_friction_order(friction, origin)


def guide_friction_numbers(spec: FrictionSpec) -> dict:
    """law, mu_s, mu_d, v_low, v_high of a guide friction (its own block, no layers); ResolveError (relative to the
    block) when a parameter is missing or unused, or when the law would stick exactly."""
    friction = {name: getattr(spec, name) for name in FrictionSpec.model_fields if getattr(spec, name) is not None}
    if "law" not in friction:
        raise ResolveError((), "a guide friction needs its friction `law`", "e.g. {law: ambrosio, mu_d: 0.15, "
                           "v_0: 0, v_1: 1 mm/s} or {law: coulomb, mu_d: 0.15, stick: smooth}")
    origin = {name: (False, ()) for name in friction}
    _check_friction(friction, origin)
    numbers = _friction_numbers(friction)
    if numbers["stick"] == "exact":
        raise _error_at(origin, "stick", f"a guide friction integrates its law as written: friction law "
                        f"'{friction['law']}' with exact sticking is not available on a guide",
                        "write `stick: smooth` (or use the ambrosio law)")
    return {"law": friction["law"]} | {key: numbers[key] for key in ("mu_s", "mu_d", "v_low", "v_high")}


def _on_joint(origin: dict, name: str) -> bool:
    where = origin.get(name)
    return where is not None and not where[0]


def _written_last(origin: dict, first: str, second: str) -> str:
    """Of two parameters checked against each other, the one on the joint when only that one is."""
    return second if _on_joint(origin, second) and not _on_joint(origin, first) else first


def _check_friction_order(friction: dict, origin: dict) -> None:
    law = friction["law"]
    if law == "stiction_step" and friction["v_s"] >= friction["v_d"]:
        raise _error_at(origin, _written_last(origin, "v_s", "v_d"), f"v_s = {friction['v_s']:g} m/s must be "
                        f"smaller than v_d = {friction['v_d']:g} m/s",
                        "stiction holds below v_s; full sliding friction is reached at v_d")
    if law == "stiction_step" and friction["mu_s"] < friction["mu_d"]:
        raise _error_at(origin, _written_last(origin, "mu_s", "mu_d"), f"mu_s = {friction['mu_s']:g} must be at "
                        f"least mu_d = {friction['mu_d']:g}", "static friction is not lower than dynamic friction")
    if law == "ambrosio" and friction["v_0"] >= friction["v_1"]:
        raise _error_at(origin, _written_last(origin, "v_0", "v_1"), f"v_0 = {friction['v_0']:g} m/s must be "
                        f"smaller than v_1 = {friction['v_1']:g} m/s", "friction ramps up from zero at v_0 to full at v_1")


def _friction_numbers(friction: dict) -> dict:
    law = friction["law"]
    speeds = {"stiction_step": ("v_s", "v_d"), "ambrosio": ("v_0", "v_1")}.get(law)
    low, high = (friction[speeds[0]], friction[speeds[1]]) if speeds else (0.0, 0.0)
    stick = friction.get("stick", FRICTION_OPTIONS.get(law, {}).get("stick", "smooth"))
    return {"mu_s": friction.get("mu_s", 0.0), "mu_d": friction.get("mu_d", 0.0), "v_low": low, "v_high": high,
            "stick": stick}


# --- lubrication ----------------------------------------------------------------------------------


def _film_numbers(lubrication: dict, origin: dict, clearance: float, pin_length: float | None) -> dict:
    """The film's numbers; checks that a lubricated joint has a length (its own, else the pin's `contact.length`)
    and a dry threshold inside c."""
    if not lubrication.get("viscosity"):
        return {}
    length = lubrication.get("length", pin_length)
    if length is None:
        raise _error_at(origin, "viscosity", "a lubricated joint needs the pin's length L (the film's width)",
                        "add `length: 50 mm` to the joint's contact (the pin) or to its lubrication", "lubrication")
    if lubrication["dry_below"] >= clearance:
        raise _error_at(origin, "dry_below", f"the film threshold dry_below = {_mm(lubrication['dry_below'])} must "
                        f"be smaller than the clearance {_mm(clearance)}", "the film acts while c − |e| > dry_below: "
                        "a fraction of c, e.g. three times the composite roughness", "lubrication")
    return {"viscosity": lubrication["viscosity"], "film_length": length,
            "film_model": lubrication["model"], "dry_below": lubrication["dry_below"]}


# --- contact stiffness ----------------------------------------------------------------------------


def _elastic_coefficients(contact: dict, origin: dict, bearing: float, journal: float, clearance: float,
                          material) -> tuple[float, float]:
    """(K, n) the elastic law reads (clearsim.physics.cylindrical): the file's stiffness and exponent for
    point_hertz; for a cylindrical law, from the pin's length, the clearance and the material."""
    from clearsim.physics.cylindrical import effective_modulus, pereira_coefficients

    elastic = contact["elastic"]
    if elastic == "point_hertz":
        return _stiffness(contact, origin, bearing, journal, material), contact["exponent"]
    if "length" not in contact:
        raise _error_at(origin, "elastic", f"the elastic law '{elastic}' needs the pin's axial length",
                        "add `length: 50 mm` to the joint's contact or to defaults.contact", "contact")
    # a point-law K or n written in a layer below the one that chose this law belongs to the point law there
    written = {"stiffness": not _is_auto(contact["stiffness"]),
               "exponent": not math.isclose(contact["exponent"], AUTO_STIFFNESS_EXPONENT)}
    for name in written:
        if written[name] and _layer(origin.get(name)) >= _layer(origin.get("elastic")):
            raise _error_at(origin, name, f"`{name}` belongs to the point_hertz law; the '{elastic}' law takes its "
                            "stiffness from the length, the clearance and the material",
                            f"remove `{name}` (or write `{name}: {'auto' if name == 'stiffness' else '1.5'}`), or "
                            "choose `elastic: point_hertz`", "contact")
    modulus = effective_modulus(material.youngs_modulus, material.poisson_ratio, material.youngs_modulus,
                                material.poisson_ratio)
    if elastic == "pereira":
        try:
            return pereira_coefficients(clearance, contact["length"], modulus)
        except ValueError as exc:
            raise _error_at(origin, "elastic", str(exc), "choose another elastic law for so small a clearance",
                            "contact") from None
    return math.pi * contact["length"] * modulus, 1.0  # S = π L E*; the exponent is not used


def _stiffness(contact: dict, origin: dict, bearing: float, journal: float, material) -> float:
    value, exponent = contact["stiffness"], contact["exponent"]
    if _is_auto(value):
        if not math.isclose(exponent, AUTO_STIFFNESS_EXPONENT):
            raise _error_at(origin, "exponent", f"`stiffness: auto` is the Hertz value for exponent 1.5, "
                            f"not {exponent:g}", f"give the stiffness in N/m^{exponent:g}", "contact")
        return auto_stiffness(bearing, journal, material)
    try:
        stiffness = contact_stiffness_to_si(value, exponent)
    except UnitError as exc:
        raise _error_at(origin, "stiffness", str(exc), "write `auto` or a value such as 1.205e12 N/m^1.5", "contact") from None
    if stiffness <= 0.0:
        raise _error_at(origin, "stiffness", f"the contact stiffness must be positive, got {value!r}", None, "contact")
    return stiffness


def _layer(where) -> int:
    """0 built in, 1 `defaults:`, 2 the joint (an origin of _merged_contact)."""
    return 0 if where is None else 1 if where[0] else 2


def _is_auto(stiffness) -> bool:
    return isinstance(stiffness, str) and stiffness.strip().lower() == "auto"


def auto_stiffness(bearing: float, journal: float, material) -> float:
    """K of a journal in a bearing of the same material (clearsim.physics.contact, docs/model-contact.md)."""
    from clearsim.physics.contact import internal_contact_stiffness

    modulus, poisson = material.youngs_modulus, material.poisson_ratio
    return internal_contact_stiffness(bearing, journal, modulus, poisson, modulus, poisson)
