"""Normal contact force laws for a journal inside a bearing.

Every law has the form F = K δⁿ (1 + D · δ̇/δ̇⁻): an elastic Hertz-type term
K δⁿ times a hysteresis factor that depends on the coefficient of restitution
c_e through D(c_e). δ is the penetration (positive in contact), δ̇ its rate
(positive while the journal moves into the wall) and δ̇⁻ the penetration rate
at contact onset ("impact speed"), which the caller stores per joint and
floors for grazing contacts. Forces are magnitudes along the contact normal,
acting on the journal towards the bearing centre.

See docs/model-contact.md for sources, units and the restitution each law
actually delivers.
"""

import math

from numba import njit

HERTZ = 0
LANKARANI_NIKRAVESH = 1
HUNT_CROSSLEY = 2
FLORES = 3
GONTHIER = 4

CONTACT_LAWS = {
    "hertz": HERTZ,
    "lankarani_nikravesh": LANKARANI_NIKRAVESH,
    "hunt_crossley": HUNT_CROSSLEY,
    "flores": FLORES,
    "gonthier": GONTHIER,
}

# ∫₀¹ dx / sqrt(1 − x^{5/2}) = (2/5) B(2/5, 1/2) ≈ 1.47164 (substitute u = x^{5/2});
# the Hertz contact lasts twice the time to reach δ_max, so t_c = 2.94328 δ_max / v⁻.
_HERTZ_HALF_TIME_INTEGRAL = 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)  # B(a, b) = Γ(a)Γ(b)/Γ(a + b)
HERTZ_CONTACT_TIME_FACTOR = 2.0 * _HERTZ_HALF_TIME_INTEGRAL  # t_c = 2.94328 δ_max / v⁻


@njit(cache=True, inline="always")
def hysteresis_factor(law, restitution):
    """D(c_e): 0 (Hertz), 3(1−c_e²)/4 (Lankarani–Nikravesh 1990, Meng 2015 eq. 11),
    3(1−c_e)/2 (Hunt–Crossley 1975), 8(1−c_e)/(5c_e) (Flores et al. 2011),
    (1−c_e²)/c_e (Gonthier, McPhee, Lange, Piedbœuf 2004)."""
    if law == LANKARANI_NIKRAVESH:
        return 0.75 * (1.0 - restitution * restitution)
    if law == HUNT_CROSSLEY:
        return 1.5 * (1.0 - restitution)
    if law == FLORES:
        return 1.6 * (1.0 - restitution) / restitution
    if law == GONTHIER:
        return (1.0 - restitution * restitution) / restitution
    return 0.0


@njit(cache=True)
def normal_force(law, penetration, penetration_rate, impact_speed, stiffness, exponent, restitution):
    """F_n = K δⁿ (1 + D(c_e) δ̇/δ̇⁻) for δ > 0, else 0 (Meng 2015 eq. 11 with D = 3(1−c_e²)/4)."""
    if penetration <= 0.0:
        return 0.0
    return damped_force(law, stiffness * penetration**exponent, penetration_rate, impact_speed, restitution)


@njit(cache=True, inline="always")
def damped_force(law, elastic, penetration_rate, impact_speed, restitution):
    """F_n = F_el (1 + D(c_e) δ̇/δ̇⁻) of any elastic force F_el > 0 (clearsim.physics.cylindrical)."""
    damping = hysteresis_factor(law, restitution) * penetration_rate / impact_speed
    # On fast separation the damping term can exceed the elastic one; contact never pulls.
    return max(0.0, elastic * (1.0 + damping))


@njit(cache=True, inline="always")
def elastic_force(penetration, stiffness, exponent):
    """Elastic part of the contact force, K δⁿ for δ > 0, else 0 (Meng 2015 eq. 8)."""
    if penetration <= 0.0:
        return 0.0
    return stiffness * penetration**exponent


@njit(cache=True, inline="always")
def elastic_energy(penetration, stiffness, exponent):
    """Contact potential energy ∫₀^δ K sⁿ ds = K δⁿ⁺¹/(n+1) for δ > 0, else 0."""
    if penetration <= 0.0:
        return 0.0
    return stiffness * penetration ** (exponent + 1.0) / (exponent + 1.0)


def internal_contact_stiffness(
    bearing_radius, journal_radius, youngs_bearing, poisson_bearing, youngs_journal, poisson_journal
):
    """Generalised stiffness K = 4/(3(σ_B + σ_J)) · sqrt(R_B R_J / (R_B − R_J)), σ_k = (1 − ν_k²)/E_k.

    Meng 2015 eq. 10 prints sqrt(R1 R2 / (R1 + R2)), the form for two convex
    bodies (external contact). A journal inside a bearing is internal contact:
    the bearing surface is concave, so its curvature enters with a negative
    sign and the effective radius is R_B R_J / (R_B − R_J). Radii in m, moduli
    in Pa; returns N/m^1.5 (for use with exponent n = 1.5).
    """
    if journal_radius >= bearing_radius:
        raise ValueError(
            f"journal radius {journal_radius} m must be smaller than bearing radius {bearing_radius} m"
        )
    sigma_bearing = (1.0 - poisson_bearing**2) / youngs_bearing
    sigma_journal = (1.0 - poisson_journal**2) / youngs_journal
    effective_radius = bearing_radius * journal_radius / (bearing_radius - journal_radius)
    return 4.0 / (3.0 * (sigma_bearing + sigma_journal)) * math.sqrt(effective_radius)


@njit(cache=True)
def hertz_max_penetration(effective_mass, stiffness, impact_speed, exponent=1.5):
    """δ_max from energy balance ½ m v² = K δ_max^{n+1}/(n+1); (5 m v²/(4K))^{2/5} for n = 1.5."""
    return ((exponent + 1.0) * effective_mass * impact_speed**2 / (2.0 * stiffness)) ** (
        1.0 / (exponent + 1.0)
    )


def hertz_peak_force(effective_mass, stiffness, impact_speed, exponent=1.5):
    """F_max = K δ_max^n of an undamped impact (Hertz 1882; Johnson, Contact Mechanics 1985, ch. 11)."""
    return stiffness * hertz_max_penetration(effective_mass, stiffness, impact_speed, exponent) ** exponent


def hertz_contact_time(effective_mass, stiffness, impact_speed, exponent=1.5):
    """t_c = 2 (δ_max/v) ∫₀¹ dx/sqrt(1 − x^{5/2}) = 2.94328 δ_max/v = 3.21807 (m/K)^{2/5} v^{−1/5}.

    Closed form of m δ̈ = −K δ^{3/2} (Hertz 1882; Johnson, Contact Mechanics 1985,
    ch. 11, quotes 2.94 δ_max/v); the integral is (2/5) B(2/5, 1/2). The often
    quoted 3.21 is the coefficient of the (m/K)^{2/5} v^{−1/5} form. Only n = 1.5.
    """
    if exponent != 1.5:
        raise ValueError(f"closed-form contact time is for exponent 1.5, got {exponent}")
    max_penetration = hertz_max_penetration(effective_mass, stiffness, impact_speed, exponent)
    return HERTZ_CONTACT_TIME_FACTOR * max_penetration / impact_speed
