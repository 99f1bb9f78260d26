"""Elastic laws of a journal (pin) of axial length L in its bearing: the point law and the cylindrical laws.

The normal contact force is F_n = F_el(δ) (1 + D(c_e) δ̇/δ̇⁻): the elastic law F_el chosen here (`elastic:`),
times the hysteresis factor of the damping law (`law:`, clearsim.physics.contact.hysteresis_factor). Each elastic
law gives its force F_el(δ), its stiffness dF_el/dδ and its elastic energy ∫₀^δ F_el, from three numbers packed
per joint: K (the law's scale), n (its exponent, power laws only) and the radial clearance ΔR = R_B − R_J.

  point_hertz  F = K δⁿ                          K, n: `stiffness`/`exponent` (sphere-Hertz K for `auto`)
  pereira      F = K δⁿ                          K, n from ΔR, L, E* (pereira_coefficients)
  johnson      δ = (F/S) [ln(4 S ΔR / F) − 1]    S = π L E*, implicit in δ (line_contact_state)
  esdu_78035   δ = (F/S) [ln(4 S ΔR / F) + 1]    S = π L E*, implicit in δ
  liu          F = (S/2) δ √(δ / (2 (ΔR + δ)))   S = π L E*

with E* = 1/((1 − ν_B²)/E_B + (1 − ν_J²)/E_J) (Pa) and L the pin's axial length (m). Sources, units and validity
are in each function's docstring and in docs/model-contact.md. Forms and Pereira's fitted coefficients as
implemented in ladisk/DyS (MBD_system/contact_model/contact_model_cylinder.py), after Pereira, Ramalho & Ambrósio,
Nonlinear Dyn. 63:681 (2011) and Skrinjar, Slavič & Boltežar, Int. J. Mech. Sci. 145:171 (2018).
"""

import math

import numpy as np
from numba import njit

from clearsim.physics.contact import elastic_energy as power_energy
from clearsim.physics.contact import elastic_force as power_force
from clearsim.physics.contact import hertz_max_penetration

POINT_HERTZ = 0
JOHNSON = 1
ESDU_78035 = 2
PEREIRA = 3
LIU = 4

ELASTIC_LAWS = {"point_hertz": POINT_HERTZ, "johnson": JOHNSON, "esdu_78035": ESDU_78035, "pereira": PEREIRA,
                "liu": LIU}
POWER_LAW_CODES = (POINT_HERTZ, PEREIRA)  # F = K δⁿ: K and n are all they need

# Pereira et al. 2011, internal contact (pin in a hole), ΔR in mm: the range their fit of Y(ΔR) covers
PEREIRA_INTERNAL_A = 0.965
PEREIRA_INTERNAL_B = 0.0965
PEREIRA_CLEARANCE_RANGE_MM = (0.005, 10.0)
_PEREIRA_Y_BREAK_MM = 0.34954  # the two branches of Y meet here (1.15627)
PEREIRA_UNDEFINED_BELOW_MM = 0.001  # ln(1000 ΔR) ≤ 0

_NEWTON_ITERATIONS = 100
_RELATIVE_TOLERANCE = 4e-16


def effective_modulus(youngs_bearing, poisson_bearing, youngs_journal, poisson_journal):
    """E* = 1/((1 − ν_B²)/E_B + (1 − ν_J²)/E_J) in Pa (Johnson, Contact Mechanics 1985)."""
    return 1.0 / ((1.0 - poisson_bearing**2) / youngs_bearing + (1.0 - poisson_journal**2) / youngs_journal)


def pereira_exponent(clearance):
    """n = Y ΔR^−0.005 (ΔR in mm) with Y = 1.51 [ln(1000 ΔR)]^−0.151 for 0.005 ≤ ΔR ≤ 0.34954 mm and
    Y = 0.0151 ΔR + 1.151 for 0.34954 < ΔR ≤ 10 mm (Pereira, Ramalho & Ambrósio 2011, internal contact).
    ValueError for ΔR ≤ 0.001 mm, where ln(1000 ΔR) ≤ 0 leaves Y undefined."""
    clearance_mm = clearance * 1e3
    if clearance_mm <= PEREIRA_UNDEFINED_BELOW_MM:
        raise ValueError(f"Pereira's exponent is undefined for clearances of {PEREIRA_UNDEFINED_BELOW_MM:g} mm and "
                         f"below (ΔR = {clearance_mm:.3g} mm)")
    if clearance_mm <= _PEREIRA_Y_BREAK_MM:
        y = 1.51 * math.log(1e3 * clearance_mm) ** -0.151
    else:
        y = 0.0151 * clearance_mm + 1.151
    return y * clearance_mm**-0.005


def pereira_coefficients(clearance, length, modulus):
    """(K in N/m^n, n) of Pereira, Ramalho & Ambrósio 2011 (Nonlinear Dyn. 63:681), internal contact:
    F = (a ΔR + b) L E* δⁿ / ΔR with a = 0.965, b = 0.0965 (1/mm), n = pereira_exponent(ΔR).

    The fit is written in mm, MPa and N (ΔR, L, δ in mm; E* in MPa); in SI it is K δⁿ with
    K = (a ΔR_mm + b)/ΔR_mm · (10³ L)(10⁻⁶ E*)(10³)ⁿ. Fitted to finite-element line contacts for
    0.005 mm ≤ ΔR ≤ 10 mm (PEREIRA_CLEARANCE_RANGE_MM); outside it the fit is extrapolated.
    """
    clearance_mm = clearance * 1e3
    exponent = pereira_exponent(clearance)
    scale = (PEREIRA_INTERNAL_A * clearance_mm + PEREIRA_INTERNAL_B) / clearance_mm
    return scale * (1e3 * length) * (1e-6 * modulus) * 1e3**exponent, exponent


# --- Johnson / ESDU-78035: δ(F) = (F/S) [ln(4 S ΔR / F) + c], inverted for F(δ) ------------------------------


@njit(cache=True, inline="always")
def line_contact_constant(law):
    """c of δ = (F/S)[ln(4 S ΔR/F) + c]: −1 (Johnson 1985, §5.6), +1 (ESDU-78035, 1978)."""
    return -1.0 if law == JOHNSON else 1.0


@njit(cache=True, inline="always")
def line_contact_edge(constant):
    """x_e = F_e/(4 S ΔR) = e^(c−2): the load where the law's stiffness has grown to S. Beyond it δ(F) bends over
    (at x = e^(c−1), dδ/dF = 0) and stops being a law in δ; the law continues there as a straight line of slope S.
    At the edge δ_e = 8 ΔR e^(c−2): 0.398 ΔR for Johnson, 2.94 ΔR for ESDU-78035."""
    return math.exp(constant - 2.0)


@njit(cache=True, inline="always")
def _normalised_load(depth, constant):
    """x in (0, x_e] with x (ln(1/x) + c) = depth (= δ/(4 ΔR) ≤ 2 x_e): Newton's method, kept inside a bracket.

    h(x) = x(c − ln x) − depth rises (h' = c − 1 − ln x ≥ 1 up to x_e) and is concave (h'' = −1/x), so from a start
    right of the root one Newton step lands left of it, x₁ = (depth − x₀)/h'(x₀) > 0, and from there the iterates
    rise monotonically to it (quadratic convergence). x₀ = depth/(c − ln depth) lies right of the root because the
    root is depth/(c − ln x) with x < depth. A step that leaves the bracket [lo, hi] is replaced by bisection.
    """
    lo, hi = 0.0, line_contact_edge(constant)
    x = min(depth / (constant - math.log(depth)), hi)
    for _ in range(_NEWTON_ITERATIONS):
        residual = x * (constant - math.log(x)) - depth
        if residual > 0.0:
            hi = x
        else:
            lo = x
        following = x - residual / (constant - 1.0 - math.log(x))
        if abs(following - x) <= _RELATIVE_TOLERANCE * x:
            return following
        x = following if lo < following < hi else 0.5 * (lo + hi)
    return x


@njit(cache=True, inline="always")
def line_contact_state(penetration, line_stiffness, clearance, constant):
    """(F, dF/dδ, ∫₀^δ F) of δ = (F/S)[ln(4 S ΔR/F) + c] (S = π L E* in N/m, ΔR in m, F in N) at δ > 0.

    Johnson (Contact Mechanics 1985, §5.6; c = −1) and ESDU-78035 (1978; c = +1), as quoted by Pereira et al.
    2011 and Skrinjar et al. 2018. F solved by _normalised_load up to the edge δ_e = 8 ΔR e^(c−2)
    (line_contact_edge), a straight line of slope S beyond. dF/dδ = S/(ln(4 S ΔR/F) + c − 1): → 0 (as S/ln(1/F))
    at small load, S at the edge and beyond. ∫F = F δ − ∫₀^F δ(f) df = (F²/2S)(ln(4 S ΔR/F) + c − ½) up to the
    edge, plus the straight line's F_e (δ − δ_e) + S (δ − δ_e)²/2 beyond. Valid for a non-conformal line contact:
    small contact angle, F well below the edge load 4 S ΔR e^(c−2).
    """
    reference = 4.0 * line_stiffness * clearance
    edge = line_contact_edge(constant)
    x = _normalised_load(min(penetration / (4.0 * clearance), 2.0 * edge), constant)
    force = reference * x
    energy = force * force / (2.0 * line_stiffness) * (constant - 0.5 - math.log(x))
    beyond = penetration - 8.0 * clearance * edge
    if beyond <= 0.0:
        return force, line_stiffness / (constant - 1.0 - math.log(x)), energy
    return force + line_stiffness * beyond, line_stiffness, energy + force * beyond + 0.5 * line_stiffness * beyond**2


# --- Liu et al. 2007: elastic foundation for a conformal cylindrical contact -----------------------------------


@njit(cache=True, inline="always")
def liu_force(penetration, line_stiffness, clearance):
    """F = (S/2) δ √(δ/(2 (ΔR + δ))), S = π L E* (Liu, Zhang, Yang, Mech. Mach. Theory 42:183, 2007, an
    improved elastic foundation model fitted to finite elements; ladisk/DyS `_Fn_Liu_etal`). → S δ^1.5/(2√(2ΔR))
    (a point law of K = π L E*/(2√(2ΔR)), n = 1.5) for δ ≪ ΔR; → S δ/(2√2) (linear) for δ ≫ ΔR. The source
    states no load range. δ > 0."""
    return 0.5 * line_stiffness * penetration * math.sqrt(penetration / (2.0 * (clearance + penetration)))


@njit(cache=True, inline="always")
def liu_stiffness(penetration, line_stiffness, clearance):
    """dF/dδ = (S/(4√2)) √δ (3 ΔR + 2 δ)/(ΔR + δ)^1.5 at δ > 0: the nonlinear stiffness coefficient
    K_n = (π E*/8) √(2 δ (3ΔR + 2δ)²/(ΔR + δ)³) of Bai & Zhao (Int. J. Non-Linear Mech. 48, 2013) times L."""
    return (line_stiffness / (4.0 * math.sqrt(2.0)) * math.sqrt(penetration) * (3.0 * clearance + 2.0 * penetration)
            / (clearance + penetration) ** 1.5)


@njit(cache=True, inline="always")
def liu_energy(penetration, line_stiffness, clearance):
    """∫₀^δ (S/(2√2)) s^1.5 (ΔR + s)^−0.5 ds. Closed form ((2δ − 3ΔR)/4) √(δ(ΔR+δ)) + (3ΔR²/4) asinh(√(δ/ΔR))
    for δ ≥ ΔR/4; below, where its terms cancel, the binomial series Σ C(−½, k) ΔR^(−½−k) δ^(k+5/2)/(k + 5/2).
    δ > 0."""
    scale = line_stiffness / (2.0 * math.sqrt(2.0))
    ratio = penetration / clearance
    if ratio >= 0.25:
        integral = ((2.0 * penetration - 3.0 * clearance) / 4.0 * math.sqrt(penetration * (clearance + penetration))
                    + 0.75 * clearance * clearance * math.asinh(math.sqrt(ratio)))
        return scale * integral
    total, coefficient, power = 0.0, 1.0, 1.0
    for k in range(200):
        term = coefficient * power / (k + 2.5)
        total += term
        if abs(term) <= 1e-17 * abs(total):
            break
        coefficient *= -(k + 0.5) / (k + 1.0)
        power *= ratio
    return scale * total * penetration**2.5 / math.sqrt(clearance)


# --- one law, chosen per joint --------------------------------------------------------------------------------


@njit(cache=True)
def law_state(law, penetration, stiffness, exponent, clearance):
    """(F_el, dF_el/dδ, ∫₀^δ F_el) of elastic law `law` (ELASTIC_LAWS) with the joint's K, n, ΔR (module
    docstring); zeros for δ ≤ 0. The power laws: K δⁿ, n K δⁿ⁻¹, K δⁿ⁺¹/(n + 1). A kernel of its own, not inlined by
    numba into its four call sites (each typed and lowered every law again: ~3 s of a compile on an empty cache; the
    loop's run time is the same within its noise, docs/performance.md)."""
    if penetration <= 0.0:
        return 0.0, 0.0, 0.0
    if law == LIU:
        return (liu_force(penetration, stiffness, clearance), liu_stiffness(penetration, stiffness, clearance),
                liu_energy(penetration, stiffness, clearance))
    if law == JOHNSON or law == ESDU_78035:
        return line_contact_state(penetration, stiffness, clearance, line_contact_constant(law))
    return (power_force(penetration, stiffness, exponent), exponent * stiffness * penetration ** (exponent - 1.0),
            power_energy(penetration, stiffness, exponent))


@njit(cache=True)
def law_force(law, penetration, stiffness, exponent, clearance):
    """F_el alone: law_state(…)[0], for the power laws without the stiffness and energy law_state also computes (two
    powers fewer a contact force, the right-hand side's; bit for bit the same force)."""
    if penetration > 0.0 and is_power_law(law):
        return power_force(penetration, stiffness, exponent)
    return law_state(law, penetration, stiffness, exponent, clearance)[0]


@njit(cache=True, inline="always")
def is_power_law(law):
    """F_el = K δⁿ (point_hertz, pereira): the closed-form Hertz estimates apply."""
    return law in POWER_LAW_CODES


@njit(cache=True)
def law_max_penetration(law, effective_mass, impact_speed, stiffness, exponent, clearance):
    """δ_max of an undamped impact: ∫₀^δmax F_el = ½ m v². Closed form for the power laws
    (hertz_max_penetration); else Newton's method on the convex, rising W(δ) − ½ m v² from a start right of the
    root (doubling ΔR until W exceeds ½ m v²), which then descends monotonically to it."""
    if is_power_law(law):
        return hertz_max_penetration(effective_mass, stiffness, impact_speed, exponent)
    target = 0.5 * effective_mass * impact_speed * impact_speed
    if not target < math.inf:
        return math.inf
    depth = clearance
    while law_state(law, depth, stiffness, exponent, clearance)[2] < target:
        depth *= 2.0
    for _ in range(_NEWTON_ITERATIONS):
        force, _, energy = law_state(law, depth, stiffness, exponent, clearance)
        step = (energy - target) / force
        depth -= step
        if abs(step) <= 1e-14 * depth:
            break
    return depth


@njit(cache=True)
def max_penetrations(laws, effective_masses, impact_speeds, stiffnesses, exponents, clearances):
    """law_max_penetration of each entry of the arrays (m)."""
    depths = np.empty(len(laws))
    for i in range(len(laws)):
        depths[i] = law_max_penetration(laws[i], effective_masses[i], impact_speeds[i], stiffnesses[i],
                                        exponents[i], clearances[i])
    return depths


# --- validity ---------------------------------------------------------------------------------------------------


def range_warnings(joint, law, clearance, line_stiffness, peak_penetration):
    """The run summary's warnings for joint `joint` (name) whose elastic law `law` (ELASTIC_LAWS value) was used
    outside its range: Pereira's fit outside 0.005–10 mm of clearance (known before the run); a line-contact law
    past its edge δ_e (line_contact_edge) at the deepest sampled penetration `peak_penetration` (m, NaN: none)."""
    if law == PEREIRA and not PEREIRA_CLEARANCE_RANGE_MM[0] <= clearance * 1e3 <= PEREIRA_CLEARANCE_RANGE_MM[1]:
        low, high = PEREIRA_CLEARANCE_RANGE_MM
        return [f"joint '{joint}': the pereira elastic law is fitted for clearances of {low:g}–{high:g} mm; "
                f"ΔR = {clearance * 1e3:.4g} mm lies outside, so its force is extrapolated"]
    if law in (JOHNSON, ESDU_78035):
        edge = line_contact_edge(line_contact_constant(law))
        edge_penetration = 8.0 * clearance * edge
        if peak_penetration > edge_penetration:
            name = "johnson" if law == JOHNSON else "esdu_78035"
            return [f"joint '{joint}': the {name} elastic law reached δ = {peak_penetration * 1e6:.3g} µm, past "
                    f"δ_e = {edge_penetration * 1e6:.3g} µm (F_e = {4.0 * line_stiffness * clearance * edge / 1e3:.3g}"
                    f" kN) where its δ(F) bends over; beyond, the force went on as a straight line of slope π L E* = "
                    f"{line_stiffness:.3g} N/m. A conformal law (liu, pereira) holds at these loads"]
    return []
