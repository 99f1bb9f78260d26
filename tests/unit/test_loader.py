"""Loading a mechanism file: a valid slider-crank, located messages for bad files, `--set` overrides."""

import math

import pytest
import yaml

from clearsim.errors import InputError, Problem, SolverError
from clearsim.model.loader import SourceMap, load_mechanism, load_mechanism_text
from clearsim.model.resolve import resolve_clearance

SLIDER_CRANK = """\
name: slider-crank
defaults:
  bearing_radius: 10 mm
  material: {youngs_modulus: 207 GPa, poisson_ratio: 0.3}
  contact: {law: lankarani_nikravesh, restitution: 0.9, exponent: 1.5, stiffness: auto}
  friction: {law: stiction_step, mu_s: 0.2, mu_d: 0.16, v_s: 1e-4 m/s, v_d: 1e-2 m/s}
points:
  O: [0 m, 0 m]
  A: [0.05 m, 0 m]
  B: [0.17 m, 0 m]
bodies:
  - name: crank
    mass: 0.30 kg
    inertia: 0.0001 kg*m^2
    position: [0.025 m, 0 m]
  - name: rod
    mass: 0.21 kg
    inertia: 0.00025 kg*m^2
    position: [0.11 m, 0 m]
  - name: slider
    mass: 0.14 kg
    inertia: 0.0001 kg*m^2
    position: [0.17 m, 0 m]
joints:
  - {name: O, type: revolute, bodies: [ground, crank], at: O}
  - {name: A, type: revolute, bodies: [crank, rod], at: A, clearance: 0.1 mm}
  - {name: B, type: revolute, bodies: [rod, slider], at: B}
  - {name: guide, type: prismatic, bodies: [ground, slider], at: B, axis: [1, 0]}
drivers:
  - {name: crank_drive, joint: O, motion: {law: constant_speed, speed: 5000 rpm}}
sensors:
  - {name: slider_x, type: point_displacement, body: slider, direction: [1, 0]}
  - {name: slider_v, type: point_velocity, body: slider, direction: [1, 0]}
  - {name: slider_a, type: point_acceleration, body: slider, direction: [1, 0]}
  - {name: crank_angle, type: body_angle, body: crank}
output: {displacement: slider_x, velocity: slider_v, acceleration: slider_a}
solver: {t_end: 24 ms, output_rate: 100 kHz, rtol: 1e-7, max_step: 0.1 ms}
"""


def edited(old: str, new: str) -> str:
    assert SLIDER_CRANK.count(old) == 1, old
    return SLIDER_CRANK.replace(old, new)


def line_of(text: str, fragment: str) -> int:
    lines = [number for number, line in enumerate(text.splitlines(), 1) if fragment in line]
    assert len(lines) == 1, fragment
    return lines[0]


def load_error(text: str, *overrides: str) -> str:
    with pytest.raises(InputError) as info:
        load_mechanism_text(text, "sc.yaml", overrides=overrides)
    return str(info.value)


# --- a valid file ---------------------------------------------------------------------------------


def test_the_slider_crank_loads_in_si_units():
    loaded = load_mechanism_text(SLIDER_CRANK, "sc.yaml")
    m = loaded.mechanism
    assert [b.name for b in m.bodies] == ["crank", "rod", "slider"]
    assert m.body("crank").inertia == pytest.approx(1e-4) and m.points["B"] == pytest.approx((0.17, 0.0))
    assert m.drivers[0].motion.speed == "5000 rpm"  # converted where the driven coordinate is known
    assert (m.solver.t_end, m.solver.output_rate, m.solver.max_step) == pytest.approx((0.024, 1e5, 1e-4))
    assert m.joint("A").clearance == pytest.approx(1e-4)
    assert [resolve_clearance(m.joint(n), m.defaults) is None for n in ("O", "A", "B")] == [True, False, True]


def test_resolved_yaml_reproduces_the_mechanism():
    loaded = load_mechanism_text(SLIDER_CRANK, overrides=["joints.A.clearance=0.2mm"])
    again = load_mechanism_text(loaded.resolved_yaml)
    assert again.mechanism == loaded.mechanism and again.mechanism.joint("A").clearance == pytest.approx(2e-4)
    assert list(yaml.safe_load(loaded.resolved_yaml))[:3] == ["name", "defaults", "points"]  # file order kept


def test_loads_of_one_text_with_different_overrides_do_not_share_their_document_or_source_map():
    """A text is parsed once and each load gets its own copy: an override of one load is in no other."""
    changed = load_mechanism_text(SLIDER_CRANK, "sc.yaml", overrides=["joints.A.clearance=0.2mm", "bodies.rod.mass=1kg"])
    plain = load_mechanism_text(SLIDER_CRANK, "sc.yaml")
    assert changed.mechanism.joint("A").clearance == pytest.approx(2e-4) and changed.mechanism.body("rod").mass == 1.0
    assert plain.mechanism.joint("A").clearance == pytest.approx(1e-4) and plain.mechanism.body("rod").mass != 1.0
    assert plain.document is not changed.document and plain.source.overrides == {}
    assert changed.source.overrides and changed.source.positions == plain.source.positions
    plain.document["joints"][1]["clearance"] = "0.3 mm"  # what a caller does to its document stays its own
    assert load_mechanism_text(SLIDER_CRANK, "sc.yaml").mechanism.joint("A").clearance == pytest.approx(1e-4)


def test_file_path_and_base_dir(tmp_path):
    config = tmp_path / "sc.yaml"
    config.write_text(SLIDER_CRANK)
    loaded = load_mechanism(config)
    assert loaded.path == config and loaded.base_dir == tmp_path
    config.write_text(edited("mass: 0.21 kg", "mass: 0.21 m"))
    with pytest.raises(InputError) as info:
        load_mechanism(config)
    assert str(info.value).startswith(f"{config}:{line_of(SLIDER_CRANK, 'mass: 0.21 kg')}:11  bodies[1] 'rod' → mass")


def test_missing_file_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="cannot read the file"):
        load_mechanism(tmp_path / "nowhere.yaml")


def test_a_spring_with_a_negative_free_length_is_an_error():
    spring = "forces:\n  - {type: spring_damper, name: s, bodies: [ground, slider], stiffness: 1e4 N/m, free_length: -1 m}\n"
    message = load_error(SLIDER_CRANK + spring)
    assert "forces[0] 's' → free_length\n  must be at least 0, got '-1 m'" in message, message


def test_a_file_that_is_not_utf8_is_located_at_its_first_bad_byte(tmp_path):
    config = tmp_path / "sc.yaml"
    config.write_bytes(edited("name: slider-crank", "name: slider-crank  # caf\xe9").encode("latin-1"))
    with pytest.raises(InputError) as info:
        load_mechanism(config)
    assert str(info.value).startswith(f"{config}:1:26\n  cannot read the file: it is not UTF-8 text (byte 0xe9)")
    assert "save it as UTF-8" in str(info.value)


def test_source_map_locates_keys_items_and_names():
    source = SourceMap.from_text(SLIDER_CRANK)
    joints_line = line_of(SLIDER_CRANK, "{name: A,")
    assert source.positions[("joints", 1)] == (joints_line, 5)
    assert source.positions[("joints", 1, "bodies", 1)] == (joints_line, 47)  # the "rod" of [crank, rod]
    assert source.positions[("bodies", 1, "mass")] == (line_of(SLIDER_CRANK, "mass: 0.21"), 11)
    assert source.positions[("bodies",)] == (SLIDER_CRANK.splitlines().index("bodies:") + 1, 1)  # block: at the key
    assert source.names[("joints", 3)] == "guide" and source.names[("bodies", 0)] == "crank"
    assert source.locate(("joints", 1, "contact", "restitution")) == ((joints_line, 5), ("joints", 1))


# --- bad files: located message, exact text -------------------------------------------------------

BAD_FILES = {
    "malformed yaml": ("bodies: [ground, crank]", "bodies: [ground, crank", "{name: O,",
                       ["invalid YAML", "expected ',' or ']'"]),
    "tab": ("  O: [0 m, 0 m]", "\tO: [0 m, 0 m]", "\tO:", ["indent with spaces: YAML does not allow tabs"]),
    "duplicate key": ("mass: 0.21 kg", "mass: 0.21 kg\n    mass: 0.3 kg", "mass: 0.3 kg",
                      ["bodies[1] 'rod' → mass", "duplicate key 'mass' (first written at line"]),
    "unknown key": ("    mass: 0.14 kg", "    mas: 0.14 kg", "mas: 0.14",
                    ["bodies[2] 'slider' → mas", "unknown key 'mas'; did you mean 'mass'?", "allowed keys here: name"]),
    "unknown body": ("bodies: [crank, rod]", "bodies: [crank, rood]", "rood",
                     ["joints[1] 'A' → bodies[1]", "unknown body 'rood'; did you mean 'rod'?"]),
    "unknown point": ("at: A,", "at: Q,", "at: Q,", ["joints[1] 'A' → at", "unknown point 'Q'", "points:"]),
    "negative mass": ("mass: 0.30 kg", "mass: -0.30 kg", "mass: -0.30", ["must be greater than 0, got -0.3"]),
    "wrong unit": ("mass: 0.30 kg", "mass: 0.30 mm", "mass: 0.30", ["expected a mass (e.g. '3.67 kg'), got '0.30 mm'"]),
    "missing key": ("    mass: 0.30 kg\n", "", "- name: crank", ["bodies[0] 'crank'\n", "missing required key 'mass'"]),
    "bad joint type": ("type: prismatic", "type: prismatc", "prismatc",
                       ["joints[3] 'guide' → type", "unknown type 'prismatc'; did you mean 'prismatic'?",
                        "allowed: revolute, prismatic"]),
    "clearance >= bearing radius": ("clearance: 0.1 mm", "clearance: 10 mm", "clearance: 10 mm",
                                    ["clearance 10 mm must be smaller than the bearing radius 10 mm"]),
    "restitution above 1": ("restitution: 0.9", "restitution: 1.2", "restitution: 1.2",
                            ["defaults → contact → restitution", "must be at most 1, got 1.2"]),
    "restitution 0": ("at: A, clearance: 0.1 mm", "at: A, clearance: 0.1 mm, contact: {restitution: 0}",
                      "restitution: 0}", ["must be greater than 0, got 0", "0 < c_e <= 1"]),
    "duplicate joint name": ("{name: B,", "{name: A,", "bodies: [rod, slider]",
                             ["joints[2] 'A' → name", "duplicate joint name 'A' (also joints[1])"]),
    "driver on unknown joint": ("joint: O,", "joint: guid,", "joint: guid",
                                ["drivers[0] 'crank_drive' → joint", "unknown joint 'guid'; did you mean 'guide'?"]),
    "driver on clearance joint": ("joint: O,", "joint: A,", "crank_drive",
                                  ["joint 'A' has a clearance; a driver needs an ideal joint"]),
    "sensor on unknown body": ("body: crank}", "body: crankk}", "crankk",
                               ["sensors[3] 'crank_angle' → body", "unknown body 'crankk'; did you mean 'crank'?"]),
    "output of the wrong type": ("velocity: slider_v", "velocity: slider_x", "output:",
                                 ["output velocity must be a point_velocity sensor; 'slider_x' is a point_displacement",
                                  "point_velocity sensors in the file: slider_v"]),
    "missing friction parameter": ("mu_s: 0.2, ", "", "friction: {law",
                                   ["defaults → friction → law", "friction law 'stiction_step' needs mu_s"]),
    "v_s >= v_d": ("v_s: 1e-4 m/s", "v_s: 0.1 m/s", "v_s: 0.1", ["v_s = 0.1 m/s must be smaller than v_d = 0.01 m/s"]),
    "missing bearing radius": ("  bearing_radius: 10 mm\n", "", "clearance: 0.1 mm",
                               ["a clearance joint needs a bearing radius", "bearing_radius: 50 mm"]),
    "unknown motion law": ("law: constant_speed", "law: constant_sped", "crank_drive",
                           ["unknown law 'constant_sped'; did you mean 'constant_speed'?"]),
    "ground as a body name": ("- name: slider\n", "- name: ground\n", "name: ground", ["'ground' is reserved"]),
    "joint without location": ("bodies: [ground, crank], at: O}", "bodies: [ground, crank]}", "{name: O,",
                               ["joint 'O' has no location", "`at:`"]),
    "true as a number": ("speed: 5000 rpm", "speed: true", "speed: true",
                         ["drivers[0] 'crank_drive' → motion → speed", "got true", "write the number"]),
    "yes in a point": ("mass: 0.21 kg", "mass: [yes, 0]", "mass: [yes",
                       ["bodies[1] 'rod' → mass[0]", "got true"]),
    "no as a name": ("- name: slider\n", "- name: no\n", "name: no", ["bodies[2] 'no' → name", "got false",
                                                                      "quote a name"]),
    "top level not a mapping": (SLIDER_CRANK, "- bodies\n- joints\n", "- bodies",
                                ["the top level must be a mapping (key: value), found a list"]),
    "nested too deep": ("  O: [0 m, 0 m]", "  O: " + "[" * 5000 + "]" * 5000, "  O: [[",
                        ["invalid YAML: nested more than 50 levels deep", "brackets opened and never closed"]),
    "nan": ("mass: 0.30 kg", "mass: .nan", "mass: .nan", ["bodies[0] 'crank' → mass", "expected a finite number, got nan"]),
    "infinite direction": ("axis: [1, 0]", "axis: [.inf, 0]", "axis: [.inf", ["joints[3] 'guide' → axis[0]",
                                                                             "expected a finite number, got inf"]),
    "beyond floating point": ("position: [0.11 m, 0 m]", "position: [1e400 m, 0 m]", "1e400",
                              ["bodies[1] 'rod' → position[0]", "expected a finite number, got '1e400 m'"]),
    "control character": ("  O: [0 m, 0 m]", "  O: [0 m, 0\x07 m]", "\x07",
                          ["invalid YAML: unacceptable character #x0007", "printable text only"]),
    "slash in a name": ("- name: rod\n", "- name: rod/x\n", "name: rod/x",
                        ["bodies[1] 'rod/x' → name", "contains '/'", "e.g. `name: rod_x`"]),
    "dot in a name": ("{name: B,", "{name: B.1,", "{name: B.1,",
                      ["joints[2] 'B.1' → name", "contains '.'", "--set joints.<name>.clearance"]),
    "empty name": ("{name: slider_v,", "{name: '',", "{name: '',", ["sensors[1] '' → name", "a sensor name must not be empty"]),
    "name with a trailing space": ("{name: crank_drive,", "{name: 'crank_drive ',", "crank_drive ",
                                   ["drivers[0] 'crank_drive ' → name", "begins or ends with a space",
                                    "`name: crank_drive`"]),
    "recursive alias": ("defaults:\n  bearing_radius: 10 mm", "defaults: &d\n  bearing_radius: *d", "defaults: &d",
                        ["an alias (*name) refers to the block it is in"]),
}


@pytest.mark.parametrize("case", list(BAD_FILES), ids=list(BAD_FILES))
def test_bad_file_gives_located_message(case):
    old, new, marker, fragments = BAD_FILES[case]
    text = edited(old, new)
    message = load_error(text)
    assert f"sc.yaml:{line_of(text, marker)}:" in message, message
    for fragment in fragments:
        assert fragment in message, message
    assert "Value error" not in message and "pydantic" not in message


DEEP_TEXTS = {  # name: (text, deeper than MAX_NESTING = 50 levels)
    "brackets-51": ("a: " + "[" * 50 + "]" * 50, True), "empty-mapping-51": ("a: " + "[" * 49 + "{}" + "]" * 49, True),
    "flow-mappings": ("a: " + "{b: " * 60 + "1" + "}" * 60, True), "dashes": ("a:\n  " + "- " * 60 + "x\n", True),
    "block-mappings": ("".join("  " * i + f"k{i}:\n" for i in range(51)) + "  " * 51 + "v: 1\n", True),
    "brackets-50": ("a: " + "[" * 49 + "]" * 49, False), "empty-mapping-50": ("a: " + "[" * 48 + "{}" + "]" * 48, False)}


@pytest.mark.parametrize("name", list(DEEP_TEXTS))
def test_nesting_is_found_at_the_same_place_with_or_without_the_event_parse(name, monkeypatch):
    """A short text skips libyaml's event parse (nesting_problem) and is checked on its composed nodes instead
    (alias_problem): both must reject the same texts, at the same line and column."""
    from clearsim.model import loader

    text, too_deep = DEEP_TEXTS[name]

    def outcome():
        try:
            load_mechanism_text(text, name="deep.yaml")
        except InputError as exc:
            return str(exc)
        return "loaded"

    skipped = outcome()
    monkeypatch.setattr(loader, "COMPOSABLE_DEPTH", 0)
    parsed = outcome()
    assert skipped == parsed
    assert ("nested more than 50 levels deep" in parsed) == too_deep, parsed


def test_aliases_that_expand_beyond_reason_are_an_error_not_a_hang():
    levels = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    levels += [f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]" for k in range(1, 5)]  # 10^5 values
    message = load_error("\n".join(levels) + "\n" + SLIDER_CRANK)
    assert message.startswith("sc.yaml:1:") and "the aliases (*name) expand the file to more than 100000 values" in message


def test_a_direction_with_huge_components_is_normalised():
    m = load_mechanism_text(edited("axis: [1, 0]", "axis: [1e200, 1e200]")).mechanism
    assert m.joint("guide").axis == pytest.approx((math.sqrt(0.5), math.sqrt(0.5)))


def test_empty_file():
    assert "sc.yaml:1:1\n  the file is empty" in load_error("# nothing here\n")


def test_all_problems_of_a_file_are_reported_in_file_order():
    text = edited("bodies: [crank, rod]", "bodies: [crank, rood]").replace("mass: 0.30 kg", "mass: -1 kg")
    message = load_error(text)
    mass_line, body_line = line_of(text, "mass: -1 kg"), line_of(text, "rood")
    assert f"sc.yaml:{mass_line}:11  bodies[0] 'crank' → mass\n  must be greater than 0, got -1.0" in message
    assert f"sc.yaml:{body_line}:47  joints[1] 'A' → bodies[1]\n  unknown body 'rood'" in message
    assert message.index("got -1.0") < message.index("rood")


def test_name_checks_run_even_when_the_schema_fails():
    text = edited("solver: {t_end: 24 ms, output_rate: 100 kHz, rtol: 1e-7, max_step: 0.1 ms}\n", "")
    text = text.replace("body: crank}", "body: crankk}").replace("mass: 0.21 kg", "mass: 0.21 m")
    message = load_error(text)
    assert "missing required key 'solver'" in message and "unknown body 'crankk'" in message
    assert "expected a mass" in message
    assert "unknown body 'rod'" not in message  # the invalid body is reported once, not again where it is used


def test_a_path_not_in_the_file_points_at_its_nearest_ancestor_and_says_so():
    source = SourceMap.from_text(SLIDER_CRANK)
    error = InputError([Problem(("joints", 1, "contact", "restitution"), "too soft", "raise it")], "sc.yaml", source)
    line = line_of(SLIDER_CRANK, "{name: A,")
    assert str(error) == (f"sc.yaml:{line}:5  joints[1] 'A' → contact → restitution  (not in the file; shown at "
                          f"joints[1] 'A')\n  too soft\n  hint: raise it")


def test_solver_error_names_time_and_joint():
    error = SolverError("the step size fell below solver.min_step", time=0.01241, element="J", hint="lower min_step")
    assert str(error) == "at t = 12.41 ms, joint J: the step size fell below solver.min_step. lower min_step"


# --- overrides ------------------------------------------------------------------------------------

VALID_OVERRIDES = {
    "joints.A.clearance=0.05mm": (lambda m: m.joint("A").clearance, 5e-5),
    "joints.A.contact.restitution=0.8": (lambda m: m.joint("A").contact.restitution, 0.8),  # `contact:` created
    "joints.A.friction.mu_d=0.1": (lambda m: resolve_clearance(m.joint("A"), m.defaults).mu_d, 0.1),
    "bodies.rod.mass=6kg": (lambda m: m.body("rod").mass, 6.0),
    "solver.rtol=1e-8": (lambda m: m.solver.rtol, 1e-8),
    "solver.t_end=20ms": (lambda m: m.solver.t_end, 0.02),
    "solver.output_rate=50kHz": (lambda m: m.solver.output_rate, 5e4),
    "defaults.bearing_radius=20 mm": (lambda m: resolve_clearance(m.joint("A"), m.defaults).bearing_radius, 0.02),
    "drivers.crank_drive.motion.speed=100 rad/s": (lambda m: m.drivers[0].motion.speed, "100 rad/s"),
}


@pytest.mark.parametrize("override", list(VALID_OVERRIDES))
def test_override_changes_the_value(override):
    get, expected = VALID_OVERRIDES[override]
    before = get(load_mechanism_text(SLIDER_CRANK).mechanism) if "contact" not in override else None
    after = get(load_mechanism_text(SLIDER_CRANK, overrides=[override]).mechanism)
    assert after == pytest.approx(expected) if not isinstance(expected, str) else after == expected
    assert before != after


def test_clearance_zero_makes_the_joint_ideal():
    m = load_mechanism_text(SLIDER_CRANK, overrides=["joints.A.clearance=0"]).mechanism
    assert resolve_clearance(m.joint("A"), m.defaults) is None


def test_clearance_on_an_ideal_joint_makes_a_clearance_joint_with_the_defaults():
    m = load_mechanism_text(SLIDER_CRANK, overrides=["joints.B.clearance=0.05mm"]).mechanism
    p = resolve_clearance(m.joint("B"), m.defaults)
    assert (p.bearing_radius, p.journal_radius, p.clearance) == pytest.approx((0.01, 0.00995, 5e-5))
    assert (p.restitution, p.friction_law, p.mu_s, p.v_high) == (0.9, "stiction_step", 0.2, 1e-2)


def test_clearance_override_keeps_the_bearing_radius_of_a_joint_given_by_two_radii():
    text = edited("at: A, clearance: 0.1 mm", "at: A, bearing_radius: 12 mm, journal_radius: 11.5 mm")
    m = load_mechanism_text(text, overrides=["joints.A.clearance=0.02mm"]).mechanism
    p = resolve_clearance(m.joint("A"), m.defaults)
    assert (p.bearing_radius, p.journal_radius, p.clearance) == pytest.approx((0.012, 0.01198, 2e-5))


@pytest.mark.parametrize("override, fragments", [
    ("joints.X.clearance=0.1mm", ["no joint named 'X'", "joints in the file: O, A, B, guide"]),
    ("joints.gide.clearance=0.1mm", ["no joint named 'gide'; did you mean 'guide'?"]),
    ("bodies.rood.mass=1kg", ["no body named 'rood'; did you mean 'rod'?"]),
    ("joints.A.clearence=0.1mm", ["unknown key 'clearence' in joints.A; did you mean 'clearance'?"]),
    ("joints.guide.clearance=0.1mm", ["unknown key 'clearance' in joints.guide", "allowed keys here: name, type"]),
    ("joints.A.friction.mu_x=0.1", ["unknown key 'mu_x' in joints.A.friction"]),
    ("drivers.crank_drive.motion.sped=1", ["unknown key 'sped' in drivers.crank_drive.motion; did you mean 'speed'?"]),
    ("solver.tend=1ms", ["unknown key 'tend' in solver; did you mean 't_end'?"]),
    ("solver.t_end", ["an override is written path=value"]),
    ("solver.t_end.x=1", ["'solver.t_end' holds a single value, not keys"]),
])
def test_bad_override_is_reported_at_the_override(override, fragments):
    message = load_error(SLIDER_CRANK, override)
    assert message.startswith(f"in --set {override}\n"), message
    for fragment in fragments:
        assert fragment in message, message


def test_a_bad_value_from_an_override_is_reported_at_the_override():
    message = load_error(SLIDER_CRANK, "joints.A.clearance=20mm", "solver.t_end=20 kg")
    assert "in --set joints.A.clearance=20mm  joints[1] 'A' → clearance\n  clearance 20 mm must be smaller" in message
    assert "in --set solver.t_end=20 kg  solver → t_end\n  expected a time" in message


def test_override_values_are_read_as_yaml():
    m = load_mechanism_text(SLIDER_CRANK, overrides=["solver.atol=1e-12", "gravity=[0, -9.81 m/s^2]"]).mechanism
    assert m.solver.atol == 1e-12 and m.gravity == pytest.approx((0.0, -9.81))
    assert math.isclose(m.solver.rtol, 1e-7)


@pytest.mark.parametrize("unit, fragments", [
    ("'2 s'", ["forces[0] 'push' → time_unit", "expected a unit alone, such as 'ms', got '2 s'", "would scale"]),
    ("sekunde", ["forces[0] 'push' → time_unit", "unknown unit 'sekunde'"]),
])
def test_a_table_unit_is_a_unit_alone(unit, fragments):
    """`time_unit: '2 s'` was read as a factor of 2 on the time column (found by fuzzing)."""
    force = ("forces:\n  - {type: tabulated, name: push, body: slider, direction: [1, 0], file: push.csv, "
             f"time_unit: {unit}}}\n")
    message = load_error(SLIDER_CRANK + force)
    for fragment in fragments:
        assert fragment in message, message


def test_table_units_with_prefixes_are_units():
    from clearsim.model import schema
    from clearsim.model.loader import parse_yaml

    force = ("forces:\n  - {type: tabulated, name: push, body: slider, direction: [1, 0], file: push.csv, "
             "time_unit: ms, value_unit: kN}\n")
    motion = "  - {name: d2, joint: guide, motion: {law: table, file: s.csv, time_unit: min, value_unit: mm}}\n"
    document, _ = parse_yaml((SLIDER_CRANK + force).replace("sensors:\n", motion + "sensors:\n", 1), "sc.yaml")
    mechanism = schema.Mechanism.model_validate(document)
    assert (mechanism.forces[0].time_unit, mechanism.forces[0].value_unit) == ("ms", "kN")
    assert (mechanism.drivers[1].motion.time_unit, mechanism.drivers[1].motion.value_unit) == ("min", "mm")
