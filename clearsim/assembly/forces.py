"""Generalised forces Q(t, q, q̇): gravity, point loads, spring-dampers, rotational springs and clearance contacts
(compiled).

Clearance joint k (Meng 2015 §2, restated in docs/model.md §3): bearing centre P_B on the first body,
journal centre P_J on the second; eccentricity e = P_J − P_B, n = e/|e|, penetration δ = |e| − c,
penetration rate δ̇ = ė·n, tangent t = (−n_y, n_x) and sliding velocity
v_t = ė·t + ω_J R_J − ω_B R_B (material points of journal and bearing at the contact).
Forces act on the journal at P_J + R_J n:  −F_n n − μ(v_t) F_n t, and the opposite on the bearing
at P_B + R_B n. Dissipated powers (F_n − F_el(δ)) δ̇ and μ(v_t) F_n v_t are returned for the energy balance.
A lubricated joint (docs/model-contact.md) measures δ from the film threshold, δ = |e| − c + h_dry, and while
free of dry contact carries its oil film's force and torque instead; the power the film takes out is booked
with the contact's.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearsim.assembly.arrays import (
    CL_BEARING_POINT, CL_BEARING_RADIUS, CL_CLEARANCE, CL_EXPONENT, CL_JOURNAL_POINT,
    CL_JOURNAL_RADIUS, CL_MIN_IMPACT_SPEED, CL_MU_D, CL_MU_S, CL_RESTITUTION, CL_STIFFNESS,
    CL_V_HIGH, CL_V_LOW, CL_DRY_GAP, CL_FILM_LENGTH, CL_VISCOSITY, LAW_FILM_MODEL, WEAR_INNERMOST, WEAR_LINE_STIFFNESS,
    WEAR_REACH, WEAR_SCALE, WEAR_SLOT, WEAR_SLOT_HARMONICS, WEAR_WEIGHTS,
)
from clearsim.assembly.kinematics import (
    GROUND, add_global_force, add_point_force, body_pose, body_rates, frame_point, frame_rotate, frame_velocity,
    kept_frame, line_kinematics, point_position, point_velocity,
)
from clearsim.assembly.constraints import prescribed
from clearsim.assembly.drivelines import driveline_potential
from clearsim.physics.contact import damped_force
from clearsim.physics.cylindrical import law_force, law_state
from clearsim.physics.friction import STICK_EXACT, friction_coefficient, sliding_coefficient
from clearsim.physics.lubrication import film_force, film_torque, line_of_centres
from clearsim.physics.wear import add_band_rates, band_half_angle, bore_curvature_radius

# modes of a clearance joint, constant within a step. CONTACT is any contact of a smooth friction
# law, and sliding along +t under an exact-stick law; STICK and SLIDE_BACK (sliding along −t)
# only occur under an exact-stick law (docs/model.md §4)
FREE = 0
CONTACT = 1
STICK = 2
SLIDE_BACK = 3


@njit(cache=True)
def clearance_kinematics(system, k, q, qd):
    """(e_x, e_y, ė_x, ė_y, δ, δ̇, n_x, n_y, v_t) of clearance joint k."""
    p = system.clearance_params[k]
    bearing = system.clearance_bodies[k, 0]
    journal = system.clearance_bodies[k, 1]
    bearing_frame = kept_frame(system, q, bearing)
    journal_frame = kept_frame(system, q, journal)
    bx, by = frame_point(bearing_frame, p[CL_BEARING_POINT], p[CL_BEARING_POINT + 1])
    jx, jy = frame_point(journal_frame, p[CL_JOURNAL_POINT], p[CL_JOURNAL_POINT + 1])
    bvx, bvy = frame_velocity(bearing_frame, qd, bearing, p[CL_BEARING_POINT], p[CL_BEARING_POINT + 1])
    jvx, jvy = frame_velocity(journal_frame, qd, journal, p[CL_JOURNAL_POINT], p[CL_JOURNAL_POINT + 1])
    ex, ey = jx - bx, jy - by
    dex, dey = jvx - bvx, jvy - bvy
    if system.wear_harmonics[k] > 0:
        penetration, rate, nx, ny, sliding = worn_contact(system, k, q, qd, ex, ey, dex, dey)[:5]
        return ex, ey, dex, dey, penetration + p[CL_DRY_GAP], rate, nx, ny, sliding
    eccentricity = np.sqrt(ex * ex + ey * ey)
    nx, ny = 1.0, 0.0  # a centred journal has no contact direction; any unit vector will do
    if eccentricity > 1e-300:
        nx, ny = ex / eccentricity, ey / eccentricity
    sliding = (-ny * dex + nx * dey + body_rates(qd, journal)[2] * p[CL_JOURNAL_RADIUS]
               - body_rates(qd, bearing)[2] * p[CL_BEARING_RADIUS])
    penetration = eccentricity - p[CL_CLEARANCE] + p[CL_DRY_GAP]
    return ex, ey, dex, dey, penetration, nx * dex + ny * dey, nx, ny, sliding


@njit(cache=True)
def worn_contact(system, k, q, qd, ex, ey, dex, dey):
    """(δ, δ̇, n_x, n_y, v_t, r_x, r_y, ψ̇) of clearance joint k with a worn bore (physics/wear.py), e = (ex, ey) and
    its rate global: the journal touches the bore at its point r closest to P_J (r from P_B, global), with the bore's
    normal n there; δ = R_J − |r − e|, δ̇ = n·(ė − ω_B k×r), v_t = t·(ė − ω_B k×r) + ω_J R_J, and ψ̇ the rate at
    which n turns (docs/model-contact.md, "Worn bores and Archard wear")."""
    c, s, wb, local_x, local_y = bearing_view(system, k, q, qd, ex, ey)
    rx, ry, tangent_x, tangent_y, curvature = nearest_point_kept(system, k, local_x, local_y)
    penetration, rate, nx, ny, sliding, arm_x, arm_y, local_nx, local_ny, distance = rim_contact(
        system, k, qd, c, s, wb, local_x, local_y, dex, dey, rx, ry)
    frame_x, frame_y = dex + wb * ey, dey - wb * ex  # ė − ω_B k×e, turned into the bearing frame below
    local_rate_x, local_rate_y = c * frame_x + s * frame_y, -s * frame_x + c * frame_y
    foot_rate = 0.0  # θ̇* of the closest point (none where it is not a minimum: free flight near the centre)
    if curvature > 0.0:
        foot_rate = (tangent_x * local_rate_x + tangent_y * local_rate_y) / curvature
    normal_turn = wb + ((-local_ny * tangent_x + local_nx * tangent_y) * foot_rate
                        - (-local_ny * local_rate_x + local_nx * local_rate_y)) / distance
    return penetration, rate, nx, ny, sliding, arm_x, arm_y, normal_turn


@njit(cache=True)
def second_rim(system, k, q, qd, ex, ey, dex, dey):
    """(δ, δ̇, n_x, n_y, v_t, r_x, r_y) of the second rim joint k's journal touches in a worn bore tighter than
    itself (wear.second_foot), as worn_contact's of the nearest point (δ measured as the joint's: from its dry gap);
    δ = −inf where there is none (docs/model-contact.md, "A pocket tighter than the journal")."""
    if not may_touch_two_rims(system, k):
        return -np.inf, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0
    c, s, wb, local_x, local_y = bearing_view(system, k, q, qd, ex, ey)
    rim, rx, ry = second_point_kept(system, k, local_x, local_y)
    if not rim == rim:
        return -np.inf, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0
    penetration, rate, nx, ny, sliding, arm_x, arm_y = rim_contact(system, k, qd, c, s, wb, local_x, local_y, dex, dey,
                                                                   rx, ry)[:7]
    return penetration + system.clearance_params[k, CL_DRY_GAP], rate, nx, ny, sliding, arm_x, arm_y


@njit(cache=True, inline="always")
def second_rim_reach(system, k):
    """The distance from the journal's centre within which a bore point touches it: R_J (+ h_dry of a lubricated
    joint)."""
    p = system.clearance_params[k]
    return p[CL_JOURNAL_RADIUS] + p[CL_DRY_GAP]


@njit(cache=True, inline="always")
def may_touch_two_rims(system, k):
    """Joint k's worn bore has an inner reach below second_rim_reach, so that a journal may touch it at two rims
    (wear.nearest_bore_point looks for a second one only then): fixed at assembly."""
    return system.wear_harmonics[k] > 0 and system.wear_bounds[k, WEAR_REACH] < second_rim_reach(system, k)


@njit(cache=True, inline="always")
def bearing_view(system, k, q, qd, ex, ey):
    """(cos θ_B, sin θ_B, ω_B, e in the bearing frame) of clearance joint k."""
    bearing = system.clearance_bodies[k, 0]
    angle = body_pose(q, bearing)[2]
    wb = body_rates(qd, bearing)[2]
    c, s = np.cos(angle), np.sin(angle)
    return c, s, wb, c * ex + s * ey, -s * ex + c * ey


@njit(cache=True, inline="always")
def rim_contact(system, k, qd, c, s, wb, local_x, local_y, dex, dey, rx, ry):
    """(δ, δ̇, n_x, n_y, v_t, r_x, r_y global, n in the bearing frame, |r − e|) of joint k's journal touching its worn
    bore at r = (rx, ry) of the bearing frame (bearing_view's c, s, ω_B and local e): δ = R_J − |r − e|,
    n = (r − e)/|r − e|, δ̇ = n·(ė − ω_B k×r), v_t = t·(ė − ω_B k×r) + ω_J R_J."""
    p = system.clearance_params[k]
    gap_x, gap_y = rx - local_x, ry - local_y
    distance = np.sqrt(gap_x * gap_x + gap_y * gap_y)
    local_nx, local_ny = gap_x / distance, gap_y / distance
    nx, ny = c * local_nx - s * local_ny, s * local_nx + c * local_ny
    arm_x, arm_y = c * rx - s * ry, s * rx + c * ry
    relative_x, relative_y = dex + wb * arm_y, dey - wb * arm_x  # ė − ω_B k×r
    rate = nx * relative_x + ny * relative_y
    wj = body_rates(qd, system.clearance_bodies[k, 1])[2]
    sliding = -ny * relative_x + nx * relative_y + wj * p[CL_JOURNAL_RADIUS]
    return p[CL_JOURNAL_RADIUS] - distance, rate, nx, ny, sliding, arm_x, arm_y, local_nx, local_ny, distance


@njit(cache=True, inline="always")
def kept_bore_points(system, k, local_x, local_y):
    """system.bore_memo[k] for the journal centre (local_x, local_y) in the bearing frame: the centre, then
    wear.nearest_bore_point's twelve values (the nearest point and the second rim, by address), found again only
    when that centre changes bit for bit (and at a zero coordinate, whose sign the angle of e reads): the forces, the
    wear rates and the stick row of one state share one search. The bore's profile is fixed for the arrays' life."""
    memo = system.bore_memo[k]
    if memo[0] != local_x or memo[1] != local_y or local_x == 0.0 or local_y == 0.0:
        p = system.clearance_params[k]
        found = system.bore_point(  # wear.nearest_bore_point, by address
            system.wear_profile[k], system.wear_samples[k], system.wear_harmonics[k], system.wear_depth_range[k],
            system.wear_bounds[k, WEAR_REACH], system.wear_bounds[k, WEAR_INNERMOST], p[CL_BEARING_RADIUS], local_x,
            local_y, second_rim_reach(system, k))
        memo[0], memo[1] = local_x, local_y
        for i in range(12):
            memo[2 + i] = found[i]
    return memo


@njit(cache=True, inline="always")
def nearest_point_kept(system, k, local_x, local_y):
    """(r_x, r_y, t_x, t_y, ρ'') of joint k's worn bore nearest to the journal centre (local_x, local_y) in the bearing
    frame (kept_bore_points)."""
    memo = kept_bore_points(system, k, local_x, local_y)
    return memo[3], memo[4], memo[5], memo[6], memo[7]


@njit(cache=True, inline="always")
def second_point_kept(system, k, local_x, local_y):
    """(θ, r_x, r_y) of the second rim joint k's journal at (local_x, local_y) touches (θ NaN: none; kept_bore_points)."""
    memo = kept_bore_points(system, k, local_x, local_y)
    return memo[8], memo[9], memo[10]


@njit(cache=True)
def bearing_contact_arm(system, k, kinematics):
    """The bearing's contact point relative to its centre P_B (global), from the joint's clearance_kinematics: R_B n
    on a circular bore; on a worn bore its point r nearest to the journal's centre, e + |r − e| n with
    |r − e| = R_J − δ (worn_contact's, without finding r again)."""
    ex, ey, _, _, penetration, _, nx, ny, _ = kinematics
    p = system.clearance_params[k]
    if system.wear_harmonics[k] > 0:
        distance = p[CL_JOURNAL_RADIUS] - (penetration - p[CL_DRY_GAP])
        return ex + distance * nx, ey + distance * ny
    return p[CL_BEARING_RADIUS] * nx, p[CL_BEARING_RADIUS] * ny


@njit(cache=True)
def exact_stick(system, k):
    """Joint k sticks by a constraint (its friction law has the `exact` stick treatment)."""
    return system.clearance_laws[k, 2] == STICK_EXACT


@njit(cache=True)
def stick_row(system, k, q, qd):
    """Stick constraint v_t = G q̇ = 0 of joint k: (G's bearing block, G's journal block, Ġ q̇).

    G q̇ = t·(ṙ_J − ṙ_B) + (n·a_J + R_J) ω_J − (n·a_B + R_B) ω_B with a = A s the arms of the joint
    centres, and Ġ q̇ = −φ̇ (n·ė) − ω_J² (t·a_J) + ω_B² (t·a_B), φ̇ = t·ė/|e| (docs/model.md §4). On a worn bore
    R_B becomes n·r (r the bore's contact point from P_B), φ̇ the rate ψ̇ at which n turns, and Ġ q̇ gains
    −ω_B (ψ̇ − ω_B)(t·r) (docs/model-contact.md, "Worn bores and Archard wear").
    """
    p = system.clearance_params[k]
    bearing = system.clearance_bodies[k, 0]
    journal = system.clearance_bodies[k, 1]
    ex, ey, dex, dey, _, rate, nx, ny, _ = clearance_kinematics(system, k, q, qd)
    tx, ty = -ny, nx
    abx, aby = frame_rotate(kept_frame(system, q, bearing), p[CL_BEARING_POINT], p[CL_BEARING_POINT + 1])
    ajx, ajy = frame_rotate(kept_frame(system, q, journal), p[CL_JOURNAL_POINT], p[CL_JOURNAL_POINT + 1])
    wb = body_rates(qd, bearing)[2]
    wj = body_rates(qd, journal)[2]
    if system.wear_harmonics[k] > 0:
        _, _, _, _, _, arm_x, arm_y, normal_turn = worn_contact(system, k, q, qd, ex, ey, dex, dey)
        bearing_block = (-tx, -ty, -(nx * abx + ny * aby) - (nx * arm_x + ny * arm_y))
        journal_block = (tx, ty, nx * ajx + ny * ajy + p[CL_JOURNAL_RADIUS])
        curvature = (-normal_turn * (nx * dex + ny * dey) - wj * wj * (tx * ajx + ty * ajy)
                     + wb * wb * (tx * abx + ty * aby) - wb * (normal_turn - wb) * (tx * arm_x + ty * arm_y))
        return bearing_block, journal_block, curvature
    eccentricity = np.sqrt(ex * ex + ey * ey)
    orbit_rate = (tx * dex + ty * dey) / eccentricity if eccentricity > 1e-300 else 0.0
    bearing_block = (-tx, -ty, -(nx * abx + ny * aby) - p[CL_BEARING_RADIUS])
    journal_block = (tx, ty, nx * ajx + ny * ajy + p[CL_JOURNAL_RADIUS])
    curvature = -orbit_rate * rate - wj * wj * (tx * ajx + ty * ajy) + wb * wb * (tx * abx + ty * aby)
    return bearing_block, journal_block, curvature


@njit(cache=True)
def contact_force_magnitudes(system, k, penetration, rate, sliding, mode, impact_speed):
    """(F_n, F_t, F_el(δ)) of clearance joint k; zero in free flight. F_t is the signed force along t."""
    if mode == FREE or penetration <= 0.0:
        return 0.0, 0.0, 0.0
    p = system.clearance_params[k]
    force, elastic = normal_force_magnitude(system, k, penetration, rate, impact_speed)
    law = system.clearance_laws[k, 1]
    if not exact_stick(system, k):
        mu = friction_coefficient(law, sliding, p[CL_MU_S], p[CL_MU_D], p[CL_V_LOW], p[CL_V_HIGH])
    elif mode == STICK:
        mu = 0.0  # the stick constraint's multiplier carries the friction force
    else:
        direction = -1.0 if mode == SLIDE_BACK else 1.0
        mu = direction * sliding_coefficient(law, abs(sliding), p[CL_MU_S], p[CL_MU_D], p[CL_V_LOW], p[CL_V_HIGH])
    return force, -mu * force, elastic


@njit(cache=True, inline="always")
def contact_energy(system, k, penetration):
    """∫ F_el dδ of clearance joint k's elastic law at penetration δ (law_state)."""
    p = system.clearance_params[k]
    return law_state(system.clearance_laws[k, 3], penetration, p[CL_STIFFNESS], p[CL_EXPONENT], p[CL_CLEARANCE])[2]


@njit(cache=True, inline="always")
def normal_force_magnitude(system, k, penetration, rate, impact_speed):
    """(F_n, F_el(δ)) of clearance joint k at δ > 0: its elastic law and damping (Meng 2015 eqs. 8–10)."""
    p = system.clearance_params[k]
    guarded_speed = max(impact_speed, p[CL_MIN_IMPACT_SPEED])  # grazing guard, docs/model.md
    elastic = law_force(system.clearance_laws[k, 3], penetration, p[CL_STIFFNESS], p[CL_EXPONENT], p[CL_CLEARANCE])
    return damped_force(system.clearance_laws[k, 0], elastic, rate, guarded_speed, p[CL_RESTITUTION]), elastic


@njit(cache=True)
def second_rim_force_magnitudes(system, k, penetration, rate, sliding, impact_speed):
    """(F_n, F_t, F_el(δ)) at the second rim of a two-point contact (second_rim): the joint's elastic law and damping
    (the impact speed of its contact episode), friction by its law as written, μ(v_t) of the rim's own sliding speed
    (the exact stick of a sticking law is the nearer rim's); zero where the rim is not touched."""
    if penetration <= 0.0:
        return 0.0, 0.0, 0.0
    p = system.clearance_params[k]
    force, elastic = normal_force_magnitude(system, k, penetration, rate, impact_speed)
    mu = friction_coefficient(system.clearance_laws[k, 1], sliding, p[CL_MU_S], p[CL_MU_D], p[CL_V_LOW], p[CL_V_HIGH])
    return force, -mu * force, elastic


@njit(cache=True, inline="always")
def add_contact_pair(system, k, q, generalized, ex, ey, nx, ny, fn, ft, arm_x, arm_y):
    """The force pair of a contact of joint k: −F_n n − F_t t on the journal at P_J + R_J n, the opposite on the
    bearing at P_B + r (arm_x, arm_y: r, global)."""
    p = system.clearance_params[k]
    fx = -fn * nx - ft * ny
    fy = -fn * ny + ft * nx
    bearing = system.clearance_bodies[k, 0]
    journal = system.clearance_bodies[k, 1]
    bx, by = frame_point(kept_frame(system, q, bearing), p[CL_BEARING_POINT], p[CL_BEARING_POINT + 1])
    add_global_force(generalized, q, journal, bx + ex + p[CL_JOURNAL_RADIUS] * nx,
                     by + ey + p[CL_JOURNAL_RADIUS] * ny, fx, fy)
    add_global_force(generalized, q, bearing, bx + arm_x, by + arm_y, -fx, -fy)


@njit(cache=True)
def add_clearance_forces(system, q, qd, modes, impact_speeds, generalized, with_films):
    """Add all contact force pairs; return (contact dissipation power, friction dissipation power). `with_films`: True,
    or None for a model without oil films, whose specialisation numba prunes of the film forces before typing them
    (dynamics.dynamics_kernel)."""
    contact_loss = 0.0
    friction_loss = 0.0
    for k in range(system.clearance_bodies.shape[0]):
        kinematics = clearance_kinematics(system, k, q, qd)
        ex, ey, dex, dey, penetration, rate, nx, ny, sliding = kinematics
        if modes[k] == FREE and system.clearance_params[k, CL_VISCOSITY] > 0.0:
            if with_films is not None:
                contact_loss += add_film_forces(system, k, q, qd, generalized)
            continue
        fn, ft, elastic = contact_force_magnitudes(system, k, penetration, rate, sliding, modes[k], impact_speeds[k])
        contact_loss += (fn - elastic) * rate  # also while the damping term clips F_n to 0 with δ > 0
        if fn != 0.0:
            arm_x, arm_y = bearing_contact_arm(system, k, kinematics)
            add_contact_pair(system, k, q, generalized, ex, ey, nx, ny, fn, ft, arm_x, arm_y)
            friction_loss -= ft * sliding
        if modes[k] != FREE and may_touch_two_rims(system, k):  # a second rim of a pocket tighter than the journal
            penetration, rate, nx, ny, sliding, arm_x, arm_y = second_rim(system, k, q, qd, ex, ey, dex, dey)
            fn, ft, elastic = second_rim_force_magnitudes(system, k, penetration, rate, sliding, impact_speeds[k])
            contact_loss += (fn - elastic) * rate
            if fn != 0.0:
                add_contact_pair(system, k, q, generalized, ex, ey, nx, ny, fn, ft, arm_x, arm_y)
                friction_loss -= ft * sliding
    return contact_loss, friction_loss


@njit(cache=True)
def add_wear_rates(system, q, qd, modes, impact_speeds, zdot):
    """Write the rates of the accumulated Archard profiles (scaled by c) into their slots of ż:
    ḣ(θ) = k_w F_n |v_t| K(θ − θ_c) / (H L R_B), θ_c the contact point's angle in the bearing frame, K the kernel
    with the band of the contact's half-angle there (physics/wear.py)."""
    for k in range(system.wear_slots.shape[0]):
        slot = system.wear_slots[k, WEAR_SLOT]
        if slot < 0:
            continue
        harmonics = system.wear_slots[k, WEAR_SLOT_HARMONICS]
        rates = zdot[slot:slot + 2 * harmonics + 1]
        for i in range(rates.shape[0]):
            rates[i] = 0.0
        if modes[k] == FREE or (modes[k] == STICK and not may_touch_two_rims(system, k)):
            continue
        kinematics = clearance_kinematics(system, k, q, qd)
        ex, ey, dex, dey, penetration, rate, _, _, sliding = kinematics
        if modes[k] != STICK:
            fn = contact_force_magnitudes(system, k, penetration, rate, sliding, modes[k], impact_speeds[k])[0]
            if fn != 0.0:
                arm_x, arm_y = bearing_contact_arm(system, k, kinematics)
                add_contact_wear(system, k, q, rates, harmonics, fn, sliding, arm_x, arm_y)
        if may_touch_two_rims(system, k):  # the second rim of a pocket tighter than the journal wears as well
            penetration, rate, _, _, sliding, arm_x, arm_y = second_rim(system, k, q, qd, ex, ey, dex, dey)
            fn = second_rim_force_magnitudes(system, k, penetration, rate, sliding, impact_speeds[k])[0]
            if fn != 0.0:
                add_contact_wear(system, k, q, rates, harmonics, fn, sliding, arm_x, arm_y)


@njit(cache=True, inline="always")
def add_contact_wear(system, k, q, rates, harmonics, fn, sliding, arm_x, arm_y):
    """rates += the Archard profile rate of one contact of joint k: F_n, v_t, the bearing's contact point r (global)."""
    contact_angle = np.arctan2(arm_y, arm_x) - body_pose(q, system.clearance_bodies[k, 0])[2]
    add_band_rates(rates, system.wear_rates[k, WEAR_WEIGHTS:], harmonics,
                   system.wear_rates[k, WEAR_SCALE] * fn * abs(sliding), contact_angle,
                   contact_half_angle(system, k, fn, contact_angle))


@njit(cache=True)
def contact_half_angle(system, k, fn, contact_angle):
    """α (rad) of clearance joint k's wear band under F_n at the bore's angle θ_c (physics/wear.band_half_angle)."""
    p = system.clearance_params[k]
    curvature_radius = bore_curvature_radius(system.wear_profile[k], system.wear_harmonics[k],
                                             p[CL_BEARING_RADIUS], contact_angle)
    return band_half_angle(fn, system.wear_rates[k, WEAR_LINE_STIFFNESS], p[CL_JOURNAL_RADIUS], curvature_radius,
                           p[CL_BEARING_RADIUS])


MAX_FILM_ECCENTRICITY = 1.0 - 1e-9  # ε of a trial stage beyond the wall (rejected by the step control) is capped


@njit(cache=True)
def film_state(system, k, q, qd):
    """(ε, ε̇, wedge speed ω_J + ω_B − 2φ̇, ω_J − ω_B) of lubricated joint k (docs/model-contact.md)."""
    p = system.clearance_params[k]
    ex, ey, dex, dey = clearance_kinematics(system, k, q, qd)[:4]
    nx, ny, eccentricity = line_of_centres(ex, ey, dex, dey, p[CL_CLEARANCE])
    rate = nx * dex + ny * dey
    orbit_rate = (-ny * dex + nx * dey) / eccentricity if eccentricity > 0.0 else 0.0
    wj = body_rates(qd, system.clearance_bodies[k, 1])[2]
    wb = body_rates(qd, system.clearance_bodies[k, 0])[2]
    eps = min(eccentricity / p[CL_CLEARANCE], MAX_FILM_ECCENTRICITY)
    return eps, rate / p[CL_CLEARANCE], wj + wb - 2.0 * orbit_rate, wj - wb


@njit(cache=True)
def film_forces(system, k, q, qd):
    """(F_n, F_t, T, ω_J − ω_B) of the oil film of lubricated joint k on its journal: the force along (n, t) in N
    and the torque in N·m (physics/lubrication.py)."""
    p = system.clearance_params[k]
    eps, eps_rate, wedge, spin = film_state(system, k, q, qd)
    fn, ft = film_force(system.clearance_laws[k, LAW_FILM_MODEL], p[CL_VISCOSITY], p[CL_JOURNAL_RADIUS],
                        p[CL_FILM_LENGTH], p[CL_CLEARANCE], eps, eps_rate, wedge)
    torque = film_torque(p[CL_VISCOSITY], p[CL_JOURNAL_RADIUS], p[CL_FILM_LENGTH], p[CL_CLEARANCE], eps, spin)
    return fn, ft, torque, spin


@njit(cache=True)
def no_film_forces(system, k, q, qd):
    """film_forces' stand-in, of its type, in the sampling of a model in which no joint has an oil film (CL_VISCOSITY
    0), which never calls it: such a model does not compile the film kernels (physics/lubrication.py;
    integrator.addressed)."""
    return 0.0, 0.0, 0.0, 0.0


@njit(cache=True)
def add_film_forces(system, k, q, qd, generalized):
    """Add the oil film's force and torque on the journal of joint k (the opposite on the bearing, at the same
    point P_J); return the power the film takes out, −F·(v_J − v_B)(P_J) − T (ω_J − ω_B)."""
    p = system.clearance_params[k]
    fn, ft, torque, spin = film_forces(system, k, q, qd)
    ex, ey, dex, dey = clearance_kinematics(system, k, q, qd)[:4]
    nx, ny = line_of_centres(ex, ey, dex, dey, p[CL_CLEARANCE])[:2]
    fx = fn * nx - ft * ny
    fy = fn * ny + ft * nx
    bearing = system.clearance_bodies[k, 0]
    journal = system.clearance_bodies[k, 1]
    bx, by = frame_point(kept_frame(system, q, bearing), p[CL_BEARING_POINT], p[CL_BEARING_POINT + 1])
    add_global_force(generalized, q, journal, bx + ex, by + ey, fx, fy)
    add_global_force(generalized, q, bearing, bx + ex, by + ey, -fx, -fy)
    if journal != GROUND:
        generalized[3 * journal + 2] += torque
    if bearing != GROUND:
        generalized[3 * bearing + 2] -= torque
    wb = body_rates(qd, bearing)[2]
    relative_x, relative_y = dex + wb * ey, dey - wb * ex  # journal centre relative to the bearing point under it
    return -(fx * relative_x + fy * relative_y) - torque * spin


@njit(cache=True)
def add_applied_forces(system, t, q, qd, generalized):
    """Add gravity, point loads, spring-dampers and rotational springs; return (applied power, spring damping loss)."""
    for b in range(system.mass.shape[0]):
        generalized[3 * b] += system.mass[b] * system.gravity[0]
        generalized[3 * b + 1] += system.mass[b] * system.gravity[1]
    applied_power = 0.0
    for k in range(system.load_bodies.shape[0]):
        body = system.load_bodies[k]
        p = system.load_params[k]
        scale = 1.0 if system.load_law[k] < 0 else prescribed(system, system.load_law[k], t)[0]
        fx, fy, torque = scale * p[2], scale * p[3], scale * p[4]
        add_point_force(generalized, q, body, p[0], p[1], fx, fy)
        if body != GROUND:
            generalized[3 * body + 2] += torque
        vx, vy = point_velocity(q, qd, body, p[0], p[1])
        applied_power += fx * vx + fy * vy + torque * body_rates(qd, body)[2]
    damping_loss = 0.0
    for k in range(system.spring_bodies.shape[0]):
        tension, rate, ux, uy = spring_state(system, k, q, qd)
        p = system.spring_params[k]
        bi, bj = system.spring_bodies[k, 0], system.spring_bodies[k, 1]
        add_point_force(generalized, q, bi, p[0], p[1], tension * ux, tension * uy)
        add_point_force(generalized, q, bj, p[2], p[3], -tension * ux, -tension * uy)
        damping_loss += p[5] * rate * rate
    for k in range(system.torsion_bodies.shape[0]):
        torque, rate = torsion_state(system, k, q, qd)
        bi, bj = system.torsion_bodies[k, 0], system.torsion_bodies[k, 1]
        if bi != GROUND:
            generalized[3 * bi + 2] += torque
        if bj != GROUND:
            generalized[3 * bj + 2] -= torque
        damping_loss += system.torsion_params[k, 1] * rate * rate
    return applied_power, damping_loss


@njit(cache=True)
def relative_angle(system, k, q):
    """θ_j − θ_i of rotational spring k (a ground end's angle is 0)."""
    return body_pose(q, system.torsion_bodies[k, 1])[2] - body_pose(q, system.torsion_bodies[k, 0])[2]


@njit(cache=True)
def torsion_state(system, k, q, qd):
    """(torque T = k (θ_j − θ_i − θ₀) + c (ω_j − ω_i) + preload, ω_j − ω_i) of rotational spring k: −T acts on body
    j, +T on body i."""
    p = system.torsion_params[k]
    rate = body_rates(qd, system.torsion_bodies[k, 1])[2] - body_rates(qd, system.torsion_bodies[k, 0])[2]
    return p[0] * (relative_angle(system, k, q) - p[2]) + p[1] * rate + p[3], rate


@njit(cache=True)
def spring_state(system, k, q, qd):
    """(tension f = k(ℓ − ℓ0) + c ℓ̇ + preload, ℓ̇, u_x, u_y) of spring-damper k, u from point i to j."""
    p = system.spring_params[k]
    length, rate, ux, uy = line_kinematics(q, qd, system.spring_bodies[k, 0], system.spring_bodies[k, 1], p[0], p[1],
                                           p[2], p[3])
    return p[4] * (length - p[6]) + p[5] * rate + p[7], rate, ux, uy


@njit(cache=True)
def potential_energy(system, q):
    """Gravity + spring and rotational spring (elastic and preload) + contact elastic energy ∫₀^δ F_el
    (K δⁿ⁺¹/(n+1) for the power laws) + spring drives and gas loads."""
    energy = 0.0
    for b in range(system.mass.shape[0]):
        energy -= system.mass[b] * (system.gravity[0] * q[3 * b] + system.gravity[1] * q[3 * b + 1])
    zero = np.zeros_like(q)
    for k in range(system.spring_bodies.shape[0]):
        p = system.spring_params[k]
        xi, yi = point_position(q, system.spring_bodies[k, 0], p[0], p[1])
        xj, yj = point_position(q, system.spring_bodies[k, 1], p[2], p[3])
        length = np.sqrt((xj - xi) ** 2 + (yj - yi) ** 2)
        energy += 0.5 * p[4] * (length - p[6]) ** 2 + p[7] * length
    for k in range(system.torsion_bodies.shape[0]):
        p = system.torsion_params[k]
        angle = relative_angle(system, k, q)
        energy += 0.5 * p[0] * (angle - p[2]) ** 2 + p[3] * angle
    for k in range(system.clearance_bodies.shape[0]):
        ex, ey, _, _, penetration = clearance_kinematics(system, k, q, zero)[:5]
        energy += contact_energy(system, k, penetration)
        if may_touch_two_rims(system, k):  # and the second rim's of a two-point contact
            rim = second_rim(system, k, q, zero, ex, ey, 0.0, 0.0)[0]
            if rim > 0.0:
                energy += contact_energy(system, k, rim)
    return energy + driveline_potential(system, q)
