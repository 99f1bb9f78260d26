"""Hydrodynamic film forces of a lubricated journal bearing (short and long bearing, half-Sommerfeld cavitation).

Frame of the eccentricity: n = e/|e| (bearing centre → journal centre), t = n turned by +90°. The angle θ is
measured from n, counter-clockwise, so the film thickness is h(θ) = c (1 − ε cos θ), ε = |e|/c, thinnest at θ = 0.
The surfaces move at ω_J and ω_B, the line of centres turns at φ̇ = t·ė/|e| and ε̇ = n·ė/c; in the frame of the
line of centres Reynolds' equation (Pinkus & Sternlicht, *Theory of Hydrodynamic Lubrication*, 1961;
Frêne et al., *Hydrodynamic Lubrication*, 1997) reads, with x = Rθ

    ∂/∂x (h³ ∂p/∂x) + ∂/∂z (h³ ∂p/∂z) = 6 μ (ω_J + ω_B − 2 φ̇) ∂h/∂θ + 12 μ ∂h/∂t,

the wedge term driven by w = ω_J + ω_B − 2φ̇ and the squeeze term by ε̇. Short bearing (Ocvirk, L/D → 0): the
circumferential flow term is dropped. Long bearing (Sommerfeld, L/D → ∞): the axial one is dropped, with p = 0 at
the thickest film (θ = π). Cavitation (Gümbel, half-Sommerfeld): negative pressures are set to zero, i.e. the
forces integrate the pressure only where it is positive, at the boundaries where it vanishes at this instant
(as Daniel, Machado & Cavalca, Mech. Mach. Theory 99 (2016) 19, instead of a fixed π film).

Every integral is in closed form through the antiderivatives of cosᵃθ sinᵇθ / (1 − ε cos θ)³. Returned forces
act on the journal (the bearing takes the opposite), (F_n, F_t) along (n, t), in N; see docs/model-contact.md.
"""

import math

from numba import njit

SHORT_BEARING = 0
LONG_BEARING = 1
BEARING_MODELS = {"short_bearing": SHORT_BEARING, "long_bearing": LONG_BEARING}

SMALL_ECCENTRICITY = 1e-4  # below it the film integrals use their Taylor series in ε (cancellation above 1e-8)
LONG_BEARING_SAMPLES = 48  # sign samples per turn when the long bearing's zero-pressure angles are searched


CENTRED = 1e-12  # ε below which the journal counts as centred (line_of_centres)


@njit(cache=True)
def line_of_centres(ex, ey, dex, dey, clearance):
    """(n_x, n_y, |e|) of the film: n = e/|e|, but along ė for a journal centred to below CENTRED·c, with |e| = 0.

    At ε → 0 the film force tends to one that depends on ė alone, whatever n: the rates (2ε̇, εw) tend to
    (2/c)(n·ė, −t·ė) (εφ̇ = t·ė/c), so the pressure ∝ ė·(cos θ, sin θ) in the frame of any n, i.e. the
    squeeze film opposing ė. It is that limit only if t·ė enters through εφ̇, which needs |e| > 0: at |e| = 0 (a
    journal started centred) φ̇ has no value and the film would ignore the part of ė across an arbitrary n. Taking
    n along ė gives the limit with φ̇ = 0; below CENTRED·c the wedge term ε(ω_J + ω_B) it drops is 1e-12 of a
    squeeze term, and e of round-off size (1e-16 m for a mechanism drawn 1 m from the origin) is noise anyway."""
    eccentricity = math.sqrt(ex * ex + ey * ey)
    if eccentricity >= CENTRED * clearance:
        return ex / eccentricity, ey / eccentricity, eccentricity
    speed = math.sqrt(dex * dex + dey * dey)
    if speed > 0.0:
        return dex / speed, dey / speed, 0.0
    return 1.0, 0.0, 0.0


@njit(cache=True, inline="always")
def _film_thickness_ratio(theta, eps):
    """D = 1 − ε cos θ: the film thickness over c."""
    return 1.0 - eps * math.cos(theta)


@njit(cache=True)
def _integral_inverse(theta, eps):
    """J₁ = ∫ dθ / D = θ/s + (2/s) atan(ε sin θ / (1 + s − ε cos θ)), s = √(1 − ε²) (continuous in θ)."""
    s = math.sqrt(1.0 - eps * eps)
    return theta / s + 2.0 / s * math.atan(eps * math.sin(theta) / (1.0 + s - eps * math.cos(theta)))


@njit(cache=True)
def film_antiderivatives(theta, eps):
    """(∫1/D³, ∫cos/D³, ∫cos²/D³, ∫sin/D³, ∫sin cos/D³) at θ, D = 1 − ε cos θ, by the reduction
    n(1−ε²) J_{n+1} = ε sin θ/Dⁿ + (2n−1) J_n − (n−1) J_{n−1} (d/dθ of sin θ/Dⁿ)."""
    d = _film_thickness_ratio(theta, eps)
    s2 = 1.0 - eps * eps
    sin = math.sin(theta)
    cos = math.cos(theta)
    j1 = _integral_inverse(theta, eps)
    j2 = (eps * sin / d + j1) / s2
    j3 = (eps * sin / (d * d) + 3.0 * j2 - j1) / (2.0 * s2)
    if eps >= SMALL_ECCENTRICITY:
        return j3, (j3 - j2) / eps, (j3 - 2.0 * j2 + j1) / (eps * eps), -0.5 / (eps * d * d), \
            -(0.5 / (d * d) - 1.0 / d) / (eps * eps)
    # 1/D³ = 1 + 3ε cos θ + 6ε² cos² θ + O(ε³), term by term
    cos2 = 0.5 * (theta + sin * cos)
    cos3 = sin - sin ** 3 / 3.0
    cos4 = 0.375 * theta + 0.25 * math.sin(2.0 * theta) + math.sin(4.0 * theta) / 32.0
    return (j3, sin + 3.0 * eps * cos2 + 6.0 * eps * eps * cos3, cos2 + 3.0 * eps * cos3 + 6.0 * eps * eps * cos4,
            -cos - 1.5 * eps * cos ** 2 - 2.0 * eps * eps * cos ** 3,
            0.5 * sin * sin - eps * cos ** 3 - 1.5 * eps * eps * cos ** 4)


@njit(cache=True)
def film_integrals(lo, hi, eps):
    """(∫1/D³, ∫cos/D³, ∫cos²/D³, ∫sin/D³, ∫sin cos/D³, ∫sin²/D³) over [lo, hi]."""
    a = film_antiderivatives(lo, eps)
    b = film_antiderivatives(hi, eps)
    cc = b[2] - a[2]
    return b[0] - a[0], b[1] - a[1], cc, b[3] - a[3], b[4] - a[4], (b[0] - a[0]) - cc


@njit(cache=True)
def short_bearing_force(viscosity, radius, length, clearance, eps, eps_rate, wedge_speed):
    """(F_n, F_t) of the Ocvirk short bearing, half-Sommerfeld: P(θ) = ∫p dz = μL³(2ε̇ cos θ − ε w sin θ)/(2c²D³)
    (Ocvirk 1952; Pinkus & Sternlicht 1961; Frêne et al. 1997), F = −R ∫ P (cos θ, sin θ) dθ where P > 0."""
    squeeze = 2.0 * eps_rate
    wedge = -eps * wedge_speed
    if squeeze == 0.0 and wedge == 0.0:
        return 0.0, 0.0
    centre = math.atan2(wedge, squeeze)  # P ∝ cos(θ − centre): positive within ±π/2 of it
    _, _, cc, _, sc, ss = film_integrals(centre - 0.5 * math.pi, centre + 0.5 * math.pi, eps)
    scale = viscosity * radius * length ** 3 / (2.0 * clearance * clearance)
    return -scale * (squeeze * cc + wedge * sc), -scale * (squeeze * sc + wedge * ss)


@njit(cache=True)
def long_bearing_pressure(theta, eps, eps_rate, wedge_speed):
    """p(θ) c²/(6μR²) of the full-Sommerfeld long bearing with p(π) = 0: the integral from π of
    p' c²/(6μR²) = (K − ε w cos θ − 2ε̇ sin θ)/D³, K = 3ε² w/(2 + ε²) making p periodic (Sommerfeld 1904)."""
    i0, ic, _, i_s, _, _ = film_integrals(math.pi, theta, eps)
    return _periodic_term(eps, wedge_speed) * i0 - eps * wedge_speed * ic - 2.0 * eps_rate * i_s


@njit(cache=True, inline="always")
def _periodic_term(eps, wedge_speed):
    return 3.0 * eps * eps * wedge_speed / (2.0 + eps * eps)


@njit(cache=True)
def _pressure_zero(lo, hi, p_lo, eps, eps_rate, wedge_speed):
    """The angle in [lo, hi] where the long bearing's pressure changes sign (bisection to 1e-13 rad)."""
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        p_mid = long_bearing_pressure(mid, eps, eps_rate, wedge_speed)
        if (p_mid > 0.0) == (p_lo > 0.0):
            lo, p_lo = mid, p_mid
        else:
            hi = mid
        if hi - lo < 1e-13:
            break
    return 0.5 * (lo + hi)


@njit(cache=True)
def _pressure_derivative_moments(lo, hi, eps, eps_rate, wedge_speed):
    """(∫p' cos, ∫p' sin) over [lo, hi] in units of 6μR²/c² when the arc is under positive pressure, else 0."""
    if long_bearing_pressure(0.5 * (lo + hi), eps, eps_rate, wedge_speed) <= 0.0:
        return 0.0, 0.0
    _, c, cc, s, sc, ss = film_integrals(lo, hi, eps)
    periodic = _periodic_term(eps, wedge_speed)
    return (periodic * c - eps * wedge_speed * cc - 2.0 * eps_rate * sc,
            periodic * s - eps * wedge_speed * sc - 2.0 * eps_rate * ss)


@njit(cache=True)
def long_bearing_force(viscosity, radius, length, clearance, eps, eps_rate, wedge_speed):
    """(F_n, F_t) of the Sommerfeld long bearing, half-Sommerfeld: F = −RL ∫ p (cos θ, sin θ) dθ over the arcs
    where p > 0, by parts with p = 0 at their ends: ∫p cos = −∫p' sin, ∫p sin = ∫p' cos (Sommerfeld 1904;
    Pinkus & Sternlicht 1961). The arcs' ends are the sign changes of p between LONG_BEARING_SAMPLES samples per
    turn, refined by bisection."""
    step = 2.0 * math.pi / LONG_BEARING_SAMPLES
    cos_part = 0.0
    sin_part = 0.0
    arc_start = math.pi  # p(π) = p(3π) = 0: the turn from π to 3π starts and ends an arc
    lo = math.pi + step
    p_lo = long_bearing_pressure(lo, eps, eps_rate, wedge_speed)
    for i in range(2, LONG_BEARING_SAMPLES):
        hi = math.pi + i * step
        p_hi = long_bearing_pressure(hi, eps, eps_rate, wedge_speed)
        if (p_hi > 0.0) != (p_lo > 0.0):
            zero = _pressure_zero(lo, hi, p_lo, eps, eps_rate, wedge_speed)
            c_arc, s_arc = _pressure_derivative_moments(arc_start, zero, eps, eps_rate, wedge_speed)
            cos_part += c_arc
            sin_part += s_arc
            arc_start = zero
        lo, p_lo = hi, p_hi
    c_arc, s_arc = _pressure_derivative_moments(arc_start, 3.0 * math.pi, eps, eps_rate, wedge_speed)
    scale = 6.0 * viscosity * radius ** 3 * length / (clearance * clearance)
    return scale * (sin_part + s_arc), -scale * (cos_part + c_arc)


@njit(cache=True)
def film_force(model, viscosity, radius, length, clearance, eps, eps_rate, wedge_speed):
    """(F_n, F_t) on the journal of the film model (SHORT_BEARING or LONG_BEARING)."""
    if model == LONG_BEARING:
        return long_bearing_force(viscosity, radius, length, clearance, eps, eps_rate, wedge_speed)
    return short_bearing_force(viscosity, radius, length, clearance, eps, eps_rate, wedge_speed)


@njit(cache=True)
def film_torque(viscosity, radius, length, clearance, eps, relative_speed):
    """Viscous torque on the journal, −2π μ R³ L (ω_J − ω_B)/(c √(1 − ε²)): the Couette shear μ R (ω_J − ω_B)/h
    over the whole film, ∫dθ/D = 2π/√(1 − ε²) (Petroff 1883 at ε = 0), without the pressure-flow term."""
    return -2.0 * math.pi * viscosity * radius ** 3 * length * relative_speed / (
        clearance * math.sqrt(1.0 - eps * eps))


# --- validity ---------------------------------------------------------------------------------------------------

SHORT_BEARING_MAX_RATIO = 0.5  # L/D up to which the short-bearing (Ocvirk) force is a fair approximation
LONG_BEARING_MIN_RATIO = 2.0  # L/D from which the long-bearing (Sommerfeld) force is


def film_range_warnings(joint, model, viscosity, length, journal_radius):
    """The run summary's warning for joint `joint` (name) whose film model (BEARING_MODELS value) is used at a
    length-to-diameter ratio L/D outside its range: short bearing above 1/2, long bearing below 2 (both then
    overestimate the load: the short one's pressure grows as L², the long one ignores the side leakage).
    The ratio is compared as printed, to 3 digits: the ranges are rules of thumb, and a 50 mm pin 10 µm loose
    in a 50 mm long bearing (L/D = 0.5001) is not outside L/D ≤ 1/2. None for a dry joint (viscosity 0)."""
    if viscosity <= 0.0:
        return []
    ratio = float(f"{length / (2.0 * journal_radius):.3g}")
    if model == SHORT_BEARING and ratio > SHORT_BEARING_MAX_RATIO:
        return [f"joint '{joint}': the short_bearing film assumes L/D <= {SHORT_BEARING_MAX_RATIO:g}; L/D = "
                f"{ratio:.3g} here, so the film force is overestimated (long_bearing holds from L/D = "
                f"{LONG_BEARING_MIN_RATIO:g})"]
    if model == LONG_BEARING and ratio < LONG_BEARING_MIN_RATIO:
        return [f"joint '{joint}': the long_bearing film assumes L/D >= {LONG_BEARING_MIN_RATIO:g}; L/D = "
                f"{ratio:.3g} here, so the film force is overestimated (short_bearing holds up to L/D = "
                f"{SHORT_BEARING_MAX_RATIO:g})"]
    return []
