"""The film forces of clearsim.physics.lubrication against quadrature of their pressure fields and textbook limits."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from clearsim.physics import lubrication as lub

MU, R, L, C = 0.1, 0.02, 0.015, 5e-5  # Pa·s, m, m, m
CASES = [  # (ε, ε̇ (1/s), w (rad/s)): wedge only, squeeze only, both with either sign, near the centre and the wall
    (0.5, 0.0, 100.0), (0.5, 3.0, 0.0), (0.3, -4.0, 50.0), (0.8, 10.0, -200.0), (0.95, -1.0, 30.0),
    (5e-5, 2.0, 10.0), (0.02, 0.5, -7.0),
]


def _positive_moments(pressure, lo, hi):
    """−R ∫ max(P, 0) (cos θ, sin θ) dθ by adaptive quadrature, split at the film's thinnest point."""
    def part(weight):
        f = lambda th: max(pressure(th), 0.0) * weight(th)  # noqa: E731
        return quad(f, lo, 0.0, limit=400, epsabs=0, epsrel=1e-12)[0] + quad(f, 0.0, hi, limit=400, epsabs=0,
                                                                            epsrel=1e-12)[0]
    return -part(math.cos), -part(math.sin)


def short_reference(eps, rate, wedge):
    pressure = lambda th: MU * L ** 3 * (2 * rate * math.cos(th) - eps * wedge * math.sin(th)) / (  # noqa: E731
        2 * C * C * (1 - eps * math.cos(th)) ** 3)
    fn, ft = _positive_moments(pressure, -math.pi, math.pi)
    return R * fn, R * ft


def long_reference(eps, rate, wedge):
    """p by quadrature of Reynolds' p' = 6μR²(K − ε w cos θ − 2ε̇ sin θ)/(c² D³) from p(π) = 0."""
    k = 3 * eps * eps * wedge / (2 + eps * eps)
    slope = lambda th: 6 * MU * R * R * (k - eps * wedge * math.cos(th) - 2 * rate * math.sin(th)) / (  # noqa: E731
        C * C * (1 - eps * math.cos(th)) ** 3)
    grid = np.linspace(-math.pi, math.pi, 4001)
    values = np.concatenate([[0.0], np.cumsum([quad(slope, a, b, epsabs=0, epsrel=1e-13)[0]
                                                for a, b in zip(grid[:-1], grid[1:])])])
    positive = np.maximum(values, 0.0)
    from scipy.integrate import simpson
    return -R * L * simpson(positive * np.cos(grid), x=grid), -R * L * simpson(positive * np.sin(grid), x=grid)


@pytest.mark.parametrize("eps, rate, wedge", CASES)
def test_short_bearing_force_equals_the_quadrature_of_its_positive_pressure(eps, rate, wedge):
    fn, ft = lub.short_bearing_force(MU, R, L, C, eps, rate, wedge)
    ref_n, ref_t = short_reference(eps, rate, wedge)
    scale = math.hypot(ref_n, ref_t)
    assert abs(fn - ref_n) <= 1e-8 * scale and abs(ft - ref_t) <= 1e-8 * scale


@pytest.mark.parametrize("eps, rate, wedge", [c for c in CASES if c[0] < 0.9])
def test_long_bearing_force_equals_the_quadrature_of_its_positive_pressure(eps, rate, wedge):
    fn, ft = lub.long_bearing_force(MU, R, L, C, eps, rate, wedge)
    ref_n, ref_t = long_reference(eps, rate, wedge)
    scale = math.hypot(ref_n, ref_t)
    assert abs(fn - ref_n) <= 1e-5 * scale and abs(ft - ref_t) <= 1e-5 * scale  # the reference's grid, not ours


@pytest.mark.parametrize("eps", [0.1, 0.5, 0.9])
def test_wedge_only_forces_are_the_textbook_closed_forms(eps):
    """Ocvirk: F_r = −μωRL³ε²/(c²(1−ε²)²), F_t = πμωRL³ε/(4c²(1−ε²)^1.5); Sommerfeld (half film):
    F_r = −12μωR³Lε²/(c²(2+ε²)(1−ε²)), F_t = 6πμωR³Lε/(c²(2+ε²)(1−ε²)^0.5) (Hamrock, Fundamentals of Fluid
    Film Lubrication, 2004, ch. 12)."""
    w = 80.0
    fn, ft = lub.short_bearing_force(MU, R, L, C, eps, 0.0, w)
    assert fn == pytest.approx(-MU * w * R * L ** 3 * eps ** 2 / (C * C * (1 - eps ** 2) ** 2), rel=1e-10)
    assert ft == pytest.approx(math.pi * MU * w * R * L ** 3 * eps / (4 * C * C * (1 - eps ** 2) ** 1.5), rel=1e-10)
    fn, ft = lub.long_bearing_force(MU, R, L, C, eps, 0.0, w)
    assert fn == pytest.approx(-12 * MU * w * R ** 3 * L * eps ** 2 / (C * C * (2 + eps ** 2) * (1 - eps ** 2)),
                               rel=1e-9)
    assert ft == pytest.approx(6 * math.pi * MU * w * R ** 3 * L * eps / (C * C * (2 + eps ** 2)
                                                                         * math.sqrt(1 - eps ** 2)), rel=1e-9)


@pytest.mark.parametrize("model", [lub.SHORT_BEARING, lub.LONG_BEARING])
def test_a_centred_still_journal_feels_no_force_and_reversing_the_motion_mirrors_it(model):
    assert lub.film_force(model, MU, R, L, C, 0.0, 0.0, 0.0) == (0.0, 0.0)
    assert lub.film_force(model, MU, R, L, C, 0.4, 0.0, 0.0) == (0.0, 0.0)
    assert lub.film_force(model, MU, R, L, C, 0.0, 0.0, 100.0) == pytest.approx((0.0, 0.0), abs=1e-9)
    fn, ft = lub.film_force(model, MU, R, L, C, 0.6, 0.0, 50.0)
    mirrored = lub.film_force(model, MU, R, L, C, 0.6, 0.0, -50.0)  # mirror image about n: F_t flips
    assert mirrored[0] == pytest.approx(fn, rel=1e-12) and mirrored[1] == pytest.approx(-ft, rel=1e-12)


@pytest.mark.parametrize("model", [lub.SHORT_BEARING, lub.LONG_BEARING])
def test_the_squeeze_force_opposes_the_approach_and_grows_without_bound_towards_the_wall(model):
    forces = [lub.film_force(model, MU, R, L, C, eps, 1.0, 0.0)[0] for eps in (0.5, 0.9, 0.99, 0.999)]
    assert all(f < 0.0 for f in forces)
    assert all(abs(b) > 10 * abs(a) for a, b in zip(forces[1:], forces[2:]))  # ~ (1 − ε)^−2.5 and steeper
    separating = lub.film_force(model, MU, R, L, C, 0.5, -1.0, 0.0)
    if model == lub.SHORT_BEARING:  # the thick side's film is squeezed: it pushes the journal on, along +n
        assert separating[0] > 0.0
    else:  # with p = 0 at the thickest film, a separating long film is below ambient everywhere: cavitated
        assert separating == (0.0, 0.0)


def test_the_small_eccentricity_series_joins_the_closed_form():
    below = lub.short_bearing_force(MU, R, L, C, 0.99999 * lub.SMALL_ECCENTRICITY, 1.0, 30.0)
    above = lub.short_bearing_force(MU, R, L, C, 1.00001 * lub.SMALL_ECCENTRICITY, 1.0, 30.0)
    scale = math.hypot(*above)  # F_t ∝ ε changes by 2e-5 of itself between the two: compare against |F|
    assert below == pytest.approx(above, abs=1e-7 * scale)


def test_petroff_torque_at_the_centre_and_its_growth_towards_the_wall():
    torque = lub.film_torque(MU, R, L, C, 0.0, 100.0)
    assert torque == pytest.approx(-2 * math.pi * MU * R ** 3 * L * 100.0 / C, rel=1e-14)
    assert lub.film_torque(MU, R, L, C, 0.8, 100.0) == pytest.approx(torque / 0.6, rel=1e-14)
    assert lub.film_torque(MU, R, L, C, 0.3, -100.0) == pytest.approx(-lub.film_torque(MU, R, L, C, 0.3, 100.0))


def test_range_warnings_name_the_joint_and_the_model_outside_its_length_to_diameter_ratio():
    assert lub.film_range_warnings("J", lub.SHORT_BEARING, MU, 0.05, 0.05) == []  # L/D = 0.5
    assert lub.film_range_warnings("J", lub.SHORT_BEARING, MU, 0.05, 0.05 - 1e-5) == []  # L/D = 0.5001 prints 0.5
    assert lub.film_range_warnings("J", lub.SHORT_BEARING, MU, 0.0501, 0.05)  # 0.501
    [text] = lub.film_range_warnings("J", lub.SHORT_BEARING, MU, 0.1, 0.05)  # L/D = 1
    assert "joint 'J'" in text and "short_bearing" in text and "L/D = 1 " in text
    assert lub.film_range_warnings("J", lub.LONG_BEARING, MU, 0.2, 0.05) == []  # L/D = 2
    [text] = lub.film_range_warnings("J", lub.LONG_BEARING, MU, 0.1, 0.05)
    assert "long_bearing" in text
    assert lub.film_range_warnings("J", lub.SHORT_BEARING, 0.0, 0.1, 0.05) == []  # a dry joint has no film


def _film_force_vector(e, e_rate, spin_sum):
    """The short-bearing film force on the journal as a global vector, built as assembly/forces.py does: the line of
    centres (lub.line_of_centres), ε, ε̇ = n·ė/c and the wedge speed ω_J + ω_B − 2φ̇ with φ̇ = t·ė/|e|."""
    nx, ny, eccentricity = lub.line_of_centres(e[0], e[1], e_rate[0], e_rate[1], C)
    orbit_rate = (-ny * e_rate[0] + nx * e_rate[1]) / eccentricity if eccentricity > 0.0 else 0.0
    fn, ft = lub.short_bearing_force(MU, R, L, C, eccentricity / C, (nx * e_rate[0] + ny * e_rate[1]) / C,
                                     spin_sum - 2.0 * orbit_rate)
    return np.array([fn * nx - ft * ny, fn * ny + ft * nx])


@pytest.mark.parametrize("e_rate", [(0.0, -2e-6), (3e-7, 1e-6), (-1e-6, 0.0)])
def test_a_centred_journal_feels_the_squeeze_film_of_its_whole_velocity(e_rate):
    """At e = 0 exactly (a journal started centred) the force is the limit of ε → 0 from any direction (the
    squeeze film opposing ė); with n = (1, 0) and φ̇ = 0 the film ignored ė's part across n (zero force for ė
    along y)."""
    e_rate = np.array(e_rate)
    centred = _film_force_vector((0.0, 0.0), e_rate, 20.0)
    for angle in (0.3, 2.0, -2.5):
        near = _film_force_vector(1e-9 * C * np.array([math.cos(angle), math.sin(angle)]), e_rate, 20.0)
        np.testing.assert_allclose(centred, near, rtol=0, atol=1e-6 * np.linalg.norm(near))
    assert centred @ e_rate < -0.99 * np.linalg.norm(centred) * np.linalg.norm(e_rate)  # opposes ė
    np.testing.assert_array_equal(_film_force_vector((0.0, 0.0), np.zeros(2), 20.0), np.zeros(2))
