"""The YAML mechanism file as pydantic models: names, SI floats, no arrays.

Every value with a physical kind is converted to SI here (see clearsim.units): a
string by its unit, a bare number by the file's `units:` block (validate_mechanism;
an error, unless 0, in a file without one). Unknown keys are errors (extra="forbid").
Cross-references between names (bodies, points, joints, sensors) are checked in clearsim.model.references so
that all problems of a file are reported together, each with its location.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal, Union

import numpy as np

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, PrivateAttr, ValidationError, \
    ValidationInfo, WithJsonSchema, field_validator, model_validator

from clearsim.units import (
    BASE_UNITS,
    DERIVED_UNITS,
    SI,
    UNITS_CONTEXT,
    Acceleration,
    Angle,
    Area,
    AngularSpeed,
    Damping,
    Density,
    Force,
    Frequency,
    Inertia,
    Length,
    Mass,
    Pressure,
    Density,
    Volume,
    RotationalDamping,
    RotationalStiffness,
    SecondMoment,
    Speed,
    SpringStiffness,
    Time,
    Torque,
    UnitError,
    UnitSystem,
    Viscosity,
    Volume,
    bare_number,
    bare_number_message,
    declared_system,
    declared_unit,
    declares_no_units,
    parse_quantity,
    unit_name,
    unit_system,
)
from clearsim.travel import crossed_limits

RawQuantity = Union[float, str]  # converted where its kind is known (a driver's stroke: m or rad)


def _needs_unit(kind: str, examples: tuple[str, ...], block: str | None = None):
    """A RawQuantity whose bare number, other than 0, is an error in a file that declares no units."""
    def check(value: RawQuantity, info: ValidationInfo) -> RawQuantity:
        number = bare_number(value)
        if number is not None and number != 0 and declares_no_units(info.context):
            raise ValueError(bare_number_message(number, kind, examples, block))
        return value

    return AfterValidator(check)


def _coefficients_need_units(values: list[float], info: ValidationInfo) -> list[float]:
    if any(values) and declares_no_units(info.context):
        raise ValueError("polynomial coefficients are bare numbers in the file's units (m or rad and s for SI), "
                         "and this file declares none: declare them at its top, e.g. `units: SI` or "
                         "`units: {length: mm, time: ms}`")
    return values


Point = tuple[Length, Length]
Direction = tuple[float, float]
PointRef = Union[str, Point]  # a named point, or [x, y]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)  # nan and inf are no one's intended value


def _unit_vector(value: Direction) -> Direction:
    norm = math.hypot(*value)  # no overflow for components beyond 1e154
    if norm < 1e-12:
        raise ValueError("a direction must not be the zero vector")
    return (value[0] / norm, value[1] / norm)


# --- materials, contact and friction -------------------------------------------------------------


class Material(Strict):
    youngs_modulus: Pressure = Field(207e9, gt=0, description="Young's modulus E (Pa)")
    poisson_ratio: float = Field(0.3, ge=0.0, lt=0.5, description="Poisson ratio ν")


class ContactSpec(Strict):
    """Normal contact law F = F_el(δ) (1 + D(c_e) δ̇/δ̇⁻), F_el = K δⁿ (`elastic: point_hertz`) or a cylindrical
    law; every field optional at joint level."""

    law: Literal["lankarani_nikravesh", "hertz", "hunt_crossley", "flores", "gonthier"] | None = Field(None, description="contact force law (docs/model.md §3)")
    restitution: float | None = Field(None, gt=0.0, le=1.0, description="coefficient of restitution c_e, 0 < c_e <= 1")
    exponent: float | None = Field(None, gt=0.0, le=3.0, description="force exponent n (1.5 for metals)")
    stiffness: Annotated[RawQuantity, _needs_unit("force", ("N/m^1.5", "N/mm^1.5"), "{length: mm, force: N}")] | None = Field(
        None, description="K in N/m^n (a bare number: force/length^n in the file's units), or 'auto' to compute it "
        "from the radii and materials")
    min_impact_speed: Speed | None = Field(
        None, gt=0.0, description="floor on the impact speed δ̇⁻ in the damping term (grazing guard)"
    )
    elastic: Literal["point_hertz", "johnson", "esdu_78035", "pereira", "liu"] | None = Field(
        None, description="elastic law F_el(δ) that the damping `law` multiplies: point_hertz (K δⁿ from `stiffness` "
        "and `exponent`) or a cylindrical law of a pin of axial `length` (docs/model-contact.md)")
    length: Length | None = Field(None, gt=0.0, description="axial length L of the pin in its bore (the cylindrical "
                                  "`elastic` laws)")


DEFAULT_CONTACT = ContactSpec(
    law="lankarani_nikravesh", restitution=0.9, exponent=1.5, stiffness="auto", min_impact_speed=1e-3,
    elastic="point_hertz",
)


class FrictionSpec(Strict):
    """Tangential friction law; the parameters a law needs are checked after merging with defaults."""

    law: Literal["none", "coulomb", "stiction_step", "ambrosio"] | None = Field(None, description="friction law; a layer that changes it starts that law afresh")
    mu_s: float | None = Field(None, ge=0.0, description="static friction coefficient (stiction_step)")
    mu_d: float | None = Field(None, ge=0.0, description="dynamic friction coefficient (all laws)")
    v_s: Speed | None = Field(None, gt=0.0, description="stiction transition speed (stiction_step)")
    v_d: Speed | None = Field(None, gt=0.0, description="dynamic transition speed (stiction_step)")
    v_0: Speed | None = Field(None, ge=0.0, description="speed below which friction is zero (ambrosio)")
    v_1: Speed | None = Field(None, gt=0.0, description="speed above which friction is full (ambrosio)")
    stick: Literal["exact", "smooth"] | None = Field(
        None, description="sticking (stiction_step, coulomb): `exact` holds v_t = 0 while |F_t| <= mu_s F_n "
        "(default); `smooth` integrates the law as written (the STEP band through zero, the bare sign function)")


FRICTION_PARAMETERS = {
    "none": (),
    "coulomb": ("mu_d",),
    "stiction_step": ("mu_s", "mu_d", "v_s", "v_d"),
    "ambrosio": ("mu_d", "v_0", "v_1"),
}
FRICTION_OPTIONS = {"coulomb": {"stick": "exact"}, "stiction_step": {"stick": "exact"}}  # optional keys, defaults


class LubricationSpec(Strict):
    """Oil film of a clearance joint (docs/model-contact.md, lubricated joints); fields merge over defaults."""

    viscosity: Viscosity | None = Field(None, ge=0.0, description="dynamic viscosity μ of the oil; 0: a dry joint")
    length: Length | None = Field(None, gt=0.0, description="axial length L wetted by the film; default: the pin's "
                                  "`contact.length`")
    model: Literal["short_bearing", "long_bearing"] | None = Field(
        None, description="film model: short_bearing (Ocvirk, L/D < 1/2, default) or long_bearing (Sommerfeld, L/D > 2)")
    cavitation: Literal["half_sommerfeld"] | None = Field(
        None, description="cavitation condition: half_sommerfeld (Gümbel: negative pressures set to 0)")
    dry_below: Length | None = Field(
        None, gt=0.0, description="film thickness h = c - |e| below which the dry contact and friction laws act "
        "instead of the film (default 1.5 µm: three times a composite roughness of 0.5 µm)")


DEFAULT_LUBRICATION = LubricationSpec(model="short_bearing", cavitation="half_sommerfeld", dry_below=1.5e-6)


MEASURED_PROFILE_HARMONICS = 32  # default harmonics of a fitted measured profile (fewer when the points allow fewer)


class WearProfile(Strict):
    """Wear depth h(θ) = a_0 + Σ a_m cos mθ + b_m sin mθ of a bore, θ in the bearing body's frame from its x axis:
    its coefficients (`cos`, `sin`), or measured depths (`angles`, `depth`) fitted by least squares."""

    cos: list[Length] = Field([], description="[a_0, a_1, a_2, ...]: the mean depth and the cosine terms")
    sin: list[Length] = Field([], description="[b_1, b_2, ...]: the sine terms")
    angles: list[Angle] = Field([], description="angles θ of measured `depth` values (instead of `cos`, `sin`)")
    depth: list[Length] = Field([], description="measured wear depths at `angles`, fitted by least squares")
    harmonics: int | None = Field(None, ge=0, description="harmonics M of the fit to measured depths; default: "
                                  "as many as the points allow, (N − 1)/2, at most 32")

    @model_validator(mode="after")
    def _one_form(self) -> "WearProfile":
        if (self.cos or self.sin) and (self.angles or self.depth):
            raise ValueError("give the profile as `cos`/`sin` coefficients or as measured `angles`/`depth`, not both")
        if len(self.angles) != len(self.depth):
            raise ValueError(f"{len(self.angles)} angles but {len(self.depth)} depths: give one depth per angle")
        points = len({round(math.remainder(a, 2.0 * math.pi), 12) for a in self.angles})
        if self.angles and 2 * self.fit_harmonics() + 1 > points:
            raise ValueError(f"{points} distinct angles fit at most {(points - 1) // 2} harmonics, not "
                             f"{self.fit_harmonics()}: measure more angles or lower `harmonics`")
        return self

    def fit_harmonics(self) -> int:
        points = len(self.angles)
        return self.harmonics if self.harmonics is not None else min((points - 1) // 2, MEASURED_PROFILE_HARMONICS)

    def coefficients(self) -> np.ndarray:
        """[a_0, a_1, b_1, ...] (m)."""
        from clearsim.physics.wear import fitted_coefficients, profile_coefficients
        if self.angles:
            return fitted_coefficients(self.angles, self.depth, self.fit_harmonics())
        return profile_coefficients(self.cos, self.sin)


KERNEL_RINGING = 1e-4  # the largest dip below 0 a worn profile may have, as a fraction of its deepest point
PROFILE_CHECK_POINTS = 4096  # the profile's depth is checked on this many angles (≥ 8 per period of harmonic 512)


class ArchardWear(Strict):
    """Archard wear accumulated over a run: V̇ = k_w F_n |v_t| / H, spread over the bore (docs/model-contact.md)."""

    coefficient: float = Field(ge=0.0, description="dimensionless wear coefficient k_w (steel on steel ~1e-4)")
    hardness: Pressure = Field(gt=0.0, description="hardness H of the worn (bearing) surface, e.g. 2 GPa")
    length: Length | None = Field(None, gt=0.0, description="axial length L of the worn band; default: the pin's "
                                  "`contact.length`")
    width: Length | None = Field(None, gt=0.0, description="a fixed contact width w over which the depth rate is "
                                 "k_w F_n |v_t| / (H L w), at least the narrowest `harmonics` carry; default: the "
                                 "band follows the load (Hertz line contact, docs/model-contact.md)")
    harmonics: int = Field(64, ge=1, le=512, description="harmonics M of the accumulated profile")


class Wear(Strict):
    """A worn bore (`profile`) and/or Archard wear accumulated during the run (`archard`)."""

    profile: WearProfile | None = Field(None, description="the bore's wear depth at the start; absent: circular")
    wall: Length | None = Field(None, gt=0.0, description="wall thickness of the bearing: the profile may not be "
                                "deeper")
    archard: ArchardWear | None = Field(None, description="accumulate Archard wear during the run; absent: none")

    @model_validator(mode="after")
    def _profile_within_wall(self) -> "Wear":
        if self.profile is None:
            return self
        from clearsim.physics.wear import evaluate_profile
        angles = np.linspace(0.0, 2.0 * math.pi, PROFILE_CHECK_POINTS, endpoint=False)
        coefficients = self.profile.coefficients()
        depth = evaluate_profile(coefficients, angles)
        shallowest, deepest = int(np.argmin(depth)), int(np.argmax(depth))
        # a profile touching 0 may round below it; an accumulated Archard profile (clearsim life) dips below 0 by the
        # truncated wear kernel's ringing, at most 3.6e-5 of its peak (physics/wear.py, σ ≥ 4/M)
        if depth[shallowest] < -1e-12 * np.abs(coefficients).sum() - KERNEL_RINGING * max(depth[deepest], 0.0):
            raise ValueError(f"the wear profile's depth is negative ({depth[shallowest] * 1e3:.4g} mm at "
                             f"{math.degrees(angles[shallowest]):.1f}°): wear only removes material; raise `cos[0]`, "
                             "the mean depth, to at least the largest dip")
        if self.wall is not None and depth[deepest] > self.wall:
            raise ValueError(f"the wear profile is {depth[deepest] * 1e3:.4g} mm deep at "
                             f"{math.degrees(angles[deepest]):.1f}°, deeper than the wall ({self.wall * 1e3:.4g} mm): "
                             "check the profile's units (e.g. 0.01 mm) or the wall thickness")
        return self


class Defaults(Strict):
    bearing_radius: Length | None = Field(None, gt=0.0, description="bearing radius R_B of clearance joints")
    material: Material = Material()
    contact: ContactSpec = DEFAULT_CONTACT
    friction: FrictionSpec = FrictionSpec(law="none")
    lubrication: LubricationSpec | None = Field(None, description="oil film of every clearance joint; absent: dry")


# --- bodies ---------------------------------------------------------------------------------------


class AxialFlexibility(Strict):
    """A two-joint link that stretches along the line between its joints (docs/model.md, flexible links)."""

    model: Literal["axial"] = Field(description="axial: the link stretches along the line between its two joints")
    youngs_modulus: Pressure | None = Field(None, gt=0.0, description="Young's modulus E of the link's material; k = E A / L")
    area: Area | None = Field(None, gt=0.0, description="cross-section area A; k = E A / L (L: joint to joint at t = 0)")
    axial_stiffness: SpringStiffness | None = Field(None, gt=0.0, description="axial stiffness k instead of E and A")
    damping_ratio: float = Field(0.0, ge=0.0, lt=1.0, description="damping ratio ζ of the link's own axial mode: c = 2 ζ √(k m/4) (m: the link's mass)")
    stiffness_damping: Time = Field(0.0, ge=0.0, description="Rayleigh stiffness-proportional damping β: c = β k added (ζ = β ω / 2 at ω)")

    @model_validator(mode="after")
    def _one_stiffness(self):
        section = (self.youngs_modulus is not None, self.area is not None)
        if self.axial_stiffness is None and not all(section):
            missing = " and ".join(k for k, given in zip(("youngs_modulus", "area"), section) if not given)
            raise ValueError(f"the axial stiffness needs the section: {missing} missing (or give axial_stiffness)")
        if self.axial_stiffness is not None and any(section):
            raise ValueError("give either axial_stiffness or youngs_modulus and area, not both")
        return self


class BeamFlexibility(Strict):
    """A link that bends in the plane: rigid segments joined by pins and rotational springs k = E I / Δ (docs/model.md,
    "Flexible links: the beam element")."""

    model: Literal["beam"] = Field(description="beam: the link bends (Euler–Bernoulli) along its axis")
    youngs_modulus: Pressure = Field(gt=0.0, description="Young's modulus E of the link's material")
    second_moment_of_area: SecondMoment = Field(gt=0.0, description="second moment of area I of the section about its bending axis")
    segments: int = Field(10, ge=2, le=200, description="number n of equal elements: n + 1 rigid segments (the two end ones half as long), n springs k = E I n / L")
    axis: tuple[PointRef, PointRef] | None = Field(None, description="the link's two ends at t = 0: body points (by name) or global points; default its first and last joints")
    damping_ratio: float = Field(0.0, ge=0.0, lt=1.0, description="damping ratio ζ of the link's first cantilever bending mode ω₁ = 3.516 √(E I / (m L³)): c = (2 ζ / ω₁) k at every spring")
    stiffness_damping: Time = Field(0.0, ge=0.0, description="Rayleigh stiffness-proportional damping β: c = β k added at every spring")


Flexibility = Annotated[Union[AxialFlexibility, BeamFlexibility], Field(discriminator="model")]


class Body(Strict):
    name: str = Field(description="unique body name; `ground` is reserved")
    mass: Mass = Field(gt=0.0, description="mass m")
    inertia: Inertia = Field(gt=0.0, description="moment of inertia about the centre of mass")
    position: Point = Field(description="centre of mass at t = 0 (global); a guess refined by assembly")
    angle: Angle = Field(0.0, description="orientation at t = 0, counter-clockwise from the global x axis")
    velocity: tuple[Speed, Speed] = Field((0.0, 0.0), description="centre-of-mass velocity at t = 0 (made consistent by assembly)")
    angular_velocity: AngularSpeed = Field(0.0, description="angular velocity at t = 0 (made consistent by assembly)")
    points: dict[str, Point] = Field(default_factory=dict, description="body-fixed points, body frame, from the centre of mass")
    flexible: Flexibility | None = Field(None, description="a compliant link: axial (two joints) or beam; absent: rigid")


# --- joints ---------------------------------------------------------------------------------------


class RevoluteJoint(Strict):
    """Pin joint; with `clearance` > 0 it is a clearance joint (first body bearing, second journal)."""

    name: str = Field(description="unique joint name")
    type: Literal["revolute"] = Field(description="joint kind")
    bodies: tuple[str, str] = Field(description="[bearing, journal]: the two bodies; for a clearance joint the first is the bearing")
    at: PointRef | None = Field(None, description="a named global point or [x, y] at t = 0")
    points: tuple[str, str] | None = Field(None, description="named body points [on first, on second]")
    clearance: Length | None = Field(None, ge=0.0, description="radial clearance c = R_B - R_J; 0 or absent: ideal")
    bearing_radius: Length | None = Field(None, gt=0.0, description="bearing radius R_B; default defaults.bearing_radius")
    journal_radius: Length | None = Field(None, gt=0.0, description="journal radius R_J; with it and no clearance, c = R_B − R_J")
    material: Material | None = None
    contact: ContactSpec | None = None
    friction: FrictionSpec | None = None
    lubrication: LubricationSpec | None = Field(None, description="oil film (a clearance joint only); merges over defaults.lubrication")
    initial_eccentricity: Point | None = Field(None, description="journal centre - bearing centre at t = 0")
    initial_velocity: tuple[Speed, Speed] | None = Field(
        None, description="velocity of the journal centre relative to the bearing centre at t = 0 (default 0)")
    wear: Wear | None = Field(None, description="worn bore and Archard wear (a clearance joint only)")


class PrismaticJoint(Strict):
    """Translational guide: the second body slides along `axis` of the first, without relative rotation."""

    name: str = Field(description="unique joint name")
    type: Literal["prismatic"] = Field(description="joint kind")
    bodies: tuple[str, str] = Field(description="[guide, slider]: the second slides along the first")
    at: PointRef | None = Field(None, description="a point on the guide line (named or [x, y]) at t = 0")
    points: tuple[str, str] | None = Field(None, description="named body points [on first, on second] on the guide line")
    axis: Direction = Field(description="guide direction, global frame at t = 0")

    _unit_axis = field_validator("axis")(_unit_vector)


Joint = Annotated[Union[RevoluteJoint, PrismaticJoint], Field(discriminator="type")]


# --- drivers --------------------------------------------------------------------------------------


class StrokeMotion(Strict):
    """Meng 2015 eq. 16 generalised: s(t) = S τ²(3 − 2τ), τ = (t − t0)/T, held at S after."""

    law: Literal["stroke"] = Field(description="motion law")
    stroke: Annotated[RawQuantity, _needs_unit("length", ("m", "mm", "deg"))] = Field(
        description="total stroke S: a length or an angle by the driven coordinate")
    duration: Time = Field(gt=0.0, description="stroke time T")
    start: Time = Field(0.0, description="time t0 at which the stroke begins")


class ConstantSpeedMotion(Strict):
    law: Literal["constant_speed"] = Field(description="motion law")
    speed: Annotated[RawQuantity, _needs_unit("angular_speed", ("rpm", "rad/s", "m/s"))] = Field(
        description="constant rate: a speed or an angular speed by the driven coordinate")


class PolynomialMotion(Strict):
    """s(t) = Σ_k c_k t^k, k = 1, 2, …, in the file's units of the driven coordinate and of time."""

    law: Literal["polynomial"] = Field(description="motion law")
    coefficients: Annotated[list[float], AfterValidator(_coefficients_need_units)] = Field(
        min_length=1, description="[c_1, c_2, …] of s = Σ c_k t^k in the file's units (length or angle, time), at most 7")


class TableMotion(Strict):
    """s(t) from a CSV file (cubic spline through the samples, value held after the last)."""

    law: Literal["table"] = Field(description="motion law")
    file: str = Field(description="CSV file, relative to the YAML file")
    time_column: Union[str, int] = Field(0, description="header name or 0-based index of the time column")
    value_column: Union[str, int] = Field(1, description="header name or 0-based index of the value column")
    time_unit: str = Field("s", description="unit of the time column")
    value_unit: str | None = Field(None, description="unit of the value column; default m or rad by the driven coordinate")

    _units_alone = field_validator("time_unit", "value_unit")(lambda value: value if value is None else unit_name(value))


Motion = Annotated[
    Union[StrokeMotion, ConstantSpeedMotion, PolynomialMotion, TableMotion], Field(discriminator="law")
]


class Driver(Strict):
    """Prescribed motion of a joint's relative coordinate or of a body coordinate, from its t = 0 value."""

    name: str = Field(description="unique driver name")
    joint: str | None = Field(None, description="ideal revolute or prismatic joint whose relative coordinate is driven")
    body: str | None = Field(None, description="body whose coordinate is driven (with coordinate:)")
    coordinate: Literal["x", "y", "angle"] | None = Field(None, description="driven body coordinate: centre-of-mass x, y, or angle")
    motion: Motion
    lag: Time = Field(0.0, ge=0.0, description="first-order lag τ of the actuator: the coordinate follows the law through τ ṡ + s = s_law (0: none)")

    @model_validator(mode="after")
    def _one_target(self):
        if (self.joint is None) == (self.body is None):
            raise ValueError("a driver takes either `joint:` or `body:` (with `coordinate:`), not both or neither")
        if self.body is not None and self.coordinate is None:
            raise ValueError("a body driver needs `coordinate: x | y | angle`")
        return self


# --- applied forces -------------------------------------------------------------------------------


class BodyPointForce(Strict):
    """A force element acting at a point of one body."""

    type: str = Field(description="force kind")
    name: str = Field(description="unique force name")
    body: str = Field(description="loaded body")
    point: PointRef | None = Field(None, description="point of application: global point at t = 0, fixed to the body; default centre of mass")


class ConstantForce(BodyPointForce):
    type: Literal["constant"] = Field(description="force kind")
    force: tuple[Force, Force] = Field((0.0, 0.0), description="[F_x, F_y], global frame")
    torque: Torque = Field(0.0, description="torque, counter-clockwise positive")


class TwoPointForce(Strict):
    """A force element acting along the line between a point of each of two bodies."""

    type: str = Field(description="force kind")
    name: str = Field(description="unique force name")
    bodies: tuple[str, str] = Field(description="the two connected bodies")
    at: tuple[PointRef, PointRef] | None = Field(None, description="the two ends as global points at t = 0; default the centres of mass")
    points: tuple[str, str] | None = Field(None, description="the two ends as named body points")


class SpringDamper(TwoPointForce):
    """Linear spring-damper between two points: F = k (ℓ − ℓ0) + c ℓ̇ + preload, along the line."""

    type: Literal["spring_damper"] = Field(description="force kind")
    stiffness: SpringStiffness = Field(0.0, description="spring rate k")
    damping: Damping = Field(0.0, description="damping coefficient c")
    free_length: Length | None = Field(None, ge=0.0, description="ℓ0; default: the length at t = 0")
    preload: Force = Field(0.0, description="constant tension added to the spring force")


class RotationalSpring(Strict):
    """Rotational spring-damper between two bodies: torque T = k (θ_j − θ_i − θ₀) + c (ω_j − ω_i) + preload, −T on the
    second body and +T on the first."""

    type: Literal["rotational_spring"] = Field(description="force kind")
    name: str = Field(description="unique force name")
    bodies: tuple[str, str] = Field(description="the two connected bodies [i, j]")
    stiffness: RotationalStiffness = Field(0.0, description="rotational spring rate k")
    damping: RotationalDamping = Field(0.0, description="rotational damping coefficient c")
    free_angle: Angle | None = Field(None, description="θ₀; default: θ_j − θ_i at t = 0")
    preload: Torque = Field(0.0, description="constant torque added to the spring torque")


class TabulatedForce(BodyPointForce):
    type: Literal["tabulated"] = Field(description="force kind")
    direction: Direction = Field(description="direction of the force, global frame, normalised")
    file: str = Field(description="CSV file, relative to the YAML file")
    time_column: Union[str, int] = Field(0, description="header name or 0-based index of the time column")
    value_column: Union[str, int] = Field(1, description="header name or 0-based index of the force column")
    time_unit: str = Field("s", description="unit of the time column")
    value_unit: str = Field("N", description="unit of the force column")

    _unit_direction = field_validator("direction")(_unit_vector)
    _units_alone = field_validator("time_unit", "value_unit")(unit_name)


# --- hydraulic cylinder (docs/model-drives.md "Hydraulic cylinder") --------------------------------


class Accumulator(Strict):
    """A gas-loaded accumulator: p V_g^n = p_0 V_0^n, the gas volume growing by the oil drawn."""

    type: Literal["accumulator"] = Field(description="supply kind")
    pressure: Pressure = Field(gt=0.0, description="gas pressure p_0 at t = 0 (the charged accumulator)")
    gas_volume: Volume = Field(gt=0.0, description="gas volume V_0 at t = 0")
    polytropic_index: float = Field(1.4, ge=1.0, le=1.67, description="polytropic index n (1 isothermal, 1.4 adiabatic nitrogen)")


class ConstantSupply(Strict):
    """A source that holds its pressure whatever flow it delivers."""

    type: Literal["constant"] = Field(description="supply kind")
    pressure: Pressure = Field(gt=0.0, description="supply pressure p_s")


Supply = Annotated[Union[Accumulator, ConstantSupply], Field(discriminator="type")]


class LinearValve(Strict):
    """Opening a_v/a_max: 0 until `delay`, rising linearly to 1 over `opening_time`, then 1."""

    law: Literal["linear"] = Field(description="valve law")
    delay: Time = Field(0.0, ge=0.0, description="time t_d at which the valve starts to open")
    opening_time: Time = Field(gt=0.0, description="time t_o from closed to fully open")


def _increasing_abscissae(points: list, what: str) -> list:
    if any(b[0] <= a[0] for a, b in zip(points, points[1:])):
        raise ValueError(f"the {what} table's first column must increase from one point to the next")
    return points


class TableValve(Strict):
    """Opening a_v/a_max linear between the listed [t, fraction] points, held before the first and after the last."""

    law: Literal["table"] = Field(description="valve law")
    points: list[tuple[Time, Annotated[float, Field(ge=0.0, le=1.0)]]] = Field(
        min_length=2, description="[time, opening fraction 0..1] pairs, times increasing")

    @field_validator("points")
    @classmethod
    def _increasing_and_opening(cls, points):
        _increasing_abscissae(points, "valve")
        if max(fraction for _, fraction in points) <= 0.0:
            raise ValueError("the valve table never opens (every fraction is 0): the cylinder would never move; "
                             "give the opening fraction it reaches (up to 1)")
        return points


ValveLaw = Annotated[Union[LinearValve, TableValve], Field(discriminator="law")]


class LinearCushion(Strict):
    """End-of-stroke cushion: the rod chamber's port area falls linearly from 1 to `residual_fraction` of itself
    over the last `length` of the stroke (the rod chamber empties as the cylinder extends)."""

    law: Literal["linear"] = Field(description="cushion law")
    length: Length = Field(gt=0.0, description="stroke length L_c over which the cushion closes, before the stroke's end")
    residual_fraction: float = Field(gt=0.0, le=1.0, description="port area left at the stroke's end, as a fraction of the open area")


class TableCushion(Strict):
    """The rod chamber's open port fraction linear between the listed [stroke, fraction] points, held outside them."""

    law: Literal["table"] = Field(description="cushion law")
    points: list[tuple[Length, Annotated[float, Field(ge=0.0, le=1.0)]]] = Field(
        min_length=2, description="[stroke s, open fraction 0..1] pairs, strokes increasing")

    _increasing = field_validator("points")(lambda points: _increasing_abscissae(points, "cushion"))


CushionLaw = Annotated[Union[LinearCushion, TableCushion], Field(discriminator="law")]


class ChamberPorts(Strict):
    piston: Literal["valve", "supply", "tank"] = Field("valve", description="what the piston chamber A connects to")
    rod: Literal["valve", "supply", "tank"] = Field("tank", description="what the rod chamber B connects to")


class PortAreas(Strict):
    piston: Area = Field(gt=0.0, description="orifice area of the piston chamber's port (fully open)")
    rod: Area = Field(gt=0.0, description="orifice area of the rod chamber's port")


class HydraulicCylinder(Strict):
    """A double-acting cylinder between two bodies, pushing them apart with F = p_A A_A − p_B A_B along the line
    between its two points; its pressures (and the accumulator's gas volume) are states integrated with the bodies.
    A port `valve` goes to the supply through a_max·u(t) and to the tank through a_max·(1 − u(t)) (a 3/2-way valve,
    u the valve law); `supply` and `tank` are permanent connections."""

    type: Literal["hydraulic_cylinder"] = Field(description="force kind")
    name: str = Field(description="unique force name (the result path /drives/<name>)")
    bodies: tuple[str, str] = Field(description="[barrel end, rod end]: the two bodies (`ground` allowed)")
    at: tuple[PointRef, PointRef] | None = Field(None, description="the two ends as global points at t = 0; default the centres of mass")
    points: tuple[str, str] | None = Field(None, description="the two ends as named body points")
    stroke: Length = Field(gt=0.0, description="full stroke S: the rod chamber's volume is V_B0 + A_B (S − s)")
    initial_length: Length | None = Field(None, gt=0.0, description="length ℓ0 at which the stroke s = ℓ − ℓ0 is 0; default the length at t = 0")
    piston_area: Area = Field(gt=0.0, description="piston area A_A (piston chamber)")
    rod_side_area: Area = Field(gt=0.0, description="annulus area A_B (rod chamber)")
    dead_volumes: tuple[Volume, Volume] = Field(description="[V_A0, V_B0]: oil volume of each chamber at s = 0 and s = S respectively (lines included)")
    bulk_modulus: Pressure = Field(1.4e9, gt=0.0, description="oil bulk modulus β")
    density: Density = Field(850.0, gt=0.0, description="oil density ρ")
    discharge_coefficient: float = Field(0.7, gt=0.0, le=1.0, description="orifice discharge coefficient C_d")
    transition_pressure: Pressure = Field(2e5, gt=0.0, description="p_tr: below this |Δp| the orifice flow is linear in Δp (laminar)")
    supply: Supply = Field(description="the pressure source: an accumulator or a constant pressure")
    tank_pressure: Pressure = Field(0.0, ge=0.0, description="return (tank) pressure p_T")
    ports: ChamberPorts = Field(default_factory=ChamberPorts, description="what each chamber connects to")
    port_areas: PortAreas = Field(description="fully open orifice area of each chamber's port")
    valve: ValveLaw | None = Field(None, description="opening of the valve a_v(t)/a_max; needed when a port is `valve`")
    cushion: CushionLaw | None = Field(None, description="end-of-stroke cushion on the rod chamber's port; absent: none")
    initial_pressures: tuple[Pressure, Pressure] | None = Field(
        None, description="[p_A, p_B] at t = 0; default: each chamber at the pressure its port connects it to at t = 0")
    resisting_force: Force = Field(0.0, ge=0.0, description="the load's force against the extension at t = 0 (a spring's preload): checked against the supply")

    @model_validator(mode="after")
    def _valve_where_a_port_needs_it(self):
        if self.valve is None and "valve" in (self.ports.piston, self.ports.rod):
            raise ValueError("a port connects through the valve (`ports: … valve`) but the cylinder has no `valve:` "
                             "law: give one, e.g. `valve: {law: linear, delay: 0 ms, opening_time: 5 ms}`")
        return self


# --- drive-line elements (docs/model-drives.md): stateless forces of a stroke s ----------------------

Sense = Literal["lengthening", "shortening"]
SENSE_DESCRIPTION = ("which change of the distance between the two points is the positive stroke s: lengthening "
                     "s = ℓ − ℓ0, shortening s = ℓ0 − ℓ (ℓ0: the distance at t = 0)")


class _StrokeTable(Strict):
    """A value against stroke, inline (`rows:`) or from a CSV file; linear between rows, held beyond the ends."""

    file: str | None = Field(None, description="CSV file, relative to the YAML file (instead of rows)")
    stroke_column: Union[str, int] = Field(0, description="header name or 0-based index of the stroke column")
    value_column: Union[str, int] = Field(1, description="header name or 0-based index of the value column")
    stroke_unit: str = Field("m", description="unit of the stroke column")

    _units_alone = field_validator("stroke_unit", "value_unit", check_fields=False)(unit_name)

    @model_validator(mode="after")
    def _one_source(self):
        if (self.rows is None) == (self.file is None):
            raise ValueError("a stroke table takes either `rows:` or `file:`, not both or neither")
        return self

    @field_validator("rows", check_fields=False)
    @classmethod
    def _strokes_increase(cls, rows):
        if rows is not None and any(b[0] <= a[0] for a, b in zip(rows, rows[1:])):
            raise ValueError("the strokes of the rows must increase strictly")
        return rows


class ForceStrokeTable(_StrokeTable):
    """A force against stroke, inline (`rows:`) or from a CSV file; linear between rows, held beyond the ends."""

    rows: list[tuple[Length, Force]] | None = Field(None, min_length=2, description="[[stroke, force], ...], strokes increasing")
    value_unit: str = Field("N", description="unit of the force column")


class PressureStrokeTable(_StrokeTable):
    """An absolute pressure against stroke, inline (`rows:`) or from a CSV file; linear between rows, held beyond
    the ends."""

    rows: list[tuple[Length, Pressure]] | None = Field(None, min_length=2, description="[[stroke, pressure], ...], strokes increasing")
    value_unit: str = Field("Pa", description="unit of the pressure column (absolute, like p_ambient)")


class SpringDrive(TwoPointForce):
    """A charged operating spring, latched until `release_time`, then F(s) ≥ 0 drives the stroke s."""

    type: Literal["spring_drive"] = Field(description="force kind")
    sense: Sense = Field("lengthening", description=SENSE_DESCRIPTION + "; the spring drives s forward (default "
                         "lengthening: a compression spring pushing the points apart)")
    stiffness: SpringStiffness | None = Field(None, ge=0.0, description="linear spring: rate k, F = preload − k s")
    preload: Force | None = Field(None, description="linear spring: force at t = 0 (s = 0)")
    free_length: Length | None = Field(None, gt=0.0, description="linear spring: distance at which F = 0, instead of preload")
    table: ForceStrokeTable | None = Field(None, description="tabulated spring: force against stroke, instead of stiffness")
    release_time: Time = Field(0.0, ge=0.0, description="time at which the latch releases the spring (no force before)")

    @model_validator(mode="after")
    def _one_law(self):
        linear = self.stiffness is not None
        if linear == (self.table is not None):
            raise ValueError("a spring drive takes either `stiffness:` (linear) or `table:`, not both or neither")
        if linear and (self.preload is None) == (self.free_length is None):
            raise ValueError("a linear spring drive takes either `preload:` or `free_length:`, not both or neither")
        if not linear and (self.preload is not None or self.free_length is not None):
            raise ValueError("a tabulated spring drive takes its forces from the table: remove preload and free_length")
        return self


class Dashpot(TwoPointForce):
    """F = −c ṡ (linear) or −sgn(ṡ) ρ A_p³ ṡ²/(2 C_d² a²) (orifice), while the stroke s is in `engaged`."""

    type: Literal["dashpot"] = Field(description="force kind")
    sense: Sense = Field("shortening", description=SENSE_DESCRIPTION + "; default shortening (a dashpot compressed "
                         "at the end of the stroke)")
    damping: Damping | None = Field(None, ge=0.0, description="linear dashpot: coefficient c")
    piston_area: Area | None = Field(None, gt=0.0, description="orifice dashpot: piston area A_p")
    orifice_area: Area | None = Field(None, gt=0.0, description="orifice dashpot: orifice area a")
    discharge_coefficient: float = Field(0.7, gt=0.0, le=1.0, description="orifice dashpot: discharge coefficient C_d")
    density: Density | None = Field(None, gt=0.0, description="orifice dashpot: oil density ρ, e.g. 870 kg/m^3")
    engaged: tuple[Length, Length] | None = Field(None, description="[start, end] of the stroke range in which the "
                                                  "dashpot acts; default everywhere")
    engagement_length: Length = Field(0.0, ge=0.0, description="length over which the force fades in after start and "
                                      "out before end (smoothstep); 0: sharp edges")

    @model_validator(mode="after")
    def _one_law(self):
        orifice = (self.piston_area, self.orifice_area, self.density)
        if (self.damping is None) == all(v is None for v in orifice):
            raise ValueError("a dashpot takes either `damping:` (linear) or piston_area, orifice_area and density "
                             "(orifice), not both or neither")
        if self.damping is None and any(v is None for v in orifice):
            missing = [k for k, v in zip(("piston_area", "orifice_area", "density"), orifice) if v is None]
            raise ValueError(f"an orifice dashpot needs {' and '.join(missing)}")
        if self.engaged is not None and 2 * self.engagement_length > self.engaged[1] - self.engaged[0]:
            raise ValueError("engagement_length is longer than half the engagement range")
        return self

    @field_validator("engaged")
    @classmethod
    def _range_in_order(cls, engaged: tuple[float, float] | None) -> tuple[float, float] | None:
        if engaged is not None and engaged[1] <= engaged[0]:
            raise ValueError(f"the engagement range [start, end] needs end > start, got [{engaged[0] * 1e3:g} mm, "
                             f"{engaged[1] * 1e3:g} mm]: write the stroke at which the dashpot starts to act first")
        return engaged


class GasLoad(BodyPointForce):
    """The gas force on a body point (of the moving contact) against its stroke s = d·(P − P(0)) along a fixed
    global direction d."""

    type: Literal["gas_load"] = Field(description="force kind")
    direction: Direction = Field(description="global direction of the compressing stroke; the force acts against it")
    force_table: ForceStrokeTable | None = Field(None, description="force against stroke (positive: resisting)")
    pressure_table: PressureStrokeTable | None = Field(None, description="absolute pressure against stroke; F = (p − p_ambient) A")
    area: Area | None = Field(None, gt=0.0, description="piston (puffer) area A of a pressure table or an adiabatic volume")
    volume: Volume | None = Field(None, gt=0.0, description="adiabatic puffer: gas volume V0 at s = 0")
    initial_pressure: Pressure | None = Field(None, gt=0.0, description="adiabatic puffer: absolute pressure p0 at s = 0; default p_ambient")
    gamma: float | None = Field(None, ge=1.0, le=5.0 / 3.0, description="adiabatic puffer: heat capacity ratio γ (air 1.4, SF6 1.1; 1: isothermal)")
    stroke: Length | None = Field(None, gt=0.0, description="adiabatic puffer: the largest stroke the motion reaches; A·stroke must stay below V0")
    p_ambient: Pressure = Field(101325.0, ge=0.0, description="absolute pressure outside the puffer; default 101.325 kPa")

    _unit_direction = field_validator("direction")(_unit_vector)

    @model_validator(mode="after")
    def _one_law(self):
        laws = [self.force_table is not None, self.pressure_table is not None, self.volume is not None]
        if sum(laws) != 1:
            raise ValueError("a gas load takes one of force_table, pressure_table or volume (adiabatic puffer)")
        if (self.pressure_table is not None or self.volume is not None) and self.area is None:
            raise ValueError("a pressure table or a puffer volume needs the piston `area`")
        if self.volume is not None and (self.gamma is None or self.stroke is None):
            raise ValueError("an adiabatic puffer needs `gamma` and `stroke`")
        return self


class GuideFriction(Strict):
    """Coulomb-type friction of a prismatic joint under a stated normal force, against the sliding speed."""

    type: Literal["guide_friction"] = Field(description="force kind")
    name: str = Field(description="unique force name")
    joint: str = Field(description="prismatic joint whose sliding it resists")
    normal_force: Force = Field(gt=0.0, description="normal force N pressing the sliding faces (e.g. the contact fingers' preload)")
    friction: FrictionSpec = Field(description="friction law and parameters (a smooth law: `stick: smooth` or ambrosio)")


AppliedForce = Annotated[Union[ConstantForce, SpringDamper, RotationalSpring, TabulatedForce, HydraulicCylinder,
                               SpringDrive, Dashpot, GasLoad, GuideFriction], Field(discriminator="type")]
TWO_ENDED = (TwoPointForce, HydraulicCylinder)  # the forces between two bodies' points (`bodies:`, `at:`/`points:`)
TWO_BODY = TWO_ENDED + (RotationalSpring,)  # every force between two bodies (`bodies:`)


# --- sensors --------------------------------------------------------------------------------------


class PointSensor(Strict):
    """A body point's displacement (from t = 0), velocity or acceleration along a global direction."""

    name: str = Field(description="unique sensor name (the result path /sensors/<name>)")
    type: Literal["point_displacement", "point_velocity", "point_acceleration"] = Field(description="quantity measured")
    body: str = Field(description="measured body")
    point: PointRef | None = Field(None, description="measured point: global point at t = 0, fixed to the body; default centre of mass")
    direction: Direction = Field(description="global direction the value is projected on, normalised")

    _unit_direction = field_validator("direction")(_unit_vector)


class BodySensor(Strict):
    name: str = Field(description="unique sensor name (the result path /sensors/<name>)")
    type: Literal["body_angle", "body_angular_velocity", "body_angular_acceleration"] = Field(description="quantity measured")
    body: str = Field(description="measured body")


class JointForceSensor(Strict):
    name: str = Field(description="unique sensor name (the result path /sensors/<name>)")
    type: Literal["joint_force"] = Field(description="quantity measured")
    joint: str = Field(description="joint whose force is measured")
    component: Literal["x", "y", "magnitude", "normal", "friction"] = Field("magnitude", description="x, y or magnitude of the force on the second body; normal F_n; friction F_t (ideal joint: reaction magnitude, 0)")


Sensor = Annotated[Union[PointSensor, BodySensor, JointForceSensor], Field(discriminator="type")]


class OutputSensors(Strict):
    """Which sensors are 'the output' in summaries (the moving contact of a breaker)."""

    displacement: str | None = Field(None, description="name of the point_displacement sensor that is the output")
    velocity: str | None = Field(None, description="name of the point_velocity sensor that is the output")
    acceleration: str | None = Field(None, description="name of the point_acceleration sensor that is the output")


def _in_time_order(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    for number, (before, after) in enumerate(zip(points, points[1:]), 1):
        if after[0] <= before[0]:
            raise ValueError(f"the times of a limit curve must increase: point {number + 1} "
                             f"({after[0] * 1e3:g} ms) does not come after point {number} ({before[0] * 1e3:g} ms); "
                             "list the [time, travel] pairs in time order, e.g. [[0 ms, 0 mm], [40 ms, 150 mm]]")
    return points


class TravelEnvelope(Strict):
    """The tolerance band of the travel curve: a lower and an upper limit curve, each straight between its
    [time, travel] points (time from t = 0, travel as the sensor's); checked where both are given."""

    lower: list[tuple[Time, Length]] = Field(min_length=2, description="lower limit curve: [time, travel] pairs, "
                                             "times increasing, e.g. [[0 ms, 0 mm], [60 ms, 230 mm]]")
    upper: list[tuple[Time, Length]] = Field(min_length=2, description="upper limit curve: [time, travel] pairs, "
                                             "times increasing")

    _limits_in_time_order = field_validator("lower", "upper")(_in_time_order)

    @model_validator(mode="after")
    def _lower_below_upper(self):
        lower, upper = self.lower, self.upper
        if max(lower[0][0], upper[0][0]) >= min(lower[-1][0], upper[-1][0]):
            raise ValueError(f"the lower limit ({lower[0][0] * 1e3:g} to {lower[-1][0] * 1e3:g} ms) and the upper "
                             f"limit ({upper[0][0] * 1e3:g} to {upper[-1][0] * 1e3:g} ms) share no time span: give "
                             "both over the same times")
        crossed = crossed_limits(lower, upper)
        if crossed is not None:
            time, low, high = crossed
            raise ValueError(f"the lower limit is above the upper one at {time * 1e3:g} ms ({low * 1e3:g} mm > "
                             f"{high * 1e3:g} mm): swap `lower` and `upper`, or correct that point")
        return self


class TravelCurve(Strict):
    """The travel-curve figures `clearsim run` reports (docs/plotting.md "Travel curve"): positions are the sensor's
    signed displacement from t = 0."""

    sensor: str = Field(description="name of the point_displacement sensor whose travel is analysed")
    command_time: Time = Field(0.0, ge=0.0, description="time of the operating command; default 0 s")
    contact_touch: Length = Field(description="position at which the contacts touch (closing) or part (opening)")
    speed_zone: tuple[Length, Length] = Field(description="the two positions, in the order the contact passes them, "
                                              "between which the average speed is taken")
    damping_start: Length | None = Field(None, description="position at which the damping zone begins; default: no damping-zone duration")
    settle_tolerance: Length = Field(1e-3, gt=0.0, description="distance from the final rest position within which "
                                     "the motion counts as ended; default 1 mm")
    envelope: TravelEnvelope | None = Field(None, description="tolerance band the travel curve must stay in; "
                                            "default: none")

    @field_validator("speed_zone")
    @classmethod
    def _zone_in_travel_order(cls, zone: tuple[float, float]) -> tuple[float, float]:
        if zone[0] * zone[1] < 0.0 or abs(zone[1]) <= abs(zone[0]):
            raise ValueError("the speed zone's two positions must be in the order the contact passes them from its "
                             "start position: the second farther from it, on the same side, e.g. [230 mm, 250 mm]")
        return zone


# --- solver ---------------------------------------------------------------------------------------


class SolverSettings(Strict):
    t_end: Time = Field(gt=0.0, description="end time of the simulation")
    output_rate: Frequency | None = Field(None, gt=0.0, description="samples per second of the written histories; default: from the model's time scales, 1 kHz to 100 kHz (docs/model.md §8)")
    rtol: float = Field(1e-7, gt=0.0, lt=1.0, description="relative error tolerance per step")
    atol: float = Field(1e-10, gt=0.0, description="absolute tolerance on positions (m, rad) and velocities")
    max_step: Time = Field(1e-3, gt=0.0, description="largest step")
    min_step: Time = Field(1e-12, gt=0.0, description="smallest step (a rejected step at min_step stops the run)")
    initial_step: Time | None = Field(None, gt=0.0, description="first step size; default chosen by the solver")
    method: Literal["dopri5", "rosenbrock", "dop853"] = Field("dopri5", description="integration method: dopri5, the explicit Dormand–Prince 5(4); dop853, the explicit Dormand–Prince 8(5,3) with its 7th-order continuous extension, for smooth models at tight tolerances; rosenbrock, the linearly implicit ROS34PW2 (order 3) for models whose steps a stiff force holds short while the motion is slow, such as a squeeze film (docs/model.md §4)")

    @model_validator(mode="after")
    def _steps_ordered(self):
        if self.min_step >= self.max_step:
            raise ValueError("min_step must be smaller than max_step")
        return self


# --- tolerances (Monte Carlo sweeps) --------------------------------------------------------------


def _quantity(value: RawQuantity, what: str):
    try:
        return parse_quantity(value)
    except UnitError as exc:
        raise ValueError(f"{what}: {exc}") from None


class Tolerance(Strict):
    """A value drawn at random for each case of `clearsim sweep --sample N` (docs/sweeps.md).

    The bounds and moments take the unit of the value at `path` ('0.01 mm', or a bare number
    for a dimensionless value such as mu_d); the drawn value is applied as `--set path=value`.
    """

    path: str = Field(description="the `--set` path of the value, e.g. joints.A.clearance")
    distribution: Literal["uniform", "normal"] = Field(description="uniform between low and high, or normal with mean and std")
    low: RawQuantity | None = Field(None, description="uniform: lower bound; normal: optional lower truncation bound")
    high: RawQuantity | None = Field(None, description="uniform: upper bound; normal: optional upper truncation bound")
    mean: RawQuantity | None = Field(None, description="normal: mean value")
    std: RawQuantity | None = Field(None, description="normal: standard deviation, > 0")

    @model_validator(mode="after")
    def _parameters_fit(self):
        needed = ("low", "high") if self.distribution == "uniform" else ("mean", "std")
        missing = [key for key in needed if getattr(self, key) is None]
        if missing:
            raise ValueError(f"a {self.distribution} distribution needs {' and '.join(missing)}")
        if self.distribution == "uniform" and (self.mean is not None or self.std is not None):
            raise ValueError("a uniform distribution takes low and high, not mean or std")
        given = {key: _quantity(getattr(self, key), key) for key in ("low", "high", "mean", "std")
                 if getattr(self, key) is not None}
        first = next(iter(given.values()))
        if any(q.dimensionality != first.dimensionality for q in given.values()):
            raise ValueError(f"{' and '.join(given)} must have units of the same kind")
        if "low" in given and "high" in given and not given["low"] < given["high"]:
            raise ValueError("low must be smaller than high")
        if "std" in given and not given["std"].magnitude > 0:
            raise ValueError("std must be greater than 0")
        return self


# --- what bare numbers mean -----------------------------------------------------------------------


def _unit_of(kind: str):
    return Annotated[str, BeforeValidator(lambda unit: declared_unit(unit, kind))]


def _unit_field(kind: str):
    default = BASE_UNITS.get(kind) or DERIVED_UNITS[kind].replace("{", "").replace("}", "")
    return Field(None, description=f"unit of a bare {kind.replace('_', ' ')}; default {default}")


class Units(Strict):
    """`units:`: what the file's bare numbers mean (`units: SI` for every kind in SI). The base kinds not named
    are SI; the derived ones are built from the base units unless named too."""

    length: _unit_of("length") | None = _unit_field("length")
    mass: _unit_of("mass") | None = _unit_field("mass")
    time: _unit_of("time") | None = _unit_field("time")
    angle: _unit_of("angle") | None = _unit_field("angle")
    force: _unit_of("force") | None = _unit_field("force")
    speed: _unit_of("speed") | None = _unit_field("speed")
    acceleration: _unit_of("acceleration") | None = _unit_field("acceleration")
    angular_speed: _unit_of("angular_speed") | None = _unit_field("angular_speed")
    frequency: _unit_of("frequency") | None = _unit_field("frequency")
    inertia: _unit_of("inertia") | None = _unit_field("inertia")
    torque: _unit_of("torque") | None = _unit_field("torque")
    pressure: _unit_of("pressure") | None = _unit_field("pressure")
    spring_stiffness: _unit_of("spring_stiffness") | None = _unit_field("spring_stiffness")
    damping: _unit_of("damping") | None = _unit_field("damping")
    second_moment: _unit_of("second_moment") | None = _unit_field("second_moment")
    rotational_stiffness: _unit_of("rotational_stiffness") | None = _unit_field("rotational_stiffness")
    rotational_damping: _unit_of("rotational_damping") | None = _unit_field("rotational_damping")

    @model_validator(mode="before")
    @classmethod
    def _si_shorthand(cls, data):
        if isinstance(data, str):
            if data.strip().upper() == "SI":
                return {}
            raise ValueError(f"expected `SI` or a mapping of kinds to units such as {{length: mm, time: ms}}, "
                             f"got {data!r}")
        return data

    def system(self) -> UnitSystem:
        return unit_system(self.model_dump(exclude_none=True))


UNITS_JSON_SCHEMA = {"anyOf": [{"const": "SI"}, {"type": "object", "additionalProperties": False, "properties": {
    kind: {"type": "string", "description": field.description} for kind, field in Units.model_fields.items()}}]}


def declared_units(document) -> UnitSystem | None:
    """The units a document's `units:` block declares; None when it has none. An invalid block is reported by
    the validation of the file, whose bare numbers are then read as SI rather than each reported again."""
    written = document.get("units") if isinstance(document, dict) else None
    if written is None:
        return None
    try:
        return Units.model_validate(written).system()
    except ValidationError:
        return SI


def validate_mechanism(document) -> "Mechanism":
    """A mechanism document validated with its bare numbers read in its declared units (pydantic's
    ValidationError lists every problem)."""
    return Mechanism.model_validate(document, context={UNITS_CONTEXT: declared_units(document)})


def driven_kind(driver: "Driver", joints) -> str | None:
    """'length' or 'angle': the kind of the coordinate a driver moves (None: a joint that does not exist)."""
    if driver.joint is None:
        return "angle" if driver.coordinate == "angle" else "length"
    joint = next((j for j in joints if j.name == driver.joint), None)
    return None if joint is None else ("length" if joint.type == "prismatic" else "angle")


def _with_unit(value: RawQuantity | None, unit: str) -> RawQuantity | None:
    """A bare number as text in `unit`; text with its own unit, a word ('auto') and None unchanged."""
    number = bare_number(value)
    return f"{number!r} {unit}" if number is not None else value


def _motion_in_units(motion, kind: str, system: UnitSystem) -> None:
    rate_kind = "speed" if kind == "length" else "angular_speed"
    if isinstance(motion, StrokeMotion):
        motion.stroke = _with_unit(motion.stroke, system.unit(kind))
    elif isinstance(motion, ConstantSpeedMotion):
        motion.speed = _with_unit(motion.speed, system.unit(rate_kind))
    elif isinstance(motion, PolynomialMotion):
        second = system.to_si(1.0, "time")
        motion.coefficients = [system.to_si(c, kind) / second ** k for k, c in enumerate(motion.coefficients, 1)]


def _contact_in_units(contact: ContactSpec | None, exponent: float, system: UnitSystem) -> None:
    if contact is not None:
        contact.stiffness = _with_unit(contact.stiffness, system.contact_stiffness_unit(exponent))


# --- the file -------------------------------------------------------------------------------------


class Mechanism(Strict):
    """A planar mechanism: what the YAML file says, validated, in SI units."""

    name: str = Field("mechanism", description="title of the mechanism, shown in summaries and result files")
    description: str | None = Field(None, description="free text about the model")
    units: Annotated[Units | None, WithJsonSchema(UNITS_JSON_SCHEMA)] = Field(None, description="what bare numbers mean: `SI`, or units by kind such as "
                                "{length: mm, time: ms}; without it every non-zero dimensional value needs its unit")
    gravity: tuple[Acceleration, Acceleration] = Field((0.0, 0.0), description="gravitational acceleration [g_x, g_y], global frame; default no gravity")
    defaults: Defaults = Defaults()
    points: dict[str, Point] = Field(default_factory=dict, description="named global points at t = 0")
    bodies: list[Body] = Field(min_length=1)
    joints: list[Joint] = Field(default_factory=list)
    drivers: list[Driver] = Field(default_factory=list)
    forces: list[AppliedForce] = Field(default_factory=list)
    sensors: list[Sensor] = Field(default_factory=list)
    output: OutputSensors = OutputSensors()
    travel: TravelCurve | None = Field(None, description="travel-curve figures of a named displacement sensor in the run summary")
    solver: SolverSettings
    tolerances: list[Tolerance] = Field(
        default_factory=list, description="random distributions of values for `clearsim sweep --sample N`; ignored by `run`")
    # set on a flexible file's expansion (model/flexible.py), whose joints are in chain order: the assembly places its
    # constraint rows joint by joint in that order (assembly/build.py, arrays.row_place)
    _rows_along_the_chain: bool = PrivateAttr(False)

    @property
    def rows_along_the_chain(self) -> bool:
        return self._rows_along_the_chain

    @model_validator(mode="after")
    def _raw_quantities_in_declared_units(self, info: ValidationInfo):
        """Bare strokes, speeds, polynomial coefficients and contact stiffnesses, whose kind depends on the driven
        coordinate or the contact exponent, in the declared units (as text with the unit, or SI coefficients)."""
        system = declared_system(info.context)
        if system is None:
            return self
        for driver in self.drivers:
            kind = driven_kind(driver, self.joints)
            if kind is not None:
                _motion_in_units(driver.motion, kind, system)
        exponent = self.defaults.contact.exponent or DEFAULT_CONTACT.exponent
        _contact_in_units(self.defaults.contact, exponent, system)
        for joint in self.joints:
            if isinstance(joint, RevoluteJoint) and joint.contact is not None:
                _contact_in_units(joint.contact, joint.contact.exponent or exponent, system)
        return self

    def body(self, name: str) -> Body:
        return next(b for b in self.bodies if b.name == name)

    def joint(self, name: str):
        return next(j for j in self.joints if j.name == name)
