"""A free journal hitting the bearing wall once, in the full solver, against the 1-DOF reference impact."""

import numpy as np
import pytest

from clearsim.physics import contact
from tests.support.impact_reference import law_impact

CLEARANCE = 5e-3  # m: wide against every penetration here (< 0.5 mm), so the rebound never reaches the far wall


def impact_yaml(law="lankarani_nikravesh", restitution=0.8, stiffness=1e10, mass=1.0, speed=1.0):
    """A journal body (no gravity) centred in a bearing on the ground, moving at `speed` along +x.

    It flies c, hits, and the run ends after it has flown back less than c: samples every t_H/400.
    """
    flight = CLEARANCE / speed
    hertz_time = contact.hertz_contact_time(mass, stiffness, speed)
    return f"""
name: single impact
points: {{O: [0 m, 0 m]}}
defaults:
  contact: {{law: {law}, restitution: {restitution}, exponent: 1.5, stiffness: {stiffness} N/m^1.5, min_impact_speed: 1e-9 m/s}}
bodies:
  - {{name: journal, mass: {mass} kg, inertia: {mass * 1e-4} kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, journal], at: O, bearing_radius: 20 mm,
      clearance: {CLEARANCE} m, initial_velocity: [{speed} m/s, 0 m/s]}}
solver: {{t_end: {1.5 * flight + 3.0 * hertz_time} s, output_rate: {400.0 / hertz_time} Hz,
          rtol: 1e-10, atol: 1e-13, max_step: 1 ms}}
"""


def measured_impact(result):
    """(restitution from the free-flight velocities before and after, contact time, onset speed)."""
    episodes = result["joints/O/episodes/onset"], result["joints/O/episodes/loss"]
    assert len(episodes[0]) == 1 and np.isfinite(episodes[1][0])  # exactly one impact, and it ended
    t, vx = result["time"], result["bodies/journal/qd"][:, 0]
    before = vx[t < episodes[0][0]][-1]
    after = vx[t > episodes[1][0]][0]
    return -after / before, episodes[1][0] - episodes[0][0], result["joints/O/episodes/impact_speed"][0]


LAWS = {"lankarani_nikravesh": contact.LANKARANI_NIKRAVESH, "hunt_crossley": contact.HUNT_CROSSLEY,
        "flores": contact.FLORES, "gonthier": contact.GONTHIER, "hertz": contact.HERTZ}
DAMPED_LAWS = sorted(set(LAWS) - {"hertz"})


@pytest.mark.parametrize("law", sorted(LAWS))
def test_restitution_matches_the_one_dof_reference(simulate, law):
    restitution = 1.0 if law == "hertz" else 0.8
    measured, duration, onset_speed = measured_impact(simulate(impact_yaml(law, restitution)))
    reference = law_impact(LAWS[law], restitution, stiffness=1e10, mass=1.0, impact_speed=1.0)
    assert onset_speed == pytest.approx(1.0, rel=1e-9)  # free flight: δ̇⁻ is the initial speed
    assert measured == pytest.approx(reference.restitution, rel=1e-3)
    assert duration == pytest.approx(reference.contact_time, rel=1e-3)


@pytest.mark.parametrize("change", [{"stiffness": 1e12}, {"mass": 0.05}, {"speed": 5.0}, {"speed": 0.05}])
def test_restitution_depends_only_on_the_law_and_c_e(simulate, change):
    base = measured_impact(simulate(impact_yaml()))[0]
    varied = measured_impact(simulate(impact_yaml(**change)))[0]
    assert varied == pytest.approx(base, rel=1e-3)


def test_elastic_impact_matches_closed_form_hertz(simulate):
    mass, stiffness, speed = 1.0, 1e10, 1.0
    result = simulate(impact_yaml("hertz", 1.0, stiffness, mass, speed))
    _, duration, _ = measured_impact(result)
    depth = contact.hertz_max_penetration(mass, stiffness, speed)
    # peaks are read from samples t_H/400 apart: at most ½(π/800)² ≈ 8e-6 below the true peak
    assert np.max(result["joints/O/penetration"]) == pytest.approx(depth, rel=1e-4)
    assert np.max(result["joints/O/normal_force"]) == pytest.approx(contact.hertz_peak_force(mass, stiffness, speed), rel=1e-4)
    assert duration == pytest.approx(contact.hertz_contact_time(mass, stiffness, speed), rel=1e-6)


@pytest.mark.parametrize("law", DAMPED_LAWS)
@pytest.mark.parametrize("change", [{}, {"mass": 0.05}, {"speed": 5.0}, {"speed": 0.05}])
def test_damped_restitution_matches_the_reference_to_1e_4_at_any_mass_and_speed(simulate, law, change):
    case = {"stiffness": 1e10, "mass": 1.0, "speed": 1.0} | change
    measured, _, _ = measured_impact(simulate(impact_yaml(law, 0.8, **case)))
    reference = law_impact(LAWS[law], 0.8, case["stiffness"], case["mass"], case["speed"])
    assert measured == pytest.approx(reference.restitution, rel=1e-4)
