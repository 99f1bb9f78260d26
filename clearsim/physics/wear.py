"""Worn bores and Archard wear (docs/model-contact.md, "Worn bores and Archard wear").

A worn bore's wear depth over the angle θ in the bearing body's frame is a truncated Fourier series

    h(θ) = a_0 + Σ_{m=1..M} (a_m cos mθ + b_m sin mθ),   coefficients stored as [a_0, a_1, b_1, a_2, b_2, ...],

so the bore is the curve r(θ) = (R_B + h(θ)) u(θ), u = (cos θ, sin θ): C∞, periodic, with exact derivatives for its
normal. The journal (radius R_J, centre e in the bearing frame) touches it at the bore point closest to e:
θ* minimises |r(θ) − e|², found by Newton's method from the angle of e (searched for only where that is not certain
to be the global minimum: nearest_bore_point); the penetration is δ = R_J − |r(θ*) − e| and
the contact normal n = (r(θ*) − e)/|r(θ*) − e| is the bore's local normal there (exact, not e/|e|).

Archard's law gives the worn volume rate V̇ = k_w F_n |v_t| / H; it is spread over the bore with a periodic kernel
K(φ) = (1/2π)(1 + 2 Σ g_m B_m cos mφ), g_m = exp(−m²σ²/2) (a wrapped Gaussian truncated at M harmonics) and B_m the
Fourier coefficients of the contact's band, ∫K dφ = 1: ḣ(θ) = V̇ K(θ − θ_c)/(L R_B), so the volume is exactly
Archard's and the depth rate under the contact is V̇/(L w) with w = R_B/K(0) the kernel's width. Either the band
follows the load (the default): a half-cosine over the contact's half-angle α = b/R_B, b the Hertz line-contact
half-width with the bore's local clearance, at most π/2 (conformal), smoothed by the narrowest Gaussian M carries
(σ = 4/M); or a stated width fixes σ (B_m = 1).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

SAFEGUARDED_ITERATIONS = 60  # Newton converges quadratically (a step below NEWTON_TOLERANCE ends it); a bisection
# step, taken when Newton would leave its bracket of one sample spacing either side, halves it (one below 1e-15 rad
# ends it)
NEWTON_TOLERANCE = 1e-12  # rad: the point after such a step is off by ~(g''/2g') 1e-24 plus the round-off of g, which
# makes the steps jitter at ~ε R_B/|e| (5e-13 rad in a 0.01 mm joint of R_B = 50 mm): a smaller one is never reached
WALK_SPACINGS = 4  # the longest step towards a minimum before its bracket, in sample spacings 2π/(8M)
SMALLEST_SIGMA = 4.0  # σ ≥ 4/M: the truncated kernel's last weight is e^{-8} = 3e-4 of the first (no ringing)
FEWEST_SAMPLES = 128  # the searches sample the bore every 2π/(8M), at least every π/64 (bore_samples): a few
# harmonics' pocket has its rims tens of degrees apart, which 2π/(8M) could step over
CONFORMAL_HALF_ANGLE = 0.5 * math.pi  # rad: a journal touches its bore within 90° of the load, however conformal


@njit(cache=True)
def profile_value(coefficients, harmonics, theta):
    """(h, h', h'') of the Fourier profile at θ (coefficients [a_0, a_1, b_1, ...], `harmonics` of them)."""
    h, slope, curvature = coefficients[0], 0.0, 0.0
    c1, s1 = np.cos(theta), np.sin(theta)
    cm, sm = 1.0, 0.0
    for m in range(1, harmonics + 1):
        cm, sm = cm * c1 - sm * s1, sm * c1 + cm * s1  # cos mθ, sin mθ by the angle-sum recurrence
        a, b = coefficients[2 * m - 1], coefficients[2 * m]
        h += a * cm + b * sm
        slope += m * (b * cm - a * sm)
        curvature -= m * m * (a * cm + b * sm)
    return h, slope, curvature


def depth_range(coefficients) -> float:
    """An upper bound of max h − min h of a profile [a_0, a_1, b_1, …] (m): the range on 64 M angles, widened by the
    most the series can move between two of them (Σ m √(a_m² + b_m²) times half their spacing, at each end)."""
    coefficients = np.asarray(coefficients, float)
    harmonics = (len(coefficients) - 1) // 2
    if harmonics <= 0:  # a circular bore (no profile, or its mean depth alone)
        return 0.0
    angles = np.linspace(0.0, 2.0 * math.pi, 64 * harmonics, endpoint=False)
    depth = evaluate_profile(coefficients, angles)
    orders = np.arange(1, harmonics + 1)
    slope_bound = float(np.sum(orders * np.hypot(coefficients[1::2][:harmonics], coefficients[2::2][:harmonics])))
    return float(depth.max() - depth.min()) + slope_bound * (angles[1] - angles[0])


@njit(cache=True)
def search_window(eccentricity, depth_range):
    """Half-width Δ (rad) round the angle θ_e of e outside which no bore point is nearer to e than the one on e's ray:
    |r(θ) − e| ≥ ρ(θ) − |e| cos φ (φ = θ − θ_e) and |r(θ_e) − e| = ρ(θ_e) − |e|, so a nearer point needs
    |e| (1 − cos φ) < ρ(θ_e) − ρ(θ) ≤ depth_range."""
    if depth_range <= 0.0:
        return 0.0
    if depth_range >= 2.0 * eccentricity:
        return math.pi
    return math.acos(1.0 - depth_range / eccentricity)


@njit(cache=True)
def _distance_squared(coefficients, harmonics, bearing_radius, ex, ey, theta):
    h, _, _ = profile_value(coefficients, harmonics, theta)
    rho = bearing_radius + h
    return (rho * math.cos(theta) - ex) ** 2 + (rho * math.sin(theta) - ey) ** 2


@njit(cache=True)
def nearest_bore_point(coefficients, samples, harmonics, depth_range, reach, innermost, bearing_radius, ex, ey,
                       within):
    """closest_bore_point, searching only where the nearest point is not certain, and the second rim of a two-point
    contact. A point inside the bore nearer to it than its inner reach (inner_reach) lies on the inward normal of
    exactly one bore point, which is its nearest, so the minimum of the distance Newton's method finds from the angle
    of e (descended_foot) is the nearest point when its distance d is below the reach — always in contact (d ≈ R_J)
    on a bore nowhere tighter than the journal. Otherwise (e far from the wall, or a bore worn tighter than the
    journal somewhere, whose distance has several local minima: a two-point contact) a nearer point can only lie where
    ρ_min − |e| cos φ < d (φ = θ − θ_e; |r(θ) − e| ≥ ρ(θ) − |e| cos φ, ρ_min ≤ ρ = `innermost`), which narrows
    search_window's window; that is searched as closest_bore_point does (searched_foot, on the bore's `samples`,
    bore_samples), and the nearer of its point and Newton's kept. Where the reach is below `within` (the journal's
    radius: the bore may be tighter than the journal) and that point is nearer than `within`, the nearest other
    minimum nearer than `within` is the second rim the journal touches (second_foot; θ NaN where there is none).
    Returns (θ*, r_x, r_y, t_x, t_y, g') of the nearest point, then the same of the second rim."""
    eccentricity = math.sqrt(ex * ex + ey * ey)
    start = math.atan2(ey, ex) if eccentricity > 0.0 else 0.0
    spacing = 2.0 * math.pi / (8.0 * max(harmonics, 1))
    theta, distance = descended_foot(coefficients, harmonics, bearing_radius, ex, ey, start, spacing)
    window = search_window(eccentricity, depth_range)
    if distance < reach:
        window = 0.0
    elif distance < math.inf:
        window = min(window, nearer_window(eccentricity, innermost, distance))
    if window > 0.0:
        searched = searched_foot(coefficients, samples, harmonics, window, bearing_radius, ex, ey, start)
        if not distance <= math.sqrt(_distance_squared(coefficients, harmonics, bearing_radius, ex, ey, searched)):
            theta = searched
    rx, ry, tx, ty, gradient, second = _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, theta)
    rim = math.nan
    if reach < within and (rx - ex) ** 2 + (ry - ey) ** 2 < within * within:
        rim = second_foot(coefficients, samples, harmonics, bearing_radius, ex, ey, start,
                          nearer_window(eccentricity, innermost, within), theta, within)
    rim_x, rim_y, rim_tx, rim_ty, rim_second = 0.0, 0.0, 0.0, 0.0, 0.0
    if rim == rim:
        rim_x, rim_y, rim_tx, rim_ty, _, rim_second = _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, rim)
    return theta, rx, ry, tx, ty, second, rim, rim_x, rim_y, rim_tx, rim_ty, rim_second


@njit(cache=True)
def second_foot(coefficients, samples, harmonics, bearing_radius, ex, ey, start, window, first, within):
    """θ of the nearest local minimum of |r(θ) − e| other than the one at `first` and nearer than `within`: the
    second rim of a journal in a bore worn tighter than itself (NaN where there is none). The bore's `samples`
    (bore_samples) over `window` round `start` (one more either side); each sampled local minimum more than 1.5
    spacings from `first` is refined (refined_foot) and kept if it converges, more than half a spacing from `first`, to
    a minimum with e on the bore's inward side. Rims closer than that are one contact (the nearer)."""
    count = sample_count(harmonics)
    spacing = 2.0 * math.pi / count
    lowest, highest = sampled_span(start, window, spacing)
    best, best_distance = math.nan, within
    before = sampled_distance_squared(samples, count, lowest - 1, ex, ey)
    here = sampled_distance_squared(samples, count, lowest, ex, ey)
    for i in range(lowest, highest + 1):
        after = sampled_distance_squared(samples, count, i + 1, ex, ey)
        candidate = i * spacing
        if here <= before and here < after and abs(_wrapped(candidate - first)) > 1.5 * spacing:
            theta, converged = refined_foot(coefficients, harmonics, bearing_radius, ex, ey, candidate, spacing)
            if converged and abs(_wrapped(theta - first)) > 0.5 * spacing:
                rx, ry, tx, ty, _, second = _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, theta)
                dx, dy = ex - rx, ey - ry
                distance = math.sqrt(dx * dx + dy * dy)
                if second > 0.0 and dy * tx - dx * ty > 0.0 and distance < best_distance:
                    best, best_distance = theta, distance
        before, here = here, after
    return best


@njit(cache=True, inline="always")
def sample_count(harmonics):
    """N, the bore's sampled points (bore_samples): every 2π/(8M), at least every π/64 (FEWEST_SAMPLES)."""
    return max(8 * harmonics, FEWEST_SAMPLES)


@njit(cache=True, inline="always")
def sampled_span(start, window, spacing):
    """(first, last) indices of the samples k·spacing from `start` − `window` to `start` + `window` (rad), rounded
    outwards."""
    return int(math.floor((start - window) / spacing)), int(math.ceil((start + window) / spacing))


@njit(cache=True, inline="always")
def sampled_distance_squared(samples, count, index, ex, ey):
    """|r(θ_k) − e|² at the sample k = index mod count of bore_samples' table."""
    k = 2 * (index % count)
    return (samples[k] - ex) ** 2 + (samples[k + 1] - ey) ** 2


def bore_samples(coefficients, bearing_radius: float) -> np.ndarray:
    """The bore's points r(θ_k) = (R_B + h(θ_k)) u(θ_k) at θ_k = 2πk/N, N = sample_count(M), as [x_0, y_0, x_1, y_1,
    …] (m): the table the nearest-point and second-rim searches sample, built with the model (its profile is fixed
    for a run), so that a sample costs a lookup instead of the M-term series."""
    coefficients = np.asarray(coefficients, float)
    harmonics = max((coefficients.shape[0] - 1) // 2, 0)
    angles = 2.0 * math.pi * np.arange(sample_count(harmonics)) / sample_count(harmonics)
    radii = bearing_radius + evaluate_profile(coefficients, angles)
    return np.column_stack((radii * np.cos(angles), radii * np.sin(angles))).ravel()


@njit(cache=True, inline="always")
def _wrapped(angle):
    """angle in [−π, π)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


# nearest_bore_point's type as the kernels call it by address (KernelArrays.bore_point, assembly/arrays.py): a row
# of wear_profile and of wear_samples, the harmonics, depth range, reach, innermost radius, R_B, e_x, e_y, the
# second rim's reach -> (θ*, r_x, r_y, t_x, t_y, g'') of the nearest point and of the second rim (θ NaN: none)
BORE_POINT_TYPE = types.FunctionType(types.UniTuple(types.float64, 12)(
    types.float64[::1], types.float64[::1], types.int64, types.float64, types.float64, types.float64, types.float64,
    types.float64, types.float64, types.float64))


@njit(cache=True)
def no_bore_point(coefficients, samples, harmonics, depth_range, reach, innermost, bearing_radius, ex, ey, within):
    """nearest_bore_point's stand-in for a model without worn bores, of the same type and never called (its kernels
    reach the worn-bore geometry only for a joint with harmonics > 0): such a model does not compile that geometry."""
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


def bore_point_kernel(harmonics: np.ndarray):
    """The kernel that finds a worn bore's nearest point for a model whose joints have these wear harmonics:
    nearest_bore_point where a joint has a worn bore, else its stand-in (no_bore_point)."""
    return nearest_bore_point if np.any(harmonics > 0) else no_bore_point


@njit(cache=True, inline="always")
def nearer_window(eccentricity, innermost, distance):
    """Half-width (rad) round the angle of e outside which no bore point is nearer to e than `distance`:
    ρ_min − |e| cos φ ≥ d there (0: none anywhere; π: the whole bore)."""
    if innermost - distance >= eccentricity:
        return 0.0
    if innermost - distance <= -eccentricity:
        return math.pi
    return math.acos((innermost - distance) / eccentricity)


@njit(cache=True)
def closest_bore_point(coefficients, samples, harmonics, depth_range, bearing_radius, ex, ey):
    """(θ*, r_x, r_y, r'_x, r'_y, g') of the bore point r(θ*) closest to e = (ex, ey), all in the bearing frame;
    g' = |r'|² + (r − e)·r'' is the curvature of |r(θ) − e|²/2 there (> 0 at a minimum; for the rate of θ*).

    The global minimum: a bore worn tighter than the journal's curvature somewhere has several local minima of the
    distance (a two-point contact) with a maximum between them, and Newton's method from the angle of e may stop on
    either: searched_foot samples the window of search_window, where a nearer point can lie (`samples`:
    bore_samples)."""
    eccentricity = math.sqrt(ex * ex + ey * ey)
    start = math.atan2(ey, ex) if eccentricity > 0.0 else 0.0
    theta = searched_foot(coefficients, samples, harmonics, search_window(eccentricity, depth_range), bearing_radius,
                          ex, ey, start)
    rx, ry, tx, ty, gradient, second = _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, theta)
    return theta, rx, ry, tx, ty, second


@njit(cache=True, inline="always")
def descended_foot(coefficients, harmonics, bearing_radius, ex, ey, start, spacing):
    """(θ, d): Newton's method on g = (r − e)·r' = 0 from `start`, each step at most WALK_SPACINGS `spacing` (downhill
    by that where g' ≤ 0); once a full step is shorter than that, refined_foot from where it leads (twice at most: again from
    where the first stopped, if the minimum was beyond its bracket). d = |r(θ) − e| where that converges to a minimum
    with e on the bore's inward side, inf where it does not."""
    theta = start
    refinements = 0
    longest = WALK_SPACINGS * spacing
    for _ in range(SAFEGUARDED_ITERATIONS):
        rx, ry, tx, ty, gradient, second = _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, theta)
        if second > 0.0 and abs(gradient) < longest * second:
            theta, converged = refined_foot(coefficients, harmonics, bearing_radius, ex, ey, theta - gradient / second,
                                            spacing)
            refinements += 1
            if converged:
                rx, ry, tx, ty, gradient, second = _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, theta)
                dx, dy = ex - rx, ey - ry
                if second > 0.0 and dy * tx - dx * ty > 0.0:  # e − r along the inward normal (−r'_y, r'_x)
                    return theta, math.sqrt(dx * dx + dy * dy)
                return theta, math.inf
            if refinements == 2:
                break
        else:
            theta += -longest if gradient > 0.0 else longest
    return theta, math.inf


@njit(cache=True, inline="always")
def searched_foot(coefficients, samples, harmonics, window, bearing_radius, ex, ey, start):
    """θ of the nearest point to e within `window` of the angle `start` of e: the nearest of the bore's `samples`
    (bore_samples) over the window, rounded outwards to the samples (none for a window 0: `start`), refined by
    refined_foot within one sample spacing either side."""
    count = sample_count(harmonics)
    spacing = 2.0 * math.pi / count
    theta = start
    if window > 0.0:
        lowest, highest = sampled_span(start, window, spacing)
        best, nearest = lowest, math.inf
        for i in range(lowest, highest + 1):
            distance = sampled_distance_squared(samples, count, i, ex, ey)
            if distance < nearest:
                best, nearest = i, distance
        theta = best * spacing
    return refined_foot(coefficients, harmonics, bearing_radius, ex, ey, theta, spacing)[0]


@njit(cache=True)
def refined_foot(coefficients, harmonics, bearing_radius, ex, ey, theta, spacing):
    """(θ, converged): Newton's method on g = (r − e)·r' = 0 from θ inside a bracket of `spacing` either side, a step
    that would leave the bracket, or a point where g' ≤ 0, taking a bisection step of the bracket instead (g' ≤ 0
    everywhere near e: e far from the wall, near a centre of curvature, in free flight — the bisection then stops in
    θ's neighbourhood); ends at a Newton step below NEWTON_TOLERANCE or a bisection step below 1e-15 rad. Converged:
    at such a Newton step, or with g < 0 met below θ and g > 0 above (a minimum lies between them)."""
    low, high = theta - spacing, theta + spacing
    rising = falling = False
    for _ in range(SAFEGUARDED_ITERATIONS):
        rx, ry, tx, ty, gradient, second = _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, theta)
        if gradient > 0.0:
            high = min(high, theta)
            rising = True
        elif gradient < 0.0:
            low = max(low, theta)
            falling = True
        newton = second > 0.0
        following = theta - gradient / second if newton else low - 1.0
        if not low <= following <= high:
            following, newton = 0.5 * (low + high), False
        if abs(following - theta) < (NEWTON_TOLERANCE if newton else 1e-15):
            return following, newton or (rising and falling and low <= following <= high)
        theta = following
    return theta, rising and falling and low <= theta <= high


@njit(cache=True)
def _bore_terms(coefficients, harmonics, bearing_radius, ex, ey, theta):
    """(r, r', g = (r − e)·r', g' = |r'|² + (r − e)·r'') at θ."""
    h, slope, curvature = profile_value(coefficients, harmonics, theta)
    rho = bearing_radius + h
    c, s = np.cos(theta), np.sin(theta)
    rx, ry = rho * c, rho * s
    tx, ty = slope * c - rho * s, slope * s + rho * c  # r' = ρ' u + ρ u⊥
    sx, sy = (curvature - rho) * c - 2.0 * slope * s, (curvature - rho) * s + 2.0 * slope * c  # r''
    dx, dy = rx - ex, ry - ey
    return rx, ry, tx, ty, dx * tx + dy * ty, tx * tx + ty * ty + dx * sx + dy * sy


@njit(cache=True)
def add_kernel_rates(rates, weights, harmonics, scale, theta):
    """rates += the Fourier coefficients of scale · K(φ − θ) (K the wear kernel of `weights` g_m, no band)."""
    add_band_rates(rates, weights, harmonics, scale, theta, 0.0)


@njit(cache=True)
def add_band_rates(rates, weights, harmonics, scale, theta, half_angle):
    """rates += the Fourier coefficients of scale · K(φ − θ), K the wear kernel of `weights` g_m times the band of
    `half_angle` α (band_coefficient; α = 0: the kernel alone)."""
    rates[0] += scale / (2.0 * np.pi)
    c1, s1 = np.cos(theta), np.sin(theta)
    cm, sm = 1.0, 0.0
    for m in range(1, harmonics + 1):
        cm, sm = cm * c1 - sm * s1, sm * c1 + cm * s1
        weight = scale * weights[m] * band_coefficient(m, half_angle)
        rates[2 * m - 1] += weight * cm / np.pi
        rates[2 * m] += weight * sm / np.pi


@njit(cache=True)
def band_coefficient(m, half_angle):
    """B_m = ∫ p(φ) cos mφ dφ / ∫ p(φ) dφ of the half-cosine band p(φ) = cos(πφ/2α) on |φ| ≤ α (0 outside):
    cos(mα)/(1 − (2mα/π)²), written as (π/4) sinc(u)/(1 + u/π) with u = mα − π/2, which has no 0/0 at mα = π/2
    (B_m = π/4 there). α = 0 (no band): 1."""
    if half_angle == 0.0:
        return 1.0
    u = m * half_angle - 0.5 * math.pi
    sinc = math.sin(u) / u if u != 0.0 else 1.0
    return 0.25 * math.pi * sinc / (1.0 + u / math.pi)


@njit(cache=True)
def bore_curvature_radius(coefficients, harmonics, bearing_radius, theta):
    """The radius of curvature (m) of the bore r(θ) = (R_B + h) u(θ) at θ: (ρ² + ρ'²)^{3/2}/(ρ² + 2ρ'² − ρρ''),
    ρ = R_B + h; inf where the bore is straight or bulges inwards (denominator ≤ 0)."""
    h, slope, curvature = profile_value(coefficients, harmonics, theta)
    rho = bearing_radius + h
    bending = rho * rho + 2.0 * slope * slope - rho * curvature
    if bending <= 0.0:
        return math.inf
    return (rho * rho + slope * slope) ** 1.5 / bending


@njit(cache=True)
def band_half_angle(force, line_stiffness, journal_radius, curvature_radius, bearing_radius):
    """α (rad) of the contact's band: b/R_B with the Hertz line contact's half-width b = √(4 F R*/S) (Johnson 1985,
    §4.2, eq. 4.43: b² = 4 P R/(π E*), P = F/L), S = π L E* (N/m), 1/R* = 1/R_J − 1/ρ_c for the journal in the bore of
    local radius of curvature ρ_c (its local clearance ρ_c − R_J); at most CONFORMAL_HALF_ANGLE, which it is where the
    bore is as tight as the journal or tighter. S = 0 (a stated width): 0."""
    if line_stiffness == 0.0:
        return 0.0
    local_clearance = curvature_radius - journal_radius
    if local_clearance <= 0.0:
        return CONFORMAL_HALF_ANGLE
    relative_radius = journal_radius * curvature_radius / local_clearance if math.isfinite(curvature_radius) \
        else journal_radius
    half_width = math.sqrt(4.0 * force * relative_radius / line_stiffness)
    return min(half_width / bearing_radius, CONFORMAL_HALF_ANGLE)


# --- set-up (Python) ------------------------------------------------------------------------------


def summed_coefficients(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """The profile h_1 + h_2 of two coefficient vectors [a_0, a_1, b_1, …] of any lengths."""
    total = np.zeros(max(len(first), len(second)))
    total[:len(first)] += first
    total[:len(second)] += second
    return total


def profile_block(coefficients: np.ndarray) -> dict:
    """The YAML `wear.profile` block (cos and sin lists with their unit) of coefficients [a_0, a_1, b_1, …] in m."""
    return {"cos": [f"{value!r} m" for value in coefficients[0::2][:1].tolist() + coefficients[1::2].tolist()],
            "sin": [f"{value!r} m" for value in coefficients[2::2].tolist()]}


def evaluate_profile(coefficients, angles) -> np.ndarray:
    """h(θ) on an array of angles (rad), for any number of harmonics."""
    coefficients = np.asarray(coefficients, float)
    angles = np.asarray(angles, float)
    depth = np.full(angles.shape, coefficients[0])
    for m in range(1, (coefficients.shape[0] - 1) // 2 + 1):
        depth += coefficients[2 * m - 1] * np.cos(m * angles) + coefficients[2 * m] * np.sin(m * angles)
    return depth


def tightest_radius(coefficients, bearing_radius: float) -> float:
    """The smallest radius of curvature (m) of the bore, on 64 M angles: a journal of a larger radius pressed into
    the bore there touches it at two points (the distance from its centre has two minima)."""
    coefficients = np.asarray(coefficients, float)
    harmonics = (coefficients.shape[0] - 1) // 2
    return _smallest_curvature_radius(coefficients, harmonics, bearing_radius, 64 * max(harmonics, 1))


def pocket_radius(coefficients, bearing_radius: float, journal_radius: float) -> float | None:
    """The bore's tightest radius of curvature (m) where it is tighter than the journal, a pocket the journal touches
    at its two rims (nearest_bore_point's second rim); None where the bore is nowhere tighter than the journal (or
    circular)."""
    if (len(coefficients) - 1) // 2 <= 0:
        return None
    tightest = tightest_radius(coefficients, bearing_radius)
    return tightest if tightest < journal_radius else None


def pocket_words(tightest: float, journal_radius: float) -> str:
    """The two radii of a pocket, to the 0.1 µm that tells them apart (both are R_B to within the clearance)."""
    return (f"smallest radius of curvature {tightest * 1e3:.4f} mm against the journal's "
            f"{journal_radius * 1e3:.4f} mm")


REACH_MARGIN = 1e-9  # relative: the refined tightest radius is a local minimum to round-off (its argument to
# 1e-13 rad changes it by ~1e-26 of itself); the margin keeps the reach below it whatever the last digits


def inner_reach(coefficients, bearing_radius: float) -> float:
    """A lower bound (m) of the bore's inner reach: the least distance from the bore to a point inside it with two
    nearest bore points or at a centre of curvature (its inner medial axis). A point inside nearer to the bore than
    that has one nearest bore point, the foot of the only inward normal through it, so a minimum of the distance
    found there by Newton's method is the global one (nearest_bore_point). The inner medial axis comes nearest the
    bore at a centre of curvature or at the middle of a bottleneck, a chord inside the bore along the normals at
    both its ends (Federer 1959, Curvature measures, Thm 4.8; Aamari et al. 2019, Estimating the reach of a
    manifold), so the reach is the lesser of

    - the tightest radius of curvature on the inner side (bore_curvature_radius): its local minima on 64 M angles,
      each refined by bounded Brent minimisation between its neighbours (32 angles to the shortest period of the bending
      ρ² + 2ρ'² − ρρ'', a trigonometric polynomial of degree 2 M), less REACH_MARGIN of itself;
    - half the narrowest bottleneck: its ends' inward normals are opposite, and the normal turns with the polar angle
      within ψ = atan(|ρ'|/ρ) of it, so they lie at least π − 2 ψ_max apart and the chord is at least
      2 ρ_min sin(π/2 − ψ_max) = 2 ρ_min cos ψ_max long; ρ_min = R_B + min h and |ρ'|_max on 64 M angles, widened by
      the most they can move between two angles (Σ m |c_m| and Σ m² |c_m| times half the spacing).

    A bore nowhere tighter than its journal has a reach above R_J, the distance in contact; a circular bore's is R_B."""
    coefficients = np.asarray(coefficients, float)
    harmonics = (coefficients.shape[0] - 1) // 2
    if harmonics <= 0:
        return float(bearing_radius)
    count = 64 * harmonics
    spacing = 2.0 * math.pi / count
    angles = spacing * np.arange(count)
    radii = np.array([bore_curvature_radius(coefficients, harmonics, bearing_radius, theta) for theta in angles])
    tightest = math.inf
    for i in np.flatnonzero((radii <= np.roll(radii, 1)) & (radii <= np.roll(radii, -1)) & np.isfinite(radii)):
        tightest = min(tightest, _least_between(
            lambda theta: bore_curvature_radius(coefficients, harmonics, bearing_radius, theta),
            angles[i] - spacing, angles[i] + spacing))
    orders = np.arange(1, harmonics + 1)
    sizes = np.hypot(coefficients[1::2][:harmonics], coefficients[2::2][:harmonics])
    slopes = np.abs(sum(order * (coefficients[2 * order] * np.cos(order * angles)
                                 - coefficients[2 * order - 1] * np.sin(order * angles)) for order in orders))
    smallest_radius = innermost_radius(coefficients, bearing_radius)
    steepest = slopes.max() + float(np.sum(orders ** 2 * sizes)) * spacing / 2.0
    half_bottleneck = smallest_radius / math.hypot(1.0, steepest / smallest_radius)
    return min(tightest * (1.0 - REACH_MARGIN), half_bottleneck)


def innermost_radius(coefficients, bearing_radius: float) -> float:
    """A lower bound (m) of the bore's smallest radius ρ_min = R_B + min h: the least on 64 M angles, less the most
    the series can move between two of them (Σ m √(a_m² + b_m²) times half their spacing)."""
    coefficients = np.asarray(coefficients, float)
    harmonics = (coefficients.shape[0] - 1) // 2
    if harmonics <= 0:
        return float(bearing_radius + (coefficients[0] if coefficients.shape[0] else 0.0))
    angles = np.linspace(0.0, 2.0 * math.pi, 64 * harmonics, endpoint=False)
    orders = np.arange(1, harmonics + 1)
    slope_bound = float(np.sum(orders * np.hypot(coefficients[1::2][:harmonics], coefficients[2::2][:harmonics])))
    return bearing_radius + float(evaluate_profile(coefficients, angles).min()) - slope_bound * (angles[1] - angles[0]) / 2.0


def _least_between(function, low: float, high: float) -> float:
    """The least value of `function` on [low, high] (a local minimum: bounded Brent, scipy's minimize_scalar, to
    1e-13 in its argument)."""
    from scipy.optimize import minimize_scalar  # here: only a model with a worn bore needs it (36 MB in each worker)

    found = minimize_scalar(function, bounds=(low, high), method="bounded", options={"xatol": 1e-13})
    return min(float(found.fun), function(low), function(high))


@njit(cache=True)
def _smallest_curvature_radius(coefficients, harmonics, bearing_radius, angles):
    smallest = math.inf
    for i in range(angles):
        smallest = min(smallest, bore_curvature_radius(coefficients, harmonics, bearing_radius, 2.0 * math.pi * i / angles))
    return smallest


def profile_coefficients(cos: list[float], sin: list[float]) -> np.ndarray:
    """[a_0, a_1, b_1, ...] from the YAML's `cos: [a_0, a_1, ...]` and `sin: [b_1, ...]` (missing terms 0)."""
    harmonics = max(len(cos) - 1, len(sin), 0)
    coefficients = np.zeros(1 + 2 * harmonics)
    for m, a in enumerate(cos):
        coefficients[max(2 * m - 1, 0)] = a
    for m, b in enumerate(sin, start=1):
        coefficients[2 * m] = b
    return coefficients


def fitted_coefficients(angles, depths, harmonics: int) -> np.ndarray:
    """[a_0, a_1, b_1, ...] of the M-harmonic series nearest to measured depths (least squares; interpolation when
    2M + 1 equals the number of distinct angles)."""
    angles = np.asarray(angles, float)
    columns = [np.ones_like(angles)]
    for m in range(1, harmonics + 1):
        columns += [np.cos(m * angles), np.sin(m * angles)]
    return np.linalg.lstsq(np.column_stack(columns), np.asarray(depths, float), rcond=None)[0]


def kernel_weights(sigma: float, harmonics: int) -> np.ndarray:
    """g_m = exp(−m²σ²/2), m = 0..M."""
    m = np.arange(harmonics + 1, dtype=float)
    return np.exp(-0.5 * (m * sigma) ** 2)


def kernel_width(sigma: float, harmonics: int, radius: float) -> float:
    """w = R/K(0) of the truncated kernel: the arc length over which its peak depth would hold the whole volume."""
    peak = (2.0 * kernel_weights(sigma, harmonics).sum() - 1.0) / (2.0 * math.pi)
    return radius / peak


def narrowest_width(harmonics: int, radius: float) -> float:
    """The narrowest kernel M harmonics carry without ringing: σ = 4/M."""
    return kernel_width(SMALLEST_SIGMA / harmonics, harmonics, radius)


def kernel_sigma(width: float, harmonics: int, radius: float) -> float:
    """σ of the kernel of width w (narrowest_width ≤ w < 2πR): w = R/K(0) solved to round-off."""
    low = SMALLEST_SIGMA / harmonics
    if width <= kernel_width(low, harmonics, radius):
        return low
    high = low
    while kernel_width(high, harmonics, radius) < width and high < 1e3:  # w → 2πR as σ → ∞
        high *= 2.0
    from scipy.optimize import brentq  # here: importing scipy.optimize takes 36 MB, in every sweep worker

    return brentq(lambda s: kernel_width(s, harmonics, radius) - width, low, high, xtol=1e-300, rtol=1e-15)
