"""Unit strings → SI floats, and errors that name the expected kind."""

import math

import pytest
import yaml

from clearsim.units import UnitError, contact_stiffness_to_si, parse_quantity, to_si


@pytest.mark.parametrize("text, kind, si", [
    ("0.01 mm", "length", 1e-5),
    ("5000 rpm", "angular_speed", 5000 * 2 * math.pi / 60),  # 523.598... rad/s
    ("30 deg", "angle", math.pi / 6),  # 0.5236 rad
    ("207 GPa", "pressure", 207e9),
    ("85 ms", "time", 0.085),
    ("100 kHz", "frequency", 1e5),
    ("1e-4 m/s", "speed", 1e-4),
    ("0.044 kg*m^2", "inertia", 0.044),
    ("3.67 kg", "mass", 3.67),
])
def test_unit_strings_convert_to_si(text, kind, si):
    assert to_si(text, kind) == pytest.approx(si, rel=1e-12)


def test_rpm_and_degrees_by_hand():
    assert to_si("5000 rpm", "angular_speed") == pytest.approx(523.5987756, rel=1e-9)
    assert to_si("30 deg", "angle") == pytest.approx(0.5235987756, rel=1e-9)


def test_a_bare_number_is_si():
    assert to_si(0.25, "length") == 0.25
    assert to_si(3, "mass") == 3.0


def test_contact_stiffness_in_n_per_m_to_the_exponent():
    assert contact_stiffness_to_si("1.205e12 N/m^1.5", 1.5) == pytest.approx(1.205e12, rel=1e-12)
    # Meng 2015 Table 2: K = 3.81e7 in Adams' N/mm^1.5 is 3.81e7 · 1000^1.5 N/m^1.5
    assert contact_stiffness_to_si("3.81e7 N/mm^1.5", 1.5) == pytest.approx(3.81e7 * 1000**1.5, rel=1e-12)
    assert contact_stiffness_to_si(2e9, 1.0) == 2e9


def test_contact_stiffness_of_the_wrong_exponent_is_an_error():
    with pytest.raises(UnitError, match=r"N/m\^1\.5"):
        contact_stiffness_to_si("1e5 N/m", 1.5)


def test_wrong_kind_names_the_expected_kind():
    with pytest.raises(UnitError) as info:
        to_si("0.01 kg", "length")
    message = str(info.value)
    assert "expected a length" in message and "0.01 mm" in message and "'0.01 kg'" in message


def test_unknown_unit_is_an_error():
    with pytest.raises(UnitError, match="unknown unit"):
        to_si("3 furlongz", "length")


def test_a_boolean_is_not_a_number():
    with pytest.raises(UnitError):
        to_si(True, "length")


@pytest.mark.parametrize("value, kind", [
    (math.nan, "length"), (math.inf, "mass"), ("nan mm", "length"), ("-inf N", "force"),
    ("1e400 m", "length"),  # beyond floating point as written
    ("1e307 km", "length"),  # beyond floating point once converted to SI
    (10**400, "time"),  # an integer too large for a float
], ids=["nan", "inf", "nan mm", "-inf N", "1e400 m", "1e307 km", "10**400"])
def test_a_value_that_is_not_a_finite_number_is_an_error(value, kind):
    with pytest.raises(UnitError, match="expected a finite number"):
        to_si(value, kind)


def test_a_contact_stiffness_that_is_not_finite_is_an_error():
    with pytest.raises(UnitError, match="expected a finite number"):
        contact_stiffness_to_si("inf N/m^1.5", 1.5)


def test_the_unit_registry_loads_from_its_cache_and_converts_the_same(tmp_path):
    """pint's parsed definitions are cached (0.15 s saved per process); a registry from the cache converts alike."""
    from clearsim.units import new_registry

    fresh = new_registry(tmp_path / "pint")
    assert any((tmp_path / "pint").iterdir())  # the cache was written
    cached = new_registry(tmp_path / "pint")
    plain = new_registry(None)
    for text in ("0.01 mm", "5000 rpm", "30 deg", "6.6e10 N/m^1.5", "2 kN*m", "1 bar"):
        values = [float(r.Quantity(text).to_base_units().magnitude) for r in (fresh, cached, plain)]
        assert values[0] == values[1] == values[2], text


def test_a_cache_folder_that_cannot_be_made_or_is_damaged_only_costs_time(tmp_path):
    from clearsim.units import new_registry

    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert new_registry(blocker / "pint").Quantity("1 mm").to_base_units().magnitude == 0.001
    folder = tmp_path / "pint"
    new_registry(folder)
    for entry in folder.iterdir():
        entry.write_bytes(b"damaged")
    assert new_registry(folder).Quantity("1 mm").to_base_units().magnitude == 0.001


@pytest.mark.parametrize("text", ["0.8 0.9", "0.01;0.02", "0.01 mm 2", "0.1 mm 0.2 mm", "3 kg @ 2"])
def test_a_value_is_one_number_with_a_unit(text):
    """pint multiplies what it is given: '0.8 0.9' read as 0.72, '0.01;0.02' as 0.0002 — now a message."""
    with pytest.raises(UnitError, match="expected one number with a unit"):
        parse_quantity(text)


@pytest.mark.parametrize("text, si", [("6.6e10 N/m^1.5", 6.6e10), ("1e-4 kg m^2", 1e-4), ("5 1/s", 5.0),
                                      ("2 kN*m", 2000.0), ("-0.5 mm", -5e-4)])
def test_units_with_digits_and_products_still_read(text, si):
    assert float(parse_quantity(text).to_base_units().magnitude) == pytest.approx(si, rel=1e-15)


# --- a file's `units:` block: what its bare numbers mean ------------------------------------------

from pathlib import Path  # noqa: E402

from clearsim.errors import InputError  # noqa: E402
from clearsim.model.loader import load_mechanism_text  # noqa: E402
from clearsim.model.resolve import resolve_clearance  # noqa: E402
from clearsim.units import SI, unit_system  # noqa: E402

FLORES = (Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml").read_text()


def flores(*edits: tuple[str, str], units: str = "") -> str:
    text = FLORES
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return (units + "\n" if units else "") + text


def load_error(text: str, *overrides: str) -> str:
    with pytest.raises(InputError) as info:
        load_mechanism_text(text, "sc.yaml", overrides=overrides)
    return str(info.value)


@pytest.mark.parametrize("old, new, place, written", [
    ("bearing_radius: 10 mm", "bearing_radius: 10", "joints[2] 'slider_pin' → bearing_radius", "'10 mm' or '10 m'"),
    ("speed: 5000 rpm", "speed: 300", "drivers[0] 'crank_drive' → motion → speed", "'300 rpm', '300 rad/s' or '300 m/s'"),
    ("position: [0.11 m, 0 m]", "position: [25, 43.3]", "bodies[1] 'rod' → position[0]", "'25 mm' or '25 m'"),
    ("stiffness: auto", "stiffness: 1e12", "defaults → contact → stiffness", "'1e+12 N/m^1.5'"),
    ("t_end: 24 ms", "t_end: 0.024", "solver → t_end", "'0.024 ms' or '0.024 s'"),
    ("mass: 0.30 kg", "mass: '0.30'", "bodies[0] 'crank' → mass", "'0.3 kg'"),
], ids=["bearing_radius", "speed", "position", "contact stiffness", "t_end", "quoted number"])
def test_a_bare_number_on_a_dimensional_key_is_a_located_error_in_a_file_without_units(old, new, place, written):
    message = load_error(flores((old, new)))
    assert f"sc.yaml:" in message and place in message
    assert f"the bare number" in message and f"write {written}" in message and "`units: SI`" in message


def test_a_bare_zero_and_dimensionless_keys_need_no_unit():
    loaded = load_mechanism_text(flores(("position: [0.025 m, 0 m]", "position: [0.025 m, 0]")))
    assert loaded.mechanism.bodies[0].position == (0.025, 0.0)
    assert loaded.mechanism.defaults.material.poisson_ratio == 0.3 and loaded.mechanism.defaults.contact.restitution == 0.9


def test_polynomial_coefficients_need_declared_units():
    law = "motion: {law: polynomial, coefficients: [523.6]}"
    assert "polynomial coefficients" in load_error(flores(("motion: {law: constant_speed, speed: 5000 rpm}", law)))
    loaded = load_mechanism_text(flores(("motion: {law: constant_speed, speed: 5000 rpm}",
                                         "motion: {law: polynomial, coefficients: [30, 6]}"),
                                        units="units: {angle: deg, time: ms}"))
    coefficients = loaded.mechanism.drivers[0].motion.coefficients  # 30 deg/ms = 523.6 rad/s; 6 deg/ms² = 1.047e5 rad/s²
    assert coefficients == pytest.approx([30 * math.pi / 180 / 1e-3, 6 * math.pi / 180 / 1e-6], rel=1e-12)


def test_a_unit_alone_is_not_a_value():
    """`mass: kg` was read as 1 kg."""
    message = load_error(flores(("mass: 0.30 kg", "mass: kg")))
    assert "bodies[0] 'crank' → mass" in message and "a unit alone" in message and "'1 kg'" in message
    with pytest.raises(UnitError, match="a unit alone"):
        to_si("deg", "angle")


MILLIMETRE_FILE = [
    ("position: [0.025 m, 0 m]", "position: [25, 0]"),
    ("A: [0.05 m, 0 m]", "A: [50, 0]"),
    ("bearing_radius: 10 mm", "bearing_radius: 10"),
    ("journal_radius: 9.5 mm", "journal_radius: 9.5"),
    ("speed: 5000 rpm", "speed: 5000"),
    ("stiffness: auto", "stiffness: 3.81e7"),
    ("youngs_modulus: 207 GPa", "youngs_modulus: 207e3"),
    ("inertia: 0.0001 kg*m^2, position: [0.17 m, 0 m]", "inertia: 100, position: [170, 0]"),
    ("t_end: 24 ms", "t_end: 24"),
    ("max_step: 0.1 ms", "max_step: 0.1"),
]


def test_a_units_block_is_honoured_and_every_number_checked_against_its_si_value():
    text = flores(*MILLIMETRE_FILE, units="units: {length: mm, time: ms, angular_speed: rpm, inertia: kg*mm^2}")
    mechanism = load_mechanism_text(text).mechanism
    assert mechanism.bodies[0].position == pytest.approx((0.025, 0.0), rel=1e-12)
    assert mechanism.points["A"] == pytest.approx((0.05, 0.0), rel=1e-12)
    assert mechanism.bodies[2].inertia == pytest.approx(1e-4, rel=1e-12)  # 100 kg*mm^2
    assert mechanism.defaults.material.youngs_modulus == pytest.approx(207e9, rel=1e-12)  # 207e3 N/mm^2
    assert mechanism.solver.t_end == pytest.approx(0.024, rel=1e-12) and mechanism.solver.max_step == pytest.approx(1e-4)
    assert to_si(mechanism.drivers[0].motion.speed, "angular_speed") == pytest.approx(523.5987756, rel=1e-9)
    clearance = resolve_clearance(mechanism.joint("slider_pin"), mechanism.defaults)
    assert (clearance.bearing_radius, clearance.clearance) == pytest.approx((0.01, 0.0005), rel=1e-12)
    assert clearance.stiffness == pytest.approx(3.81e7 * 1000 ** 1.5, rel=1e-12)  # N/mm^1.5, Meng 2015 Table 2
    si = load_mechanism_text(FLORES).mechanism
    assert mechanism.bodies[0].mass == si.bodies[0].mass and mechanism.solver.output_rate == si.solver.output_rate


def test_units_si_is_the_explicit_shorthand_and_derived_kinds_follow_the_base_ones():
    mechanism = load_mechanism_text(flores(("bearing_radius: 10 mm", "bearing_radius: 0.01"), units="units: SI")).mechanism
    assert mechanism.joint("slider_pin").bearing_radius == 0.01
    system = unit_system({"length": "mm", "time": "ms", "force": "kN"})
    assert system.to_si(1.0, "speed") == pytest.approx(1.0)  # mm/ms
    assert system.to_si(1.0, "acceleration") == pytest.approx(1e3)  # mm/ms²
    assert system.to_si(1.0, "pressure") == pytest.approx(1e9)  # kN/mm²
    assert system.to_si(1.0, "spring_stiffness") == pytest.approx(1e6)  # kN/mm
    assert system.to_si(1.0, "torque") == pytest.approx(1.0)  # kN·mm
    assert system.to_si(1.0, "frequency") == pytest.approx(1e3)  # 1/ms
    assert unit_system({"speed": "km/h"}).to_si(36.0, "speed") == pytest.approx(10.0)  # a derived kind named itself
    assert all(SI.to_si(1.0, kind) == 1.0 for kind, _ in SI.units)


@pytest.mark.parametrize("block, message", [
    ("units: {lenght: mm}", "unknown key 'lenght'; did you mean 'length'?"),
    ("units: {time: kg}", "'kg' is not a unit of time"),
    ("units: {length: 2 mm}", "expected a unit alone, such as 'mm', got '2 mm'"),
    ("units: imperial", "expected `SI` or a mapping of kinds to units"),
], ids=["misspelt kind", "wrong kind", "a number in it", "not SI"])
def test_a_bad_units_block_is_a_located_error(block, message):
    error = load_error(flores(units=block))
    assert "sc.yaml:1:" in error and message in error


def test_set_bare_numbers_follow_the_declared_units_and_are_an_error_without():
    error = load_error(FLORES, "joints.slider_pin.clearance=0.1")
    assert "in --set joints.slider_pin.clearance=0.1" in error and "the bare number 0.1 has no unit" in error
    declared = flores(units="units: {length: mm}")
    loaded = load_mechanism_text(declared, overrides=["joints.slider_pin.clearance=0.1"])
    assert resolve_clearance(loaded.mechanism.joint("slider_pin"), loaded.mechanism.defaults).clearance == pytest.approx(1e-4)
    with_si = load_mechanism_text(FLORES, overrides=["units=SI", "joints.slider_pin.clearance=1e-4"])
    assert with_si.mechanism.joint("slider_pin").clearance == pytest.approx(1e-4)


def test_the_resolved_yaml_of_a_file_with_units_reloads_identically():
    text = flores(*MILLIMETRE_FILE, units="units: {length: mm, time: ms, angular_speed: rpm, inertia: kg*mm^2}")
    loaded = load_mechanism_text(text, overrides=["joints.slider_pin.clearance=0.2"])
    again = load_mechanism_text(loaded.resolved_yaml)
    assert again.mechanism == loaded.mechanism


def test_diagnose_writes_si_values_that_a_file_with_declared_units_reads_unchanged():
    """The candidates wrote bare SI floats into the document: 2e-4 (m) read as 2e-4 mm in a file of millimetres."""
    from clearsim.diagnose.candidates import candidates_for

    text = flores(("bearing_radius: 10 mm", "bearing_radius: 10"), ("journal_radius: 9.5 mm", "journal_radius: 9.5"),
                  units="units: {length: mm, time: ms}")
    loaded = load_mechanism_text(text)
    candidates = {(c.kind, c.target, c.parameter): c for c in
                  candidates_for(loaded.mechanism, loaded.document, ["clearance", "drive", "stiffness", "damping", "mass"])}

    def applied(kind, target, parameter, value):
        document = candidates[kind, target, parameter].applied(loaded.document, value)
        return load_mechanism_text(yaml.safe_dump(document)).mechanism

    joint = applied("clearance", "slider_pin", "clearance", 2e-4).joint("slider_pin")
    assert resolve_clearance(joint, loaded.mechanism.defaults).clearance == pytest.approx(2e-4, rel=1e-12)
    assert applied("drive", "crank_drive", "lag", 2e-3).drivers[0].lag == pytest.approx(2e-3, rel=1e-12)
    stiff = applied("stiffness", "slider_pin", "stiffness", 3e10)
    assert resolve_clearance(stiff.joint("slider_pin"), stiff.defaults).stiffness == pytest.approx(3e10, rel=1e-12)
    damper = applied("damping", "slider", "damping", 5.0).forces[-1]
    assert damper.damping == pytest.approx(5.0, rel=1e-12)
    assert abs(damper.at[0][0] - 1000.17) < 1e-9  # the far anchor: 1000 m along the output direction, in metres
    heavier = applied("mass", "crank", "mass factor", 1.5)
    assert heavier.bodies[0].mass == pytest.approx(0.45) and heavier.bodies[0].inertia == pytest.approx(1.5e-4)


def test_a_stored_mechanism_without_units_is_read_as_si_and_one_with_units_as_declared():
    """A result file's config_yaml written when bare numbers meant SI still loads (clearsim plot reads its clearances)."""
    from clearsim.model.loader import load_stored_mechanism

    old = flores(("bearing_radius: 10 mm", "bearing_radius: 0.01"), ("journal_radius: 9.5 mm", "journal_radius: 0.0095"))
    assert "units" in load_error(old)
    def clearance(text: str) -> float:
        mechanism = load_stored_mechanism(text, "run.h5 (config_yaml)").mechanism
        return resolve_clearance(mechanism.joint("slider_pin"), mechanism.defaults).clearance

    assert clearance(old) == pytest.approx(0.5e-3, rel=1e-12)
    millimetres = flores(("bearing_radius: 10 mm", "bearing_radius: 10"), ("journal_radius: 9.5 mm", "journal_radius: 9.5"),
                         units="units: {length: mm}")
    assert clearance(millimetres) == pytest.approx(0.5e-3, rel=1e-12)
