"""Independent loop-closure kinematics of the reconstructed UHV breaker transmission.

The reference against which the multibody solver is checked on the ideal
(rigid, no clearance) model of ``clearsim/configs/uhv_breaker.yaml``. It does
not import clearsim: the mechanism is solved stage by stage in closed form
(circle/circle and circle/line intersections), in the order of the chain

    driving link (slider, horizontal guide through A)
      -> lower linkage A-B -> lower turn arm (ground pivot C)
      -> lower linking board D-E -> sealing rod (slider, vertical guide through E)
      -> insulating pole F-G -> main crank arm (ground pivot H)
      -> upper linking board I-J -> moving contact (slider, vertical guide through J)

Every stage keeps the assembly branch it has at t = 0 (the sign of the
triangle it closes), which is unambiguous because no stage passes a dead
centre over the stroke (see ``transmission_angles``).

Velocities and accelerations come from the kinematic coefficients
dX/dx and d²X/dx² with respect to the drive coordinate x (five-point central
differences, h = 0.5 mm; truncation ~1e-12, round-off ~1e-9 relative),
combined with the analytic drive law: v = X' ẋ, a = X'' ẋ² + X' ẍ.

The geometry below is the single source of the numbers: ``docs/scripts/
uhv_geometry.py`` imports it, prints/plots it and checks that the YAML file
carries the same values. The reconstruction and its rationale are in
``docs/uhv-geometry.md`` (the paper gives no lengths).

Units: SI (m, rad, s) everywhere unless a name says otherwise.
"""

from __future__ import annotations

import numpy as np

# ---------------------------------------------------------------------------
# Geometry at t = 0 (global frame, m). Origin at the ground pivot C of the
# lower turn arm, x to the right, y up (gravity along -y).
# ---------------------------------------------------------------------------
POINTS0: dict[str, tuple[float, float]] = {
    "A": (0.095, -0.222),  # driving link - lower linkage (on the horizontal drive axis)
    "B": (0.219, -0.144),  # lower linkage - lower turn arm
    "C": (0.000, 0.000),  # ground pivot of the lower turn arm
    "D": (0.182, 0.124),  # lower turn arm - lower linking board
    "E": (0.177, 0.274),  # lower linking board - sealing rod (bottom end of the sealing rod)
    "F": (0.177, 0.574),  # sealing rod - insulating pole (top end of the sealing rod)
    "G": (0.177, 2.574),  # insulating pole - main crank arm
    "H": (0.356, 2.463),  # ground pivot of the main crank arm
    "I": (0.633, 2.335),  # main crank arm - upper linking board
    "J": (0.589, 2.667),  # upper linking board - moving contact
}

# Guides of the three sliders: a point on the line and the unit direction
# (global, t = 0). The drive law is applied along DRIVE_AXIS.
DRIVE_AXIS = (1.0, 0.0)  # driving link moves by -0.23 m along +x, i.e. to the left
SEALING_ROD_AXIS = (0.0, 1.0)  # guide line through E and F
CONTACT_AXIS = (0.0, 1.0)  # guide line through J

# Directions in which the outputs are counted positive (global unit vectors):
CONTACT_STROKE_DIRECTION = (0.0, 1.0)  # the moving contact travels up
SEALING_ROD_STROKE_DIRECTION = (0.0, -1.0)  # the sealing rod travels down (pole pulled)

# Drive law, paper eq. (16): x(T) = S (T/T_d)^2 (3 - 2 T/T_d), S = -0.23 m, T_d = 0.085 s.
DRIVE_STROKE = -0.23  # m, along DRIVE_AXIS
DRIVE_DURATION = 0.085  # s

# Lengths of the parts that carry only one joint (slider bodies), m.
DRIVING_LINK_LENGTH = 0.380  # piston rod, A at its right end, cylinder on the left
SEALING_ROD_LENGTH = 0.300  # = |EF|
MOVING_CONTACT_LENGTH = 0.300  # contact tube, J at its lower end

# Bodies: name -> (mass kg, inertia kg m^2 about the CoM, CoM at t = 0 (m), angle at t = 0 (deg)).
# Masses and inertias: paper Table 1. CoM = middle of the link (centroid of B, C, D for the
# bell-crank turn arm, rounded to 1 mm; middle of G-I for the main crank arm). Angle = direction
# of the link (first joint -> second joint along the chain; C -> B for the turn arm, G -> I for
# the main crank arm), 0 for the three sliders. These are the values written in the YAML file.
BODIES: dict[str, dict] = {
    "driving_link": dict(mass=3.670, inertia=0.044, com=(-0.095, -0.222), angle_deg=0.0),
    "lower_linkage": dict(mass=3.720, inertia=0.015, com=(0.157, -0.183), angle_deg=32.171),
    "lower_turn_arm": dict(mass=56.92, inertia=0.200, com=(0.134, -0.007), angle_deg=-33.326),
    "lower_linking_board": dict(mass=4.760, inertia=0.010, com=(0.1795, 0.199), angle_deg=91.909),
    "sealing_rod": dict(mass=12.06, inertia=0.090, com=(0.177, 0.424), angle_deg=0.0),
    "insulating_pole": dict(mass=81.54, inertia=0.051, com=(0.177, 1.574), angle_deg=90.0),
    "main_crank_arm": dict(mass=25.66, inertia=0.120, com=(0.405, 2.4545), angle_deg=-27.660),
    "upper_linking_board": dict(mass=13.25, inertia=0.027, com=(0.611, 2.501), angle_deg=97.549),
    "moving_contact": dict(mass=5.420, inertia=0.038, com=(0.589, 2.817), angle_deg=0.0),
}
BODY_NAMES = tuple(BODIES)

# Revolute joints: name -> (bearing body, journal body), paper Fig. 4 labels.
REVOLUTE_JOINTS: dict[str, tuple[str, str]] = {
    "A": ("driving_link", "lower_linkage"),
    "B": ("lower_linkage", "lower_turn_arm"),
    "C": ("ground", "lower_turn_arm"),
    "D": ("lower_turn_arm", "lower_linking_board"),
    "E": ("lower_linking_board", "sealing_rod"),
    "F": ("sealing_rod", "insulating_pole"),
    "G": ("insulating_pole", "main_crank_arm"),
    "H": ("ground", "main_crank_arm"),
    "I": ("main_crank_arm", "upper_linking_board"),
    "J": ("upper_linking_board", "moving_contact"),
}
# Prismatic joints to ground: name -> (body, point on the guide, axis)
PRISMATIC_JOINTS: dict[str, tuple[str, str, tuple[float, float]]] = {
    "driving_guide": ("driving_link", "A", DRIVE_AXIS),
    "sealing_rod_guide": ("sealing_rod", "E", SEALING_ROD_AXIS),
    "contact_guide": ("moving_contact", "J", CONTACT_AXIS),
}

# Transmission angles reported by ``transmission_angles``: name -> description.
# At a crank joint: the angle between the coupler and the crank arm (both as vectors
# from the joint). At a slider joint: the angle between the coupler and the normal of
# the guide. Both are 90 deg at ideal force transmission and 0/180 deg at a dead centre.
TRANSMISSION_ANGLES: dict[str, str] = {
    "A": "lower linkage vs. normal of the drive guide (input side, driving link)",
    "B": "lower linkage vs. turn-arm arm C-B (output of stage 1)",
    "D": "turn-arm arm C-D vs. lower linking board (input of stage 2)",
    "E": "lower linking board vs. normal of the sealing-rod guide (output of stage 2)",
    "F": "insulating pole vs. normal of the sealing-rod guide (input of stage 3)",
    "G": "insulating pole vs. crank arm H-G (output of stage 3)",
    "I": "crank arm H-I vs. upper linking board (input of stage 4)",
    "J": "upper linking board vs. normal of the contact guide (output of stage 4)",
}
OUTPUT_TRANSMISSION_ANGLES = ("B", "E", "G", "J")


# ---------------------------------------------------------------------------
# Drive law
# ---------------------------------------------------------------------------
def drive_law(times):
    """Drive displacement x, velocity and acceleration along DRIVE_AXIS (eq. 16).

    The polynomial holds on the closed interval 0 <= t <= T_d (so the accelerations
    at t = 0 and t = T_d are the one-sided limits from inside, +/-6 S / T_d^2); the
    driving link rests at 0 before and at the full stroke after.
    """
    t = np.asarray(times, dtype=float)
    tau = np.clip(t / DRIVE_DURATION, 0.0, 1.0)
    inside = (t >= 0.0) & (t <= DRIVE_DURATION)
    x = DRIVE_STROKE * tau**2 * (3.0 - 2.0 * tau)
    xd = np.where(inside, DRIVE_STROKE * 6.0 * tau * (1.0 - tau) / DRIVE_DURATION, 0.0)
    xdd = np.where(inside, DRIVE_STROKE * 6.0 * (1.0 - 2.0 * tau) / DRIVE_DURATION**2, 0.0)
    return x, xd, xdd


# ---------------------------------------------------------------------------
# Position analysis (one stage at a time)
# ---------------------------------------------------------------------------
def _p(name):
    return np.array(POINTS0[name], dtype=float)


def _cross(u, v):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _angle(v):
    return np.arctan2(v[..., 1], v[..., 0])


def _circle_circle(P, rP, Q, rQ, branch):
    """Point X with |X-P| = rP, |X-Q| = rQ and sign(cross(X-P, Q-P)) = branch."""
    d = Q - P
    dist = np.hypot(d[..., 0], d[..., 1])
    a = (rP**2 - rQ**2 + dist**2) / (2.0 * dist)
    h2 = rP**2 - a**2
    if np.any(h2 <= 0.0):
        raise ValueError("loop does not close (dead centre or beyond reach)")
    ex = d / dist[..., None]
    ey = np.stack([-ex[..., 1], ex[..., 0]], axis=-1)  # ex turned by +90 deg
    # cross(X-P, Q-P) = cross(a ex + s h ey, dist ex) = -s h dist  ->  s = -branch
    return P + a[..., None] * ex - branch * np.sqrt(h2)[..., None] * ey


def _circle_line(P, r, L0, u, branch):
    """Point X = L0 + s u on the line with |X-P| = r and sign((X-P).u) = branch."""
    w = L0 - P
    b = np.sum(w * u, axis=-1)
    c = np.sum(w * w, axis=-1) - r**2
    disc = b**2 - c
    if np.any(disc <= 0.0):
        raise ValueError("loop does not close (slider at a dead centre or beyond reach)")
    # (X-P).u = b + s  ->  choose s so that its sign is branch
    s = -b + branch * np.sqrt(disc)
    return L0 + s[..., None] * u


class _Geometry:
    """Derived, fixed quantities: lengths, initial arm angles and assembly branches."""

    def __init__(self):
        A, B, C, D, E, F, G, H, I, J = (_p(k) for k in "ABCDEFGHIJ")
        self.P0 = dict(A=A, B=B, C=C, D=D, E=E, F=F, G=G, H=H, I=I, J=J)
        self.drive_axis = np.array(DRIVE_AXIS, float)
        self.seal_axis = np.array(SEALING_ROD_AXIS, float)
        self.contact_axis = np.array(CONTACT_AXIS, float)
        self.L_AB = np.linalg.norm(B - A)
        self.L_CB = np.linalg.norm(B - C)
        self.L_CD = np.linalg.norm(D - C)
        self.L_DE = np.linalg.norm(E - D)
        self.L_EF = np.linalg.norm(F - E)
        self.L_FG = np.linalg.norm(G - F)
        self.L_HG = np.linalg.norm(G - H)
        self.L_HI = np.linalg.norm(I - H)
        self.L_IJ = np.linalg.norm(J - I)
        self.ang_CB0 = _angle(B - C)
        self.ang_CD0 = _angle(D - C)
        self.ang_HG0 = _angle(G - H)
        self.ang_HI0 = _angle(I - H)
        # assembly branches (kept over the whole stroke)
        self.br1 = np.sign(_cross(B - C, A - C))
        self.br2 = np.sign(np.dot(E - D, self.seal_axis))
        self.br3 = np.sign(_cross(G - H, F - H))
        self.br4 = np.sign(np.dot(J - I, self.contact_axis))
        self.F_minus_E = F - E  # the sealing rod translates
        # body-fixed CoM offsets (global components at t = 0) and angles
        self.com0 = {n: np.array(b["com"], float) for n, b in BODIES.items()}
        self.angle0 = {n: np.radians(b["angle_deg"]) for n, b in BODIES.items()}

    def lengths(self):
        return {
            "lower_linkage AB": self.L_AB,
            "turn arm CB": self.L_CB,
            "turn arm CD": self.L_CD,
            "lower_linking_board DE": self.L_DE,
            "sealing_rod EF": self.L_EF,
            "insulating_pole FG": self.L_FG,
            "crank arm HG": self.L_HG,
            "crank arm HI": self.L_HI,
            "upper_linking_board IJ": self.L_IJ,
        }


GEOMETRY = _Geometry()


def solve_points(x):
    """Joint points and body rotations for drive displacement(s) x (m along DRIVE_AXIS).

    Returns (points, rotations): points[name] has shape (..., 2); rotations has the
    rotation angle of the two cranks since t = 0: 'lower_turn_arm', 'main_crank_arm'.
    """
    g = GEOMETRY
    x = np.asarray(x, dtype=float)
    one = np.ones(x.shape + (1,))
    C = g.P0["C"] * one
    H = g.P0["H"] * one
    # stage 1: slider A -> turn arm (circle about C through B, circle about A)
    A = g.P0["A"] + x[..., None] * g.drive_axis
    B = _circle_circle(C, g.L_CB, A, g.L_AB, g.br1)
    phi3 = _wrap(_angle(B - C) - g.ang_CB0)
    # stage 2: turn arm -> slider E on its guide
    D = C + g.L_CD * np.stack([np.cos(g.ang_CD0 + phi3), np.sin(g.ang_CD0 + phi3)], axis=-1)
    E = _circle_line(D, g.L_DE, g.P0["E"] * one, g.seal_axis, g.br2)
    F = E + g.F_minus_E
    # stage 3: slider F -> main crank arm (circle about H through G, circle about F)
    G = _circle_circle(H, g.L_HG, F, g.L_FG, g.br3)
    phi7 = _wrap(_angle(G - H) - g.ang_HG0)
    # stage 4: crank arm -> slider J on its guide
    I = H + g.L_HI * np.stack([np.cos(g.ang_HI0 + phi7), np.sin(g.ang_HI0 + phi7)], axis=-1)
    J = _circle_line(I, g.L_IJ, g.P0["J"] * one, g.contact_axis, g.br4)
    pts = dict(A=A, B=B, C=C, D=D, E=E, F=F, G=G, H=H, I=I, J=J)
    return pts, {"lower_turn_arm": phi3, "main_crank_arm": phi7}


def _wrap(a):
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def _rot(v, phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def body_poses(x):
    """(x, y, theta) of every body's CoM for drive displacement(s) x; dict name -> (..., 3)."""
    g = GEOMETRY
    pts, rot = solve_points(x)
    P0 = g.P0

    def link(name, anchor, rotation):
        # CoM = current anchor point + rotated body-fixed offset
        com = pts[anchor] + _rot(g.com0[name] - P0[anchor], rotation)
        theta = g.angle0[name] + rotation
        return np.concatenate([com, theta[..., None]], axis=-1)

    def direction_rotation(p, q):
        return _wrap(_angle(pts[q] - pts[p]) - _angle(P0[q] - P0[p]))

    zero = np.zeros(np.shape(x))
    out = {
        "driving_link": link("driving_link", "A", zero),
        "lower_linkage": link("lower_linkage", "A", direction_rotation("A", "B")),
        "lower_turn_arm": link("lower_turn_arm", "C", rot["lower_turn_arm"]),
        "lower_linking_board": link("lower_linking_board", "D", direction_rotation("D", "E")),
        "sealing_rod": link("sealing_rod", "E", zero),
        "insulating_pole": link("insulating_pole", "F", direction_rotation("F", "G")),
        "main_crank_arm": link("main_crank_arm", "H", rot["main_crank_arm"]),
        "upper_linking_board": link("upper_linking_board", "I", direction_rotation("I", "J")),
        "moving_contact": link("moving_contact", "J", zero),
    }
    return out


_H_FD = 5.0e-4  # m, step in the drive coordinate for the kinematic coefficients
_FD1 = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / (12.0 * _H_FD)
_FD2 = np.array([-1.0, 16.0, -30.0, 16.0, -1.0]) / (12.0 * _H_FD**2)


def _coefficients(fun, x):
    """f(x), f'(x), f''(x) of an array-valued function of the drive coordinate."""
    x = np.asarray(x, dtype=float)
    offsets = np.arange(-2, 3) * _H_FD
    vals = [fun(x + o) for o in offsets]  # each (..., k)
    stack = np.stack(vals, axis=0)
    d1 = np.tensordot(_FD1, stack, axes=(0, 0))
    d2 = np.tensordot(_FD2, stack, axes=(0, 0))
    return vals[2], d1, d2


def _pose_vector(x):
    poses = body_poses(x)
    return np.concatenate([poses[n] for n in BODY_NAMES], axis=-1)


def solve_uhv_kinematics(times) -> dict:
    """Ideal (rigid) kinematics of the reconstructed UHV transmission at the given times (s).

    Returns a dict with, for N = len(times):
      '<body name>'                       (N, 3) x, y, theta of the CoM (global, m, rad)
      'moving_contact_displacement'       (N,) m, along the contact guide, + in the stroke direction
      'moving_contact_velocity'           (N,) m/s, same direction
      'moving_contact_acceleration'       (N,) m/s^2, same direction
      'sealing_rod_displacement'          (N,) m, along its guide, + in its stroke direction (down)
      'lower_turn_arm_angular_velocity'   (N,) rad/s, counter-clockwise positive (it turns
                                          clockwise here, so the values are <= 0)
    and, for convenience:
      'time' (N,), 'drive' (N, 3) x, xdot, xddot of the driving link along DRIVE_AXIS,
      'velocities' / 'accelerations': body name -> (N, 3) time derivatives of the poses,
      'points': joint name -> (N, 2), 'transmission_angles': name -> (N,) deg.
    The two angles theta are continuous (no wrapping) and equal the YAML body angles at t = 0.
    """
    t = np.atleast_1d(np.asarray(times, dtype=float))
    x, xd, xdd = drive_law(t)
    q, dq, ddq = _coefficients(_pose_vector, x)
    vel = dq * xd[:, None]
    acc = ddq * xd[:, None] ** 2 + dq * xdd[:, None]
    out: dict = {"time": t, "drive": np.stack([x, xd, xdd], axis=-1)}
    out["velocities"], out["accelerations"] = {}, {}
    for i, name in enumerate(BODY_NAMES):
        sl = slice(3 * i, 3 * i + 3)
        out[name] = q[:, sl]
        out["velocities"][name] = vel[:, sl]
        out["accelerations"][name] = acc[:, sl]
    u9 = np.array(CONTACT_STROKE_DIRECTION)
    u5 = np.array(SEALING_ROD_STROKE_DIRECTION)
    mc0 = np.array(BODIES["moving_contact"]["com"])
    sr0 = np.array(BODIES["sealing_rod"]["com"])
    out["moving_contact_displacement"] = (out["moving_contact"][:, :2] - mc0) @ u9
    out["moving_contact_velocity"] = out["velocities"]["moving_contact"][:, :2] @ u9
    out["moving_contact_acceleration"] = out["accelerations"]["moving_contact"][:, :2] @ u9
    out["sealing_rod_displacement"] = (out["sealing_rod"][:, :2] - sr0) @ u5
    out["lower_turn_arm_angular_velocity"] = out["velocities"]["lower_turn_arm"][:, 2]
    pts, _ = solve_points(x)
    out["points"] = pts
    out["transmission_angles"] = transmission_angles(pts)
    return out


def _angle_between(u, v):
    cosang = np.sum(u * v, axis=-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1))
    return np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))


def transmission_angles(pts) -> dict:
    """Transmission angles (deg) of every coupler, see TRANSMISSION_ANGLES."""
    g = GEOMETRY

    def normal(axis):
        return np.array([-axis[1], axis[0]])

    n_drive, n_seal, n_contact = normal(g.drive_axis), normal(g.seal_axis), normal(g.contact_axis)
    return {
        "A": _angle_between(pts["B"] - pts["A"], n_drive * np.ones_like(pts["A"])),
        "B": _angle_between(pts["A"] - pts["B"], pts["C"] - pts["B"]),
        "D": _angle_between(pts["E"] - pts["D"], pts["C"] - pts["D"]),
        "E": _angle_between(pts["D"] - pts["E"], n_seal * np.ones_like(pts["E"])),
        "F": _angle_between(pts["G"] - pts["F"], n_seal * np.ones_like(pts["F"])),
        "G": _angle_between(pts["F"] - pts["G"], pts["H"] - pts["G"]),
        "I": _angle_between(pts["J"] - pts["I"], pts["H"] - pts["I"]),
        "J": _angle_between(pts["I"] - pts["J"], n_contact * np.ones_like(pts["J"])),
    }
