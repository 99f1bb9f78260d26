"""Reference geometry of a worn bore, independent of clearsim's: the bore point nearest to the journal centre by a
dense polygon and Newton's method on the explicitly differentiated profile."""

import numpy as np


def _curve(profile, bearing_radius, theta):
    """r, r', r'' of the bore r(θ) = (R_B + h(θ)) u(θ); profile(θ) → (h, h', h'')."""
    h, slope, curvature = profile(theta)
    rho = bearing_radius + h
    u, v = np.array([np.cos(theta), np.sin(theta)]), np.array([-np.sin(theta), np.cos(theta)])
    return rho * u, slope * u + rho * v, (curvature - rho) * u + 2 * slope * v


def _refined(profile, bearing_radius, local_e, theta):
    """θ of the minimum of |r(θ) − e| by 30 Newton steps from theta."""
    for _ in range(30):
        r, tangent, second = _curve(profile, bearing_radius, theta)
        theta -= (r - local_e) @ tangent / (tangent @ tangent + (r - local_e) @ second)
    return theta


def _contact(profile, bearing_radius, journal_radius, local_e, theta):
    gap = _curve(profile, bearing_radius, theta)[0] - local_e
    return journal_radius - np.hypot(*gap), gap / np.hypot(*gap)


def _polygon_distance(profile, bearing_radius, local_e, vertices):
    grid = np.linspace(0, 2 * np.pi, vertices, endpoint=False)
    polygon = (bearing_radius + profile(grid)[0]) * np.array([np.cos(grid), np.sin(grid)])
    return grid, np.hypot(*(polygon - np.asarray(local_e)[:, None]))


def nearest_bore_contact(profile, bearing_radius, journal_radius, local_e, vertices=20000):
    """(δ, n) in the bearing frame of a journal centred at local_e: δ = R_J − |r(θ*) − e|, n = (r(θ*) − e)/|…|,
    r(θ) = (R_B + h(θ)) u(θ) the bore; profile(θ) → (h, h', h'')."""
    grid, distance = _polygon_distance(profile, bearing_radius, local_e, vertices)
    theta = _refined(profile, bearing_radius, local_e, grid[np.argmin(distance)])
    return _contact(profile, bearing_radius, journal_radius, local_e, theta)


def bore_contacts(profile, bearing_radius, journal_radius, local_e, vertices=200000):
    """[(δ, n, θ)] of every bore point the journal centred at local_e touches, nearest first: the local minima of the
    distance on a dense polygon nearer than R_J, each refined by Newton's method (a pocket tighter than the journal:
    two)."""
    grid, distance = _polygon_distance(profile, bearing_radius, local_e, vertices)
    found = []
    for i in np.flatnonzero((distance < np.roll(distance, 1)) & (distance <= np.roll(distance, -1))):
        theta = _refined(profile, bearing_radius, local_e, grid[i])
        penetration, normal = _contact(profile, bearing_radius, journal_radius, local_e, theta)
        if penetration > 0.0:
            found.append((penetration, normal, theta))
    return sorted(found, key=lambda contact: -contact[0])


def rotate(angle, vector):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]])


def series_profile(coefficients):
    """profile(θ) → (h, h', h'') of the Fourier series [a_0, a_1, b_1, …], differentiated term by term (θ a number or
    an array)."""
    coefficients = np.asarray(coefficients, float)
    orders = np.arange(1, (coefficients.size - 1) // 2 + 1)
    a, b = coefficients[1::2], coefficients[2::2]

    def profile(theta):
        phases = np.multiply.outer(np.asarray(theta, float), orders)
        return (coefficients[0] + np.cos(phases) @ a + np.sin(phases) @ b,
                (-np.sin(phases) * orders) @ a + (np.cos(phases) * orders) @ b,
                (-np.cos(phases) * orders ** 2) @ a + (-np.sin(phases) * orders ** 2) @ b)

    return profile


POCKET_BEARING, POCKET_JOURNAL, POCKET_HARMONICS = 0.010, 0.0095, 64


def pocket_coefficients(depth=1e-5, width=0.0015, angle=-0.5 * np.pi):
    """[a_0, a_1, b_1, …] of a pocket `depth` deep at `angle` (the bottom) of a 10 mm bore, worn by a kernel `width`
    wide: 7.97 mm its tightest radius of curvature, against the 9.5 mm journal of pocket_model."""
    from clearsim.physics import wear

    rates = np.zeros(2 * POCKET_HARMONICS + 1)
    weights = wear.kernel_weights(wear.kernel_sigma(width, POCKET_HARMONICS, POCKET_BEARING), POCKET_HARMONICS)
    wear.add_kernel_rates(rates, weights, POCKET_HARMONICS, 1.0, angle)
    return rates * depth / wear.evaluate_profile(rates, np.array([angle]))[0]


def pocket_model(contact, friction="{law: none}", t_end="20 ms", start=0.0, mass=1.0, gravity=9.81):
    """A journal (a pin of `mass`, its centre `start` m right of the bore's) dropped by gravity into the pocket at the
    bottom of a fixed worn bore (pocket_coefficients), as YAML text in SI."""
    coefficients = pocket_coefficients()
    cosines = ", ".join(repr(float(value)) for value in [coefficients[0], *coefficients[1::2]])
    sines = ", ".join(repr(float(value)) for value in coefficients[2::2])
    return f"""
name: a journal dropped into a pocket tighter than itself
units: SI
gravity: [0, {-gravity}]
defaults:
  contact: {contact}
  friction: {friction}
points: {{O: [0, 0]}}
bodies:
  - {{name: pin, mass: {mass}, inertia: 1e-4, position: [{start}, 0]}}
joints:
  - {{name: J, type: revolute, bodies: [ground, pin], at: O, bearing_radius: {POCKET_BEARING},
      clearance: {POCKET_BEARING - POCKET_JOURNAL}, wear: {{profile: {{cos: [{cosines}], sin: [{sines}]}}}}}}
solver: {{t_end: {t_end}, output_rate: 10 kHz, rtol: 1e-9, atol: 1e-12, max_step: 0.1 ms}}
"""
