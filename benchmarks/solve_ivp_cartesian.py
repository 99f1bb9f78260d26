"""The issue's baseline: the Flores slider-crank written by hand in Cartesian coordinates with solve_ivp.

This is the formulation of the clearance literature (Flores & Ambrósio, Computers & Structures 82, 2004;
Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, 1988), as a researcher writes it:

- q = (x1, y1, φ1, x2, y2, φ2, x3, y3, φ3), the centre of mass and angle of crank, rod and slider;
- seven constraints Φ(q, t) = 0: crank pivot at O (2), crank pin A (2), slider guide y3 = 0 and
  φ3 = 0 (2), the driver φ1 − ω t = 0 (1); the clearance joint rod–slider is not a constraint but a
  force element, so the two coordinates of the journal's eccentricity are free;
- the augmented equations [M Φqᵀ; Φq 0] [q̈; λ] = [Q; γ − 2α Φ̇ − β² Φ] with Baumgarte stabilisation,
  α = β = BAUMGARTE = 5 1/s (a usual choice; the constraint drift it leaves is reported as max |Φ|), solved by
  np.linalg.solve on the dense 16 × 16 matrix at every right-hand-side call;
- the contact force (Lankarani–Nikravesh, and Ambrósio friction in the friction case) from the
  eccentricity e = J − B of journal centre J (rod) and bearing centre B (slider);
- scipy solve_ivp (DOP853), with contact onset (δ rising through 0) and loss (δ falling through 0) as
  terminal events, restarted at each: the impact velocity δ̇⁻ of the Lankarani–Nikravesh damping is δ̇
  at the onset event (floored as clearsim floors it). The contact force acts wherever δ > 0, so a graze
  that starts and ends within one step is not lost; it uses the δ̇⁻ of the last onset.

The scalar force laws and the parameter set are those of tests/support/slider_crank_minimal.py (the
numbers of clearsim/configs/slider_crank_flores*.yaml, K as clearsim's `stiffness: auto`); everything
else (coordinates, constraints, equations, events) is written here. Masses and inertias the minimal
model does not need (the crank's, the slider's rotation) are the configs'.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from tests.support.slider_crank_minimal import (
    FRICTION,
    FRICTIONLESS,
    Parameters,
    friction_coefficient,
    ideal_initial_state,
    normal_force,
)

BAUMGARTE = 5.0  # α = β, 1/s
CRANK_MASS, CRANK_INERTIA = 0.30, 0.0001  # kg, kg m² (the configs; the crank's motion is prescribed)
SLIDER_INERTIA = 0.0001  # kg m² (the configs; φ3 = 0 is a constraint)
MAX_STEP = 1e-4  # s, the configs' solver.max_step, as clearsim runs them
OUTPUT_PERIOD = 1e-5  # s, clearsim's 100 kHz output grid
ATOL_PER_RTOL = 1e-4  # atol = 1e-4 rtol (m, rad; m/s, rad/s), as the minimal-coordinate baseline's
COORDINATES, CONSTRAINTS = 9, 7
METHOD = "DOP853"  # RK45 tried too: it needs a tighter rtol for clearsim's accuracy and is slower there (performance.md)


def mass_matrix(p: Parameters) -> np.ndarray:
    """M = diag(m1, m1, J1, m2, m2, J2, m3, m3, J3)."""
    return np.diag([CRANK_MASS, CRANK_MASS, CRANK_INERTIA, p.rod_mass, p.rod_mass, p.rod_inertia,
                    p.slider_mass, p.slider_mass, SLIDER_INERTIA])


def constraints(p: Parameters, t: float, q) -> np.ndarray:
    """Φ(q, t): crank pivot at O, crank pin A shared by crank and rod, slider guide, driver φ1 = ω t."""
    a, b = 0.5 * p.crank_length, 0.5 * p.rod_length
    x1, y1, f1, x2, y2, f2, _, y3, f3 = q
    return np.array([x1 - a * math.cos(f1), y1 - a * math.sin(f1),
                     x1 + a * math.cos(f1) - x2 + b * math.cos(f2), y1 + a * math.sin(f1) - y2 + b * math.sin(f2),
                     y3, f3, f1 - p.crank_speed * t])


def jacobian(p: Parameters, q) -> np.ndarray:
    """Φq, the 7 × 9 constraint Jacobian."""
    a, b = 0.5 * p.crank_length, 0.5 * p.rod_length
    s1, c1, s2, c2 = math.sin(q[2]), math.cos(q[2]), math.sin(q[5]), math.cos(q[5])
    out = np.zeros((CONSTRAINTS, COORDINATES))
    out[0, [0, 2]] = 1.0, a * s1
    out[1, [1, 2]] = 1.0, -a * c1
    out[2, [0, 2, 3, 5]] = 1.0, -a * s1, -1.0, -b * s2
    out[3, [1, 2, 4, 5]] = 1.0, a * c1, -1.0, b * c2
    out[4, 7] = out[5, 8] = out[6, 2] = 1.0
    return out


def gamma(p: Parameters, q, v) -> np.ndarray:
    """γ = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt, the right-hand side of Φq q̈ = γ."""
    a, b = 0.5 * p.crank_length, 0.5 * p.rod_length
    w1, w2 = v[2] ** 2, v[5] ** 2
    s1, c1, s2, c2 = math.sin(q[2]), math.cos(q[2]), math.sin(q[5]), math.cos(q[5])
    return np.array([-a * c1 * w1, -a * s1 * w1, a * c1 * w1 + b * c2 * w2, a * s1 * w1 + b * s2 * w2, 0.0, 0.0, 0.0])


def constraint_rate(p: Parameters, phi_q: np.ndarray, v) -> np.ndarray:
    """Φ̇ = Φq q̇ + Φt (Φt = −ω in the driver row)."""
    out = phi_q @ v
    out[6] -= p.crank_speed
    return out


@dataclass(frozen=True)
class Contact:
    """The clearance joint at one state: penetration δ, its rate δ̇, normal n, sliding velocity v_t."""
    penetration: float
    rate: float
    normal: tuple
    sliding: float


def contact_kinematics(p: Parameters, q, v) -> Contact:
    """e = J − B, δ = |e| − c, n = e/|e|, δ̇ = ė·n, v_t = ė·t + R_J φ̇2 − R_B φ̇3 with t = (−n_y, n_x)."""
    b = 0.5 * p.rod_length
    s2, c2 = math.sin(q[5]), math.cos(q[5])
    ex, ey = q[3] + b * c2 - q[6], q[4] + b * s2 - q[7]
    vx, vy = v[3] - b * s2 * v[5] - v[6], v[4] + b * c2 * v[5] - v[7]
    norm = math.hypot(ex, ey)
    nx, ny = (ex / norm, ey / norm) if norm > 0.0 else (1.0, 0.0)  # centred: any normal
    sliding = -vx * ny + vy * nx + p.journal_radius * v[5] - p.bearing_radius * v[8]
    return Contact(norm - p.clearance, vx * nx + vy * ny, (nx, ny), sliding)


def contact_forces(p: Parameters, contact: Contact, impact_speed: float) -> tuple[float, float]:
    """(F_n, F_t): Lankarani–Nikravesh F_n = K δⁿ (1 + 3(1 − c_e²)/4 δ̇/δ̇⁻), F_t = −μ(v_t) F_n (Ambrósio)."""
    fn = normal_force(p, contact.penetration, contact.rate, impact_speed)
    return fn, -friction_coefficient(p, contact.sliding) * fn


def generalised_forces(p: Parameters, q, v, impact_speed: float) -> np.ndarray:
    """Q of the contact force F = −F_n n + F_t t on the journal at J + R_J n and −F on the bearing at B + R_B n."""
    contact = contact_kinematics(p, q, v)
    out = np.zeros(COORDINATES)
    fn, ft = contact_forces(p, contact, impact_speed)
    if fn == 0.0:
        return out
    nx, ny = contact.normal
    fx, fy = -fn * nx - ft * ny, -fn * ny + ft * nx
    arm_x = 0.5 * p.rod_length * math.cos(q[5]) + p.journal_radius * nx  # (J + R_J n) − G2
    arm_y = 0.5 * p.rod_length * math.sin(q[5]) + p.journal_radius * ny
    out[3:6] = fx, fy, arm_x * fy - arm_y * fx
    out[6:9] = -fx, -fy, -p.bearing_radius * (nx * fy - ny * fx)  # arm (B + R_B n) − G3 = R_B n
    return out


def accelerations(p: Parameters, mass: np.ndarray, t: float, y, impact_speed: float) -> np.ndarray:
    """q̈ from [M Φqᵀ; Φq 0][q̈; λ] = [Q; γ − 2α Φ̇ − β² Φ] (Baumgarte), np.linalg.solve of the dense matrix."""
    q, v = y[:COORDINATES], y[COORDINATES:]
    phi_q = jacobian(p, q)
    matrix = np.zeros((COORDINATES + CONSTRAINTS, COORDINATES + CONSTRAINTS))
    matrix[:COORDINATES, :COORDINATES] = mass
    matrix[:COORDINATES, COORDINATES:] = phi_q.T
    matrix[COORDINATES:, :COORDINATES] = phi_q
    stabilised = (gamma(p, q, v) - 2.0 * BAUMGARTE * constraint_rate(p, phi_q, v)
                  - BAUMGARTE**2 * constraints(p, t, q))
    forces = generalised_forces(p, q, v, impact_speed)
    return np.linalg.solve(matrix, np.concatenate([forces, stabilised]))[:COORDINATES]


def initial_state(p: Parameters) -> np.ndarray:
    """(q, q̇) at t = 0: the ideal mechanism at outer dead centre, journal centred (minimal model's θ2, x3)."""
    theta2, x3, rate2, v3 = ideal_initial_state(p)
    a, b, w = 0.5 * p.crank_length, 0.5 * p.rod_length, p.crank_speed
    pin = (p.crank_length, 0.0)  # θ1 = 0
    q = [a, 0.0, 0.0, pin[0] + b * math.cos(theta2), pin[1] + b * math.sin(theta2), theta2, x3, 0.0, 0.0]
    v = [0.0, a * w, w, -b * math.sin(theta2) * rate2, p.crank_length * w + b * math.cos(theta2) * rate2, rate2,
         v3, 0.0, 0.0]
    return np.array(q + v)


@dataclass
class Segment:
    """One solve_ivp call between two contact switches, with the δ̇⁻ its contact force uses."""
    t0: float
    t1: float
    sol: object
    impact_speed: float
    steps: int


@dataclass
class CartesianResult:
    parameters: Parameters
    segments: list = field(repr=False)
    onsets: list  # (time, δ̇ at onset) of every contact episode
    rhs_evaluations: int

    @property
    def steps(self) -> int:
        return sum(s.steps for s in self.segments)

    def _segment(self, t: float) -> Segment:
        return next((s for s in self.segments if s.t0 <= t <= s.t1), self.segments[-1])

    def normal_force(self, t: float) -> float:
        """F_n at time t from the dense output."""
        segment = self._segment(t)
        return self._normal_forces(segment, [t])[0]

    def _normal_forces(self, segment: Segment, times) -> list:
        """F_n at `times` within one segment (its dense output called once for all of them)."""
        p = self.parameters
        return [contact_forces(p, contact_kinematics(p, y[:COORDINATES], y[COORDINATES:]), segment.impact_speed)[0]
                for y in segment.sol(np.asarray(times, dtype=float)).T]

    def slider_acceleration(self, t: float) -> float:
        """ẍ3 at time t (the augmented system solved at the dense-output state)."""
        segment = self._segment(t)
        p = self.parameters
        return accelerations(p, mass_matrix(p), t, segment.sol(t), segment.impact_speed)[6]

    def max_contact_force(self, t0: float = 0.0, t1: float = math.inf) -> tuple[float, float]:
        """(max F_n, its time) over [t0, t1]: 9 points in every step, then a bounded refinement around the best."""
        best, where, bracket = 0.0, math.nan, None
        for segment in self.segments:
            ts = segment.sol.ts
            grid = np.unique(np.concatenate([np.linspace(ts[k], ts[k + 1], 9) for k in range(len(ts) - 1)]))
            grid = grid[(grid >= max(t0, segment.t0)) & (grid <= min(t1, segment.t1))]
            for k, force in enumerate(self._normal_forces(segment, grid) if len(grid) else []):
                if force > best:
                    best, where, bracket = force, grid[k], (grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)])
        if bracket is not None and bracket[1] > bracket[0]:
            refined = minimize_scalar(lambda t: -self.normal_force(t), bounds=bracket, method="bounded",
                                      options={"xatol": 1e-15})
            if -refined.fun > best:
                best, where = -refined.fun, float(refined.x)
        return best, where

    def peak_slider_acceleration(self, t_end: float) -> float:
        """max |ẍ3| on clearsim's output grid."""
        times = np.arange(0.0, t_end + 0.5 * OUTPUT_PERIOD, OUTPUT_PERIOD)
        return float(max(abs(self.slider_acceleration(t)) for t in times))

    def output_history(self, t_end: float) -> tuple[np.ndarray, np.ndarray]:
        """(states, accelerations) on clearsim's output grid, as clearsim's run keeps them: each segment's dense
        output called once for its samples, the augmented system solved at each (a sample on a switch belongs to the
        segment that ends there and one past the last segment's end to the last segment, as in slider_acceleration)."""
        p = self.parameters
        mass = mass_matrix(p)
        times = np.arange(0.0, t_end + 0.5 * OUTPUT_PERIOD, OUTPUT_PERIOD)
        states = np.full((times.size, 2 * COORDINATES), np.nan)  # a grid point no segment holds stays NaN
        qdd = np.full((times.size, COORDINATES), np.nan)
        start = 0
        for number, segment in enumerate(self.segments):  # a grid point past the end belongs to the last one
            last = number == len(self.segments) - 1
            stop = times.size if last else int(np.searchsorted(times, segment.t1, side="right"))
            if stop > start:
                block = segment.sol(times[start:stop]).T
                states[start:stop] = block
                for k, y in enumerate(block):
                    qdd[start + k] = accelerations(p, mass, times[start + k], y, segment.impact_speed)
                start = stop
        return states, qdd

    def constraint_drift(self, t_end: float) -> float:
        """max |Φ| on the output grid (m or rad): what Baumgarte leaves of the constraint violation."""
        times = np.arange(0.0, t_end + 0.5 * OUTPUT_PERIOD, OUTPUT_PERIOD)
        return float(max(np.max(np.abs(constraints(self.parameters, t, self._segment(t).sol(t)[:COORDINATES])))
                         for t in times))


def simulate(p: Parameters, t_end: float, rtol: float, atol: float, max_segments: int = 10_000) -> CartesianResult:
    """DOP853 from switch to switch: onset (δ up through 0) stores δ̇⁻ and restarts, loss (δ down through 0) restarts."""
    mass = mass_matrix(p)
    y, t = initial_state(p), 0.0
    impact_speed, in_contact = p.min_impact_speed, False
    segments, onsets, evaluations = [], [], 0

    def penetration(tt, state):
        return contact_kinematics(p, state[:COORDINATES], state[COORDINATES:]).penetration

    penetration.terminal = True
    while t < t_end:
        if len(segments) >= max_segments:
            raise RuntimeError(f"more than {max_segments} contact switches before t = {t:.9e} s")
        penetration.direction = -1.0 if in_contact else 1.0

        def rhs(tt, state, speed=impact_speed):
            return np.concatenate([state[COORDINATES:], accelerations(p, mass, tt, state, speed)])

        with np.errstate(over="ignore", invalid="ignore"):  # a trial step deep through the wall, then rejected
            res = solve_ivp(rhs, (t, t_end), y, method=METHOD, rtol=rtol, atol=atol, max_step=MAX_STEP,
                            events=penetration, dense_output=True)
        if res.status < 0:
            raise RuntimeError(f"integration failed at t = {res.t[-1]:.9e} s: {res.message}")
        evaluations += res.nfev
        segments.append(Segment(t, res.t[-1], res.sol, impact_speed, len(res.t) - 1))
        t, y = res.t[-1], res.y[:, -1]
        if res.status != 1:
            break
        if not in_contact:
            rate = contact_kinematics(p, y[:COORDINATES], y[COORDINATES:]).rate
            onsets.append((t, rate))
            impact_speed = max(rate, p.min_impact_speed)
        in_contact = not in_contact
    return CartesianResult(p, segments, onsets, evaluations)


def first_impact(p: Parameters, t_end: float, rtol: float, atol: float) -> dict:
    """Onset time, δ̇⁻ and peak normal force of the first contact episode (the run stopped at t_end)."""
    result = simulate(p, t_end, rtol, atol)
    onset, speed = result.onsets[0]
    loss = next(segment.t1 for segment in result.segments if segment.t0 == onset)  # the segment the onset starts
    force, when = result.max_contact_force(onset, loss)
    return {"onset_s": onset, "impact_speed": speed, "peak_normal_force": force, "peak_time_s": when}


def run(friction: bool, t_end: float, rtol: float, atol: float, outputs: bool = False) -> dict:
    """One run: wall time (integration and max contact force, as the minimal baseline's), steps, the two figures.

    The peak slider acceleration on the output grid is taken after the clock stops, as in
    benchmarks/solve_ivp_slider_crank.py; clearsim's wall includes its output sampling and HDF5 file. With
    outputs=True the clock also covers the states and accelerations on the 100 kHz output grid (output_history):
    the same outputs clearsim's in-memory run keeps, for the equal-output comparison.
    """
    p = FRICTION if friction else FRICTIONLESS
    started = time.perf_counter()
    result = simulate(p, t_end, rtol, atol)
    force, _ = result.max_contact_force()
    if outputs:
        result.output_history(t_end)
    wall = time.perf_counter() - started
    return {"rtol": rtol, "wall_s": wall, "steps": result.steps, "rhs_evaluations": result.rhs_evaluations,
            "contact_events": len(result.onsets), "max_contact_force": force,
            "peak_acceleration": result.peak_slider_acceleration(t_end), "constraint_drift": result.constraint_drift(t_end)}


RTOL_LADDER = (1e-6, 3e-7, 1e-7, 5e-8, 3e-8, 1e-8, 3e-9, 1e-9)  # loosest first; atol = ATOL_PER_RTOL rtol
QUICK_RTOL = 1e-8
REFERENCE_RTOL = 1e-12  # the minimal model's: within 1.2e-12 of its rtol 1e-13 run on both figures (24 ms)
FIGURES = ("max_contact_force", "peak_acceleration")


def relative_errors(row: dict, reference: dict, prefix: str = "error_") -> dict:
    """|x − x_ref| / |x_ref| of the max contact force and the peak slider acceleration."""
    return {prefix + name: abs(row[name] - reference[name]) / abs(reference[name]) for name in FIGURES}


def common_reference(friction: bool, t_end: float) -> dict:
    """The independent reference of every tool: the minimal-coordinate model at REFERENCE_RTOL."""
    from benchmarks.solve_ivp_slider_crank import run as minimal_run

    return {name: minimal_run(friction, t_end, REFERENCE_RTOL)[name] for name in ("rtol", *FIGURES)}


def ladder_row(friction: bool, t_end: float, rtol: float, reference: dict) -> dict:
    """One rung: errors against the common reference and against its own run at rtol/100 (self-convergence)."""
    try:
        row = run(friction, t_end, rtol, ATOL_PER_RTOL * rtol)
        tight = run(friction, t_end, rtol / 100.0, ATOL_PER_RTOL * rtol / 100.0)
    except RuntimeError as exc:
        return {"rtol": rtol, "failed": str(exc)[:160]}
    return {**row, **relative_errors(row, reference), **relative_errors(row, tight, "self_error_")}


def matched_row(rows: list[dict], clearsim_errors: dict) -> dict | None:
    """The loosest rung whose errors against the common reference are ≤ clearsim's on both figures."""
    return next((r for r in rows if _as_accurate(r, clearsim_errors)), None)


def settled_row(rows: list[dict], clearsim_errors: dict) -> dict | None:
    """The loosest rung from which every tighter rung is as accurate as clearsim too (errors are not monotone in rtol)."""
    settled = None
    for row in reversed(rows):  # tightest first
        if not _as_accurate(row, clearsim_errors):
            break
        settled = row
    return settled


def _as_accurate(row: dict, clearsim_errors: dict) -> bool:
    return "failed" not in row and all(row["error_" + name] <= clearsim_errors["error_" + name] for name in FIGURES)


def timed_against_clearsim(friction: bool, clearsim_case, t_end: float, rtol: float, repeats: int, folder) -> dict:
    """Wall medians of the baseline at rtol and of clearsim's run of the case, alternated run by run, and their ratio."""
    from benchmarks.suite import _run, _run_in_memory

    mine, theirs, mine_equal, theirs_equal = [], [], [], []
    for k in range(repeats):  # alternated, so that a busy spell of the shared machine falls on both
        theirs.append(_run(clearsim_case.config, clearsim_case.overrides, folder, f"cartesian-clearsim-{k}")[0])
        mine.append(run(friction, t_end, rtol, ATOL_PER_RTOL * rtol)["wall_s"])
        # equal outputs: both keep the 100 kHz states and accelerations and the max contact force in memory
        theirs_equal.append(_run_in_memory(clearsim_case.config, clearsim_case.overrides)[0])
        mine_equal.append(run(friction, t_end, rtol, ATOL_PER_RTOL * rtol, outputs=True)["wall_s"])
    return {"wall_median_s": statistics.median(mine), "wall_min_s": min(mine), "wall_max_s": max(mine),
            "clearsim_wall_median_s": statistics.median(theirs), "clearsim_wall_min_s": min(theirs),
            "clearsim_wall_max_s": max(theirs), "ratio": statistics.median(mine) / statistics.median(theirs),
            "equal_outputs_wall_median_s": statistics.median(mine_equal),
            "clearsim_in_memory_wall_median_s": statistics.median(theirs_equal),
            "ratio_equal_outputs": statistics.median(mine_equal) / statistics.median(theirs_equal)}


def compare_case(friction: bool, clearsim, repeats: int, quick: bool, folder) -> dict:
    """The ladder, the matched (and settled) rtol timed against clearsim, alternated, and the wall ratios."""
    from benchmarks.suite import CASES, Case

    t_end = clearsim.simulated_time_s
    known = next(c for c in CASES if c.name == clearsim.case)
    clearsim_case = Case(known.name, known.config, known.overrides + (known.quick_overrides if quick else ()))
    reference = common_reference(friction, t_end)
    clearsim_errors = relative_errors({name: getattr(clearsim, name) for name in FIGURES}, reference)
    rows = [ladder_row(friction, t_end, rtol, reference) for rtol in ((QUICK_RTOL,) if quick else RTOL_LADDER)]
    matched, settled = matched_row(rows, clearsim_errors), settled_row(rows, clearsim_errors)
    out = {"case": clearsim.case, "t_end_s": t_end, "method": METHOD, "baumgarte": BAUMGARTE,
           "reference": reference, "rows": rows, "matched": matched, "settled": settled,
           "clearsim_reference_error_max_contact_force": clearsim_errors["error_max_contact_force"],
           "clearsim_reference_error_peak_acceleration": clearsim_errors["error_peak_acceleration"],
           "clearsim_error_max_contact_force": clearsim.error_max_contact_force,
           "clearsim_error_peak_acceleration": clearsim.error_peak_acceleration}
    if matched is None:
        return out
    out.update(timed_against_clearsim(friction, clearsim_case, t_end, matched["rtol"], repeats, folder))
    if settled is not None and settled["rtol"] != matched["rtol"]:
        out["settled"] = {**settled, **timed_against_clearsim(friction, clearsim_case, t_end, settled["rtol"], repeats, folder)}
    return out


def baseline(quick: bool, folder, measurements, repeats: int = 1) -> dict:
    """Study entry for the harness: both slider-crank cases against clearsim's measurement in the same run."""
    from benchmarks.suite import crank_study

    def compare(friction, clearsim, repeats, quick):
        return compare_case(friction, clearsim, repeats, quick, folder)

    return crank_study(compare, measurements, repeats, quick, folder)
