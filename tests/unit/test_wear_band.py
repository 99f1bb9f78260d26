"""The load-following wear band (physics/wear.py): its Fourier coefficients, its half-angle, its volume and ringing."""

import math

import numpy as np
import pytest

from clearsim.physics import wear

BEARING_RADIUS, CLEARANCE = 0.05, 1e-5
JOURNAL_RADIUS = BEARING_RADIUS - CLEARANCE
LINE_STIFFNESS = math.pi * 0.04 * 207e9 / (2 * (1 - 0.3**2))  # S = π L E*, steel on steel, L = 40 mm


def band_quadrature(m, half_angle, nodes=400):
    """∫ p(φ) cos mφ dφ / ∫ p(φ) dφ of p(φ) = cos(πφ/2α) on |φ| ≤ α by Gauss–Legendre quadrature (exact to round-off
    for these entire integrands: 400 nodes over at most 32 periods of cos 64φ)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    phi = half_angle * x
    shape = np.cos(0.5 * math.pi * x)
    return float(np.sum(w * shape * np.cos(m * phi)) / np.sum(w * shape))


@pytest.mark.parametrize("half_angle", [0.01, 0.3, math.pi / 6, 1.0, 0.5 * math.pi])
def test_band_coefficients_are_those_of_the_half_cosine(half_angle):
    """B_m against a quadrature of ∫ cos(πφ/2α) cos mφ dφ / ∫ cos(πφ/2α) dφ, m = 0..64 (1e-12), including
    mα = π/2 (α = π/6, m = 3), where the closed form's fraction is 0/0."""
    for m in range(65):
        assert wear.band_coefficient(m, half_angle) == pytest.approx(band_quadrature(m, half_angle), abs=1e-12), m


def test_no_band_leaves_the_kernel_as_it_is():
    harmonics = 32
    weights = wear.kernel_weights(wear.SMALLEST_SIGMA / harmonics, harmonics)
    kernel, band = np.zeros(2 * harmonics + 1), np.zeros(2 * harmonics + 1)
    wear.add_kernel_rates(kernel, weights, harmonics, 2.5, 0.7)
    wear.add_band_rates(band, weights, harmonics, 2.5, 0.7, 0.0)
    assert np.array_equal(kernel, band)


def test_the_half_angle_is_the_hertz_line_contact_s():
    """α = b/R_B, b = √(4 F R*/(π L E*)), R* = R_J R_B/c on a circular bore (Johnson 1985, eq. 4.43): √F, and the
    brief's ±36° at J's 18 kN with L = 50 mm."""
    for force in (10.0, 1e3, 1.8e4):
        expected = math.sqrt(4 * force * JOURNAL_RADIUS * BEARING_RADIUS / (CLEARANCE * LINE_STIFFNESS))
        assert wear.band_half_angle(force, LINE_STIFFNESS, JOURNAL_RADIUS, BEARING_RADIUS, BEARING_RADIUS) == \
            pytest.approx(expected / BEARING_RADIUS, rel=1e-14)
    fifty_mm = LINE_STIFFNESS * 50 / 40
    assert math.degrees(wear.band_half_angle(1.8e4, fifty_mm, JOURNAL_RADIUS, BEARING_RADIUS, BEARING_RADIUS)) == \
        pytest.approx(36.3, abs=0.1)


def test_the_half_angle_is_conformal_at_most():
    """At most 90°: under a large load, and wherever the bore is as tight as the journal or tighter; a stated
    width (S = 0) has no band."""
    assert wear.band_half_angle(1e9, LINE_STIFFNESS, JOURNAL_RADIUS, BEARING_RADIUS, BEARING_RADIUS) == 0.5 * math.pi
    for radius in (JOURNAL_RADIUS, 0.9 * JOURNAL_RADIUS):
        assert wear.band_half_angle(1.0, LINE_STIFFNESS, JOURNAL_RADIUS, radius, BEARING_RADIUS) == 0.5 * math.pi
    assert wear.band_half_angle(1e3, 0.0, JOURNAL_RADIUS, BEARING_RADIUS, BEARING_RADIUS) == 0.0


def test_a_groove_narrows_the_local_clearance():
    """The bore's radius of curvature: R_B + a_0 on a circle; (R + d)²/(R + d + m² d) at the bottom θ = 0 of a
    groove h = a_0 + d cos mθ (ρ' = 0 there), so the band widens as the groove deepens."""
    circle = np.array([2e-6])
    assert wear.bore_curvature_radius(circle, 0, BEARING_RADIUS, 0.3) == pytest.approx(BEARING_RADIUS + 2e-6,
                                                                                      rel=1e-15)
    m, depth = 8, 1e-6
    groove = np.zeros(2 * m + 1)
    groove[0], groove[2 * m - 1] = depth, depth
    rho = BEARING_RADIUS + 2 * depth
    radius = wear.bore_curvature_radius(groove, m, BEARING_RADIUS, 0.0)
    assert radius == pytest.approx(rho**2 / (rho + m * m * depth), rel=1e-14)
    assert wear.band_half_angle(100.0, LINE_STIFFNESS, JOURNAL_RADIUS, radius, BEARING_RADIUS) > \
        wear.band_half_angle(100.0, LINE_STIFFNESS, JOURNAL_RADIUS, BEARING_RADIUS, BEARING_RADIUS)


@pytest.mark.parametrize("harmonics", [8, 32, 512])
def test_every_band_keeps_the_volume_and_hardly_rings(harmonics):
    """Whatever its half-angle, the band's series holds the whole volume (a_0 = 1/2π), peaks at the contact and dips
    below 0 by less than the narrowest kernel's 1e-4 of its peak (the schema's allowance for a worn profile)."""
    weights = wear.kernel_weights(wear.SMALLEST_SIGMA / harmonics, harmonics)
    angles = np.linspace(0, 2 * np.pi, 20000, endpoint=False)
    for half_angle in np.linspace(0.0, 0.5 * math.pi, 13):
        rates = np.zeros(2 * harmonics + 1)
        wear.add_band_rates(rates, weights, harmonics, 1.0, 0.3, half_angle)
        kernel = wear.evaluate_profile(rates, angles)
        assert rates[0] == 1 / (2 * np.pi)
        assert angles[np.argmax(kernel)] == pytest.approx(0.3, abs=2 * np.pi / 20000)
        assert kernel.min() > -1e-4 * kernel.max()
