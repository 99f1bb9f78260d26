"""The YAML mechanism file as pydantic models: names, SI floats, no arrays.

Every value with a physical kind is converted to SI here (see clearsim.units);
unknown keys are errors (extra="forbid"). Cross-references between names
(bodies, points, joints, sensors) are checked in clearsim.model.references so
that all problems of a file are reported together, each with its location.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from clearsim.units import (
    Acceleration,
    Angle,
    AngularSpeed,
    Damping,
    Force,
    Frequency,
    Inertia,
    Length,
    Mass,
    Pressure,
    Speed,
    SpringStiffness,
    Time,
    Torque,
)

RawQuantity = Union[float, str]  # converted where its kind is known (a driver's stroke: m or rad)
Point = tuple[Length, Length]
Direction = tuple[float, float]
PointRef = Union[str, Point]  # a named point, or [x, y]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


def _unit_vector(value: Direction) -> Direction:
    norm = (value[0] ** 2 + value[1] ** 2) ** 0.5
    if norm < 1e-12:
        raise ValueError("a direction must not be the zero vector")
    return (value[0] / norm, value[1] / norm)


# --- materials, contact and friction -------------------------------------------------------------


class Material(Strict):
    youngs_modulus: Pressure = Field(207e9, gt=0, description="Young's modulus E (Pa)")
    poisson_ratio: float = Field(0.3, ge=0.0, lt=0.5, description="Poisson ratio ν")


class ContactSpec(Strict):
    """Normal contact law F = K δⁿ (1 + D(c_e) δ̇/δ̇⁻); every field optional at joint level."""

    law: Literal["lankarani_nikravesh", "hertz", "hunt_crossley", "flores"] | None = None
    restitution: float | None = Field(None, gt=0.0, le=1.0, description="coefficient of restitution c_e, 0 < c_e <= 1")
    exponent: float | None = Field(None, gt=0.0, le=3.0, description="force exponent n (1.5 for metals)")
    stiffness: RawQuantity | None = Field(
        None, description="K in N/m^n, or 'auto' to compute it from the radii and materials"
    )
    min_impact_speed: Speed | None = Field(
        None, gt=0.0, description="floor on the impact speed δ̇⁻ in the damping term (grazing guard)"
    )


DEFAULT_CONTACT = ContactSpec(
    law="lankarani_nikravesh", restitution=0.9, exponent=1.5, stiffness="auto", min_impact_speed=1e-3
)


class FrictionSpec(Strict):
    """Tangential friction law; the parameters a law needs are checked after merging with defaults."""

    law: Literal["none", "coulomb", "stiction_step", "ambrosio"] | None = None
    mu_s: float | None = Field(None, ge=0.0, description="static friction coefficient (stiction_step)")
    mu_d: float | None = Field(None, ge=0.0, description="dynamic friction coefficient (all laws)")
    v_s: Speed | None = Field(None, gt=0.0, description="stiction transition speed (stiction_step)")
    v_d: Speed | None = Field(None, gt=0.0, description="dynamic transition speed (stiction_step)")
    v_0: Speed | None = Field(None, ge=0.0, description="speed below which friction is zero (ambrosio)")
    v_1: Speed | None = Field(None, gt=0.0, description="speed above which friction is full (ambrosio)")


FRICTION_PARAMETERS = {
    "none": (),
    "coulomb": ("mu_d",),
    "stiction_step": ("mu_s", "mu_d", "v_s", "v_d"),
    "ambrosio": ("mu_d", "v_0", "v_1"),
}


class Defaults(Strict):
    bearing_radius: Length | None = Field(None, gt=0.0, description="bearing radius R_B of clearance joints")
    material: Material = Material()
    contact: ContactSpec = DEFAULT_CONTACT
    friction: FrictionSpec = FrictionSpec(law="none")


# --- bodies ---------------------------------------------------------------------------------------


class Body(Strict):
    name: str
    mass: Mass = Field(gt=0.0)
    inertia: Inertia = Field(gt=0.0, description="moment of inertia about the centre of mass")
    position: Point = Field(description="centre of mass at t = 0 (global); a guess refined by assembly")
    angle: Angle = 0.0
    velocity: tuple[Speed, Speed] = (0.0, 0.0)
    angular_velocity: AngularSpeed = 0.0
    points: dict[str, Point] = Field(default_factory=dict, description="body-fixed points, body frame, from the centre of mass")


# --- joints ---------------------------------------------------------------------------------------


class RevoluteJoint(Strict):
    """Pin joint; with `clearance` > 0 it is a clearance joint (first body bearing, second journal)."""

    name: str
    type: Literal["revolute"]
    bodies: tuple[str, str]
    at: PointRef | None = Field(None, description="a named global point or [x, y] at t = 0")
    points: tuple[str, str] | None = Field(None, description="named body points [on first, on second]")
    clearance: Length | None = Field(None, ge=0.0, description="radial clearance c = R_B - R_J; 0 or absent: ideal")
    bearing_radius: Length | None = Field(None, gt=0.0)
    journal_radius: Length | None = Field(None, gt=0.0)
    material: Material | None = None
    contact: ContactSpec | None = None
    friction: FrictionSpec | None = None
    initial_eccentricity: Point | None = Field(None, description="journal centre - bearing centre at t = 0")
    initial_velocity: tuple[Speed, Speed] | None = Field(
        None, description="velocity of the journal centre relative to the bearing centre at t = 0 (default 0)")


class PrismaticJoint(Strict):
    """Translational guide: the second body slides along `axis` of the first, without relative rotation."""

    name: str
    type: Literal["prismatic"]
    bodies: tuple[str, str]
    at: PointRef | None = Field(None, description="a point on the guide line (named or [x, y]) at t = 0")
    points: tuple[str, str] | None = None
    axis: Direction = Field(description="guide direction, global frame at t = 0")

    _unit_axis = field_validator("axis")(_unit_vector)


Joint = Annotated[Union[RevoluteJoint, PrismaticJoint], Field(discriminator="type")]


# --- drivers --------------------------------------------------------------------------------------


class StrokeMotion(Strict):
    """Meng 2015 eq. 16 generalised: s(t) = S τ²(3 − 2τ), τ = (t − t0)/T, held at S after."""

    law: Literal["stroke"]
    stroke: RawQuantity
    duration: Time = Field(gt=0.0)
    start: Time = 0.0


class ConstantSpeedMotion(Strict):
    law: Literal["constant_speed"]
    speed: RawQuantity


class PolynomialMotion(Strict):
    """s(t) = Σ_k c_k t^k, k = 1, 2, …, in SI units of the driven coordinate."""

    law: Literal["polynomial"]
    coefficients: list[float] = Field(min_length=1)


class TableMotion(Strict):
    """s(t) from a CSV file (cubic spline through the samples, value held after the last)."""

    law: Literal["table"]
    file: str
    time_column: Union[str, int] = 0
    value_column: Union[str, int] = 1
    time_unit: str = "s"
    value_unit: str | None = None


Motion = Annotated[
    Union[StrokeMotion, ConstantSpeedMotion, PolynomialMotion, TableMotion], Field(discriminator="law")
]


class Driver(Strict):
    """Prescribed motion of a joint's relative coordinate or of a body coordinate, from its t = 0 value."""

    name: str
    joint: str | None = None
    body: str | None = None
    coordinate: Literal["x", "y", "angle"] | None = None
    motion: Motion

    @model_validator(mode="after")
    def _one_target(self):
        if (self.joint is None) == (self.body is None):
            raise ValueError("a driver takes either `joint:` or `body:` (with `coordinate:`), not both or neither")
        if self.body is not None and self.coordinate is None:
            raise ValueError("a body driver needs `coordinate: x | y | angle`")
        return self


# --- applied forces -------------------------------------------------------------------------------


class ConstantForce(Strict):
    type: Literal["constant"]
    name: str
    body: str
    point: PointRef | None = None
    force: tuple[Force, Force] = (0.0, 0.0)
    torque: Torque = 0.0


class SpringDamper(Strict):
    """Linear spring-damper between two points: F = k (ℓ − ℓ0) + c ℓ̇ + preload, along the line."""

    type: Literal["spring_damper"]
    name: str
    bodies: tuple[str, str]
    at: tuple[PointRef, PointRef] | None = None
    points: tuple[str, str] | None = None
    stiffness: SpringStiffness = 0.0
    damping: Damping = 0.0
    free_length: Length | None = Field(None, description="ℓ0; default: the length at t = 0")
    preload: Force = 0.0


class TabulatedForce(Strict):
    type: Literal["tabulated"]
    name: str
    body: str
    point: PointRef | None = None
    direction: Direction
    file: str
    time_column: Union[str, int] = 0
    value_column: Union[str, int] = 1
    time_unit: str = "s"
    value_unit: str = "N"

    _unit_direction = field_validator("direction")(_unit_vector)


AppliedForce = Annotated[Union[ConstantForce, SpringDamper, TabulatedForce], Field(discriminator="type")]


# --- sensors --------------------------------------------------------------------------------------


class PointSensor(Strict):
    """A body point's displacement (from t = 0), velocity or acceleration along a global direction."""

    name: str
    type: Literal["point_displacement", "point_velocity", "point_acceleration"]
    body: str
    point: PointRef | None = None
    direction: Direction

    _unit_direction = field_validator("direction")(_unit_vector)


class BodySensor(Strict):
    name: str
    type: Literal["body_angle", "body_angular_velocity", "body_angular_acceleration"]
    body: str


class JointForceSensor(Strict):
    name: str
    type: Literal["joint_force"]
    joint: str
    component: Literal["x", "y", "magnitude", "normal", "friction"] = "magnitude"


Sensor = Annotated[Union[PointSensor, BodySensor, JointForceSensor], Field(discriminator="type")]


class OutputSensors(Strict):
    """Which sensors are 'the output' in summaries (the moving contact of a breaker)."""

    displacement: str | None = None
    velocity: str | None = None
    acceleration: str | None = None


# --- solver ---------------------------------------------------------------------------------------


class SolverSettings(Strict):
    t_end: Time = Field(gt=0.0)
    output_rate: Frequency = Field(1e5, gt=0.0, description="samples per second of the written histories")
    rtol: float = Field(1e-7, gt=0.0, lt=1.0)
    atol: float = Field(1e-10, gt=0.0, description="absolute tolerance on positions (m, rad) and velocities")
    max_step: Time = Field(1e-3, gt=0.0)
    min_step: Time = Field(1e-12, gt=0.0)
    initial_step: Time | None = Field(None, gt=0.0)

    @model_validator(mode="after")
    def _steps_ordered(self):
        if self.min_step >= self.max_step:
            raise ValueError("min_step must be smaller than max_step")
        return self


# --- the file -------------------------------------------------------------------------------------


class Mechanism(Strict):
    """A planar mechanism: what the YAML file says, validated, in SI units."""

    name: str = "mechanism"
    description: str | None = None
    gravity: tuple[Acceleration, Acceleration] = (0.0, 0.0)
    defaults: Defaults = Defaults()
    points: dict[str, Point] = Field(default_factory=dict, description="named global points at t = 0")
    bodies: list[Body] = Field(min_length=1)
    joints: list[Joint] = Field(default_factory=list)
    drivers: list[Driver] = Field(default_factory=list)
    forces: list[AppliedForce] = Field(default_factory=list)
    sensors: list[Sensor] = Field(default_factory=list)
    output: OutputSensors = OutputSensors()
    solver: SolverSettings

    def body(self, name: str) -> Body:
        return next(b for b in self.bodies if b.name == name)

    def joint(self, name: str):
        return next(j for j in self.joints if j.name == name)
