"""Friction laws: chosen values, continuity at the band edges, odd symmetry, dissipation."""

import numpy as np
import pytest

from clearsim.physics.friction import (
    AMBROSIO,
    COULOMB,
    FRICTION_LAWS,
    NONE,
    STICTION_STEP,
    friction_coefficient,
    step_blend,
)

# Meng 2015 Table 2
MU_S, MU_D, V_S, V_D = 0.2, 0.16, 1e-4, 1e-2
V_0, V_1 = 1e-4, 1e-3  # Ambrósio's c_d ramp, m/s
ALL_LAWS = (NONE, COULOMB, STICTION_STEP, AMBROSIO)


def mu(law, velocity):
    if law == AMBROSIO:
        return friction_coefficient(law, velocity, MU_S, MU_D, V_0, V_1)
    return friction_coefficient(law, velocity, MU_S, MU_D, V_S, V_D)


def test_law_codes_are_named():
    assert FRICTION_LAWS == {"none": 0, "coulomb": 1, "stiction_step": 2, "ambrosio": 3}


def test_step_blend_endpoints_and_midpoint():
    assert step_blend(-1.0, 0.0, 2.0, 1.0, 5.0) == 2.0
    assert step_blend(0.0, 0.0, 2.0, 1.0, 5.0) == 2.0
    assert step_blend(1.0, 0.0, 2.0, 1.0, 5.0) == 5.0
    assert step_blend(3.0, 0.0, 2.0, 1.0, 5.0) == 5.0
    assert step_blend(0.5, 0.0, 2.0, 1.0, 5.0) == pytest.approx(3.5, abs=1e-15)
    # Δ = 0.25: 2 + 3 · 0.0625 · 2.5 = 2.46875
    assert step_blend(0.25, 0.0, 2.0, 1.0, 5.0) == pytest.approx(2.46875, abs=1e-15)


@pytest.mark.parametrize("end", [1.0, 3.0])
def test_step_blend_has_zero_slope_at_ends(end):
    # cubic STEP: slope at the ends is O(h) from inside, exactly 0 outside
    h = 1e-7
    inside = end + h if end == 1.0 else end - h
    slope = (step_blend(inside, 1.0, -2.0, 3.0, 4.0) - step_blend(end, 1.0, -2.0, 3.0, 4.0)) / h
    assert abs(slope) < 1e-5


def test_none_is_zero():
    assert mu(NONE, 0.3) == 0.0 and mu(NONE, -1e-5) == 0.0


def test_coulomb_values():
    assert mu(COULOMB, 1e-9) == MU_D
    assert mu(COULOMB, -3.0) == -MU_D
    assert mu(COULOMB, 0.0) == 0.0


def test_stiction_step_chosen_values():
    assert mu(STICTION_STEP, 0.0) == 0.0
    assert mu(STICTION_STEP, V_S) == pytest.approx(MU_S, abs=1e-15)  # peak static friction at v_s
    assert mu(STICTION_STEP, 0.5) == MU_D
    assert mu(STICTION_STEP, -V_D) == -MU_D
    # |v| = v_s/2: Δ = 0.75 → −0.2 + 0.4 · 0.5625 · 1.5 = 0.1375
    assert mu(STICTION_STEP, 0.5 * V_S) == pytest.approx(0.1375, abs=1e-12)
    # middle of the stiction→sliding band: (μ_s + μ_d)/2
    assert mu(STICTION_STEP, -0.5 * (V_S + V_D)) == pytest.approx(-0.18, abs=1e-12)


def test_stiction_step_falls_from_static_to_dynamic():
    speeds = np.linspace(V_S, V_D, 50)
    values = [mu(STICTION_STEP, v) for v in speeds]
    assert all(np.diff(values) <= 0.0)  # the paper's print would rise from μ_d to μ_s here


def test_ambrosio_ramp():
    assert mu(AMBROSIO, 0.5 * V_0) == 0.0
    assert mu(AMBROSIO, V_0) == 0.0
    assert mu(AMBROSIO, 0.5 * (V_0 + V_1)) == pytest.approx(0.5 * MU_D, abs=1e-15)
    assert mu(AMBROSIO, -(V_0 + 0.25 * (V_1 - V_0))) == pytest.approx(-0.25 * MU_D, abs=1e-15)
    assert mu(AMBROSIO, V_1) == MU_D
    assert mu(AMBROSIO, 2.0) == MU_D


@pytest.mark.parametrize(
    ("law", "edge"),
    [(STICTION_STEP, V_S), (STICTION_STEP, V_D), (STICTION_STEP, -V_S), (STICTION_STEP, -V_D),
     (AMBROSIO, V_0), (AMBROSIO, V_1), (AMBROSIO, -V_0), (AMBROSIO, -V_1)],
)
def test_continuous_at_band_edges(law, edge):
    below, above = np.nextafter(edge, -np.inf), np.nextafter(edge, np.inf)
    assert mu(law, below) == pytest.approx(mu(law, above), abs=1e-9)
    assert mu(law, edge) == pytest.approx(mu(law, above), abs=1e-9)


@pytest.mark.parametrize("law", ALL_LAWS)
def test_odd_in_sliding_velocity(law):
    for velocity in np.geomspace(1e-7, 1.0, 57):
        assert mu(law, -velocity) == pytest.approx(-mu(law, velocity), abs=1e-15)


@pytest.mark.parametrize("law", ALL_LAWS)
def test_friction_opposes_sliding(law):
    normal_force = 1.0e3
    for velocity in np.concatenate([-np.geomspace(1e-7, 1.0, 40), np.geomspace(1e-7, 1.0, 40)]):
        tangential_force = -mu(law, velocity) * normal_force
        assert tangential_force * velocity <= 0.0
