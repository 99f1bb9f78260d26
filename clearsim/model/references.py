"""Cross-references between names: bodies, points, joints, drivers, sensors, outputs.

The schema checks each item on its own; this module checks that the names they
use exist and fit together, and that every clearance joint resolves to numbers.
Every problem carries its YAML path and a hint saying what would fix it.
"""

from __future__ import annotations


from clearsim.errors import Problem, did_you_mean
from clearsim.model import schema
from clearsim.model.resolve import ResolveError, guide_friction_numbers, is_clearance_joint, resolve_clearance

GROUND = "ground"
KINDS = {"bodies": "body", "joints": "joint", "drivers": "driver", "forces": "force", "sensors": "sensor"}
OUTPUT_TYPES = {"displacement": "point_displacement", "velocity": "point_velocity",
                "acceleration": "point_acceleration"}


def _listing(names) -> str:
    names = [str(n) for n in names]
    if not names:
        return "none are defined"
    return ", ".join(names) if len(names) <= 12 else ", ".join(names[:12]) + ", ..."


class _Names:
    """The mechanism's names, and checks that a reference to one of them exists."""

    def __init__(self, mechanism: schema.Mechanism, known: dict[str, set] | None = None):
        self.mechanism = mechanism
        self.known = known or {}  # kind → names of items written in the file but invalid (reported already)
        self.bodies = {b.name: b for b in mechanism.bodies if b.name != GROUND}
        self.joints = {j.name: j for j in mechanism.joints}
        self.sensors = {s.name: s for s in mechanism.sensors}

    def body(self, name: str, path: tuple, ground_allowed: bool = True) -> list[Problem]:
        if name == GROUND:
            if ground_allowed:
                return []
            return [Problem(path, "the ground does not move", "name a moving body here")]
        if name in self.bodies or name in self.known.get("bodies", ()):
            return []
        candidates = [*self.bodies, *sorted(self.known.get("bodies", ())), *([GROUND] if ground_allowed else [])]
        return [Problem(path, f"unknown body '{name}'{did_you_mean(name, candidates)}",
                        f"bodies in the file: {_listing(candidates)}")]

    def global_point(self, reference, path: tuple) -> list[Problem]:
        """A `PointRef`: a name from the top-level `points:`, or [x, y] (always fine)."""
        points = self.mechanism.points
        if not isinstance(reference, str) or reference in points:
            return []
        return [Problem(path, f"unknown point '{reference}'{did_you_mean(reference, points)}",
                        f"define it under the top-level `points:` (defined: {_listing(points)}), or write [x, y]")]

    def body_point(self, body: str, point: str, path: tuple) -> list[Problem]:
        """A point named on a body (the ground's points are the top-level `points:`)."""
        if body == GROUND:
            table, where = self.mechanism.points, "the top-level `points:` (the ground's points)"
        elif body in self.bodies:
            table, where = self.bodies[body].points, f"`points:` of body '{body}'"
        else:
            return []  # an unknown or invalid body is reported already
        if point in table:
            return []
        return [Problem(path, f"body '{body}' has no point '{point}'{did_you_mean(point, table)}",
                        f"define it under {where} (defined: {_listing(table)})")]

    def joint(self, name: str, path: tuple) -> list[Problem]:
        if name in self.joints or name in self.known.get("joints", ()):
            return []
        return [Problem(path, f"unknown joint '{name}'{did_you_mean(name, self.joints)}",
                        f"joints in the file: {_listing(self.joints)}")]


def check_references(mechanism: schema.Mechanism, known: dict[str, set] | None = None) -> list[Problem]:
    """Every problem with the names a mechanism uses, and with its clearance joints.

    `known` (kind → names) are items of the file left out of `mechanism` because they are
    invalid: references to them are not reported again.
    """
    names = _Names(mechanism, known)
    problems = _unusable_names(mechanism) + _duplicate_names(mechanism) + _reserved_ground(mechanism)
    for index, joint in enumerate(mechanism.joints):
        problems += _check_joint(names, joint, ("joints", index), mechanism.defaults)
    for index, driver in enumerate(mechanism.drivers):
        problems += _check_driver(names, driver, ("drivers", index))
    problems += _doubly_driven(mechanism)
    for index, force in enumerate(mechanism.forces):
        problems += _check_force(names, force, ("forces", index))
    for index, sensor in enumerate(mechanism.sensors):
        problems += _check_sensor(names, sensor, ("sensors", index))
    problems += _check_output(names, mechanism.output)
    if mechanism.travel is not None:
        problems += _check_sensor_kind(names, mechanism.travel.sensor, ("travel", "sensor"), "point_displacement",
                                      "the travel sensor")
    return list(dict.fromkeys(problems))


# characters a name cannot hold: where the name goes, each would mean something else
NAME_SEPARATORS = {
    "/": "the result file stores each item under its name (`/bodies/<name>/…`), and / would open a group",
    ".": "`--set` reaches an item by its name (`--set joints.<name>.clearance=…`), and . separates the parts",
    "=": "`--set` splits path and value at the first =",
}


def name_problem(name: str, singular: str) -> tuple[str, str] | None:
    """(message, hint) when a name cannot serve as a result-file group and a `--set` path segment, else None."""
    if not name.strip():
        return f"a {singular} name must not be empty", f"name the {singular}, e.g. `name: {singular}_1`"
    if name != name.strip():
        return (f"the {singular} name {name!r} begins or ends with a space",
                f"write it without the spaces: `name: {name.strip()}`")
    for character, reason in NAME_SEPARATORS.items():
        if character in name:
            return (f"the {singular} name {name!r} contains {character!r}: {reason}",
                    f"use letters, digits, _ or - instead, e.g. `name: {name.replace(character, '_')}`")
    if any(not character.isprintable() for character in name):
        return f"the {singular} name {name!r} contains a control character", "use letters, digits, _ or - only"
    return None


def _unusable_names(mechanism: schema.Mechanism) -> list[Problem]:
    problems = []
    for kind, singular in KINDS.items():
        for index, item in enumerate(getattr(mechanism, kind)):
            found = name_problem(item.name, singular)
            if found is not None:
                problems.append(Problem((kind, index, "name"), *found))
    return problems


def _duplicate_names(mechanism: schema.Mechanism) -> list[Problem]:
    problems = []
    for kind, singular in KINDS.items():
        first: dict[str, int] = {}
        for index, item in enumerate(getattr(mechanism, kind)):
            if item.name in first:
                problems.append(Problem((kind, index, "name"), f"duplicate {singular} name '{item.name}' "
                                        f"(also {kind}[{first[item.name]}])", f"give each {singular} its own name"))
            first.setdefault(item.name, index)
    return problems


def _reserved_ground(mechanism: schema.Mechanism) -> list[Problem]:
    return [Problem(("bodies", index, "name"), "'ground' is reserved for the fixed frame",
                    "rename this body; joints refer to the fixed frame as `ground`")
            for index, body in enumerate(mechanism.bodies) if body.name == GROUND]


# --- joints ---------------------------------------------------------------------------------------


def _check_joint(names: _Names, joint, path: tuple, defaults: schema.Defaults) -> list[Problem]:
    problems = []
    for k, body in enumerate(joint.bodies):
        problems += names.body(body, path + ("bodies", k))
    if joint.bodies[0] == joint.bodies[1]:
        problems.append(Problem(path + ("bodies",), f"a joint connects two different bodies; both are '{joint.bodies[0]}'",
                                "name the two bodies the joint connects"))
    problems += _check_location(names, joint, path)
    if isinstance(joint, schema.RevoluteJoint):
        problems += _check_clearance(joint, path, defaults)
    return problems


def _check_location(names: _Names, joint, path: tuple) -> list[Problem]:
    """Exactly one of `at:` (a point of the drawing) and `points:` (a named point on each body)."""
    if joint.at is None and joint.points is None:
        return [Problem(path, f"joint '{joint.name}' has no location",
                        "add `at:` (a named point or [x, y]) or `points:` (a named point on each body)")]
    if joint.at is not None and joint.points is not None:
        return [Problem(path + ("points",), "a joint is located by `at:` or by `points:`, not both",
                        "remove one of them")]
    if joint.at is not None:
        return names.global_point(joint.at, path + ("at",))
    return [p for k in (0, 1) for p in names.body_point(joint.bodies[k], joint.points[k], path + ("points", k))]


def _check_clearance(joint: schema.RevoluteJoint, path: tuple, defaults: schema.Defaults) -> list[Problem]:
    if joint.lubrication is not None and not is_clearance_joint(joint):
        return [Problem(path + ("lubrication",), f"joint '{joint.name}' is lubricated but has no clearance",
                        "an oil film needs a gap: give the joint `clearance: 0.05 mm` (or `journal_radius:`), "
                        "or remove `lubrication:`")]
    try:
        resolve_clearance(joint, defaults)
    except ResolveError as exc:
        base = ("defaults",) if exc.in_defaults else path
        return [Problem(base + exc.path_suffix, exc.message, exc.hint)]
    return []


# --- drivers --------------------------------------------------------------------------------------


def _check_driver(names: _Names, driver: schema.Driver, path: tuple) -> list[Problem]:
    if driver.body is not None:
        return names.body(driver.body, path + ("body",), ground_allowed=False)
    problems = names.joint(driver.joint, path + ("joint",))
    joint = names.joints.get(driver.joint)
    if joint is None:
        return problems
    if joint.type not in ("revolute", "prismatic"):
        problems.append(Problem(path + ("joint",), f"joint '{joint.name}' is a {joint.type} joint",
                                "a driver moves a revolute or prismatic joint"))
    elif is_clearance_joint(joint):
        problems.append(Problem(path + ("joint",), f"joint '{joint.name}' has a clearance; a driver needs an ideal joint",
                                "remove the joint's clearance, or drive a body coordinate (`body:` and `coordinate:`)"))
    return problems


def _driven_target(driver: schema.Driver) -> tuple:
    if driver.joint is not None:
        return ("joint", driver.joint)
    return ("body", driver.body, driver.coordinate)


def _doubly_driven(mechanism: schema.Mechanism) -> list[Problem]:
    first: dict[tuple, str] = {}
    problems = []
    for index, driver in enumerate(mechanism.drivers):
        target = _driven_target(driver)
        if target in first:
            what = f"joint '{target[1]}'" if target[0] == "joint" else f"{target[2]} of body '{target[1]}'"
            problems.append(Problem(("drivers", index), f"{what} is driven already, by driver '{first[target]}'",
                                    "one driver per joint or body coordinate"))
        first.setdefault(target, driver.name)
    return problems


# --- forces, sensors, outputs ---------------------------------------------------------------------


def _check_force(names: _Names, force, path: tuple) -> list[Problem]:
    if isinstance(force, schema.GuideFriction):
        return _check_guide_friction(names, force, path)
    if not isinstance(force, schema.TWO_BODY):
        return names.body(force.body, path + ("body",), ground_allowed=False) + names.global_point(
            force.point, path + ("point",))
    kind = {schema.SpringDamper: "spring"}.get(type(force), force.type.replace("_", " "))
    problems = [p for k in (0, 1) for p in names.body(force.bodies[k], path + ("bodies", k))]
    if force.bodies[0] == force.bodies[1]:
        problems.append(Problem(path + ("bodies",), f"a {kind} connects two different bodies; both are "
                                f"'{force.bodies[0]}'", "name the two bodies it connects"))
    if isinstance(force, schema.RotationalSpring):
        return problems
    if force.at is not None and force.points is not None:
        return problems + [Problem(path + ("points",), f"a {kind}'s ends are given by `at:` or by `points:`, not both",
                                   "remove one of them")]
    if force.points is not None:
        problems += [p for k in (0, 1) for p in names.body_point(force.bodies[k], force.points[k], path + ("points", k))]
    if force.at is not None:
        problems += [p for k in (0, 1) for p in names.global_point(force.at[k], path + ("at", k))]
    return problems


def _check_guide_friction(names: _Names, force: schema.GuideFriction, path: tuple) -> list[Problem]:
    """The joint exists and is prismatic; the friction law resolves to numbers a smooth law integrates."""
    problems = names.joint(force.joint, path + ("joint",))
    joint = names.joints.get(force.joint)
    if joint is not None and not isinstance(joint, schema.PrismaticJoint):
        problems.append(Problem(path + ("joint",), f"joint '{force.joint}' is a {joint.type} joint; a guide friction "
                                "acts on a prismatic joint", "name a prismatic joint: "
                                + _listing(j.name for j in names.joints.values() if j.type == "prismatic")))
    try:
        guide_friction_numbers(force.friction)
    except ResolveError as exc:
        problems.append(Problem(path + ("friction",) + exc.path_suffix, exc.message, exc.hint))
    return problems


def _check_sensor(names: _Names, sensor, path: tuple) -> list[Problem]:
    if isinstance(sensor, schema.PointSensor):
        return names.body(sensor.body, path + ("body",), ground_allowed=False) + names.global_point(
            sensor.point, path + ("point",))
    if isinstance(sensor, schema.BodySensor):
        return names.body(sensor.body, path + ("body",), ground_allowed=False)
    # `normal`/`friction` of an ideal joint are its reaction magnitude and 0 (clearsim.solver.outputs), so that
    # a sweep down to clearance 0 keeps its sensors.
    return names.joint(sensor.joint, path + ("joint",))


def _check_output(names: _Names, output: schema.OutputSensors) -> list[Problem]:
    problems = []
    for role, expected in OUTPUT_TYPES.items():
        name = getattr(output, role)
        if name is not None:
            problems += _check_sensor_kind(names, name, ("output", role), expected, f"output {role}")
    return problems


def _check_sensor_kind(names: _Names, name: str, path: tuple, expected: str, role: str) -> list[Problem]:
    """`name` is a sensor of type `expected` (one left out of the file as invalid is reported already)."""
    fitting = [s.name for s in names.sensors.values() if s.type == expected]
    if name in names.known.get("sensors", ()):
        return []
    if name not in names.sensors:
        return [Problem(path, f"unknown sensor '{name}'{did_you_mean(name, names.sensors)}",
                        f"{expected} sensors in the file: {_listing(fitting)}")]
    if names.sensors[name].type != expected:
        return [Problem(path, f"{role} must be a {expected} sensor; '{name}' is a {names.sensors[name].type}",
                        f"{expected} sensors in the file: {_listing(fitting)}")]
    return []
