"""Values that are valid but almost certainly a misread unit: warnings, each with its place and the fix.

A bearing larger than the links it joins, a clearance out of proportion to its radius, a contact
stiffness or a Young's modulus far from any metal's, a driver that moves a point faster than a racing
engine's crank pin, a centre of mass far from the joints of its body. `clearsim validate` and `clearsim run`
print them before anything else; none stops a run (a test rig may really be unusual).
"""

from __future__ import annotations

import math
from itertools import combinations

import numpy as np

from clearsim.errors import InputError, Problem
from clearsim.model import schema
from clearsim.model.resolve import auto_stiffness, resolve_clearance

CLEARANCE_RATIO = (1e-5, 0.25)  # c / R_B of journal bearings: 0.5 µm to 12.5 mm on a 50 mm radius
STIFFNESS_FACTOR = 1e3  # a contact stiffness this many times above or below the Hertz value of its joint
YOUNGS_MODULUS = (1e6, 1.2e12)  # Pa: rubber to diamond
MAX_DRIVEN_SPEED = 40.0  # m/s: a racing engine's crank pin (18 000 rpm at 20 mm) moves at 38 m/s
CENTRE_FACTOR = 2.0  # a centre of mass farther than this many body sizes from every joint of its body
COINCIDENT = 1e-9  # of the mechanism's extent: joints closer than this are at one place


def warning_text(problems: list[Problem], loaded) -> str:
    """The warnings located in the file as its errors are (file:line:column, path, message, fix)."""
    return InputError(problems, loaded.path, loaded.source).report()


def plausibility_warnings(mechanism: schema.Mechanism) -> list[Problem]:
    """Every warning of a valid mechanism (one that passed the schema and the name checks)."""
    from clearsim.assembly.build import initial_poses, joint_points  # assembly imports the model: import late

    poses = initial_poses(mechanism)
    locations = {j.name: poses.to_global(*joint_points(poses, j, ())[::2]) for j in mechanism.joints}
    attached = _joint_locations_by_body(mechanism, locations)
    sizes = {body: _span(points) for body, points in attached.items()}
    return (_clearance_joint_warnings(mechanism, sizes) + _material_warnings(mechanism)
            + _driver_warnings(mechanism, locations, attached)
            + _centre_of_mass_warnings(mechanism, attached, sizes, _span(list(locations.values()))))


def _joint_locations_by_body(mechanism, locations) -> dict[str, list[np.ndarray]]:
    attached: dict[str, list[np.ndarray]] = {body.name: [] for body in mechanism.bodies}
    for joint in mechanism.joints:
        for body in joint.bodies:
            if body in attached:
                attached[body].append(locations[joint.name])
    return attached


def _span(points: list[np.ndarray]) -> float:
    """The largest distance between two of the points (0 for fewer than two)."""
    return max((float(np.linalg.norm(a - b)) for a, b in combinations(points, 2)), default=0.0)


def _length(metres: float) -> str:
    return f"{metres * 1e3:.3g} mm" if abs(metres) < 1.0 else f"{metres:.3g} m"


def _written(joint, defaults: schema.Defaults, path: tuple, key: str) -> tuple:
    """The path of a clearance joint's key: on the joint when it writes it, else in defaults."""
    return path + (key,) if getattr(joint, key, None) is not None else ("defaults", key)


# --- clearance joints -----------------------------------------------------------------------------


def _clearance_joint_warnings(mechanism, sizes: dict[str, float]) -> list[Problem]:
    warnings = []
    for index, joint in enumerate(mechanism.joints):
        parameters = resolve_clearance(joint, mechanism.defaults) if joint.type == "revolute" else None
        if parameters is None:
            continue
        path = ("joints", index)
        warnings += _bearing_size(joint, parameters, sizes, _written(joint, mechanism.defaults, path, "bearing_radius"))
        warnings += _clearance_ratio(parameters, path + (("clearance",) if joint.clearance is not None
                                                         else ("journal_radius",)))
        warnings += _contact_stiffness(joint, mechanism.defaults, parameters, path)
        warnings += _worn_pocket(joint, parameters, path)
    return warnings


def _worn_pocket(joint, parameters, path: tuple) -> list[Problem]:
    """A worn profile with a pocket tighter than the journal (its smallest radius of curvature below R_J): the journal
    touches it at two points, and where it comes to rest there a friction law with exact sticking (which sticks at the
    nearer rim only) makes the run crawl."""
    profile = joint.wear.profile if joint.wear is not None else None
    if profile is None:
        return []
    from clearsim.physics.wear import pocket_radius, pocket_words

    tightest = pocket_radius(profile.coefficients(), parameters.bearing_radius, parameters.journal_radius)
    if tightest is None:
        return []
    return [Problem(path + ("wear", "profile"), f"the worn bore of joint '{joint.name}' has a pocket tighter than its "
                    f"journal ({pocket_words(tightest, parameters.journal_radius)}): the journal touches it at two "
                    "points, and a friction law with exact sticking treats the nearer alone exactly, which stalls the "
                    "run where the journal lands on the pocket's axis, both points equally near",
                    "check the profile's units and harmonics: a journal wears a pocket at least as wide as itself "
                    "(fewer or smaller high harmonics widen it)")]


def _bearing_size(joint, parameters, sizes, path: tuple) -> list[Problem]:
    radius = parameters.bearing_radius
    for body in joint.bodies:
        if 0.0 < sizes.get(body, 0.0) < radius:
            return [Problem(path, f"bearing radius {_length(radius)} is larger than body '{body}' that the joint "
                            f"joins ({_length(sizes[body])} between its joints)",
                            "check the unit: a bearing is a fraction of its links, e.g. `bearing_radius: 10 mm`")]
    return []


def _clearance_ratio(parameters, path: tuple) -> list[Problem]:
    ratio = parameters.clearance / parameters.bearing_radius
    low, high = CLEARANCE_RATIO
    if low <= ratio <= high:
        return []
    return [Problem(path, f"c/R_B = {ratio:.2g} (clearance {_length(parameters.clearance)}, bearing radius "
                    f"{_length(parameters.bearing_radius)}); journal bearings have c/R_B between {low:g} and {high:g}",
                    "check the units of the clearance and the radii, e.g. `clearance: 0.1 mm`, "
                    "`bearing_radius: 10 mm`")]


def _contact_stiffness(joint, defaults, parameters, path: tuple) -> list[Problem]:
    if parameters.elastic != "point_hertz" or not math.isclose(parameters.exponent, 1.5):
        return []
    material = joint.material or defaults.material
    hertz = auto_stiffness(parameters.bearing_radius, parameters.journal_radius, material)
    ratio = parameters.stiffness / hertz
    if 1.0 / STIFFNESS_FACTOR <= ratio <= STIFFNESS_FACTOR:
        return []
    written = path + ("contact", "stiffness") if joint.contact is not None and joint.contact.stiffness is not None \
        else ("defaults", "contact", "stiffness")
    return [Problem(written, f"contact stiffness {parameters.stiffness:.3g} N/m^1.5 of joint '{joint.name}' is "
                    f"{ratio:.2g} times the Hertz value of its radii and material ({hertz:.3g} N/m^1.5)",
                    "check its unit (3.81e7 N/mm^1.5 is 1.2e12 N/m^1.5), or write `stiffness: auto`")]


def _material_warnings(mechanism) -> list[Problem]:
    places = [(("defaults", "material"), mechanism.defaults.material)]
    places += [(("joints", i, "material"), j.material) for i, j in enumerate(mechanism.joints)
               if getattr(j, "material", None) is not None]
    low, high = YOUNGS_MODULUS
    return [Problem(path + ("youngs_modulus",), f"Young's modulus {material.youngs_modulus:.3g} Pa is outside the "
                    f"range of solids ({low:g} Pa, rubber, to {high:g} Pa, diamond)",
                    "check its unit, e.g. `youngs_modulus: 207 GPa`")
            for path, material in places if not low <= material.youngs_modulus <= high]


# --- drivers --------------------------------------------------------------------------------------


def _driver_warnings(mechanism, locations, attached) -> list[Problem]:
    warnings = []
    for index, driver in enumerate(mechanism.drivers):
        kind = schema.driven_kind(driver, mechanism.joints)
        rate, key = _driven_rate(driver.motion, kind)
        if rate is None:
            continue
        lever = _lever(mechanism, driver, locations, attached) if kind == "angle" else 1.0
        speed = abs(rate) * lever
        if speed > MAX_DRIVEN_SPEED:
            what = f"{abs(rate):.4g} rad/s ({abs(rate) * 30 / math.pi:.4g} rpm) at {_length(lever)} from its " \
                   f"pivot" if kind == "angle" else f"{abs(rate):.4g} m/s"
            warnings.append(Problem(("drivers", index, "motion", key), f"the driver moves a point at {speed:.3g} m/s "
                                    f"({what}), faster than a racing engine's crank pin (~{MAX_DRIVEN_SPEED:g} m/s)",
                                    "check the unit: `300 rpm` is 31.4 rad/s, and a bare number in `units: SI` is "
                                    "rad/s or m/s"))
    return warnings


def _driven_rate(motion, kind: str | None) -> tuple[float | None, str]:
    """(peak rate of the driven coordinate in SI, the key that sets it), for the laws that state one."""
    from clearsim.units import to_si

    rate_kind = "speed" if kind == "length" else "angular_speed"
    if kind is None:
        return None, ""
    if isinstance(motion, schema.ConstantSpeedMotion):
        return to_si(motion.speed, rate_kind), "speed"
    if isinstance(motion, schema.StrokeMotion):
        return 1.5 * to_si(motion.stroke, kind) / motion.duration, "stroke"  # peak of S τ²(3 − 2τ) is 1.5 S/T
    return None, ""


def _lever(mechanism, driver, locations, attached) -> float:
    """The largest distance from a driven rotation's pivot (the joint, or the centre of mass) to a joint of the
    moving bodies."""
    if driver.joint is not None:
        joint = mechanism.joint(driver.joint)
        pivot, bodies = locations[joint.name], joint.bodies
    else:
        pivot, bodies = np.asarray(mechanism.body(driver.body).position, float), (driver.body,)
    return max((float(np.linalg.norm(p - pivot)) for b in bodies for p in attached.get(b, [])), default=0.0)


# --- bodies ---------------------------------------------------------------------------------------


def _centre_of_mass_warnings(mechanism, attached, sizes, extent: float) -> list[Problem]:
    warnings = []
    for index, body in enumerate(mechanism.bodies):
        points, centre = attached.get(body.name, []), np.asarray(body.position, float)
        size = sizes.get(body.name, 0.0)
        # joints at one place (a flexible link's half: its pin and its slide) span no size: the mechanism's is used
        scale = size if size > COINCIDENT * extent else extent
        if not points or scale <= 0.0:
            continue
        distance = min(float(np.linalg.norm(p - centre)) for p in points)
        if distance > CENTRE_FACTOR * scale:
            warnings.append(Problem(("bodies", index, "position"), f"the centre of mass of '{body.name}' is "
                                    f"{_length(distance)} from its nearest joint, while "
                                    f"{'its joints' if scale == size else 'the joints of the mechanism'} "
                                    f"span {_length(scale)}",
                                    "check the unit of `position`, e.g. `position: [25 mm, 43.3 mm]`"))
    return warnings
