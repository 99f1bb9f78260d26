"""Reference geometry of a worn bore, independent of clearsim's: the bore point nearest to the journal centre by a
dense polygon and Newton's method on the explicitly differentiated profile."""

import numpy as np


def nearest_bore_contact(profile, bearing_radius, journal_radius, local_e, vertices=20000):
    """(δ, n) in the bearing frame of a journal centred at local_e: δ = R_J − |r(θ*) − e|, n = (r(θ*) − e)/|…|,
    r(θ) = (R_B + h(θ)) u(θ) the bore; profile(θ) → (h, h', h'')."""
    def curve(theta):
        h, slope, curvature = profile(theta)
        rho = bearing_radius + h
        u, v = np.array([np.cos(theta), np.sin(theta)]), np.array([-np.sin(theta), np.cos(theta)])
        return rho * u, slope * u + rho * v, (curvature - rho) * u + 2 * slope * v

    grid = np.linspace(0, 2 * np.pi, vertices, endpoint=False)
    polygon = (bearing_radius + profile(grid)[0]) * np.array([np.cos(grid), np.sin(grid)])
    theta = grid[np.argmin(np.hypot(*(polygon - np.asarray(local_e)[:, None])))]
    for _ in range(30):
        r, tangent, second = curve(theta)
        theta -= (r - local_e) @ tangent / (tangent @ tangent + (r - local_e) @ second)
    gap = curve(theta)[0] - local_e
    return journal_radius - np.hypot(*gap), gap / np.hypot(*gap)


def rotate(angle, vector):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]])
