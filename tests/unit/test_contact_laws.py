"""Normal contact laws: hand-computed forces, the stiffness formula, and single-impact restitution."""

import math

import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from clearsim.physics.contact import (
    CONTACT_LAWS,
    FLORES,
    GONTHIER,
    HERTZ,
    HUNT_CROSSLEY,
    LANKARANI_NIKRAVESH,
    elastic_energy,
    elastic_force,
    hertz_contact_time,
    hertz_max_penetration,
    hertz_peak_force,
    hysteresis_factor,
    internal_contact_stiffness,
    normal_force,
)
from tests.support.impact_reference import law_impact

DAMPED_LAWS = (LANKARANI_NIKRAVESH, HUNT_CROSSLEY, FLORES, GONTHIER)
ALL_LAWS = (HERTZ,) + DAMPED_LAWS
STEEL_E, STEEL_NU = 207e9, 0.3  # Pa, -

# K = 1e10 N/m^1.5, δ = 1e-5 m, δ̇ = 0.2 m/s, δ̇⁻ = 0.5 m/s, c_e = 0.8:
# K δ^1.5 = 1e10 · 3.16228e-8 = 316.228 N, δ̇/δ̇⁻ = 0.4
K, DELTA, RATE, V_IMPACT, C_E = 1.0e10, 1.0e-5, 0.2, 0.5, 0.8
ELASTIC = 316.22776601683796
HAND_FORCES = {
    HERTZ: ELASTIC,
    LANKARANI_NIKRAVESH: ELASTIC * (1.0 + 0.75 * 0.36 * 0.4),  # D = 3(1 − 0.64)/4 = 0.27
    HUNT_CROSSLEY: ELASTIC * (1.0 + 1.5 * 0.2 * 0.4),  # D = 3(0.2)/2 = 0.3
    FLORES: ELASTIC * (1.0 + 8.0 * 0.2 / 4.0 * 0.4),  # D = 8(0.2)/(5·0.8) = 0.4
    GONTHIER: ELASTIC * (1.0 + 0.45 * 0.4),  # D = (1 − 0.64)/0.8 = 0.45
}


def test_law_codes_are_distinct_and_named():
    assert CONTACT_LAWS == {"hertz": 0, "lankarani_nikravesh": 1, "hunt_crossley": 2, "flores": 3,
                            "gonthier": 4}


@pytest.mark.parametrize("law", ALL_LAWS)
def test_force_matches_hand_computed_value(law):
    force = normal_force(law, DELTA, RATE, V_IMPACT, K, 1.5, C_E)
    assert force == pytest.approx(HAND_FORCES[law], rel=1e-12)


@pytest.mark.parametrize("law", ALL_LAWS)
@pytest.mark.parametrize("penetration", [0.0, -1e-9, -1e-3])
def test_no_force_without_penetration(law, penetration):
    assert normal_force(law, penetration, 5.0, 1.0, K, 1.5, 0.5) == 0.0


@pytest.mark.parametrize("law", DAMPED_LAWS)
def test_fast_separation_never_pulls(law):
    # δ̇ = −10 δ̇⁻ makes 1 + D δ̇/δ̇⁻ negative for every damped law at c_e = 0.5
    assert normal_force(law, DELTA, -10.0 * V_IMPACT, V_IMPACT, K, 1.5, 0.5) == 0.0


@pytest.mark.parametrize("law", DAMPED_LAWS)
def test_perfectly_elastic_restitution_removes_damping(law):
    assert hysteresis_factor(law, 1.0) == 0.0
    assert normal_force(law, DELTA, RATE, V_IMPACT, K, 1.5, 1.0) == pytest.approx(ELASTIC, rel=1e-14)


def test_hertz_has_no_damping_at_any_restitution():
    assert hysteresis_factor(HERTZ, 0.3) == 0.0


def test_elastic_force_and_energy():
    assert elastic_force(DELTA, K, 1.5) == pytest.approx(ELASTIC, rel=1e-14)
    assert elastic_energy(DELTA, K, 1.5) == pytest.approx(ELASTIC * DELTA / 2.5, rel=1e-14)
    assert elastic_force(-DELTA, K, 1.5) == 0.0 and elastic_energy(-DELTA, K, 1.5) == 0.0
    # energy is the potential of the elastic force: dU/dδ = K δⁿ
    step = 1e-9 * DELTA
    derivative = (elastic_energy(DELTA + step, K, 1.5) - elastic_energy(DELTA - step, K, 1.5)) / (2 * step)
    assert derivative == pytest.approx(ELASTIC, rel=1e-6)


def test_internal_stiffness_steel_hand_value():
    # σ = (1 − 0.09)/207e9 = 4.39614e-12 1/Pa each; 4/(3·8.79227e-12) = 1.51648e11 Pa
    # sqrt(0.010·0.0095/0.0005) = sqrt(0.19) m^0.5 = 0.435890 → K = 6.61020e10 N/m^1.5
    stiffness = internal_contact_stiffness(0.010, 0.0095, STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
    assert stiffness == pytest.approx(4.0 / (3.0 * 2 * 0.91 / 207e9) * math.sqrt(0.19), rel=1e-12)
    assert stiffness == pytest.approx(6.61020e10, rel=1e-5)


def test_internal_stiffness_rejects_journal_not_inside():
    with pytest.raises(ValueError, match="smaller than bearing radius"):
        internal_contact_stiffness(0.01, 0.01, STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)


def test_paper_stiffness_matches_steel_pin_at_plausible_clearance():
    """Meng 2015 Table 2: K = 3.81e7 N/mm^1.5 (Adams units) = 1.205e12 N/m^1.5, for R_B = 0.05 m."""
    paper_stiffness = 3.81e7 * 1000.0**1.5
    assert paper_stiffness == pytest.approx(1.205e12, rel=1e-3)

    def mismatch(clearance):
        journal_radius = 0.05 - clearance
        stiffness = internal_contact_stiffness(0.05, journal_radius, STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
        return stiffness - paper_stiffness

    clearance = brentq(mismatch, 1e-9, 1e-3)
    # solves to c = 0.0396 mm; the paper's clearances are 0.01-0.1 mm
    assert 0.005e-3 < clearance < 0.1e-3
    assert clearance == pytest.approx(3.9575e-5, rel=1e-4)


def test_hertz_contact_time_constant_is_the_integral():
    integral, _ = quad(lambda x: 1.0 / math.sqrt(1.0 - x**2.5), 0.0, 1.0)
    ratio = hertz_contact_time(1.0, 1.0, 1.0) / hertz_max_penetration(1.0, 1.0, 1.0)
    assert ratio == pytest.approx(2.0 * integral, rel=1e-10)
    assert ratio == pytest.approx(2.9433, abs=1e-4)


@pytest.mark.parametrize(
    ("mass", "stiffness", "impact_speed"),
    [(1.0, 1e10, 1.0), (0.3, 1.205e12, 0.05), (50.0, 6.6e10, 4.0)],
)
def test_hertz_impact_matches_closed_form(mass, stiffness, impact_speed):
    result = law_impact(HERTZ, 1.0, stiffness, mass, impact_speed)
    # 1e-6 relative: the reference is integrated at rtol 1e-12 with events at δ̇ = 0 and δ = 0
    case = (mass, stiffness, impact_speed)
    assert result.max_penetration == pytest.approx(hertz_max_penetration(*case), rel=1e-6)
    assert result.peak_force == pytest.approx(hertz_peak_force(*case), rel=1e-6)
    assert result.contact_time == pytest.approx(hertz_contact_time(*case), rel=1e-6)
    assert result.restitution == pytest.approx(1.0, abs=1e-8)


def test_hertz_contact_time_in_mass_stiffness_form():
    # t_c = 2.94328 δ_max/v = 2.94328 (5/4)^{2/5} (m/K)^{2/5} v^{-1/5} = 3.21807 (m/K)^{2/5} v^{-1/5}
    expected = 3.21807 * (2.0 / 1e10) ** 0.4 * 3.0**-0.2
    assert hertz_contact_time(2.0, 1e10, 3.0) == pytest.approx(expected, rel=1e-5)


@pytest.mark.parametrize("law", ALL_LAWS)
@pytest.mark.parametrize("restitution", [0.3, 0.9])
@pytest.mark.parametrize("parameter", ["stiffness", "mass", "impact_speed"])
def test_effective_restitution_is_scale_free(law, restitution, parameter):
    base = {"stiffness": 1e10, "mass": 1.0, "impact_speed": 1.0}
    scaled = dict(base, **{parameter: 100.0 * base[parameter]})
    reference = law_impact(law, restitution, **base).restitution
    assert law_impact(law, restitution, **scaled).restitution == pytest.approx(reference, abs=1e-6)


# Measured with docs/scripts/restitution_table.py (see docs/model-contact.md):
# LN 0.9 → 0.9132, 0.99 → 0.99015; Flores 0.5 → 0.4704, 0.7 → 0.6832, 0.9 → 0.8939.
@pytest.mark.parametrize(("restitution", "tolerance"), [(0.9, 0.015), (0.99, 0.0002)])
def test_lankarani_nikravesh_is_accurate_near_elastic(restitution, tolerance):
    effective = law_impact(LANKARANI_NIKRAVESH, restitution).restitution
    assert abs(effective - restitution) < tolerance
    assert effective > restitution  # LN under-dissipates: its derivation assumes c_e ≈ 1


def test_lankarani_nikravesh_is_inaccurate_for_plastic_impacts():
    assert law_impact(LANKARANI_NIKRAVESH, 0.3).restitution > 0.6


@pytest.mark.parametrize("restitution", [0.5, 0.7, 0.9, 0.99])
def test_flores_is_close_to_nominal_over_a_wide_range(restitution):
    assert abs(law_impact(FLORES, restitution).restitution - restitution) < 0.035


# Gonthier: 0.1 → 0.1010, 0.3 → 0.3042, 0.5 → 0.4877, 0.9 → 0.8764, 0.99 → 0.9868.
@pytest.mark.parametrize("restitution", [0.1, 0.3, 0.5])
def test_gonthier_is_accurate_for_plastic_impacts(restitution):
    assert abs(law_impact(GONTHIER, restitution).restitution - restitution) < 0.013


@pytest.mark.parametrize("restitution", [0.99, 0.999])
def test_gonthier_over_dissipates_near_elastic_by_four_thirds(restitution):
    # Near c_e = 1, D = (1 − c_e²)/c_e ≈ 2(1 − c_e) is 4/3 of the Hunt–Crossley D = 3(1 − c_e)/2,
    # whose first-order loss matches c_e exactly: the effective 1 − c_e is 4/3 of the nominal one.
    effective = law_impact(GONTHIER, restitution).restitution
    assert (1.0 - effective) / (1.0 - restitution) == pytest.approx(4.0 / 3.0, rel=0.02)


@pytest.mark.parametrize("law", DAMPED_LAWS)
def test_more_damping_gives_lower_effective_restitution(law):
    values = [law_impact(law, c).restitution for c in (0.3, 0.6, 0.9)]
    assert values[0] < values[1] < values[2] < 1.0
