"""Named time histories from sampled chunks: the HDF5 layout of README and docs/reference.md as a dict path → (array, unit).

Contact modes (written per sample, int8): 0 free flight (no contact episode), 1 impact, 2
continuous contact. A contact episode runs from onset (δ rising through 0) to loss; it is an
*impact* when it ends within IMPACT_DURATION_FACTOR × the Hertz contact time of an impact at
its own δ̇⁻ and effective mass (t_H = 2.943 δ_max/δ̇⁻, δ_max = (5 m_eff δ̇⁻²/(4K))^(2/5)),
and *continuous contact* otherwise (including an episode still open at the end of the run).

The output rate, when the file does not set `solver.output_rate`, comes from the model's time scales
(`derived_output_rate`), and each dataset is stored in float64 or float32 by what its users need
(`stored_values`); docs/model.md §8 argues both.
"""

from __future__ import annotations

import math

import numpy as np

from clearsim.assembly.arrays import (
    CL_CLEARANCE, CL_EXPONENT, CL_MIN_IMPACT_SPEED, CL_STIFFNESS, CL_VISCOSITY, OFF_DIRECTION,
)
from clearsim.assembly.forces import STICK
from clearsim.assembly import hydraulics
from clearsim.assembly.drivelines import DASHPOT, GUIDE_FRICTION, driveline_histories, driveline_stored_energies
from clearsim.assembly.dynamics import (
    WORK_APPLIED, WORK_CONTACT, WORK_COUNT, WORK_DAMPING, WORK_DASHPOT, WORK_DRIVER, WORK_FRICTION, WORK_GUIDE_FRICTION,
    WORK_OIL, WORK_ORIFICE, WORK_SUPPLY, WORK_TANK,
)
from clearsim.assembly.system import SensorSpec, System
from clearsim.io.wear_results import wear_histories
from clearsim.model import schema
from clearsim.physics.cylindrical import POWER_LAW_CODES, max_penetrations
from clearsim.units import UnitError, to_si
from clearsim.solver.samples import (
    C_ECC_X, C_ECC_Y, C_FILM_ACTIVE, C_FILM_RADIAL, C_FILM_TANGENTIAL, C_FILM_THICKNESS, C_FRICTION, C_NORMAL,
    C_PENETRATION, C_RATE, C_SLIDING,
)

FREE_FLIGHT, IMPACT, CONTINUOUS_CONTACT = 0, 1, 2
IMPACT_DURATION_FACTOR = 3.0
HERTZ_DURATION = 2.943  # t_c = 2.943 δ_max / v (docs/model-contact.md)

# the default output rate (docs/model.md §8): enough samples per the shortest time scale of the model, within bounds
SAMPLES_PER_CONTACT = 20  # per Hertz contact duration t_c: the shape of an impact; a half sine's peak within 1.2 %
SAMPLES_PER_DRIVE = 1000  # per stroke time, or per revolution of a constant-speed rotary drive
REFERENCE_IMPACT_SPEED = 1.0  # m/s: the impact speed of the t_c estimate (t_c ∝ v^(-1/5): 0.1 m/s → 1.58 × longer)
LOWEST_DEFAULT_RATE, HIGHEST_DEFAULT_RATE = 1e3, 1e5  # Hz

# datasets a user needs to full precision (docs/model.md §8); every other floating-point history is stored as float32
FULL_PRECISION_SUFFIXES = ("/q", "/eccentricity", "/penetration", "/normal_force", "/friction_force", "/film_force")
FULL_PRECISION_GROUPS = ("sensors/", "energy/", "drives/")

COORDINATE_UNITS = {"q": "m, m, rad", "qd": "m/s, m/s, rad/s", "qdd": "m/s^2, m/s^2, rad/s^2"}


def contact_durations(system: System) -> np.ndarray:
    """t_H (hertz_durations) of each clearance joint at REFERENCE_IMPACT_SPEED, with the reduced mass m₁m₂/(m₁ + m₂)
    of its two bodies as m_eff (the ground counts as infinitely heavy): an estimate before the mechanism moves."""
    arrays = system.arrays
    joints = np.arange(arrays.clearance_bodies.shape[0])
    masses = np.where(arrays.clearance_bodies >= 0, arrays.mass[np.maximum(arrays.clearance_bodies, 0)], np.inf)
    reduced = 1.0 / np.sum(1.0 / masses, axis=1)
    return hertz_durations(system, joints, np.full(len(joints), REFERENCE_IMPACT_SPEED), reduced)


def drive_time_scales(mechanism: schema.Mechanism) -> list[float]:
    """The stroke time of each stroke drive and the revolution 2π/|ω| of each constant-speed rotary drive (other
    laws, and constant-speed linear drives, have no time scale of their own)."""
    revolute = {joint.name for joint in mechanism.joints if isinstance(joint, schema.RevoluteJoint)}
    scales = []
    for driver in mechanism.drivers:
        law = driver.motion
        if isinstance(law, schema.StrokeMotion):
            scales.append(law.duration)
        elif isinstance(law, schema.ConstantSpeedMotion) and (driver.joint in revolute or driver.coordinate == "angle"):
            try:
                speed = abs(to_si(law.speed, "angular_speed"))
            except UnitError:
                continue
            if speed > 0.0:
                scales.append(2.0 * math.pi / speed)
    return scales


def derived_output_rate(system: System) -> float:
    """The default output rate (Hz): SAMPLES_PER_CONTACT per the shortest contact duration and SAMPLES_PER_DRIVE per
    the shortest drive time scale, whichever needs more, within LOWEST_DEFAULT_RATE … HIGHEST_DEFAULT_RATE."""
    needed = [SAMPLES_PER_CONTACT / t for t in contact_durations(system)]
    needed += [SAMPLES_PER_DRIVE / t for t in drive_time_scales(system.mechanism)]
    return float(np.clip(max(needed, default=LOWEST_DEFAULT_RATE), LOWEST_DEFAULT_RATE, HIGHEST_DEFAULT_RATE))


def output_rate(system: System) -> float:
    """Samples per second written: the file's `solver.output_rate`, or derived_output_rate when it sets none."""
    explicit = system.mechanism.solver.output_rate
    return float(explicit) if explicit is not None else derived_output_rate(system)


def output_acceleration_point(system: System) -> tuple[float, float, float, float, float]:
    """(body index, point x, y in the body frame, direction x, y) of the `output.acceleration` sensor, whose peak the
    integrator tracks at every step; body −1 when the mechanism names none."""
    spec = next((spec for spec in system.sensors
                 if spec.name == system.output.acceleration and spec.kind == "point_acceleration"), None)
    if spec is None:
        return (-1.0, 0.0, 0.0, 0.0, 0.0)
    return (float(spec.body), *map(float, spec.point), *map(float, spec.direction))


def full_precision(name: str) -> bool:
    """Whether a dataset is stored in float64 (docs/model.md §8)."""
    return name == "time" or name.startswith(FULL_PRECISION_GROUPS) or name.endswith(FULL_PRECISION_SUFFIXES)


def stored_values(name: str, values: np.ndarray) -> np.ndarray:
    """The values as the result file stores them: float32 unless `full_precision(name)`; integers as they are."""
    if values.dtype == np.float64 and not full_precision(name):
        return values.astype(np.float32)
    return values


def _rotate(angle, vectors):
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * vectors[..., 0] - s * vectors[..., 1], s * vectors[..., 0] + c * vectors[..., 1]], axis=-1)


def hertz_durations(system: System, joints: np.ndarray, impact_speeds: np.ndarray,
                    effective_masses: np.ndarray) -> np.ndarray:
    """t_H = 2.943 δ_max/v (s) of an impact of each clearance joint at δ̇⁻ (at least its min_impact_speed) with its
    effective mass; δ_max of a cylindrical law from its own energy (cylindrical.law_max_penetration)."""
    params = system.arrays.clearance_params[joints]
    speed = np.maximum(impact_speeds, params[:, CL_MIN_IMPACT_SPEED])
    exponent = params[:, CL_EXPONENT]
    depth = (5.0 * effective_masses * speed**2 / (4.0 * params[:, CL_STIFFNESS])) ** (1.0 / (exponent + 1.0))
    laws = system.arrays.clearance_laws[joints, 3]
    other = np.isin(laws, POWER_LAW_CODES, invert=True)
    if other.any():
        depth[other] = max_penetrations(laws[other], np.asarray(effective_masses, float)[other], speed[other],
                                        params[other, CL_STIFFNESS], exponent[other], params[other, CL_CLEARANCE])
    return HERTZ_DURATION * depth / speed


def classify_episodes(system: System, episodes) -> np.ndarray:
    """IMPACT or CONTINUOUS_CONTACT for each logged contact episode."""
    hertz_time = hertz_durations(system, episodes.joint, episodes.impact_speed, episodes.effective_mass)
    duration = episodes.loss - episodes.onset
    short = np.isfinite(duration) & (duration <= IMPACT_DURATION_FACTOR * hertz_time)
    return np.where(short, IMPACT, CONTINUOUS_CONTACT).astype(np.int8)


def sample_modes(episode_kinds: np.ndarray, sample_episodes: np.ndarray) -> np.ndarray:
    """(S, nc) int8 mode per sample from the episode each sample belongs to."""
    modes = np.zeros(sample_episodes.shape, np.int8)
    inside = sample_episodes >= 0
    modes[inside] = episode_kinds[sample_episodes[inside]]
    return modes


def body_histories(system: System, chunk) -> dict:
    n = system.coordinate_count
    out = {}
    for b, name in enumerate(system.body_names):
        columns = slice(3 * b, 3 * b + 3)
        out[f"bodies/{name}/q"] = (chunk.states[:, :n][:, columns], COORDINATE_UNITS["q"])
        out[f"bodies/{name}/qd"] = (chunk.states[:, n:2 * n][:, columns], COORDINATE_UNITS["qd"])
        out[f"bodies/{name}/qdd"] = (chunk.accelerations[:, columns], COORDINATE_UNITS["qdd"])
    return out


def ideal_joint_reactions(system: System, chunk) -> dict:
    """Force on the second body of each ideal joint (global frame), from λ; driver efforts."""
    out = {}
    for k, name in enumerate(system.pin_joints):
        out[f"joints/{name}/reaction"] = (chunk.multipliers[:, 2 * k:2 * k + 2], "N")
    n_pin_rows = 2 * len(system.pin_joints)
    arrays = system.arrays
    for name, offset in system.prismatic_joints:
        guide = arrays.offset_bodies[offset, 0]
        angle = chunk.states[:, 3 * guide + 2] if guide >= 0 else np.zeros(len(chunk.times))
        normal = _rotate(angle, arrays.offset_params[offset, OFF_DIRECTION:OFF_DIRECTION + 2][None, :])
        out[f"joints/{name}/reaction"] = (-normal * chunk.multipliers[:, n_pin_rows + offset][:, None], "N")
    for name, row in system.drivers:
        out[f"drivers/{name}/effort"] = (-chunk.multipliers[:, row], "N or N*m")
    return out


def clearance_histories(system: System, chunk, modes: np.ndarray) -> dict:
    out = {}
    for k, name in enumerate(system.clearance_joints):
        contact = chunk.contact[:, k, :]
        out[f"joints/{name}/eccentricity"] = (contact[:, [C_ECC_X, C_ECC_Y]], "m")
        out[f"joints/{name}/penetration"] = (contact[:, C_PENETRATION], "m")
        out[f"joints/{name}/penetration_rate"] = (contact[:, C_RATE], "m/s")
        out[f"joints/{name}/normal_force"] = (contact[:, C_NORMAL], "N")
        out[f"joints/{name}/friction_force"] = (contact[:, C_FRICTION], "N")
        out[f"joints/{name}/sliding_velocity"] = (contact[:, C_SLIDING], "m/s")
        out[f"joints/{name}/mode"] = (modes[:, k], "0 free, 1 impact, 2 contact")
        out[f"joints/{name}/stick"] = ((chunk.modes[:, k] == STICK).astype(np.int8), "1 sticking (v_t = 0), 0 not")
        if system.arrays.clearance_params[k, CL_VISCOSITY] > 0.0:
            out |= film_histories(name, contact)
    return out


def film_histories(joint: str, contact: np.ndarray) -> dict:
    """The oil film of a lubricated joint from its (S, CONTACT_FIELDS) contact fields: its force on the journal along
    (n, t) of the eccentricity frame (zero while the dry laws act), the thinnest film c − |e|, and which acts."""
    return {f"joints/{joint}/film_force": (contact[:, [C_FILM_RADIAL, C_FILM_TANGENTIAL]], "N"),
            f"joints/{joint}/film_thickness": (contact[:, C_FILM_THICKNESS], "m"),
            f"joints/{joint}/film_active": (contact[:, C_FILM_ACTIVE].astype(np.int8), "1 film acts, 0 dry contact laws")}


def driveline_dissipations(system: System) -> dict[str, int]:
    """{energy name: WORK slot} of the dissipations of the driveline element kinds the model has (a model without
    dashpots writes no `dashpot_dissipated`)."""
    kinds = set(system.arrays.driveline_kinds[:, 0].tolist())
    slots = {DASHPOT: ("dashpot_dissipated", WORK_DASHPOT), GUIDE_FRICTION: ("guide_friction_dissipated", WORK_GUIDE_FRICTION)}
    return dict(slots[kind] for kind in sorted(kinds & slots.keys()))


def energy_histories(system: System, chunk, initial_energy: float) -> dict:
    n = system.coordinate_count
    work = chunk.states[:, 2 * n:]
    named = {
        "kinetic": chunk.kinetic, "potential": chunk.potential,
        "contact_dissipated": work[:, WORK_CONTACT], "friction_dissipated": work[:, WORK_FRICTION],
        "damping_dissipated": work[:, WORK_DAMPING], "driver_work": work[:, WORK_DRIVER],
        "applied_work": work[:, WORK_APPLIED],
    } | {name: work[:, slot] for name, slot in driveline_dissipations(system).items()}
    named |= driveline_stored_energies(system, chunk.states)  # parts of the potential: not in the balance again
    if system.hydraulic_cylinders:
        named |= {"hydraulic_supply_work": work[:, WORK_SUPPLY], "hydraulic_tank_work": work[:, WORK_TANK],
                  "orifice_dissipated": work[:, WORK_ORIFICE], "oil_compression": work[:, WORK_OIL]}
    named["balance_error"] = (chunk.kinetic + chunk.potential - initial_energy - work[:, WORK_DRIVER]
                              - work[:, WORK_APPLIED] + work[:, WORK_CONTACT] + work[:, WORK_FRICTION]
                              + work[:, WORK_DAMPING] - work[:, WORK_SUPPLY] + work[:, WORK_TANK]
                              + work[:, WORK_ORIFICE] + work[:, WORK_OIL] + work[:, WORK_DASHPOT]
                              + work[:, WORK_GUIDE_FRICTION])
    return {f"energy/{key}": (value, "J") for key, value in named.items()}


def _point_kinematics(spec: SensorSpec, n: int, chunk):
    """Global position, velocity and acceleration of a sensor's body point."""
    b = spec.body
    q, qd, qdd = chunk.states[:, 3 * b:3 * b + 3], chunk.states[:, n + 3 * b:n + 3 * b + 3], chunk.accelerations[:, 3 * b:3 * b + 3]
    arm = _rotate(q[:, 2], np.asarray(spec.point)[None, :])
    turned = np.stack([-arm[:, 1], arm[:, 0]], axis=1)
    position = q[:, :2] + arm
    velocity = qd[:, :2] + qd[:, 2:3] * turned
    acceleration = qdd[:, :2] + qdd[:, 2:3] * turned - qd[:, 2:3] ** 2 * arm
    return position, velocity, acceleration


SENSOR_UNITS = {"point_displacement": "m", "point_velocity": "m/s", "point_acceleration": "m/s^2",
                "body_angle": "rad", "body_angular_velocity": "rad/s", "body_angular_acceleration": "rad/s^2"}


def sensor_value(system: System, spec: SensorSpec, chunk, joint_outputs: dict, origin: np.ndarray) -> tuple:
    """(values, unit) of one sensor over the chunk; `origin` is the point's position at t = 0."""
    n = system.coordinate_count
    if spec.kind.startswith("point_"):
        position, velocity, acceleration = _point_kinematics(spec, n, chunk)
        vector = {"point_displacement": position - origin, "point_velocity": velocity,
                  "point_acceleration": acceleration}[spec.kind]
        return vector @ np.asarray(spec.direction), SENSOR_UNITS[spec.kind]
    if spec.kind.startswith("body_"):
        column = {"body_angle": chunk.states[:, 3 * spec.body + 2],
                  "body_angular_velocity": chunk.states[:, n + 3 * spec.body + 2],
                  "body_angular_acceleration": chunk.accelerations[:, 3 * spec.body + 2]}[spec.kind]
        return column, SENSOR_UNITS[spec.kind]
    return joint_force_component(spec, joint_outputs), "N"


def eccentricity_frame(eccentricity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, t) per sample: n = e/|e| from the bearing centre to the journal's, t = n turned by +90°; a centred journal
    takes n = x, as the solver does (assembly/forces.clearance_kinematics)."""
    length = np.linalg.norm(eccentricity, axis=1, keepdims=True)
    normal = np.where(length > 1e-300, eccentricity / np.maximum(length, 1e-300), [1.0, 0.0])
    return normal, np.stack([-normal[:, 1], normal[:, 0]], axis=1)


def joint_force_component(spec: SensorSpec, joint_outputs: dict) -> np.ndarray:
    """A joint's force component; an ideal joint's 'normal' force is its reaction magnitude, its friction 0; a
    lubricated joint's x, y and magnitude include its oil film's force, its normal and friction are the dry contact's."""
    prefix = f"joints/{spec.joint}/"
    if spec.component in ("normal", "friction") and prefix + "normal_force" in joint_outputs:
        return joint_outputs[prefix + f"{spec.component}_force"][0]
    if prefix + "reaction" in joint_outputs:
        force = joint_outputs[prefix + "reaction"][0]
        if spec.component == "friction":
            return np.zeros(len(force))
        if spec.component == "normal":
            return np.linalg.norm(force, axis=1)
    else:  # clearance joint: the contact force on the journal in global components, and a lubricated joint's film
        normal, tangent = eccentricity_frame(joint_outputs[prefix + "eccentricity"][0])
        force = (-joint_outputs[prefix + "normal_force"][0][:, None] * normal
                 + joint_outputs[prefix + "friction_force"][0][:, None] * tangent)
        if prefix + "film_force" in joint_outputs:
            film = joint_outputs[prefix + "film_force"][0]
            force = force + film[:, :1] * normal + film[:, 1:] * tangent
    if spec.component == "x":
        return force[:, 0]
    if spec.component == "y":
        return force[:, 1]
    return np.linalg.norm(force, axis=1)


def sensor_origins(system: System) -> dict[str, np.ndarray]:
    """Each point sensor's global position at t = 0 (displacements are measured from it)."""
    origins = {}
    for spec in system.sensors:
        if spec.kind.startswith("point_"):
            q = system.q0[3 * spec.body:3 * spec.body + 3]
            origins[spec.name] = q[:2] + _rotate(np.array([q[2]]), np.asarray(spec.point)[None, :])[0]
    return origins


def chunk_outputs(system: System, chunk, modes: np.ndarray, initial_energy: float) -> dict:
    """Every dataset of the result file for one chunk (except /time)."""
    out = body_histories(system, chunk)
    joints = ideal_joint_reactions(system, chunk) | clearance_histories(system, chunk, modes)
    out |= joints
    out |= energy_histories(system, chunk, initial_energy)
    n = system.coordinate_count
    out |= hydraulics.drive_histories(system.hydraulic_cylinders, system.arrays.hydraulic_bodies,
                                      system.arrays.hydraulic_params, chunk.states[:, :n],
                                      chunk.states[:, 2 * n + WORK_COUNT:])
    out |= driveline_histories(system, chunk.times, chunk.states)
    out |= wear_histories(system, chunk.states)
    out["constraints/violation"] = (chunk.violation, "m")
    origins = sensor_origins(system)
    for spec in system.sensors:
        out[f"sensors/{spec.name}"] = sensor_value(system, spec, chunk, joints, origins.get(spec.name))
    return out


def stored_outputs(outputs: dict) -> dict:
    """chunk_outputs' datasets in the precision the file stores each in (stored_values)."""
    return {name: (stored_values(name, values), unit) for name, (values, unit) in outputs.items()}
