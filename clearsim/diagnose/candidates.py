"""Candidate effects: named, bounded, one-parameter changes of a mechanism document.

A candidate knows its kind ("clearance", "friction", ...), its target (a joint, body or driver
name, or None), its parameter with physical bounds, and how to write a value into a YAML
document (a dict, edited in place). To add a kind, write one function `kind(mechanism, document)
-> list[Candidate]` and register it in KINDS.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path
from typing import Callable

import numpy as np

from clearsim.model.flexible import initial_tensions, link_split, point_text, set_spring, split_link, two_joint_links
from clearsim.model.loader import dump_yaml, load_mechanism_text
from clearsim.model.overrides import apply_overrides
from clearsim.model.resolve import is_clearance_joint, resolve_clearance
from clearsim.model.schema import Mechanism, StrokeMotion
from clearsim.physics.wear import (
    add_kernel_rates, evaluate_profile, kernel_sigma, kernel_weights, profile_block, summed_coefficients,
    tightest_radius,
)
from clearsim.units import DIMENSIONS, si_text, to_si

FAR_ANCHOR = 1000.0  # m: a damper anchored this far along its line acts in a fixed direction


@dataclass(frozen=True)
class Candidate:
    kind: str
    target: str | None
    parameter: str  # name of the fitted quantity, e.g. "clearance"
    unit: str  # SI unit of the parameter ("" for a factor)
    low: float
    high: float
    logarithmic: bool
    current: float | None  # the parameter's value in the model as given (None: the effect is absent)
    write: Callable[[dict, float], None]  # puts a value into a document
    display_unit: tuple[str, float] = ("", 1.0)  # unit shown to engineers and the SI value of one of it
    resonant: bool = False  # the parameter is a stiffness setting a resonance, frequency ∝ √value (search.resonance_seeds)
    rough: bool = False  # its cost is a comb of narrow minima: fitted on the smoothed profile (search.rough_rounds)
    pin_radius: float | None = None  # friction of an ideal pin: the journal radius its torque μ F R_J uses (m)
    angle: float | None = None  # a worn arc's angular position φ in the bearing body's frame (rad): one candidate each
    parameters: int = 1  # quantities fitted, for the BIC's penalty: a worn arc's angle, chosen among candidates, is one

    @property
    def key(self) -> tuple[str, str | None, str]:
        return self.kind, self.target, self.parameter + (f" {self.around}" if self.angle is not None else "")

    @property
    def quantity(self) -> tuple[str, str | None, str]:
        """What the candidate changes, wherever it sits: the worn arcs of one joint at every angle are one quantity (a
        depth at an angle), of which the search fits one member at a time (search.to_fit, search.candidate_pairs)."""
        return self.kind, self.target, self.parameter

    @property
    def around(self) -> str:
        return f"around {math.degrees(self.angle) % 360.0:.0f}°"

    @property
    def label(self) -> str:
        where = f" in joint {self.target}" if self.kind in JOINT_KINDS else (f" of {self.target}" if self.target else "")
        pin = f" (pin, R = {self.pin_radius * 1e3:.3g} mm)" if self.pin_radius is not None else ""
        around = f" {self.around}" if self.angle is not None else ""
        return (f"{KIND_TITLES.get(self.kind, self.kind)}{where}{pin}{around}"
                + (f" ({self.parameter})" if self.kind in PARAMETER_NAMED else ""))

    def finding(self, value: float) -> str:
        """The effect at a value in words: 'clearance in joint B, clearance = 0.08 mm', 'joint B worn 0.05 mm around
        120°'."""
        if self.kind == "wear":
            return f"joint {self.target} worn {self.shown(value)} {self.around}"
        return f"{self.label}, {self.parameter} = {self.shown(value)}"

    def applied(self, document: dict, value: float) -> dict:
        """A copy of the document with the parameter set to `value`."""
        return with_effects(document, [self], [value])

    def grid(self, points: int) -> np.ndarray:
        """`points` values spread over the bounds (log-spaced for scale parameters), ends excluded."""
        inner = np.linspace(0.0, 1.0, points + 2)[1:-1]
        return self.from_unit(inner)

    def from_unit(self, u) -> np.ndarray:
        u = np.asarray(u, dtype=float)
        if self.logarithmic:
            return np.exp(np.log(self.low) + u * (np.log(self.high) - np.log(self.low)))
        return self.low + u * (self.high - self.low)

    def to_unit(self, value) -> np.ndarray:
        value = np.asarray(value, dtype=float)
        if self.logarithmic:
            return (np.log(value) - np.log(self.low)) / (np.log(self.high) - np.log(self.low))
        return (value - self.low) / (self.high - self.low)

    def shown(self, value: float) -> str:
        unit, scale = self.display_unit
        return f"{value / scale:.3g}{' ' + unit if unit else ''}"


def with_effects(document: dict, candidates: list[Candidate], values) -> dict:
    """A copy of the document with each candidate's parameter set to its value, in order."""
    changed = copy.deepcopy(document)
    for candidate, value in zip(candidates, values):
        candidate.write(changed, float(value))
    return changed


KIND_TITLES = {"clearance": "clearance", "friction": "friction", "stiffness": "contact stiffness",
               "restitution": "restitution", "drive": "drive", "damping": "viscous damping", "mass": "mass",
               "compliance": "axial compliance", "beam_stiffness": "bending stiffness",
               "contact_length": "pin contact length", "port_area": "port area", "precharge": "accumulator precharge",
               "bulk_modulus": "oil bulk modulus", "preload": "spring preload", "dashpot": "dashpot",
               "gas_load": "gas load", "guide_friction": "guide friction", "wear": "wear", "viscosity": "oil viscosity",
               "load": "constant load"}
JOINT_KINDS = {"clearance", "friction", "stiffness", "restitution", "contact_length", "wear", "viscosity"}
PARAMETER_NAMED = {"drive", "port_area", "dashpot"}  # kinds with several parameters per target: the label names it


def _set(document: dict, path: str, value) -> None:
    """Write a value as `--set path=value` would (a clearance keeps the joint's bearing radius)."""
    text = f"{path}={value!r}" if not isinstance(value, str) else f"{path}={value}"
    _, problems = apply_overrides(document, [text], Mechanism)
    if problems:
        raise ValueError(f"{text}: {problems[0].message}")


def _revolute(mechanism):
    """Revolute joints that may get a clearance: not those a driver moves."""
    driven = {d.joint for d in mechanism.drivers}
    return [j for j in mechanism.joints if j.type == "revolute" and j.name not in driven]


def _clearance_joints(mechanism):
    return [j for j in _revolute(mechanism) if is_clearance_joint(j)]


# --- one function per kind ------------------------------------------------------------------------

CLEARANCE_BOUNDS = (2e-6, 0.5e-3)  # m: 2 µm (a tight fit) to 0.5 mm (a worn pin)
DEFAULT_BEARING_RADIUS = 0.01  # m, given to a new clearance joint when the file knows none


def _radius_missing(mechanism, joint) -> bool:
    """Neither the joint nor `defaults` gives a bearing radius: a new clearance joint gets DEFAULT_BEARING_RADIUS."""
    return mechanism.defaults.bearing_radius is None and joint.bearing_radius is None and joint.journal_radius is None


def clearance(mechanism, document) -> list[Candidate]:
    """Radial clearance c of each revolute joint (an ideal one becomes a clearance joint)."""
    out = []
    for joint in _revolute(mechanism):
        current = resolve_clearance(joint, mechanism.defaults).clearance if is_clearance_joint(joint) else None
        radius_missing = _radius_missing(mechanism, joint)

        def write(doc, value, name=joint.name, add_radius=radius_missing):
            if add_radius:
                _set(doc, f"joints.{name}.bearing_radius", si_text(DEFAULT_BEARING_RADIUS, "length"))
            _set(doc, f"joints.{name}.clearance", si_text(value, "length"))

        out.append(Candidate("clearance", joint.name, "clearance", "m", *CLEARANCE_BOUNDS, True, current, write,
                             ("mm", 1e-3)))
    return out


FRICTION_BOUNDS = (0.0, 0.5)
PIN_CLEARANCE = 5e-6  # m: an ideal pin given friction becomes a journal in its bearing with this tight fit (2 µm: 7× the steps)


def friction(mechanism, document) -> list[Candidate]:
    """Dynamic friction coefficient μ_d of each revolute joint (μ_s keeps its ratio to μ_d). A clearance joint's
    own friction; an ideal pin becomes what it physically is, a journal in a bearing with a tight fit
    (PIN_CLEARANCE) pressed on the wall by the joint's load, whose friction torque is μ_d F_n R_J (the
    friction circle), with the file's default friction law. Rough: friction reaches kinematic sensors through
    the chaotic journal motion, so χ² over μ_d is a comb of narrow minima (slider-crank: teeth ~0.004 wide in
    μ_d) over a smooth basin."""
    out = []
    for joint in _revolute(mechanism):
        pin = not is_clearance_joint(joint)
        radius_missing = pin and _radius_missing(mechanism, joint)
        as_journal = joint.model_copy(update={"clearance": PIN_CLEARANCE, "journal_radius": None,
                                              **({"bearing_radius": DEFAULT_BEARING_RADIUS} if radius_missing else {})})
        p = resolve_clearance(as_journal if pin else joint, mechanism.defaults)
        law = p.friction_law if p.friction_law != "none" else "coulomb"
        ratio = p.mu_s / p.mu_d if p.friction_law == "stiction_step" and p.mu_d > 0 else 1.0
        spec = {"stiction_step": {"v_s": p.v_low, "v_d": p.v_high}, "ambrosio": {"v_0": p.v_low, "v_1": p.v_high}}

        def write(doc, value, name=joint.name, law=law, ratio=ratio, extra=spec.get(law, {}), pin=pin,
                  add_radius=radius_missing):
            if add_radius:
                _set(doc, f"joints.{name}.bearing_radius", si_text(DEFAULT_BEARING_RADIUS, "length"))
            if pin:
                _set(doc, f"joints.{name}.clearance", si_text(PIN_CLEARANCE, "length"))
            numbers = {"mu_d": repr(value), **({"mu_s": repr(value * ratio)} if law == "stiction_step" else {}),
                       **{key: si_text(speed, "speed") for key, speed in extra.items()}}
            body = ", ".join(f"{k}: {v}" for k, v in numbers.items())
            _set(doc, f"joints.{name}.friction", f"{{law: {law}, {body}}}")

        current = None if pin or p.friction_law == "none" else p.mu_d
        out.append(Candidate("friction", joint.name, "mu_d", "", *FRICTION_BOUNDS, False, current, write, rough=True,
                             pin_radius=p.journal_radius if pin else None))
    return out


def _contact_candidates(mechanism, kind: str, key: str, unit: str, bounds, logarithmic: bool,
                        applies: Callable = lambda joint: True) -> list[Candidate]:
    """One candidate per clearance joint (that `applies`) for a key of its `contact:` block; bounds(present) →
    (low, high). A unit ending in ^n is the contact exponent's."""
    out = []
    for joint in filter(applies, _clearance_joints(mechanism)):
        parameters = resolve_clearance(joint, mechanism.defaults)
        present = getattr(parameters, key)
        written_unit = unit.replace("^n", f"^{parameters.exponent:g}")

        def write(doc, value, name=joint.name, written_unit=written_unit):
            _set(doc, f"joints.{name}.contact.{key}", f"{value!r} {written_unit}".strip())

        out.append(Candidate(kind, joint.name, key, unit, *bounds(present), logarithmic, present, write))
    return out


def _cylindrical(mechanism, joint) -> bool:
    """The joint's elastic law is a cylindrical one: its stiffness follows from the pin's length and the materials."""
    return resolve_clearance(joint, mechanism.defaults).elastic != "point_hertz"


def stiffness(mechanism, document) -> list[Candidate]:
    """Contact stiffness K of each clearance joint with the point-Hertz law, from 1/10 to 10 times its present value
    (a cylindrical law has no K to write: its `length` candidate changes its stiffness)."""
    return _contact_candidates(mechanism, "stiffness", "stiffness", "N/m^n", lambda k0: (0.1 * k0, 10.0 * k0), True,
                               lambda joint: not _cylindrical(mechanism, joint))


CONTACT_LENGTH_FACTORS = (0.25, 4.0)  # a pin bearing on a quarter of its length (edge loading, misalignment) to 4×


def contact_length(mechanism, document) -> list[Candidate]:
    """Axial length L of the pin in its bore, for each clearance joint with a cylindrical elastic law (the contact's
    stiffness grows with it), ¼ … 4 times its present value."""
    return _scaled_joint_candidates(
        mechanism, "contact_length", "contact.length", "length", CONTACT_LENGTH_FACTORS, ("mm", 1e-3),
        lambda joint: resolve_clearance(joint, mechanism.defaults).length if _cylindrical(mechanism, joint) else None)


def _scaled_joint_candidates(mechanism, kind: str, path: str, dimension: str, factors: tuple[float, float],
                             display_unit: tuple[str, float], present: Callable) -> list[Candidate]:
    """One candidate per clearance joint whose `present` value (joint → value, or None) is above 0, for the key `path`
    under the joint, in SI units of `dimension`, from factors[0] to factors[1] times its present value (log)."""
    out = []
    for joint in _clearance_joints(mechanism):
        value_now = present(joint)
        if value_now is None or not value_now > 0.0:
            continue

        def write(doc, value, name=joint.name):
            _set(doc, f"joints.{name}.{path}", si_text(value, dimension))

        out.append(Candidate(kind, joint.name, path.rsplit(".", 1)[-1], DIMENSIONS[dimension].si_unit,
                             factors[0] * value_now, factors[1] * value_now, True, value_now, write, display_unit))
    return out


def restitution(mechanism, document) -> list[Candidate]:
    """Coefficient of restitution c_e of each clearance joint, 0.3 … 1."""
    return _contact_candidates(mechanism, "restitution", "restitution", "", lambda c0: (0.3, 1.0), False)


VISCOSITY_FACTORS = (0.1, 10.0)  # a thinner oil (hot, a lighter grade) to a thicker one (cold, aged, a heavier grade)


def viscosity(mechanism, document) -> list[Candidate]:
    """Dynamic viscosity μ of each lubricated clearance joint's oil film (`lubrication.viscosity`, written on the joint:
    it merges over `defaults.lubrication`), 0.1 … 10 times its present value."""
    return _scaled_joint_candidates(mechanism, "viscosity", "lubrication.viscosity", "viscosity", VISCOSITY_FACTORS,
                                    ("mPa·s", 1e-3), lambda joint: resolve_clearance(joint, mechanism.defaults).viscosity)


WEAR_DEPTH_BOUNDS = (2e-6, 0.5e-3)  # m: peak depth d of a worn arc, 2 µm to 0.5 mm
WEAR_ANGLE_STEP = math.radians(30.0)  # positions φ of the worn arc tried: every 30° of the bore
WEAR_ARC = math.radians(60.0)  # the worn arc's width w = R_B · 60° (the Archard kernel's, physics/wear.py)
WEAR_HARMONICS = 16  # harmonics of the worn arc's profile: its kernel's σ = 0.42 rad is above the ringing limit 4/16
WEAR_POCKET_CLEARANCE = 0.1  # the worn arc's tightest curvature radius leaves the journal this share of the clearance
NO_WEAR = np.zeros(1)  # the profile of an unworn bore, [a_0]
UNIFORM_SIGMA = 4.0 * math.pi  # rad: a worn arc's kernel this wide is a uniform depth (its harmonics e^(−m² σ²/2) ≤ 5e-35)


def worn_arc(depth: float, angle: float, radius: float, clearance: float, present: np.ndarray = NO_WEAR) -> np.ndarray:
    """[a_0, a_1, b_1, …] (m) of a worn arc of peak depth d at φ in a bore of radius R_B and radial clearance c:
    h(θ) = d K(θ − φ)/K(0), K the Archard wear kernel of width R_B · WEAR_ARC — the shape Archard wear leaves under a
    contact that stays at φ (its mean a_0 = d w/2π is the uniform clearance the worn volume adds) — or wider, as a
    journal wears it: the pocket it makes with the bore's `present` wear has its tightest radius of curvature at
    least R_J + c/10 (arc_sigma)."""
    return _kernel_arc(depth, angle, arc_sigma(depth, radius, clearance, present, angle))


def arc_sigma(depth: float, radius: float, clearance: float, present: np.ndarray = NO_WEAR, angle: float = 0.0) -> float:
    """σ (rad) of a worn arc's kernel at φ: that of the width R_B · WEAR_ARC, or the narrowest whose sum with the
    bore's `present` wear has its tightest radius of curvature at R_B − (1 − WEAR_POCKET_CLEARANCE) c, when the 60°
    arc makes it tighter than that. A journal cannot wear a pocket tighter than itself, and one tighter than the
    journal touches it at two points, where a journal sticking at the nearer chatters (a 0.0105 mm arc in a
    0.01 mm joint of R_B = 50 mm: radius 49.950 mm against the journal's 49.990 mm; 49.991 mm as widened). A present
    wear too tight for any arc to leave the journal that (`validate` warns of it) leaves the arc at its width."""
    narrow = kernel_sigma(WEAR_ARC * radius, WEAR_HARMONICS, radius)
    loosest = radius - (1.0 - WEAR_POCKET_CLEARANCE) * clearance

    def slack(sigma: float) -> float:
        return tightest_radius(summed_coefficients(present, _kernel_arc(depth, angle, sigma)), radius) - loosest

    if slack(narrow) >= 0.0:
        return narrow
    wide = 2.0 * narrow
    while slack(wide) < 0.0:  # a wide arc tends to a uniform depth d, which loosens every curvature by d
        if wide > UNIFORM_SIGMA:
            return narrow
        wide *= 2.0
    from scipy.optimize import brentq  # here: importing scipy.optimize takes 36 MB, in every sweep worker

    return brentq(slack, narrow, wide, xtol=1e-6)


def _kernel_arc(depth: float, angle: float, sigma: float) -> np.ndarray:
    """[a_0, a_1, b_1, …] of d K(θ − φ)/K(0), K the wear kernel of σ on WEAR_HARMONICS."""
    weights = kernel_weights(sigma, WEAR_HARMONICS)
    peak = (2.0 * weights.sum() - 1.0) / (2.0 * math.pi)
    coefficients = np.zeros(1 + 2 * WEAR_HARMONICS)
    add_kernel_rates(coefficients, weights, WEAR_HARMONICS, depth / peak, angle)
    return coefficients


def _set_profile(document: dict, joint: str, coefficients: np.ndarray) -> None:
    """Write a joint's `wear.profile` as `{cos: [a_0, a_1, …], sin: [b_1, …]}` in metres: the path is made and checked
    as `--set` would (with a one-term placeholder: the series is longer than an override's value may be), then the
    series put in its place."""
    applied, problems = apply_overrides(document, [f"joints.{joint}.wear.profile={{cos: [0 m]}}"], Mechanism)
    if problems:
        raise ValueError(f"joints.{joint}.wear.profile: {problems[0].message}")
    *parents, key = next(iter(applied))
    node = document
    for step in parents:
        node = node[step]
    node[key] = profile_block(coefficients)


def wear(mechanism, document) -> list[Candidate]:
    """A worn arc of each clearance joint's bore (worn_arc), added to its present profile: one candidate per position
    φ = 0°, 30°, … in the bearing body's frame, its parameter the peak depth d (2 µm … 0.5 mm, or less than the
    wall's thickness leaves)."""
    angles = np.arange(0.0, 2.0 * math.pi - 1e-9, WEAR_ANGLE_STEP)
    return [c for joint in _clearance_joints(mechanism) for c in worn_arcs(mechanism, joint, angles)]


def wear_between(mechanism, candidate: Candidate) -> list[Candidate]:
    """The worn arc of a wear candidate's joint halfway to the positions beside it, φ ± 15°: its angle refined."""
    joint = next(j for j in mechanism.joints if j.name == candidate.target)
    return worn_arcs(mechanism, joint, [candidate.angle - WEAR_ANGLE_STEP / 2.0, candidate.angle + WEAR_ANGLE_STEP / 2.0])


def worn_arcs(mechanism, joint, angles) -> list[Candidate]:
    """A worn arc at each angle of a clearance joint's bore (none when its wall leaves no room for one)."""
    parameters = resolve_clearance(joint, mechanism.defaults)
    radius, clearance = parameters.bearing_radius, parameters.clearance
    worn = joint.wear.profile.coefficients() if joint.wear is not None and joint.wear.profile is not None else NO_WEAR
    deepest = float(evaluate_profile(worn, np.linspace(0.0, 2.0 * math.pi, 360, endpoint=False)).max())
    wall = joint.wear.wall if joint.wear is not None else None
    high = min(WEAR_DEPTH_BOUNDS[1], wall - deepest) if wall is not None else WEAR_DEPTH_BOUNDS[1]
    if not high > WEAR_DEPTH_BOUNDS[0]:
        return []
    out = []
    for angle in angles:
        angle = float(angle) % (2.0 * math.pi)

        def write(doc, value, name=joint.name, angle=angle):
            _set_profile(doc, name, summed_coefficients(worn, worn_arc(value, angle, radius, clearance, worn)))

        out.append(Candidate("wear", joint.name, "depth", "m", WEAR_DEPTH_BOUNDS[0], high, True, None, write,
                             ("mm", 1e-3), angle=angle, parameters=2))
    return out


LAG_BOUNDS = (5e-5, 10e-3)  # s
STROKE_FACTOR_BOUNDS = (0.9, 1.1)


def drive(mechanism, document) -> list[Candidate]:
    """Per driver: the actuator's first-order lag τ, and for stroke laws a stroke error (factor)."""
    out = []
    for driver in mechanism.drivers:
        def write_lag(doc, value, name=driver.name):
            _set(doc, f"drivers.{name}.lag", si_text(value, "time"))

        out.append(Candidate("drive", driver.name, "lag", "s", *LAG_BOUNDS, True, driver.lag or None, write_lag,
                             ("ms", 1e-3)))
        if isinstance(driver.motion, StrokeMotion):
            written = driver.motion.stroke

            def write_stroke(doc, value, name=driver.name, written=written):
                kind = "length" if not str(written).strip().endswith(("deg", "rad")) else "angle"
                _set(doc, f"drivers.{name}.motion.stroke", si_text(to_si(written, kind) * value, kind))

            out.append(Candidate("drive", driver.name, "stroke factor", "", *STROKE_FACTOR_BOUNDS, False, 1.0,
                                 write_stroke))
    return out


def damping(mechanism, document) -> list[Candidate]:
    """A viscous damper on the output body along the output direction (gas or oil damping)."""
    sensors = {s.name: s for s in mechanism.sensors}
    output = sensors.get(mechanism.output.velocity or mechanism.output.displacement or "")
    if output is None or not hasattr(output, "direction"):
        return []
    body = next(b for b in mechanism.bodies if b.name == output.body)
    where = np.asarray(body.position, float)
    direction = np.asarray(output.direction, float) / np.linalg.norm(output.direction)
    anchor = where + FAR_ANCHOR * direction
    total_mass = sum(b.mass for b in mechanism.bodies)
    scale = total_mass / mechanism.solver.t_end  # N·s/m: a damper that matters over the run

    def write(doc, value):
        forces = doc.setdefault("forces", []) or []
        doc["forces"] = [f for f in forces if f.get("name") != "diagnose_damping"] + [{
            "type": "spring_damper", "name": "diagnose_damping", "bodies": ["ground", body.name],
            "at": [point_text(anchor), point_text(where)], "damping": si_text(value, "damping")}]

    return [Candidate("damping", body.name, "damping", "N*s/m", 1e-3 * scale, 10.0 * scale, True, None, write,
                      ("N·s/m", 1.0))]


MASS_FACTOR_BOUNDS = (0.5, 2.0)


def mass(mechanism, document) -> list[Candidate]:
    """Mass (and inertia, in proportion) of each body, 0.5 … 2 times as written."""
    out = []
    for body in mechanism.bodies:
        def write(doc, value, name=body.name, m0=body.mass, j0=body.inertia):
            _set(doc, f"bodies.{name}.mass", si_text(m0 * value, "mass"))
            _set(doc, f"bodies.{name}.inertia", si_text(j0 * value, "inertia"))

        out.append(Candidate("mass", body.name, "mass factor", "", *MASS_FACTOR_BOUNDS, True, 1.0, write))
    return out


COMPLIANCE_BOUNDS = (1e6, 1e10)  # N/m: a soft composite pull rod (≈ 1 MN/m) to a short steel link (≈ 10 GN/m)
COMPLIANCE_DAMPING_RATIO = 0.02  # structural damping of the axial mode, 2 % of critical (bolted steel, GFRP: 1–5 %)


def compliance(mechanism, document, base_dir: Path = Path(".")) -> list[Candidate]:
    """Axial stiffness k of each two-joint link: the link split in two halves along the line between
    its joints, joined by a prismatic joint and a spring-damper k, c = 2 ζ √(k m/4) (ζ = 2 %), whose free
    length L − T₀/k makes it carry the rigid link's tension T₀ at t = 0 (no start transient)."""
    out = []
    for body, joints in two_joint_links(mechanism):
        split = link_split(mechanism, body, joints)
        if split is None:
            continue
        split = replace(split, tension=initial_tensions(document, [split], base_dir)[0])

        def write(doc, value, split=split):
            if not any(f.get("name") == split.spring for f in doc.get("forces") or []):
                split_link(doc, split)
            set_spring(doc, split, value, COMPLIANCE_DAMPING_RATIO)

        out.append(Candidate("compliance", body, "stiffness", "N/m", *COMPLIANCE_BOUNDS, True, None, write,
                             ("MN/m", 1e6), resonant=True))
    return out


BEAM_STIFFNESS_BOUNDS = (0.1, 10.0)  # factor on E·I: a cracked or thinner section to a stiffer one


def beam_stiffness(mechanism, document) -> list[Candidate]:
    """Bending stiffness E·I of each beam link (`flexible: {model: beam}`), as a factor on it (written into E, so
    every spring k = E I n / L and its damping scale with it), 0.1 … 10."""
    out = []
    for body in document.get("bodies") or []:
        flexible = body.get("flexible") or {}
        if flexible.get("model") != "beam":
            continue
        modulus = to_si(str(flexible["youngs_modulus"]), "pressure")

        def write(doc, value, name=body["name"], modulus=modulus):
            _set(doc, f"bodies.{name}.flexible.youngs_modulus", si_text(modulus * value, "pressure"))

        out.append(Candidate("beam_stiffness", body["name"], "E·I factor", "", *BEAM_STIFFNESS_BOUNDS, True, 1.0, write,
                             resonant=True))
    return out


def _ground_sliders(mechanism) -> dict[str, tuple[float, float]]:
    """Each body that slides in a prismatic joint on the ground, and that joint's unit axis (the first such joint
    in file order). A slider on a moving guide has none: its axis turns with the guide, which a constant force in the
    global frame does not follow."""
    sliders: dict[str, tuple[float, float]] = {}
    for joint in mechanism.joints:
        if joint.type == "prismatic" and joint.bodies[0] == "ground":
            sliders.setdefault(joint.bodies[1], tuple(float(x) for x in joint.axis))
    return sliders


def load_scales(document: dict, base_dir: Path, axes: dict[str, tuple[float, float]]) -> dict[str, float]:
    """F_max = E_max / s of each slider (N): E_max the largest kinetic energy of the whole mechanism and s the
    slider's travel along its axis (max − min), both in one run of the model as given: a constant load doing the work
    of the mechanism's peak kinetic energy over that travel. A slider that does not travel (s below 1 µm) or a model
    that does not run to its end gets none."""
    return dict(_load_scales(dump_yaml(document), str(base_dir), tuple(sorted(axes.items()))))


@lru_cache(maxsize=8)
def _load_scales(text: str, base_dir: str, axes: tuple) -> tuple:
    from clearsim.errors import SolverError
    from clearsim.runner import prepare
    from clearsim.solver.simulate import simulate

    system = prepare(load_mechanism_text(text, "load scale", (), Path(base_dir)))  # a flexible link's parts as bodies
    try:
        samples = simulate(system).chunk
    except SolverError:
        return ()
    n = system.coordinate_count
    travels = {body: float(np.ptp(samples.states[:, :n][:, _planar(system, body)] @ np.asarray(axis)))
               for body, axis in axes}
    return tuple((body, float(np.max(samples.kinetic)) / travel) for body, travel in travels.items()
                 if travel > MIN_TRAVEL)


def _planar(system, body: str) -> slice:
    """The columns of a body's x and y in q."""
    b = system.body_names.index(body)
    return slice(3 * b, 3 * b + 2)


MIN_TRAVEL = 1e-6  # m: a slider that moves less has no load scale (E_max / s)


def load(mechanism, document, base_dir: Path = Path(".")) -> list[Candidate]:
    """A constant force F on each body sliding in a prismatic joint on the ground, along that joint's axis (positive
    in the axis's direction), written as a `constant` force element at its centre of mass: seal or guide friction,
    a gas or spring force, a cable the model lacks. −F_max … F_max (load_scales), present value 0 N."""
    axes = _ground_sliders(mechanism)
    scales = load_scales(document, base_dir, axes) if axes else {}
    out = []
    for body, axis in axes.items():
        if body not in scales:
            continue

        def write(doc, value, name=body, axis=axis):
            forces = [f for f in doc.get("forces") or [] if f.get("name") != f"diagnose_load_{name}"]
            doc["forces"] = forces + [{"type": "constant", "name": f"diagnose_load_{name}", "body": name,
                                       "force": [si_text(value * axis[0], "force"), si_text(value * axis[1], "force")]}]

        out.append(Candidate("load", body, "force", "N", -scales[body], scales[body], False, 0.0, write, ("N", 1.0)))
    return out


@dataclass(frozen=True)
class ForceParameter:
    """A parameter of a force element of type `force_type`, written at `forces.<name>.<path>` in SI units of
    `dimension`; scanned from `factors[0]` to `factors[1]` times its present value (log-spaced)."""

    kind: str
    force_type: str
    parameter: str
    path: str
    dimension: str
    factors: tuple[float, float]
    display_unit: tuple[str, float]
    present: Callable  # the force element → the parameter's value in the model as given (None: not this element's)
    resonant: bool = False  # a stiffness setting a resonance, frequency ∝ √value (Candidate.resonant)


def _force_candidates(mechanism, spec: ForceParameter) -> list[Candidate]:
    """One candidate per force element of the spec's type that has the parameter."""
    out = []
    for force in mechanism.forces:
        present = spec.present(force) if force.type == spec.force_type else None
        if present is None or not present > 0.0:
            continue

        def write(doc, value, name=force.name):
            _set(doc, f"forces.{name}.{spec.path}", si_text(value, spec.dimension))

        out.append(Candidate(spec.kind, force.name, spec.parameter, DIMENSIONS[spec.dimension].si_unit,
                             spec.factors[0] * present, spec.factors[1] * present, True, present, write,
                             spec.display_unit, resonant=spec.resonant))
    return out


def _force_kind(*specs: ForceParameter) -> Callable:
    """A candidate kind made of force-element parameters."""
    def kind(mechanism, document) -> list[Candidate]:
        return [c for spec in specs for c in _force_candidates(mechanism, spec)]

    kind.__doc__ = "; ".join(f"{s.parameter} of each {s.force_type}" for s in specs)
    return kind


def _accumulator_pressure(cylinder) -> float | None:
    return cylinder.supply.pressure if cylinder.supply.type == "accumulator" else None


PORT_AREA_FACTORS = (0.25, 4.0)  # a port choked by dirt or a worn valve seat (¼) to a bigger replacement orifice (4×)
PRECHARGE_FACTORS = (0.5, 1.2)  # a leaking accumulator (half its charge) to an overcharged one
BULK_MODULUS_FACTORS = (0.1, 2.0)  # entrained air and hoses (β/10) to a stiff, air-free circuit
PRELOAD_FACTORS = (0.5, 1.2)  # a relaxed operating spring (half its preload) to an over-tensioned one
DASHPOT_FACTORS = (0.1, 10.0)
GAS_LOAD_FACTORS = (0.5, 2.0)  # the puffer's working area: a leaking puffer to a blocked nozzle
GUIDE_FRICTION_FACTORS = (0.2, 5.0)  # μN: the contact fingers' preload and friction together

port_area = _force_kind(
    ForceParameter("port_area", "hydraulic_cylinder", "piston port area", "port_areas.piston", "area",
                   PORT_AREA_FACTORS, ("mm²", 1e-6), lambda f: f.port_areas.piston),
    ForceParameter("port_area", "hydraulic_cylinder", "rod port area", "port_areas.rod", "area",
                   PORT_AREA_FACTORS, ("mm²", 1e-6), lambda f: f.port_areas.rod))
precharge = _force_kind(ForceParameter("precharge", "hydraulic_cylinder", "accumulator precharge", "supply.pressure",
                                       "pressure", PRECHARGE_FACTORS, ("bar", 1e5), _accumulator_pressure))
# the oil column is a spring k = β A²/V: where the cylinder rings against it (the trapped oil at the end stop), f ∝ √β
bulk_modulus = _force_kind(ForceParameter("bulk_modulus", "hydraulic_cylinder", "bulk modulus", "bulk_modulus",
                                          "pressure", BULK_MODULUS_FACTORS, ("GPa", 1e9), lambda f: f.bulk_modulus,
                                          resonant=True))
preload = _force_kind(ForceParameter("preload", "spring_drive", "preload", "preload", "force", PRELOAD_FACTORS,
                                     ("N", 1.0), lambda f: f.preload))
dashpot = _force_kind(
    ForceParameter("dashpot", "dashpot", "damping", "damping", "damping", DASHPOT_FACTORS, ("N·s/m", 1.0),
                   lambda f: f.damping),
    ForceParameter("dashpot", "dashpot", "orifice area", "orifice_area", "area", PORT_AREA_FACTORS, ("mm²", 1e-6),
                   lambda f: f.orifice_area))
gas_load = _force_kind(ForceParameter("gas_load", "gas_load", "puffer area", "area", "area", GAS_LOAD_FACTORS,
                                      ("cm²", 1e-4), lambda f: f.area))
guide_friction = _force_kind(ForceParameter("guide_friction", "guide_friction", "normal force", "normal_force", "force",
                                            GUIDE_FRICTION_FACTORS, ("N", 1.0), lambda f: f.normal_force))


KINDS: dict[str, Callable] = {"clearance": clearance, "friction": friction, "stiffness": stiffness,
                              "restitution": restitution, "drive": drive, "damping": damping, "mass": mass,
                              "compliance": compliance, "beam_stiffness": beam_stiffness,
                              "contact_length": contact_length, "port_area": port_area, "precharge": precharge,
                              "bulk_modulus": bulk_modulus, "preload": preload, "dashpot": dashpot,
                              "gas_load": gas_load, "guide_friction": guide_friction, "wear": wear,
                              "viscosity": viscosity, "load": load}


def candidates_for(mechanism, document: dict, kinds: list[str], base_dir: Path | str = ".") -> list[Candidate]:
    """The candidates of the kinds; `base_dir`: where the file's tables are (a compliance assembles the model)."""
    makers = {**KINDS, "compliance": partial(compliance, base_dir=Path(base_dir)), "load": partial(load, base_dir=Path(base_dir))}
    return [c for kind in kinds for c in makers[kind](mechanism, document)]


PERTURBATION = 1e-9  # m: where each clearance joint's journal starts, off its given place: no bench controls it


def perturbed(mechanism, document: dict, seed: int, size: float = PERTURBATION) -> dict:
    """A copy of the document no bench could tell from it: each clearance joint's journal starts `size` off its
    given place, in a direction drawn from numpy's generator seeded with `seed`. A rattling joint's impact sequence
    is chaotic, and this re-rolls it; without a clearance joint the copy is the document itself."""
    changed = copy.deepcopy(document)
    rng = np.random.default_rng(seed)
    for joint in _clearance_joints(mechanism):
        angle = rng.uniform(0.0, 2.0 * np.pi)
        x, y = joint.initial_eccentricity or (0.0, 0.0)
        moved = (float(x + size * np.cos(angle)), float(y + size * np.sin(angle)))
        _set(changed, f"joints.{joint.name}.initial_eccentricity", f"[{moved[0]!r} m, {moved[1]!r} m]")
    return changed
