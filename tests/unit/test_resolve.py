"""Clearance description → contact numbers: radii, merging over defaults, friction rules, stiffness."""

import math

import pytest

from clearsim.model.resolve import ResolveError, resolve_clearance
from clearsim.model.schema import Defaults, RevoluteJoint

STEEL_E, STEEL_NU = 207e9, 0.3  # Pa, -
TABLE_2_FRICTION = {"law": "stiction_step", "mu_s": 0.2, "mu_d": 0.16, "v_s": "1e-4 m/s", "v_d": "1e-2 m/s"}


def joint(**fields) -> RevoluteJoint:
    return RevoluteJoint.model_validate({"name": "J", "type": "revolute", "bodies": ["a", "b"], "at": [0, 0], **fields})


def defaults(**fields) -> Defaults:
    return Defaults.model_validate(fields)


def hand_stiffness(bearing, journal, modulus=STEEL_E, poisson=STEEL_NU):
    """K = 4/(3(σ_B + σ_J)) sqrt(R_B R_J/(R_B − R_J)), σ = (1 − ν²)/E, same material (docs/model-contact.md)."""
    sigma = (1.0 - poisson**2) / modulus
    return 4.0 / (3.0 * 2.0 * sigma) * math.sqrt(bearing * journal / (bearing - journal))


def resolve_error(j, d=None) -> ResolveError:
    with pytest.raises(ResolveError) as info:
        resolve_clearance(j, d or defaults(bearing_radius="10 mm"))
    return info.value


# --- ideal or clearance --------------------------------------------------------------------------


@pytest.mark.parametrize("fields", [{}, {"clearance": 0}, {"clearance": "0 mm", "bearing_radius": "10 mm"}])
def test_no_or_zero_clearance_is_an_ideal_joint(fields):
    assert resolve_clearance(joint(**fields), defaults(bearing_radius="10 mm")) is None


@pytest.mark.parametrize("fields, bearing, journal, clearance", [
    ({"clearance": "0.1 mm"}, 10e-3, 9.9e-3, 1e-4),  # R_B from defaults
    ({"clearance": "0.1 mm", "bearing_radius": "20 mm"}, 20e-3, 19.9e-3, 1e-4),  # the joint's R_B wins
    ({"clearance": "0.1 mm", "journal_radius": "5 mm"}, 5.1e-3, 5e-3, 1e-4),  # two on the joint give the third
    ({"journal_radius": "9.5 mm"}, 10e-3, 9.5e-3, 5e-4),  # c = R_B − R_J
    ({"bearing_radius": "10 mm", "journal_radius": "9.5 mm"}, 10e-3, 9.5e-3, 5e-4),
])
def test_any_two_of_the_radii_and_clearance_give_the_third(fields, bearing, journal, clearance):
    p = resolve_clearance(joint(**fields), defaults(bearing_radius="10 mm"))
    assert (p.bearing_radius, p.journal_radius, p.clearance) == pytest.approx((bearing, journal, clearance), rel=1e-12)


def test_missing_bearing_radius_says_where_to_add_it():
    error = resolve_error(joint(clearance="0.1 mm"), defaults())
    assert "needs a bearing radius" in error.message and "bearing_radius: 50 mm" in error.hint
    assert error.path_suffix == ("clearance",)


@pytest.mark.parametrize("fields, text", [
    ({"clearance": "10 mm"}, "must be smaller than the bearing radius 10 mm"),
    ({"clearance": "12 mm"}, "must be smaller than the bearing radius"),
    ({"journal_radius": "10 mm"}, "must be smaller than the bearing radius"),
    ({"clearance": "0.1 mm", "bearing_radius": "10 mm", "journal_radius": "9.5 mm"}, "differs from"),
])
def test_impossible_geometry_is_an_error(fields, text):
    assert text in resolve_error(joint(**fields)).message


def test_initial_eccentricity_must_lie_inside_the_clearance_circle():
    inside = resolve_clearance(joint(clearance="0.1 mm", initial_eccentricity=["0.06 mm", "0.08 mm"]),
                               defaults(bearing_radius="10 mm"))
    assert inside.initial_eccentricity == pytest.approx((6e-5, 8e-5))  # |e| = c exactly: touching is allowed
    pressed = resolve_clearance(joint(clearance="0.1 mm", initial_eccentricity=["0 mm", "-0.109 mm"]),
                                defaults(bearing_radius="10 mm"))
    assert pressed.initial_eccentricity == pytest.approx((0.0, -1.09e-4))  # a static preload up to 10 % of c
    error = resolve_error(joint(clearance="0.1 mm", initial_eccentricity=["0.11 mm", "0.01 mm"]))
    assert "outside the clearance circle" in error.message and error.path_suffix == ("initial_eccentricity",)


# --- contact --------------------------------------------------------------------------------------


def test_contact_merges_field_by_field_over_defaults_and_built_ins():
    d = defaults(bearing_radius="10 mm", contact={"restitution": 0.7})  # law, exponent: built in
    p = resolve_clearance(joint(clearance="0.1 mm", contact={"min_impact_speed": "2 mm/s"}), d)
    assert (p.law, p.restitution, p.exponent, p.min_impact_speed) == ("lankarani_nikravesh", 0.7, 1.5, 2e-3)
    assert resolve_clearance(joint(clearance="0.1 mm", contact={"restitution": 0.5}), d).restitution == 0.5


def test_auto_stiffness_is_the_internal_contact_formula():
    p = resolve_clearance(joint(clearance="0.1 mm"), defaults(bearing_radius="10 mm"))
    assert p.stiffness == pytest.approx(hand_stiffness(10e-3, 9.9e-3), rel=1e-12)
    # by hand: σ = 0.91/207e9 = 4.396e-12 Pa⁻¹, 4/(6σ) = 1.5165e11 Pa, sqrt(0.01·0.0099/1e-4) = 0.99499 m^½
    # → K = 1.5089e11 N/m^1.5
    assert p.stiffness == pytest.approx(1.5089e11, rel=1e-4)


def test_auto_stiffness_uses_the_joint_material():
    d = defaults(bearing_radius="10 mm")
    steel = resolve_clearance(joint(clearance="0.1 mm"), d).stiffness
    bronze = resolve_clearance(joint(clearance="0.1 mm", material={"youngs_modulus": "103.5 GPa"}), d).stiffness
    assert bronze / steel == pytest.approx(0.5, rel=1e-12)  # K ∝ E at equal ν


def test_given_stiffness_is_converted_with_the_exponent():
    p = resolve_clearance(joint(clearance="0.1 mm", contact={"stiffness": "3.81e7 N/mm^1.5"}),
                          defaults(bearing_radius="10 mm"))
    assert p.stiffness == pytest.approx(1.2048e12, rel=1e-4)


def test_auto_stiffness_needs_exponent_one_and_a_half():
    error = resolve_error(joint(clearance="0.1 mm", contact={"exponent": 1.0}))
    assert "exponent 1.5" in error.message and error.path_suffix == ("contact", "exponent")


def test_stiffness_of_the_wrong_unit_is_an_error():
    error = resolve_error(joint(clearance="0.1 mm", contact={"stiffness": "1e5 N/m"}))
    assert "N/m^1.5" in error.message and error.path_suffix == ("contact", "stiffness")


# --- friction -------------------------------------------------------------------------------------


def test_stiction_step_speeds_are_v_low_and_v_high():
    p = resolve_clearance(joint(clearance="0.1 mm"), defaults(bearing_radius="10 mm", friction=TABLE_2_FRICTION))
    assert (p.friction_law, p.mu_s, p.mu_d, p.v_low, p.v_high) == ("stiction_step", 0.2, 0.16, 1e-4, 1e-2)


def test_sticking_is_exact_by_default_smooth_on_request_and_only_for_laws_that_stick():
    d = defaults(bearing_radius="10 mm", friction=TABLE_2_FRICTION)
    assert resolve_clearance(joint(clearance="0.1 mm"), d).stick == "exact"
    assert resolve_clearance(joint(clearance="0.1 mm", friction={"stick": "smooth"}), d).stick == "smooth"
    coulomb = resolve_clearance(joint(clearance="0.1 mm", friction={"law": "coulomb", "mu_d": 0.1}), d)
    assert coulomb.stick == "exact"
    error = resolve_error(joint(clearance="0.1 mm", friction={"law": "ambrosio", "mu_d": 0.1, "v_0": "0.1 mm/s",
                                                              "v_1": "1 mm/s", "stick": "exact"}))
    assert "does not use stick" in error.message and "stiction_step" in error.hint


def test_ambrosio_speeds_are_v_low_and_v_high():
    friction = {"law": "ambrosio", "mu_d": 0.1, "v_0": "0.1 mm/s", "v_1": "1 mm/s"}
    p = resolve_clearance(joint(clearance="0.1 mm", friction=friction), defaults(bearing_radius="10 mm"))
    assert (p.friction_law, p.mu_s, p.mu_d, p.v_low, p.v_high) == pytest.approx(("ambrosio", 0.0, 0.1, 1e-4, 1e-3))


def test_joint_friction_fields_override_defaults_one_by_one():
    d = defaults(bearing_radius="10 mm", friction=TABLE_2_FRICTION)
    p = resolve_clearance(joint(clearance="0.1 mm", friction={"mu_d": 0.1}), d)
    assert (p.friction_law, p.mu_s, p.mu_d, p.v_high) == ("stiction_step", 0.2, 0.1, 1e-2)


def test_a_joint_that_changes_the_law_does_not_inherit_the_other_laws_parameters():
    d = defaults(bearing_radius="10 mm", friction=TABLE_2_FRICTION)
    p = resolve_clearance(joint(clearance="0.1 mm", friction={"law": "coulomb", "mu_d": 0.3}), d)
    assert (p.friction_law, p.mu_s, p.mu_d, p.v_low, p.v_high) == ("coulomb", 0.0, 0.3, 0.0, 0.0)


def test_missing_friction_parameter_is_an_error():
    d = defaults(bearing_radius="10 mm", friction={"law": "stiction_step", "mu_s": 0.2, "mu_d": 0.16})
    error = resolve_error(joint(clearance="0.1 mm"), d)
    assert "needs v_s, v_d" in error.message and error.in_defaults and error.path_suffix == ("friction", "law")


def test_a_parameter_the_law_does_not_use_is_an_error():
    error = resolve_error(joint(clearance="0.1 mm", friction={"law": "coulomb", "mu_d": 0.1, "v_s": "1 mm/s"}))
    assert "does not use v_s" in error.message and error.path_suffix == ("friction", "v_s")
    assert not error.in_defaults and "stiction_step" in error.hint


def test_friction_without_a_law_is_an_error():
    error = resolve_error(joint(clearance="0.1 mm", friction={"mu_d": 0.1}))  # built-in law: none
    assert "friction law 'none' does not use mu_d" in error.message


@pytest.mark.parametrize("change, text", [
    ({"v_s": "1e-2 m/s"}, "v_s = 0.01 m/s must be smaller than v_d = 0.01 m/s"),
    ({"mu_s": 0.1}, "mu_s = 0.1 must be at least mu_d = 0.16"),
])
def test_stiction_step_parameters_must_be_ordered(change, text):
    error = resolve_error(joint(clearance="0.1 mm", friction={**TABLE_2_FRICTION, **change}))
    assert text in error.message and not error.in_defaults


def test_ambrosio_speeds_must_be_ordered():
    friction = {"law": "ambrosio", "mu_d": 0.1, "v_0": "1 mm/s", "v_1": "1 mm/s"}
    assert "v_0 = 0.001 m/s must be smaller than v_1" in resolve_error(joint(clearance="0.1 mm", friction=friction)).message


def test_the_error_points_at_the_value_written_on_the_joint():
    d = defaults(bearing_radius="10 mm", friction=TABLE_2_FRICTION)
    error = resolve_error(joint(clearance="0.1 mm", friction={"mu_d": 0.3}), d)  # mu_s = 0.2 from defaults
    assert error.path_suffix == ("friction", "mu_d") and not error.in_defaults
