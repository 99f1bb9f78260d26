"""Elastic laws of a pin in its bore (clearsim.physics.cylindrical): each law's force, stiffness and energy against
its closed form, its small-load limit, a full-solver impact against the 1-DOF reference, the energy balance, the
range warnings and bad input."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.physics import contact
from clearsim.solver.outputs import IMPACT
from clearsim.physics.cylindrical import (
    ELASTIC_LAWS, ESDU_78035, JOHNSON, LIU, PEREIRA, POINT_HERTZ, effective_modulus, law_max_penetration,
    law_state, line_contact_edge, pereira_coefficients, pereira_exponent, range_warnings,
)
from tests.support.impact_reference import elastic_law_impact
from tests.validation.conftest import simulate, simulate_with_statistics  # noqa: F401  (the fixtures: run a YAML text, read its result)

MODULUS = effective_modulus(207e9, 0.3, 207e9, 0.3)  # Pa: steel on steel, 113.7 GPa
LENGTH, CLEARANCE = 0.05, 1e-5  # m: the breaker's pins, 50 mm long, 10 µm radial clearance
LINE = math.pi * LENGTH * MODULUS  # S = π L E*, N/m
PEREIRA_K, PEREIRA_N = pereira_coefficients(CLEARANCE, LENGTH, MODULUS)
COEFFICIENTS = {POINT_HERTZ: (2.4e12, 1.5), PEREIRA: (PEREIRA_K, PEREIRA_N), JOHNSON: (LINE, 1.0),
                ESDU_78035: (LINE, 1.0), LIU: (LINE, 1.0)}
LAWS = sorted(COEFFICIENTS)
# up to the line laws' edge (Johnson: 0.398 ΔR) and well into the conformal range for the others
PENETRATIONS = (1e-11, 1e-9, 1e-7, 1e-6, 3e-6, 3.9e-6)


def force(law, penetration):
    stiffness, exponent = COEFFICIENTS[law]
    return law_state(law, penetration, stiffness, exponent, CLEARANCE)[0]


def stiffness(law, penetration):
    scale, exponent = COEFFICIENTS[law]
    return law_state(law, penetration, scale, exponent, CLEARANCE)[1]


def energy(law, penetration):
    scale, exponent = COEFFICIENTS[law]
    return law_state(law, penetration, scale, exponent, CLEARANCE)[2]


def line_penetration(load, constant):
    """δ(F) = (F/S)[ln(4 S ΔR/F) + c]: Johnson (c = −1), ESDU-78035 (c = +1), explicit in F."""
    return load / LINE * (math.log(4.0 * LINE * CLEARANCE / load) + constant)


def liu_closed_form(penetration):
    return 0.5 * math.pi * MODULUS * LENGTH * penetration * math.sqrt(penetration / (2.0 * (CLEARANCE + penetration)))


def test_law_names_and_codes():
    assert ELASTIC_LAWS == {"point_hertz": 0, "johnson": 1, "esdu_78035": 2, "pereira": 3, "liu": 4}


@pytest.mark.parametrize(("law", "constant"), [(JOHNSON, -1.0), (ESDU_78035, 1.0)])
@pytest.mark.parametrize("load", [1e-3, 1.0, 1e2, 1e3, 1e4, 3e4])
def test_line_laws_invert_their_closed_form(law, constant, load):
    assert force(law, line_penetration(load, constant)) == pytest.approx(load, rel=1e-9)


@pytest.mark.parametrize("penetration", PENETRATIONS)
def test_explicit_laws_match_their_closed_form(penetration):
    assert force(LIU, penetration) == pytest.approx(liu_closed_form(penetration), rel=1e-12)
    assert force(PEREIRA, penetration) == pytest.approx(PEREIRA_K * penetration**PEREIRA_N, rel=1e-12)


def test_pereira_fit_in_its_own_units():
    """F = (a ΔR + b) L E* δⁿ/ΔR with ΔR, L, δ in mm, E* in MPa (a = 0.965, b = 0.0965), n = Y ΔR^−0.005 with
    Y = 1.51 [ln(1000 ΔR)]^−0.151; the two branches of Y meet at ΔR = 0.34954 mm."""
    clearance_mm, length_mm, modulus_mpa, penetration_mm = 0.01, 50.0, MODULUS * 1e-6, 1e-3
    exponent = 1.51 * math.log(1000 * clearance_mm) ** -0.151 * clearance_mm**-0.005
    expected = (0.965 * clearance_mm + 0.0965) * length_mm * modulus_mpa * penetration_mm**exponent / clearance_mm
    assert PEREIRA_N == pytest.approx(exponent, rel=1e-14)
    assert force(PEREIRA, penetration_mm * 1e-3) == pytest.approx(expected, rel=1e-12)
    below, above = pereira_exponent(0.34954e-3 * (1 - 1e-9)), pereira_exponent(0.34954e-3 * (1 + 1e-9))
    assert below == pytest.approx(above, rel=1e-5)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("penetration", PENETRATIONS)
def test_stiffness_is_the_derivative_of_the_force(law, penetration):
    step = 1e-5 * penetration  # central difference: error ~ step² F''' / 6, round-off ~ 1e-16 F / step
    numerical = (force(law, penetration + step) - force(law, penetration - step)) / (2.0 * step)
    assert stiffness(law, penetration) == pytest.approx(numerical, rel=1e-7)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("penetration", PENETRATIONS + (2e-5,))
def test_energy_is_the_integral_of_the_force(law, penetration):
    integral, _ = quad(lambda s: force(law, s), 0.0, penetration, epsabs=0.0, epsrel=1e-13, limit=200)
    assert energy(law, penetration) == pytest.approx(integral, rel=1e-9)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("penetration", [0.0, -1e-9, -1e-3])
def test_nothing_without_penetration(law, penetration):
    assert force(law, penetration) == stiffness(law, penetration) == energy(law, penetration) == 0.0


@pytest.mark.parametrize("law", LAWS)
def test_force_rises_monotonically(law):
    edge = 8.0 * CLEARANCE * line_contact_edge(-1.0)  # the tightest range: Johnson's
    penetrations = np.geomspace(1e-12, 3.0 * edge, 400)
    forces = np.array([force(law, p) for p in penetrations])
    assert np.all(np.diff(forces) > 0.0)
    assert all(stiffness(law, p) > 0.0 for p in penetrations)


def test_small_load_limits():
    """Liu → a point law K δ^1.5 with K = π L E*/(2√(2ΔR)); Pereira is a power law throughout; the line laws'
    stiffness S/(ln(4 S ΔR/F) + c − 1) tends to 0 (logarithmically) as F → 0."""
    liu_limit = LINE / (2.0 * math.sqrt(2.0 * CLEARANCE))
    assert force(LIU, 1e-13) / 1e-13**1.5 == pytest.approx(liu_limit, rel=1e-7)
    assert stiffness(LIU, 1e-13) / (1.5 * 1e-13**0.5) == pytest.approx(liu_limit, rel=1e-7)
    for law, constant in ((JOHNSON, -1.0), (ESDU_78035, 1.0)):
        loads = (1e-6, 1e-3, 1.0)
        for load in loads:
            expected = LINE / (math.log(4.0 * LINE * CLEARANCE / load) + constant - 1.0)
            assert stiffness(law, line_penetration(load, constant)) == pytest.approx(expected, rel=1e-9)
        assert stiffness(law, line_penetration(1e-6, constant)) < stiffness(law, line_penetration(1.0, constant))


def test_bai_zhao_stiffness_is_liu_tangent_stiffness():
    """Bai & Zhao's K_n = (π E*/8) √(2δ(3ΔR + 2δ)²/(ΔR + δ)³) per unit length is dF/dδ of Liu's law."""
    for penetration in PENETRATIONS:
        bai_zhao = math.pi * MODULUS / 8.0 * math.sqrt(
            2.0 * penetration * (3.0 * CLEARANCE + 2.0 * penetration) ** 2 / (CLEARANCE + penetration) ** 3)
        assert stiffness(LIU, penetration) == pytest.approx(bai_zhao * LENGTH, rel=1e-12)


@pytest.mark.parametrize("law", LAWS)
def test_max_penetration_stores_the_impact_energy(law):
    scale, exponent = COEFFICIENTS[law]
    for mass, speed in ((1.0, 1.0), (50.0, 3.0), (0.01, 0.01)):
        depth = law_max_penetration(law, mass, speed, scale, exponent, CLEARANCE)
        assert energy(law, depth) == pytest.approx(0.5 * mass * speed**2, rel=1e-12)


def test_line_laws_continue_straight_past_their_edge():
    for law, constant in ((JOHNSON, -1.0), (ESDU_78035, 1.0)):
        edge = 8.0 * CLEARANCE * line_contact_edge(constant)
        edge_force = 4.0 * LINE * CLEARANCE * line_contact_edge(constant)
        assert force(law, edge) == pytest.approx(edge_force, rel=1e-12)
        assert force(law, 2.0 * edge) == pytest.approx(edge_force + LINE * edge, rel=1e-12)
        assert stiffness(law, edge * (1 - 1e-12)) == pytest.approx(LINE, rel=1e-9)


def test_restitution_does_not_depend_on_the_elastic_law():
    """With F_n = F_el(δ)(1 + D δ̇/δ̇⁻) the kinetic energy E as a function of the stored W = ∫F_el obeys
    dE/dW = −(1 ± D √(2E/m)/δ̇⁻), whatever F_el: each damping law delivers the same restitution under every
    elastic law (docs/model-contact.md), while the contact time differs."""
    impacts = [elastic_law_impact(contact.LANKARANI_NIKRAVESH, law, 0.8, *COEFFICIENTS[law], CLEARANCE, mass=2.0,
                                  impact_speed=0.3) for law in LAWS]
    for impact in impacts[1:]:
        assert impact.restitution == pytest.approx(impacts[0].restitution, rel=1e-8)
    times = sorted(impact.contact_time for impact in impacts)
    assert times[-1] > 1.2 * times[0]


# --- range warnings -----------------------------------------------------------------------------------------


def test_range_warnings():
    edge = 8.0 * CLEARANCE * line_contact_edge(-1.0)
    assert range_warnings("J", JOHNSON, CLEARANCE, LINE, 0.9 * edge) == []
    [text] = range_warnings("J", JOHNSON, CLEARANCE, LINE, 1.1 * edge)
    assert "joint 'J'" in text and "johnson" in text
    assert range_warnings("J", PEREIRA, CLEARANCE, PEREIRA_K, np.nan) == []
    [text] = range_warnings("J", PEREIRA, 2e-6, PEREIRA_K, np.nan)  # ΔR = 0.002 mm < 0.005 mm
    assert "pereira" in text and "0.002 mm" in text
    assert range_warnings("J", LIU, CLEARANCE, LINE, 1.0) == []


# --- the full solver ----------------------------------------------------------------------------------------

WIDE_CLEARANCE = 5e-3  # m: the journal flies back less than c after its one impact


def impact_yaml(elastic, law="lankarani_nikravesh", restitution=0.8, mass=1.0, speed=1.0, length="50 mm",
                clearance=WIDE_CLEARANCE, t_end=None, output_rate="4 MHz"):
    t_end = t_end if t_end is not None else 1.5 * clearance / speed + 2e-4
    return f"""
name: single impact, cylindrical law
points: {{O: [0 m, 0 m]}}
defaults:
  material: {{youngs_modulus: 207 GPa, poisson_ratio: 0.3}}
  contact: {{law: {law}, restitution: {restitution}, elastic: {elastic}, length: {length}, min_impact_speed: 1e-9 m/s}}
bodies:
  - {{name: journal, mass: {mass} kg, inertia: {mass * 1e-4} kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, journal], at: O, bearing_radius: 20 mm,
      clearance: {clearance} m, initial_velocity: [{speed} m/s, 0 m/s]}}
solver: {{t_end: {t_end} s, output_rate: {output_rate}, rtol: 1e-10, atol: 1e-13, max_step: 1 ms}}
"""


def measured_impact(result):
    onset, loss = result["joints/O/episodes/onset"], result["joints/O/episodes/loss"]
    assert len(onset) == 1 and np.isfinite(loss[0])
    t, vx = result["time"], result["bodies/journal/qd"][:, 0]
    return -vx[t > loss[0]][0] / vx[t < onset[0]][-1], loss[0] - onset[0]


@pytest.mark.parametrize("elastic", ["johnson", "esdu_78035", "pereira", "liu"])
def test_single_impact_matches_the_one_dof_reference(simulate, elastic):
    result = simulate(impact_yaml(elastic))
    restitution, duration = measured_impact(result)
    law = ELASTIC_LAWS[elastic]
    stiffness, exponent = pereira_coefficients(WIDE_CLEARANCE, LENGTH, MODULUS) if law == PEREIRA else (LINE, 1.0)
    reference = elastic_law_impact(contact.LANKARANI_NIKRAVESH, law, 0.8, stiffness, exponent, WIDE_CLEARANCE)
    assert restitution == pytest.approx(reference.restitution, rel=1e-4)
    assert duration == pytest.approx(reference.contact_time, rel=1e-4)
    assert np.max(result["joints/O/normal_force"]) == pytest.approx(reference.peak_force, rel=1e-3)
    assert result["joints/O/episodes/kind"][0] == IMPACT  # its duration against the law's own contact time


PENDULUM = """
name: pendulum hanging from a pivot with clearance, a cylindrical law
gravity: [0 m/s^2, -9.81 m/s^2]
defaults:
  contact: {{law: {law}, restitution: {restitution}, elastic: {elastic}, length: 20 mm}}
  friction: {friction}
points: {{O: [0 m, 0 m]}}
bodies:
  - {{name: link, mass: 0.5 kg, inertia: 0.00375 kg*m^2, position: [0.15 m, 0 m]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, link], at: O, bearing_radius: 10 mm, clearance: 0.1 mm}}
solver: {{t_end: {t_end} s, output_rate: 100 kHz, rtol: 1e-10, atol: 1e-13, max_step: 1 ms}}
"""
CYLINDRICAL = ["johnson", "esdu_78035", "pereira", "liu"]


@pytest.mark.parametrize("elastic", CYLINDRICAL)
def test_an_elastic_impact_conserves_energy_including_the_law_s_potential(simulate, elastic):
    """An undamped impact (law: hertz) of the free journal: at the deepest point all its kinetic energy is the
    law's contact energy ∫F, so an error of 1e-3 in that integral would show as 1e-3 of the total."""
    result = simulate(impact_yaml(elastic, law="hertz", restitution=1.0))
    energy = result["energy/kinetic"] + result["energy/potential"]
    assert np.min(result["energy/kinetic"]) <= 1e-3 * energy[0]  # it did reach the deepest point
    assert np.max(np.abs(energy - energy[0])) <= 1e-6 * energy[0]


@pytest.mark.parametrize("elastic", CYLINDRICAL)
def test_energy_balance_closes_under_a_cylindrical_law(simulate, elastic):
    """Damped, frictional impacts: the written dissipation closes the balance (tests/validation/test_energy.py for
    the point law)."""
    result = simulate(PENDULUM.format(law="lankarani_nikravesh", restitution=0.7, elastic=elastic,
                                      friction="{law: coulomb, mu_d: 0.1}", t_end=0.2))
    lost = result["energy/contact_dissipated"][-1] + result["energy/friction_dissipated"][-1]
    assert len(result["joints/O/episodes/onset"]) >= 3
    assert lost > 1e-4 * np.max(result["energy/kinetic"])  # precondition: there is dissipation to account for
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-3 * lost


def test_point_hertz_is_the_default(simulate):
    base = impact_yaml("point_hertz").replace("elastic: point_hertz, length: 50 mm, ", "")
    named = impact_yaml("point_hertz")
    first, second = simulate(base), simulate(named)
    assert np.array_equal(first["joints/O/normal_force"], second["joints/O/normal_force"])


def test_a_line_law_past_its_edge_warns_in_the_run_summary(tmp_path):
    """A 100 kg journal at 1 m/s in a 10 µm clearance: Johnson's edge (0.4 ΔR, 36 kN) is far exceeded."""
    path = tmp_path / "hard.yaml"
    path.write_text(impact_yaml("johnson", mass=100.0, clearance=1e-5, t_end=2e-4, output_rate="2 MHz"))
    result = CliRunner().invoke(app, ["run", str(path), "-o", str(tmp_path / "hard.h5")])
    assert result.exit_code == 0, result.output
    assert "johnson elastic law reached" in " ".join(result.output.split())


def test_pereira_outside_its_clearance_range_warns_in_the_run_summary(tmp_path):
    """ΔR = 0.002 mm lies below the 0.005 mm of Pereira's fit."""
    path = tmp_path / "tight.yaml"
    path.write_text(impact_yaml("pereira", clearance=2e-6, t_end=2e-5, output_rate="1 MHz"))
    result = CliRunner().invoke(app, ["run", str(path), "-o", str(tmp_path / "tight.h5")])
    assert result.exit_code == 0, result.output
    assert "pereira elastic law is fitted for clearances of 0.005–10 mm" in " ".join(result.output.split())


def test_a_joint_choosing_a_cylindrical_law_leaves_the_defaults_point_stiffness_to_the_other_joints(tmp_path):
    """defaults: a point law with its K; joint O: `elastic: liu` — the joint's choice starts that law afresh."""
    text = impact_yaml("point_hertz").replace("elastic: point_hertz, length: 50 mm, ",
                                              "stiffness: 1.2e12 N/m^1.5, exponent: 1.5, ")
    text = text.replace("initial_velocity:", "contact: {elastic: liu, length: 50 mm}, initial_velocity:")
    path = tmp_path / "mixed.yaml"
    path.write_text(text)
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 0, result.output


# --- bad input ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("elastic", "clearance", "edit", "fragments"), [
    ("johnson", WIDE_CLEARANCE, ("length: 50 mm", "length: -50 mm"), ("length",)),
    ("johnson", WIDE_CLEARANCE, ("length: 50 mm, ", ""), ("elastic", "needs the pin's axial length")),
    ("johnson", WIDE_CLEARANCE, ("elastic: johnson", "elastic: johnson, stiffness: 1e12 N/m^1.5"),
     ("stiffness", "point_hertz")),
    ("pereira", 5e-7, ("", ""), ("elastic", "undefined for clearances of 0.001 mm and below")),
])
def test_bad_input_is_located_exit_2(tmp_path, elastic, clearance, edit, fragments):
    path = tmp_path / "bad.yaml"
    text = impact_yaml(elastic, clearance=clearance)
    assert edit[0] in text
    path.write_text(text.replace(*edit) if edit[0] else text)
    result = CliRunner().invoke(app, ["run", str(path), "-o", str(tmp_path / "bad.h5")])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert "bad.yaml" in result.output and "contact" in result.output
    for fragment in fragments:
        assert fragment in result.output, result.output
