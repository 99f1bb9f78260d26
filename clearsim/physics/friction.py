"""Tangential friction laws for a journal sliding on a bearing wall.

Each law returns a signed friction coefficient μ(v_t), an odd function of the
sliding velocity v_t, so that the friction force on the journal along the
contact tangent is F_t = −μ(v_t) F_n (Meng 2015 eq. 12 with the factor
v_t/|v_t| folded into μ, which avoids dividing by |v_t| near sticking).
See docs/model-contact.md for sources and units.
"""

from numba import njit

NONE = 0
COULOMB = 1
STICTION_STEP = 2
AMBROSIO = 3

FRICTION_LAWS = {
    "none": NONE,
    "coulomb": COULOMB,
    "stiction_step": STICTION_STEP,
    "ambrosio": AMBROSIO,
}

# how a law treats sticking (column 2 of clearance_laws): "smooth" integrates the law as written
# (the STEP band through zero, the bare sign function); "exact" makes a sticking contact a
# constraint v_t = 0 that holds while |F_t| <= μ_s F_n (stiction_step and coulomb only)
STICK_SMOOTH = 0
STICK_EXACT = 1
STICK_TREATMENTS = {"smooth": STICK_SMOOTH, "exact": STICK_EXACT}


@njit(cache=True, inline="always")
def _sign(value):
    if value > 0.0:
        return 1.0
    if value < 0.0:
        return -1.0
    return 0.0


@njit(cache=True, inline="always")
def step_blend(x, x0, h0, x1, h1):
    """Adams STEP, h0 + (h1 − h0) Δ²(3 − 2Δ) with Δ = (x − x0)/(x1 − x0), held outside [x0, x1]."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    fraction = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * fraction * fraction * (3.0 - 2.0 * fraction)


@njit(cache=True)
def _stiction_step(sliding_velocity, mu_s, mu_d, v_s, v_d):
    """Meng 2015 eq. 13 as intended: μ_s at |v| = v_s blends to μ_d at v_d (the print swaps them)."""
    speed = abs(sliding_velocity)
    if speed >= v_d:
        return mu_d * _sign(sliding_velocity)
    if speed >= v_s:
        return step_blend(speed, v_s, mu_s, v_d, mu_d) * _sign(sliding_velocity)
    return step_blend(sliding_velocity, -v_s, -mu_s, v_s, mu_s)


@njit(cache=True)
def _ambrosio(sliding_velocity, mu_d, v_0, v_1):
    """Ambrósio 2003 modified Coulomb: μ_d c_d(|v|) sign v, c_d linear from 0 at v_0 to 1 at v_1."""
    speed = abs(sliding_velocity)
    if speed <= v_0:
        return 0.0
    if speed >= v_1:
        return mu_d * _sign(sliding_velocity)
    return mu_d * (speed - v_0) / (v_1 - v_0) * _sign(sliding_velocity)


@njit(cache=True)
def friction_coefficient(law, sliding_velocity, mu_s, mu_d, v_low, v_high):
    """Signed μ(v_t) for F_t = −μ(v_t) F_n (Meng 2015 eq. 12/13); v_low/v_high are v_s/v_d or v_0/v_1."""
    if law == COULOMB:
        return mu_d * _sign(sliding_velocity)
    if law == STICTION_STEP:
        return _stiction_step(sliding_velocity, mu_s, mu_d, v_low, v_high)
    if law == AMBROSIO:
        return _ambrosio(sliding_velocity, mu_d, v_low, v_high)
    return 0.0


@njit(cache=True)
def sliding_coefficient(law, speed, mu_s, mu_d, v_low, v_high):
    """|μ| of a journal sliding at |v_t| = speed > 0 when sticking is a constraint (docs/model-contact.md §2).

    The limit v_s → 0 of the stiction band: μ_s up to v_s, the STEP blend to μ_d at v_d, μ_d beyond
    (stiction_step); μ_d at any speed (coulomb). Other laws have no sticking phase.
    """
    if law == STICTION_STEP:
        return step_blend(speed, v_low, mu_s, v_high, mu_d)
    if law == COULOMB:
        return mu_d
    return 0.0


@njit(cache=True, inline="always")
def static_coefficient(law, mu_s, mu_d):
    """Largest |F_t|/F_n a sticking contact holds: μ_s (stiction_step), μ_d (coulomb), 0 otherwise."""
    if law == STICTION_STEP:
        return mu_s
    if law == COULOMB:
        return mu_d
    return 0.0
