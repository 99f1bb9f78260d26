"""Reconstructed geometry of the UHV circuit-breaker transmission (Meng et al. 2015, Fig. 4).

Run from anywhere:  python3 docs/scripts/uhv_geometry.py

Prints the design (joint coordinates at t = 0, lengths, guides, bodies), the ideal
(rigid, no clearance) kinematics over the 85 ms stroke of the drive law (paper
eq. 16) — stroke, peak speed and peak acceleration of the moving contact,
transmission-angle ranges — and three independent checks:

1. the loop-closure solution satisfies the full set of 27 constraint equations
   (10 revolute, 3 prismatic, 1 driver) written in absolute coordinates, and the
   27 x 27 constraint Jacobian stays regular over the whole stroke (no singular
   position; 27 coordinates - 26 joint equations = 1 DOF);
2. the body centres of mass and angles are the middles/directions of the links;
3. clearsim/configs/uhv_breaker.yaml carries exactly these numbers.

and draws docs/figures/uhv_geometry.png.

The numbers live in tests/support/uhv_loop_closure.py (the reference the
multibody solver is tested against); this script does not import clearsim.
The rationale is in docs/uhv-geometry.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from tests.support import uhv_loop_closure as uhv  # noqa: E402

FIGURE = ROOT / "docs" / "figures" / "uhv_geometry.png"
YAML_FILE = ROOT / "clearsim" / "configs" / "uhv_breaker.yaml"
N_SAMPLES = 8501  # 10 us spacing over 85 ms
LIMITS = (35.0, 145.0)  # admissible transmission angles, deg


# ---------------------------------------------------------------------------
# report
# ---------------------------------------------------------------------------
def print_design():
    g = uhv.GEOMETRY
    print("Reconstructed UHV breaker transmission (the paper gives no lengths)")
    print("\nJoint coordinates at t = 0 (m), origin at the turn-arm pivot C:")
    print("| joint | bodies (bearing, journal) | x (m) | y (m) |")
    print("|---|---|---:|---:|")
    for name, (xx, yy) in uhv.POINTS0.items():
        b = uhv.REVOLUTE_JOINTS[name]
        print(f"| {name} | {b[0]} / {b[1]} | {xx:.3f} | {yy:.3f} |")
    print("\nLengths (mm):")
    for k, v in g.lengths().items():
        print(f"  {k:26s} {1e3 * v:8.1f}")
    print(f"  {'driving_link (piston rod)':26s} {1e3 * uhv.DRIVING_LINK_LENGTH:8.1f}")
    print(f"  {'moving_contact (tube)':26s} {1e3 * uhv.MOVING_CONTACT_LENGTH:8.1f}")
    bell3 = np.degrees(g.ang_CD0 - g.ang_CB0)
    bell7 = np.degrees((g.ang_HG0 - g.ang_HI0) % (2 * np.pi))
    print(f"  angle B-C-D of the turn arm       {bell3:7.2f} deg")
    print(f"  angle G-H-I of the main crank arm {bell7:7.2f} deg")
    print("\nGuides: driving link along", uhv.DRIVE_AXIS, "through A;",
          "sealing rod along", uhv.SEALING_ROD_AXIS, "through E;",
          "moving contact along", uhv.CONTACT_AXIS, "through J")


def report_kinematics(r):
    t = r["time"]
    s, v, a = (r["moving_contact_" + k] for k in ("displacement", "velocity", "acceleration"))
    x, xd, _ = r["drive"].T
    rot3 = r["lower_turn_arm"][:, 2] - r["lower_turn_arm"][0, 2]
    rot7 = r["main_crank_arm"][:, 2] - r["main_crank_arm"][0, 2]
    i_v, i_amax, i_amin = v.argmax(), a.argmax(), a.argmin()
    print("\nIdeal model over the stroke (0 <= t <= 85 ms):")
    print(f"  drive: stroke {x[-1]:.3f} m along {uhv.DRIVE_AXIS}, peak speed {np.abs(xd).max():.3f} m/s")
    print(f"  sealing rod stroke            {r['sealing_rod_displacement'][-1]:.4f} m (downwards)")
    print(f"  lower turn arm rotation       {np.degrees(rot3[-1]):.2f} deg, "
          f"peak |omega| {np.abs(r['lower_turn_arm_angular_velocity']).max():.2f} rad/s")
    print(f"  main crank arm rotation       {np.degrees(rot7[-1]):.2f} deg")
    print(f"  moving contact stroke         {s[-1]:.4f} m (upwards)")
    print(f"  moving contact peak speed     {v[i_v]:.3f} m/s at t = {1e3 * t[i_v]:.2f} ms")
    print(f"  moving contact acceleration   {a[0]:.1f} m/s^2 at t = 0+, "
          f"max {a[i_amax]:.1f} at {1e3 * t[i_amax]:.2f} ms, min {a[i_amin]:.1f} at {1e3 * t[i_amin]:.2f} ms")
    print(f"  peak |acceleration|           {np.abs(a).max():.1f} m/s^2")
    print(f"  overall ratio  stroke_contact/stroke_drive = {s[-1] / abs(x[-1]):.3f}, "
          f"peak speeds ratio {v.max() / np.abs(xd).max():.3f}")
    if np.any(np.diff(s) < 0):
        print("  WARNING: the moving contact does not move monotonically")
    print("\nTransmission angles (deg; 90 = ideal, 0/180 = dead centre; admissible 35..145):")
    margins = {}
    for name, desc in uhv.TRANSMISSION_ANGLES.items():
        ang = r["transmission_angles"][name]
        m = min(ang.min() - LIMITS[0], LIMITS[1] - ang.max())
        margins[name] = m
        out = " (output)" if name in uhv.OUTPUT_TRANSMISSION_ANGLES else ""
        print(f"  {name}: {ang.min():6.1f} .. {ang.max():6.1f}  margin {m:5.1f}   {desc}{out}")
    worst = min(margins, key=margins.get)
    worst_out = min(uhv.OUTPUT_TRANSMISSION_ANGLES, key=margins.get)
    print(f"  minimum margin: {margins[worst]:.1f} deg (at {worst}); "
          f"over the output angles {margins[worst_out]:.1f} deg (at {worst_out})")
    checks = {
        "stroke 0.25..0.32 m": 0.25 <= s[-1] <= 0.32,
        "peak speed 5.5..7.5 m/s": 5.5 <= v.max() <= 7.5,
        "transmission angles within 35..145 deg": margins[worst] > 0.0,
    }
    for k, ok in checks.items():
        print(f"  [{'ok' if ok else 'FAIL'}] {k}")
    return all(checks.values())


# ---------------------------------------------------------------------------
# check 1: full constraint equations in absolute coordinates
# ---------------------------------------------------------------------------
def _rotm(th):
    c, s = np.cos(th), np.sin(th)
    return np.array([[c, -s], [s, c]])


def constraint_system():
    """Phi(q, x_drive) for the 9 bodies with the body-fixed points taken from the t = 0 pose."""
    names = list(uhv.BODY_NAMES)
    idx = {n: i for i, n in enumerate(names)}
    r0 = {n: np.array(b["com"]) for n, b in uhv.BODIES.items()}
    th0 = {n: np.radians(b["angle_deg"]) for n, b in uhv.BODIES.items()}

    def local(body, point):
        p = np.array(uhv.POINTS0[point])
        if body == "ground":
            return p
        return _rotm(th0[body]).T @ (p - r0[body])

    rev = [(b1, local(b1, j), b2, local(b2, j)) for j, (b1, b2) in uhv.REVOLUTE_JOINTS.items()]
    pri = [(b, local(b, p), np.array(uhv.POINTS0[p]), np.array(ax)) for b, p, ax in uhv.PRISMATIC_JOINTS.values()]

    def glob(q, body, s):
        if body == "ground":
            return s
        i = idx[body]
        return q[3 * i:3 * i + 2] + _rotm(q[3 * i + 2]) @ s

    def phi(q, x_drive):
        out = []
        for b1, s1, b2, s2 in rev:
            out.extend(glob(q, b1, s1) - glob(q, b2, s2))
        for b, s, p0, ax in pri:
            n = np.array([-ax[1], ax[0]])
            out.append(n @ (glob(q, b, s) - p0))
            out.append(q[3 * idx[b] + 2] - th0[b])
        i = idx["driving_link"]
        out.append(np.array(uhv.DRIVE_AXIS) @ (q[3 * i:3 * i + 2] - r0["driving_link"]) - x_drive)
        return np.array(out)

    return phi, len(rev), len(pri)


def check_constraints(r):
    phi, n_rev, n_pri = constraint_system()
    nq = 3 * len(uhv.BODY_NAMES)
    n_eq = 2 * n_rev + 2 * n_pri
    print(f"\nCheck 1 - constraint equations: {nq} coordinates, {n_rev} revolute x 2 + {n_pri} prismatic x 2"
          f" = {n_eq} equations -> {nq - n_eq} DOF, + 1 driver -> {nq - n_eq - 1}")
    q_all = np.concatenate([r[n] for n in uhv.BODY_NAMES], axis=1)
    x = r["drive"][:, 0]
    worst_res, smin, kmax = 0.0, np.inf, 0.0
    h = 1e-7
    for k in range(0, len(x), 50):
        q = q_all[k]
        worst_res = max(worst_res, np.abs(phi(q, x[k])).max())
        jac = np.empty((nq, nq))
        for c in range(nq):
            dq = np.zeros(nq)
            dq[c] = h
            jac[:, c] = (phi(q + dq, x[k]) - phi(q - dq, x[k])) / (2 * h)
        sv = np.linalg.svd(jac, compute_uv=False)
        smin = min(smin, sv[-1])
        kmax = max(kmax, sv[0] / sv[-1])
    # velocities and accelerations: Phi along the quadratic path q + e qd + e^2/2 qdd must have
    # zero first and second derivatives in e (= dPhi/dt, d2Phi/dt2); 5-point differences, step 0.1 ms
    qd_all = np.concatenate([r["velocities"][n] for n in uhv.BODY_NAMES], axis=1)
    qdd_all = np.concatenate([r["accelerations"][n] for n in uhv.BODY_NAMES], axis=1)
    drv = r["drive"]
    worst_v = worst_a = 0.0
    e = 1e-4
    for k in range(0, len(x), 250):
        def path(s_, k=k):
            return phi(q_all[k] + s_ * qd_all[k] + 0.5 * s_**2 * qdd_all[k],
                       drv[k, 0] + s_ * drv[k, 1] + 0.5 * s_**2 * drv[k, 2])
        f = [path(m * e) for m in (-2, -1, 0, 1, 2)]
        d1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * e)
        d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * e**2)
        worst_v = max(worst_v, np.abs(d1).max() / np.abs(qd_all).max())
        worst_a = max(worst_a, np.abs(d2).max() / np.abs(qdd_all).max())
    print(f"  max |Phi| along the loop-closure solution: {worst_res:.2e} (m or rad)")
    print(f"  velocity / acceleration constraints: max |dPhi/dt| / max|qdot| = {worst_v:.1e}, "
          f"max |d2Phi/dt2| / max|qddot| = {worst_a:.1e} (finite-difference check, step 0.1 ms)")
    print(f"  27x27 Jacobian: smallest singular value over the stroke {smin:.3f}, "
          f"largest condition number {kmax:.1f} -> regular everywhere, no singular position")
    return worst_res < 1e-9 and smin > 1e-3 and worst_v < 1e-7 and worst_a < 1e-6


# ---------------------------------------------------------------------------
# check 2: centres of mass in the middle of the links, angles along the links
# ---------------------------------------------------------------------------
LINK_ENDS = {  # body -> (points whose centroid is the CoM, (from, to) of the angle) ; None = slider
    "lower_linkage": ("AB", "AB"),
    "lower_turn_arm": ("BCD", "CB"),
    "lower_linking_board": ("DE", "DE"),
    "sealing_rod": ("EF", None),
    "insulating_pole": ("FG", "FG"),
    "main_crank_arm": ("GI", "GI"),
    "upper_linking_board": ("IJ", "IJ"),
}


def check_bodies():
    P = {k: np.array(v) for k, v in uhv.POINTS0.items()}
    ok = True
    print("\nCheck 2 - bodies (CoM in the middle of each link, angle along the link):")
    for name, b in uhv.BODIES.items():
        com = np.array(b["com"])
        if name == "driving_link":
            mid = P["A"] - 0.5 * uhv.DRIVING_LINK_LENGTH * np.array(uhv.DRIVE_AXIS)
            ang = 0.0
        elif name == "moving_contact":
            mid = P["J"] + 0.5 * uhv.MOVING_CONTACT_LENGTH * np.array(uhv.CONTACT_AXIS)
            ang = 0.0
        else:
            pts, ends = LINK_ENDS[name]
            mid = np.mean([P[c] for c in pts], axis=0)
            if ends is None:
                ang = 0.0
            else:
                d = P[ends[1]] - P[ends[0]]
                ang = np.degrees(np.arctan2(d[1], d[0]))
        dev = np.linalg.norm(com - mid)
        dang = abs(ang - b["angle_deg"])
        good = dev <= 0.5e-3 + 1e-12 and dang <= 0.0005 + 1e-12
        ok &= good
        print(f"  {name:20s} m = {b['mass']:6.2f} kg  J = {b['inertia']:.3f} kg m^2  "
              f"CoM ({com[0]:7.4f}, {com[1]:7.4f}) m  |CoM - middle| = {1e3 * dev:.2f} mm  "
              f"angle {b['angle_deg']:8.3f} deg  {'ok' if good else 'MISMATCH'}")
    return ok


# ---------------------------------------------------------------------------
# check 3: the YAML file carries the same numbers
# ---------------------------------------------------------------------------
_UNITS = {"m": 1.0, "mm": 1e-3, "ms": 1e-3, "deg": 1.0, "kg": 1.0, "kg*m^2": 1.0}


def _val(text, unit):
    if isinstance(text, (int, float)):
        return float(text)
    num, _, u = str(text).strip().partition(" ")
    u = u.replace(" ", "")
    if u != unit:
        raise ValueError(f"expected unit {unit!r} in {text!r}")
    return float(num) * _UNITS[u]


def check_yaml():
    print(f"\nCheck 3 - {YAML_FILE.relative_to(ROOT)} against tests/support/uhv_loop_closure.py:")
    if not YAML_FILE.exists():
        print("  (file missing)")
        return False
    import yaml

    cfg = yaml.safe_load(YAML_FILE.read_text())
    problems = []
    pts = {k: tuple(_val(c, "m") for c in v) for k, v in cfg["points"].items()}
    for k, v in uhv.POINTS0.items():
        if k not in pts or max(abs(a - b) for a, b in zip(pts[k], v)) > 1e-12:
            problems.append(f"point {k}: yaml {pts.get(k)} vs {v}")
    bodies = {b["name"]: b for b in cfg["bodies"]}
    if list(bodies) != list(uhv.BODY_NAMES):
        problems.append(f"body names/order {list(bodies)}")
    for n, b in uhv.BODIES.items():
        yb = bodies.get(n)
        if yb is None:
            continue
        got = (_val(yb["mass"], "kg"), _val(yb["inertia"], "kg*m^2"),
               *(_val(c, "m") for c in yb["position"]), _val(yb["angle"], "deg"))
        want = (b["mass"], b["inertia"], *b["com"], b["angle_deg"])
        if max(abs(a - w) for a, w in zip(got, want)) > 1e-12:
            problems.append(f"body {n}: yaml {got} vs {want}")
    joints = {j["name"]: j for j in cfg["joints"]}
    for name, pair in uhv.REVOLUTE_JOINTS.items():
        j = joints.get(name, {})
        if j.get("type") != "revolute" or tuple(j.get("bodies", ())) != pair or j.get("at") != name:
            problems.append(f"joint {name}: {j}")
    for name, (body, point, axis) in uhv.PRISMATIC_JOINTS.items():
        j = joints.get(name, {})
        if (j.get("type") != "prismatic" or tuple(j.get("bodies", ())) != ("ground", body)
                or j.get("at") != point or tuple(float(a) for a in j.get("axis", ())) != axis):
            problems.append(f"joint {name}: {j}")
    if len(joints) != len(uhv.REVOLUTE_JOINTS) + len(uhv.PRISMATIC_JOINTS):
        problems.append(f"unexpected joints {sorted(joints)}")
    drv = cfg["drivers"][0]
    if (drv["joint"] != "driving_guide" or drv["motion"]["law"] != "stroke"
            or abs(_val(drv["motion"]["stroke"], "m") - uhv.DRIVE_STROKE) > 1e-12
            or abs(_val(drv["motion"]["duration"], "ms") - uhv.DRIVE_DURATION) > 1e-12):
        problems.append(f"driver {drv}")
    sens = {s["name"]: s for s in cfg["sensors"]}
    for sname, direction in (("contact_displacement", uhv.CONTACT_STROKE_DIRECTION),
                             ("contact_velocity", uhv.CONTACT_STROKE_DIRECTION),
                             ("contact_acceleration", uhv.CONTACT_STROKE_DIRECTION),
                             ("sealing_rod_displacement", uhv.SEALING_ROD_STROKE_DIRECTION)):
        d = tuple(float(c) for c in sens.get(sname, {}).get("direction", ()))
        if d != direction:
            problems.append(f"sensor {sname} direction {d} vs {direction}")
    for p in problems:
        print("  MISMATCH", p)
    if not problems:
        print("  points, bodies, joints, driver stroke and sensor directions agree")
    return not problems


def print_yaml_snippet():
    print("\nYAML snippet (points and bodies, as in clearsim/configs/uhv_breaker.yaml):")
    print("points:")
    for k, (xx, yy) in uhv.POINTS0.items():
        print(f"  {k}: [{xx:g} m, {yy:g} m]")
    print("bodies:")
    for n, b in uhv.BODIES.items():
        print(f"  - {{name: {n}, mass: {b['mass']:.4g} kg, inertia: {b['inertia']:.3f} kg*m^2, "
              f"position: [{b['com'][0]:g} m, {b['com'][1]:g} m], angle: {b['angle_deg']:g} deg}}")


# ---------------------------------------------------------------------------
# drawing
# ---------------------------------------------------------------------------
COLORS = {
    "driving_link": "#1f77b4",
    "lower_linkage": "#ff7f0e",
    "lower_turn_arm": "#2ca02c",
    "lower_linking_board": "#d62728",
    "sealing_rod": "#9467bd",
    "insulating_pole": "#8c564b",
    "main_crank_arm": "#e377c2",
    "upper_linking_board": "#17becf",
    "moving_contact": "#bcbd22",
}


def _ground(ax, p, size=0.035, color="k"):
    x, y = p
    ax.fill([x, x - size, x + size], [y, y - 1.4 * size, y - 1.4 * size], color="0.85",
            edgecolor=color, lw=1.0, zorder=2)
    for k in range(5):
        xx = x - size + k * size / 2
        ax.plot([xx, xx - 0.4 * size], [y - 1.4 * size, y - 1.9 * size], color=color, lw=0.8, zorder=2)


def _guide(ax, p, axis, length, offset=0.03):
    p, u = np.array(p), np.array(axis, float)
    n = np.array([-u[1], u[0]])
    for sgn in (-1, 1):
        a = p - 0.5 * length * u + sgn * offset * n
        b = p + 0.5 * length * u + sgn * offset * n
        ax.plot(*np.c_[a, b], color="0.45", lw=0.9, ls=(0, (6, 3)), zorder=1)


def draw(ax, r, k, faded=False, labels=True):
    """Mechanism at sample k of the kinematics result r."""
    P = {n: v[k] for n, v in r["points"].items()}
    alpha = 0.35 if faded else 1.0
    lw = 2.0 if faded else 3.0
    ls = "--" if faded else "-"

    def seg(name, *pts_, width=lw):
        xy = np.array([P[p] if isinstance(p, str) else p for p in pts_])
        ax.plot(xy[:, 0], xy[:, 1], color=COLORS[name], lw=width, ls=ls, alpha=alpha,
                solid_capstyle="round", zorder=3)

    u1 = np.array(uhv.DRIVE_AXIS)
    seg("driving_link", "A", P["A"] - uhv.DRIVING_LINK_LENGTH * u1, width=lw + 2)
    seg("lower_linkage", "A", "B")
    tri = np.array([P["B"], P["C"], P["D"]])
    ax.fill(tri[:, 0], tri[:, 1], color=COLORS["lower_turn_arm"], alpha=0.25 * alpha, zorder=2)
    seg("lower_turn_arm", "B", "C", "D")
    seg("lower_linking_board", "D", "E")
    seg("sealing_rod", "E", "F", width=lw + 2)
    seg("insulating_pole", "F", "G", width=lw + 3)
    seg("main_crank_arm", "G", "H", "I", width=lw + 1)
    seg("upper_linking_board", "I", "J")
    seg("moving_contact", "J", P["J"] + uhv.MOVING_CONTACT_LENGTH * np.array(uhv.CONTACT_AXIS), width=lw + 2)
    for name in "ABCDEFGHIJ":
        ax.plot(*P[name], "o", ms=5 if not faded else 4, mfc="white", mec="k" if not faded else "0.5",
                mew=1.2, alpha=alpha, zorder=5)
    if faded:
        return
    # CoM markers
    for n in uhv.BODY_NAMES:
        c = r[n][k, :2]
        ax.plot(*c, marker="+", color="k", ms=7, mew=1.0, zorder=6)
        ax.plot(*c, marker="o", mfc="none", mec="k", ms=5, mew=0.8, zorder=6)
    if labels:
        offs = {"A": (-0.035, 0.02), "B": (0.02, -0.025), "C": (-0.05, 0.0), "D": (0.025, -0.01),
                "E": (0.025, 0.0), "F": (0.025, 0.0), "G": (-0.05, 0.0), "H": (-0.01, 0.035),
                "I": (0.025, -0.015), "J": (0.025, 0.0)}
        for name, (dx, dy) in offs.items():
            ax.annotate(name, P[name], xytext=(P[name][0] + dx, P[name][1] + dy), fontsize=10,
                        fontweight="bold", zorder=7)


BODY_LABEL = {  # body -> offset (m) of its label from its centre of mass at t = 0
    "driving_link": (-0.05, -0.07),
    "lower_linkage": (0.06, -0.06),
    "lower_turn_arm": (-0.36, -0.12),
    "lower_linking_board": (0.10, -0.04),
    "sealing_rod": (0.10, 0.0),
    "insulating_pole": (0.05, 0.0),
    "main_crank_arm": (-0.12, -0.22),
    "upper_linking_board": (0.05, 0.02),
    "moving_contact": (0.05, -0.02),
}


def label_bodies(ax, r, which, fontsize=8):
    for n in which:
        c = r[n][0, :2]
        dx, dy = BODY_LABEL[n]
        ax.annotate(n.replace("_", " "), c, xytext=(c[0] + dx, c[1] + dy), fontsize=fontsize,
                    color=COLORS[n], fontweight="bold",
                    arrowprops=dict(arrowstyle="-", color=COLORS[n], lw=0.6), zorder=8)


def draw_static(ax):
    g = uhv.GEOMETRY
    _ground(ax, g.P0["C"])
    _ground(ax, g.P0["H"])
    _guide(ax, uhv.POINTS0["A"], uhv.DRIVE_AXIS, 0.9)
    _guide(ax, (uhv.POINTS0["E"][0], 0.35), uhv.SEALING_ROD_AXIS, 0.75)
    _guide(ax, (uhv.POINTS0["J"][0], 2.85), uhv.CONTACT_AXIS, 0.75)


def make_figure(r):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.gridspec import GridSpec
    from matplotlib.lines import Line2D

    t_ms = 1e3 * r["time"]
    last = len(t_ms) - 1
    fig = plt.figure(figsize=(16, 11.8))
    outer = GridSpec(2, 1, figure=fig, height_ratios=[6.4, 3.2], hspace=0.18)
    top = outer[0].subgridspec(1, 3, width_ratios=[0.6, 1.0, 1.0], wspace=0.2)
    bottom = outer[1].subgridspec(1, 4, wspace=0.32)
    ax_full = fig.add_subplot(top[0])
    ax_low = fig.add_subplot(top[1])
    ax_top = fig.add_subplot(top[2])
    ax_s, ax_v, ax_a, ax_ta = (fig.add_subplot(bottom[k]) for k in range(4))

    for ax in (ax_full, ax_low, ax_top):
        draw_static(ax)
        draw(ax, r, last, faded=True)
        draw(ax, r, 0, labels=ax is not ax_full)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.grid(alpha=0.3)
    ax_full.set_xlim(-0.6, 0.95)
    ax_full.set_ylim(-0.4, 3.35)
    ax_full.set_title("whole transmission")
    for name in "CFGJ":
        p = uhv.POINTS0[name]
        ax_full.annotate(name, p, xytext=(p[0] + 0.04, p[1]), fontsize=9, fontweight="bold")
    label_bodies(ax_full, r, ["insulating_pole"])
    ax_low.set_xlim(-0.58, 0.67)
    ax_low.set_ylim(-0.42, 0.83)
    ax_low.set_title("lower part: drive, lower turn arm, sealing rod")
    label_bodies(ax_low, r, ["driving_link", "lower_linkage", "lower_turn_arm", "lower_linking_board", "sealing_rod"])
    ax_top.set_xlim(-0.05, 1.2)
    ax_top.set_ylim(2.08, 3.33)
    ax_top.set_title("upper part: main crank arm, moving contact")
    label_bodies(ax_top, r, ["insulating_pole", "main_crank_arm", "upper_linking_board", "moving_contact"])
    legend = [Line2D([], [], color="k", lw=2.5, label="t = 0"),
              Line2D([], [], color="k", lw=1.8, ls="--", alpha=0.4, label="t = 85 ms (end of stroke)"),
              Line2D([], [], color="k", marker="+", ls="none", ms=7, label="centre of mass"),
              Line2D([], [], color="0.45", ls=(0, (6, 3)), label="prismatic guide")]
    ax_top.legend(handles=legend, loc="upper right", fontsize=9)

    ax_s.plot(t_ms, 1e3 * r["moving_contact_displacement"], label="moving contact")
    ax_s.plot(t_ms, 1e3 * r["sealing_rod_displacement"], label="sealing rod (down)")
    ax_s.plot(t_ms, -1e3 * r["drive"][:, 0], ls=":", color="k", label="driving link (-x)")
    ax_s.set_ylabel("displacement (mm)")
    ax_s.legend(fontsize=8)
    ax_v.plot(t_ms, r["moving_contact_velocity"], label="moving contact")
    ax_v.plot(t_ms, -r["drive"][:, 1], ls=":", color="k", label="driving link (-x)")
    ax_v.set_ylabel("velocity (m/s)")
    ax_v.legend(fontsize=8)
    ax_a.plot(t_ms, r["moving_contact_acceleration"], label="moving contact")
    ax_a.plot(t_ms, -r["drive"][:, 2], ls=":", color="k", label="driving link (-x)")
    ax_a.set_ylabel("acceleration (m/s²)")
    for ax in (ax_s, ax_v, ax_a):
        ax.set_xlabel("t (ms)")
    ax_a.legend(fontsize=8)
    for ax in (ax_s, ax_v, ax_a):
        ax.grid(alpha=0.3)
        ax.set_xlim(0, 85)
    ax_s.set_title("displacements (ideal joints)")
    ax_v.set_title("velocities")
    ax_a.set_title("accelerations")
    for name, ang in r["transmission_angles"].items():
        ax_ta.plot(t_ms, ang, label=name, lw=2.0 if name in uhv.OUTPUT_TRANSMISSION_ANGLES else 1.0,
                   ls="-" if name in uhv.OUTPUT_TRANSMISSION_ANGLES else "--")
    ax_ta.axhspan(0, LIMITS[0], color="r", alpha=0.08)
    ax_ta.axhspan(LIMITS[1], 180, color="r", alpha=0.08)
    ax_ta.axhline(90, color="k", lw=0.6)
    ax_ta.set_ylim(0, 180)
    ax_ta.set_xlim(0, 85)
    ax_ta.set_yticks([0, 35, 60, 90, 120, 145, 180])
    ax_ta.set_xlabel("t (ms)")
    ax_ta.set_ylabel("transmission angle (deg)")
    ax_ta.set_title("transmission angles (solid: output of a stage)")
    ax_ta.legend(ncol=4, fontsize=8, loc="lower center")
    ax_ta.grid(alpha=0.3)
    fig.suptitle(
        "UHV circuit-breaker transmission (Meng et al. 2015, Fig. 4) — reconstructed geometry, "
                 "ideal joints, drive law eq. (16)", fontsize=13, y=0.93)
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110, bbox_inches="tight")
    plt.close(fig)
    print(f"\nwrote {FIGURE.relative_to(ROOT)}")


def main():
    print_design()
    times = np.linspace(0.0, uhv.DRIVE_DURATION, N_SAMPLES)
    r = uhv.solve_uhv_kinematics(times)
    ok = report_kinematics(r)
    ok &= check_constraints(r)
    ok &= check_bodies()
    ok &= check_yaml()
    print_yaml_snippet()
    make_figure(r)
    print("\nall checks passed" if ok else "\nSOME CHECKS FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
