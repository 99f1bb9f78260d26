"""simulate(system) → time histories by name: the Python side of the compiled integration loop.

`Run.chunks()` yields blocks of output samples as the compiled loop produces them, so that
the caller can show progress, write them to disk and survive Ctrl-C; `simulate()` collects
them into one `History`. A solver failure stops the run with a `SolverError` naming the time
and the joint involved, after every sample up to that point has been yielded.
"""

from __future__ import annotations

import time as clock
from dataclasses import dataclass, field, fields
from typing import Callable, Iterator

import numpy as np
from numba import typeof

from clearsim.assembly.arrays import (
    CL_BEARING_RADIUS, CL_JOURNAL_RADIUS, CL_MU_D, CL_MU_S, CL_STIFFNESS, CL_VISCOSITY, for_kernels,
)
from clearsim.assembly.constraints import constraint_count, evaluate_constraints
from clearsim.assembly.drivelines import puffer_overrun
from clearsim.assembly.dynamics import WORK_COUNT, effective_mass, has_oil_films
from clearsim.assembly.forces import (
    FREE, bearing_view, clearance_kinematics, film_forces, nearest_point_kept, second_rim,
)
from clearsim.assembly.system import System
from clearsim.errors import SolverError
from clearsim.model.schema import SolverSettings
from clearsim.physics.wear import bore_curvature_radius, pocket_radius, pocket_words
from clearsim.solver import integrator as ig
from clearsim.solver import precompile
from clearsim.solver.outputs import hertz_durations, output_acceleration_point, output_rate
from clearsim.solver.samples import CONTACT_FIELDS, ENERGY_FIELDS, E_KINETIC, E_POTENTIAL, E_VIOLATION

SAMPLE_BUFFER = 2048
LOG_CAPACITY = 4096
CHUNKS = 100  # finest progress granularity: the loop returns to Python at least every 1 % of t_end...
PROGRESS_SECONDS = 0.05  # ...or, when that is quicker, about this often (progress bar, Ctrl-C, the file's flushes)
GROWTH = 4.0  # a chunk spans at most this many times the simulated time of the one before
# the pace (docs/model.md §4 "Progress"): judged every WATCH_STEPS tried steps, over those steps
WATCH_STEPS = 20_000
COLLAPSED = 1e-3  # a mean step below this fraction of the contact time t_c of a joint in contact: collapsed
# N/m^1.5: above any Hertz contact of steel journals (`stiffness: auto`: 6.6e10 for the slider-crank's 10 mm bearing
# with c = 0.5 mm, 1.5e13 for a 1 m one with c = 0.1 mm, 6.8e13 for 10 m with c = 0.5 mm)
REALISTIC_STIFFNESS = 1e15
HOPELESS_STEPS = 1e7  # tried steps still needed to reach t_end at the pace judged: a collapsed run stops, another warns
# an explicit method's stability boundary on the negative real axis, |h λ| (DOPRI5's 3.31; DOP853's 6.39, so that
# its steps may reach twice the bound): a film's squeeze damping b on the effective mass m, λ = −b/m, bounds the
# steps to ≈ EXPLICIT_BOUND · m/b
EXPLICIT_BOUND = 3.3
FILM_BOUND_FACTOR = 10.0  # steps within this factor below a film's bound are held by the film, not by the accuracy
# a journal nearer than this fraction of its penetration to the centre of curvature of its worn bore at the contact
# point: the bore conforms to it there, and its one contact point is ill-conditioned (curvature_lever)
CONFORMING = 0.1


@dataclass
class Chunk:
    """Output samples of one stretch of the run, with everything derived from them."""

    times: np.ndarray
    states: np.ndarray  # (S, 2n + WORK_COUNT + nz): q, q̇, integrated powers, force elements' states
    modes: np.ndarray  # (S, nc) FREE / CONTACT while the sample's step ran
    impact_speeds: np.ndarray  # (S, nc) δ̇⁻ of the current contact episode
    episodes: np.ndarray  # (S, nc) index into the episode log, −1 in free flight
    accelerations: np.ndarray  # (S, n)
    multipliers: np.ndarray  # (S, m)
    contact: np.ndarray  # (S, nc, CONTACT_FIELDS)
    kinetic: np.ndarray
    potential: np.ndarray
    violation: np.ndarray

    @staticmethod
    def joined(chunks: list["Chunk"]) -> "Chunk":
        """One chunk holding the samples of consecutive chunks, in order."""
        if len(chunks) == 1:
            return chunks[0]
        return Chunk(*(np.concatenate([getattr(c, f.name) for c in chunks]) for f in fields(Chunk)))


@dataclass
class Statistics:
    steps: int = 0
    rejected_steps: int = 0
    rhs_evaluations: int = 0
    contact_events: int = 0
    max_violation: float = 0.0
    wall_time: float = 0.0  # s in the compiled loop, without its first call (below)
    kernel_time: float = 0.0  # s of the loop's first call in this run: loading it, or on an empty cache compiling it
    kernels_compiled: bool = False  # numba compiled the loop, or a kernel it takes by address, for its first call
    peak_normal_force: np.ndarray = field(default_factory=lambda: np.zeros(0))
    peak_output_acceleration: float = 0.0  # |output.acceleration| at every step's end (0: no such sensor)
    tolerance_over_penetration: float = 0.0  # largest over the contact onsets (docs/model.md §4)
    penetration_rejections: int = 0  # tries the penetration guard alone rejected (docs/model.md §4)


@dataclass
class EpisodeLog:
    """One row per contact episode: joint index, onset and loss time, impact speed δ̇⁻, effective mass."""

    joint: np.ndarray
    onset: np.ndarray
    loss: np.ndarray
    impact_speed: np.ndarray
    effective_mass: np.ndarray


def error_controlled(system: System, y: np.ndarray) -> np.ndarray:
    """The components of a state (or its rate) that the step's error control weighs: q, q̇ and the element states z,
    not the integrated powers W between them (dopri.error_norm)."""
    n = system.coordinate_count
    return np.concatenate([y[:2 * n], y[2 * n + WORK_COUNT:]])


def _initial_step(system: System, y: np.ndarray, f: np.ndarray) -> float:
    """0.01 ‖y‖/‖ẏ‖ in the tolerance-weighted norm (Hairer, Nørsett & Wanner II.4), within the limits."""
    settings = system.mechanism.solver
    if settings.initial_step is not None:
        return settings.initial_step
    y, f = error_controlled(system, y), error_controlled(system, f)
    scale = settings.atol + settings.rtol * np.abs(y)
    d0 = np.sqrt(np.mean((y / scale) ** 2))
    d1 = np.sqrt(np.mean((f / scale) ** 2))
    guess = 0.01 * d0 / d1 if d0 > 1e-5 and d1 > 1e-5 else 1e-6
    return float(np.clip(guess, settings.min_step, settings.max_step))


def chunk_span(finest: float, last_span: float, simulated: float, wall: float) -> float:
    """Simulated time for the loop's next call: what it integrates in PROGRESS_SECONDS at the last call's pace,
    at least `finest` (1 % of t_end) and at most GROWTH × the last span (the pace drops when impacts begin).

    A return costs ~10 µs (the call's arguments, the samples' copies): returning every 1 % would be 1 ms of a 30 ms
    run; this way a run returns a handful of times."""
    if simulated <= 0.0 or wall <= 0.0:
        return finest
    return max(finest, min(GROWTH * last_span, simulated / wall * PROGRESS_SECONDS))


@dataclass(frozen=True)
class Pace:
    """How far a stretch of the run advanced the time, against the contact time of the joints in contact at its end."""

    time: float  # s, at the stretch's end
    steps: int  # tried (accepted and rejected)
    advanced: float  # s of simulated time
    remaining_time: float  # s to t_end
    joint: int  # the clearance joint in contact with the shortest contact time, −1 when none is in contact
    contact_time: float  # s, its Hertz contact time t_c at its impact speed and effective mass; inf when none

    @property
    def mean_step(self) -> float:
        return self.advanced / self.steps

    @property
    def remaining_steps(self) -> float:
        """Tried steps to reach t_end at this pace."""
        return self.remaining_time / self.mean_step if self.advanced > 0.0 else np.inf

    @property
    def collapsed(self) -> bool:
        """The steps are orders of magnitude below the contact time (an impact is resolved in tens of steps)."""
        return self.joint >= 0 and self.mean_step < COLLAPSED * self.contact_time

    @property
    def hopeless(self) -> bool:
        return self.collapsed and self.remaining_steps > HOPELESS_STEPS

    @property
    def slow(self) -> bool:
        return self.remaining_steps > HOPELESS_STEPS


def pace_of(system: System, steps: int, advanced: float, time: float, modes: np.ndarray, episode_of: np.ndarray,
            log: list[np.ndarray]) -> Pace:
    """The Pace of `steps` tried steps that advanced the time by `advanced`, ending at `time` with these contact
    modes and episodes (the joints' contact times from their episodes' impact speeds and effective masses)."""
    in_contact = np.flatnonzero((modes != FREE) & (episode_of >= 0))
    remaining = float(system.mechanism.solver.t_end) - time
    if len(in_contact) == 0:
        return Pace(time, steps, advanced, remaining, -1, np.inf)
    episodes = episode_of[in_contact]
    times = hertz_durations(system, in_contact, log[3][episodes], log[4][episodes])
    shortest = int(np.argmin(times))
    return Pace(time, steps, advanced, remaining, int(in_contact[shortest]), float(times[shortest]))


def mechanism_extent(system: System) -> float:
    """m: the largest span, along x or y, of the bodies' origins at t = 0 (the mechanism's size)."""
    positions = system.q0.reshape(-1, 3)[:, :2]
    return float(np.max(np.ptp(positions, axis=0))) if len(positions) > 1 else 0.0


def positions_and_rates(system: System, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Copies of q and q̇ of the integrator's state y, contiguous, as the kernels take them."""
    n = system.coordinate_count
    return y[:n].copy(), y[n:2 * n].copy()


def touching_two_rims(system: System, kernel_arrays, y: np.ndarray) -> set[int]:
    """The clearance joints whose journal touches two rims of its worn bore at the state y (forces.second_rim)."""
    q, qd = positions_and_rates(system, y)
    touching = set()
    for k in np.flatnonzero(system.arrays.wear_harmonics > 0):
        ex, ey, dex, dey = clearance_kinematics(kernel_arrays, int(k), q, qd)[:4]
        if second_rim(kernel_arrays, int(k), q, qd, ex, ey, dex, dey)[0] > 0.0:
            touching.add(int(k))
    return touching


def worn_pockets(system: System, touching: set[int] | None = None) -> list[str]:
    """In words (a list of one, or none): the clearance joints whose worn bore has a pocket tighter than the journal,
    of them only those in `touching` when it is given (touching_two_rims: the run's state). A journal pressed into it
    touches its two rims; a friction law with exact sticking treats the nearer alone exactly, so a journal landing
    within round-off of the pocket's axis, where the nearer rim changes with every rounding, chatters between them
    (docs/model-contact.md, "A pocket tighter than the journal"). A run that crawls or stops with no journal on two
    rims does not do so for the pocket, whose journal may still rest in it on one rim."""
    arrays = system.arrays
    pockets = []
    for k, name in enumerate(system.clearance_joints):
        if touching is not None and k not in touching:
            continue
        harmonics = int(arrays.wear_harmonics[k])
        params = arrays.clearance_params[k]
        tightest = pocket_radius(arrays.wear_profile[k, :2 * harmonics + 1], params[CL_BEARING_RADIUS],
                                 params[CL_JOURNAL_RADIUS])
        if tightest is not None:
            pockets.append(f"joint {name} ({pocket_words(tightest, params[CL_JOURNAL_RADIUS])})")
    if not pockets:
        return []
    return [f"a worn bore with a pocket tighter than its journal at {', '.join(pockets)}: the journal touches the "
            "pocket's two rims, and a friction law with exact sticking treats the nearer one alone exactly, so a "
            "journal landing on the pocket's axis, both rims equally near, chatters between them; give "
            "`wear.profile` no pocket narrower than the journal (R_B + h + h'' >= R_J everywhere: fewer or smaller "
            "high harmonics), or the friction `stick: smooth`"]


def curvature_lever(system: System, kernel_arrays, k: int, q: np.ndarray,
                    qd: np.ndarray) -> tuple[float, float]:
    """(ℓ, δ) in m of worn-bore joint k: ℓ = ρ_c − d, the distance from the journal's centre to the bore's centre of
    curvature at the contact point (a shift s of the journal along the wall turns the contact normal by ≈ s/ℓ), with
    ρ_c the bore's radius of curvature there (wear.bore_curvature_radius) and d = |r − e| its distance from the
    journal's centre; δ its penetration."""
    ex, ey, _, _, penetration = clearance_kinematics(kernel_arrays, k, q, qd)[:5]
    local_x, local_y = bearing_view(kernel_arrays, k, q, qd, ex, ey)[3:]
    rx, ry = nearest_point_kept(kernel_arrays, k, local_x, local_y)[:2]
    arrays = system.arrays
    radius = bore_curvature_radius(arrays.wear_profile[k], arrays.wear_harmonics[k],
                                   arrays.clearance_params[k, CL_BEARING_RADIUS], np.arctan2(ry, rx))
    return radius - np.hypot(rx - local_x, ry - local_y), penetration


def conforming_bores(system: System, kernel_arrays, y: np.ndarray, modes: np.ndarray) -> list[str]:
    """In words (a list of one, or none): the worn-bore joints in contact whose journal lies nearer than CONFORMING
    times its penetration to the bore's centre of curvature at the contact point (curvature_lever): a groove worn to
    the loaded journal's shape, where the one contact point of the model is ill-conditioned (docs/model-contact.md,
    "What the nearest-point contact leaves out")."""
    q, qd = positions_and_rates(system, y)
    found = []
    for k in np.flatnonzero((system.arrays.wear_harmonics > 0) & (modes != FREE)):
        lever, penetration = curvature_lever(system, kernel_arrays, int(k), q, qd)
        if 0.0 < penetration and lever < CONFORMING * penetration:
            found.append(f"joint {system.clearance_joints[k]} ({lever * 1e9:.3g} nm from it, "
                         f"{penetration * 1e6:.3g} µm deep)")
    if not found:
        return []
    return [f"a worn bore conforming to its journal at {', '.join(found)}: the journal rests near the centre of "
            "curvature of the bore at its contact point, where the model's one contact point is ill-conditioned (a "
            "shift s along the wall turns the contact normal by s/ℓ, ℓ that distance); a groove worn to the loaded "
            "journal's shape does this: a wear band wider than the journal's imprint (`archard.width` left to its "
            "default) or fewer harmonics keep it from forming"]


def squeeze_damping(system: System, kernel_arrays, k: int, q: np.ndarray, qd: np.ndarray,
                    speed: float = 1e-6) -> float:
    """N·s/m: b = ∂F_n/∂v_n of joint k's oil film at (q, q̇), its force along n against the journal's velocity along
    the line of centres n (central difference of film_forces at ± `speed`; the film force is linear in the squeeze
    rate ε̇ within a pressure region, docs/model-contact.md)."""
    ex, ey = clearance_kinematics(kernel_arrays, k, q, qd)[:2]
    eccentricity = np.hypot(ex, ey)
    nx, ny = (ex / eccentricity, ey / eccentricity) if eccentricity > 0.0 else (1.0, 0.0)
    journal = 3 * int(system.arrays.clearance_bodies[k, 1])
    forces = []
    for sign in (1.0, -1.0):
        pushed = qd.copy()
        pushed[journal] += sign * speed * nx
        pushed[journal + 1] += sign * speed * ny
        forces.append(film_forces(kernel_arrays, k, q, pushed)[0])
    return abs(forces[0] - forces[1]) / (2.0 * speed)


def stiff_films(system: System, kernel_arrays, y: np.ndarray, modes: np.ndarray, mean_step: float) -> list[str]:
    """In words (a list of one, or none): the oil films carrying a journal whose squeeze damping b, on the joint's
    effective mass m, bounds an explicit method's steps to ≈ 3.3 m/b, no more than tenfold above the steps taken, so
    that the film, not the accuracy, sets them; `solver.method: rosenbrock` takes steps the accuracy sets
    (docs/model.md §4)."""
    if system.mechanism.solver.method == "rosenbrock":
        return []
    q, qd = positions_and_rates(system, y)
    films = []
    for k in np.flatnonzero((modes == FREE) & (system.arrays.clearance_params[:, CL_VISCOSITY] > 0.0)):
        damping = squeeze_damping(system, kernel_arrays, int(k), q, qd)
        mass = effective_mass(kernel_arrays, int(k), q, modes)
        bound = EXPLICIT_BOUND * mass / damping if damping > 0.0 else np.inf
        if mean_step * FILM_BOUND_FACTOR >= bound:  # near the bound: an explicit run's steps cannot be far above it
            films.append(f"joint {system.clearance_joints[k]} (b = {damping:.3g} N·s/m on m = {mass:.3g} kg: "
                         f"{bound:.2g} s)")
    if not films:
        return []
    return [f"the oil film at {', '.join(films)}: a film's squeeze damping b on the joint's effective mass m bounds "
            f"an explicit method's steps to ≈ {EXPLICIT_BOUND} m/b, and the steps ({mean_step:.2g} s) are held there, "
            "not by the accuracy: set `solver: {method: rosenbrock}`, whose steps the accuracy sets "
            "(docs/performance.md, \"Stiff models\")"]


def likely_causes(system: System, pace: Pace, touching: set[int] | None = None) -> list[str]:
    """What in the model makes the steps this short, as far as its parameters tell: a worn pocket first (it makes
    any contact in it crawl; only one a journal touches at two rims when `touching` is given, worn_pockets), then the
    joint's or the model's parameters."""
    settings = system.mechanism.solver
    causes = worn_pockets(system, touching)
    if pace.joint >= 0:
        params = system.arrays.clearance_params[pace.joint]
        radius, extent = params[CL_BEARING_RADIUS], mechanism_extent(system)
        if radius > extent > 0.0:
            causes.append(f"its bearing radius is {radius:.4g} m, more than the whole mechanism measures "
                          f"({extent:.3g} m): a radius in the wrong unit (m for mm?); its friction acts with that "
                          "lever arm")
        if params[CL_STIFFNESS] > REALISTIC_STIFFNESS:
            causes.append(f"its contact stiffness {params[CL_STIFFNESS]:.3g} N/m^1.5 is above any Hertz contact of "
                          f"steel ({REALISTIC_STIFFNESS:.0e} N/m^1.5): check `stiffness` and its unit, or use "
                          "`stiffness: auto`")
        if max(params[CL_MU_S], params[CL_MU_D]) > 0.0:
            causes.append("friction whose force changes far faster than the contact (a large normal force or radius "
                          "against the friction law's small transition speeds): check the friction parameters and "
                          "their units, or try `friction: {stick: smooth}`")
    else:
        causes.append("no clearance joint is in contact, so it is not a contact: a spring, damper, mass or force off "
                      "by orders of magnitude (a unit), or a drive whose motion jumps")
    default_min_step = SolverSettings.model_fields["min_step"].default
    if settings.min_step < default_min_step:
        causes.append(f"solver.min_step = {settings.min_step:.3g} s lets the steps fall below the default "
                      f"{default_min_step:g} s, where the run would have stopped")
    return causes


class Run:
    """The integrator's state arrays for one simulation of a System; warn(text) is told a warning of the run as soon
    as it is seen (judge_pace)."""

    def __init__(self, system: System, warn: Callable[[str], None] | None = None):
        self.system = system
        self.warn = warn
        settings = system.mechanism.solver
        arrays = system.arrays
        self.kernel_arrays = for_kernels(arrays)
        self.lubricated = has_oil_films(arrays)  # which dynamics the loop takes (integrator.addressed)
        nc = len(system.clearance_joints)
        n = system.coordinate_count
        self.y = np.concatenate([system.q0, system.qd0, np.zeros(WORK_COUNT), system.z0])
        self.f = np.zeros_like(self.y)
        self.modes = np.zeros(nc, np.int64)
        self.speeds = np.zeros(nc)
        self.episode_of = np.full(nc, -1, np.int64)
        self.log = [np.zeros(LOG_CAPACITY, np.int64)] + [np.zeros(LOG_CAPACITY) for _ in range(4)]
        self.peak_force = np.zeros(nc)
        self.real = np.zeros(ig.REAL_SLOTS)
        self.ints = np.zeros(ig.INT_SLOTS, np.int64)
        self.ints[ig.I_METHOD] = ig.METHODS[settings.method]
        self.ints[ig.I_JACOBIAN_AGE] = -1
        # rosenbrock: ∂f/∂y and ∂f/∂t (last column), and the contact modes it was taken in
        size = self.y.size if settings.method == "rosenbrock" else 0
        self.jacobian = np.zeros((size, size + 1))
        # and the Jacobians taken since a full one, and the rhs evaluations of the last (rosenbrock.evaluate_jacobian)
        self.jacobian_modes = np.zeros(nc + 2, np.int64)
        dt = 1.0 / output_rate(system)
        self.real[[ig.R_T_END, ig.R_RTOL, ig.R_ATOL, ig.R_MAX_STEP, ig.R_MIN_STEP, ig.R_SAMPLE_DT]] = (
            settings.t_end, settings.rtol, settings.atol, settings.max_step, settings.min_step, dt)
        self.ints[ig.I_TOTAL_SAMPLES] = int(np.floor(settings.t_end / dt + 1e-9)) + 1
        self.real[[ig.R_OUTPUT_BODY, ig.R_OUTPUT_POINT_X, ig.R_OUTPUT_POINT_Y, ig.R_OUTPUT_DIRECTION_X,
                   ig.R_OUTPUT_DIRECTION_Y]] = output_acceleration_point(system)
        self.buffers = (np.zeros(SAMPLE_BUFFER), np.zeros((SAMPLE_BUFFER, self.y.size)),
                        np.zeros((SAMPLE_BUFFER, nc), np.int64), np.zeros((SAMPLE_BUFFER, nc)),
                        np.zeros((SAMPLE_BUFFER, nc), np.int64), np.zeros((SAMPLE_BUFFER, n)),
                        np.zeros((SAMPLE_BUFFER, constraint_count(self.kernel_arrays))),
                        np.zeros((SAMPLE_BUFFER, nc, CONTACT_FIELDS)), np.zeros((SAMPLE_BUFFER, ENERGY_FIELDS)))
        # no first step yet: the loop's first call returns FIRST_STEP with ẏ(0) in f and _initial_step chooses it
        # here (numpy's sums, as always: the step, and so every result, stays bitwise the same); calling the
        # compiled rhs from Python instead would load a second copy of the dynamics (docs/performance.md)
        self.wall_time = 0.0
        self.kernel_time = 0.0
        # the loop and the kernels it takes by address for this method and model (integrator.addressed: the
        # Rosenbrock or DOP853 step, the oil films' dynamics): whether numba compiled any of them for the loop's first call
        # (rather than loading it from the cache, or finding it in memory) is known once that call has returned
        self.compiled_kernels = (ig.advance, *ig.addressed(int(self.ints[ig.I_METHOD]), self.lubricated))
        self.compilations_before = precompile.compilations(self.compiled_kernels)
        self.kernels_compiled = False
        self.coordinate_count = n
        self.watched = (0, 0.0)  # tried steps and time where the stretch being watched began (judge_pace)
        self.pace_warnings: list[str] = []
        self.pace_warned: set[str] = set()  # the kinds of pace warned about: "slow", "collapsed"

    @property
    def time(self) -> float:
        return float(self.real[ig.R_TIME])

    def statistics(self) -> Statistics:
        return Statistics(
            steps=int(self.ints[ig.I_STEPS]), rejected_steps=int(self.ints[ig.I_REJECTED]),
            rhs_evaluations=int(self.ints[ig.I_RHS]), contact_events=int(self.ints[ig.I_EVENTS]),
            penetration_rejections=int(self.ints[ig.I_PENETRATION_REJECTED]),
            max_violation=float(self.real[ig.R_VIOLATION]), wall_time=self.wall_time, kernel_time=self.kernel_time,
            kernels_compiled=self.kernels_compiled,
            peak_normal_force=self.peak_force.copy(), tolerance_over_penetration=float(self.real[ig.R_COARSE_RATIO]),
            peak_output_acceleration=float(self.real[ig.R_PEAK_ACCELERATION]),
        )

    def warnings(self) -> list[str]:
        """What the run did but could not vouch for, in words (empty when nothing)."""
        return self._coarse_warnings() + self.pace_warnings

    def _coarse_warnings(self) -> list[str]:
        coarse = int(self.ints[ig.I_COARSE])
        if coarse == 0:
            return []
        settings = self.system.mechanism.solver
        joint = self.system.clearance_joints[int(self.ints[ig.I_COARSE_JOINT])]
        return [f"{coarse} contact onset(s) not resolved by the solver tolerance (first: joint {joint} at "
                f"t = {self.real[ig.R_COARSE_TIME] * 1e3:.4g} ms; the position tolerance, atol + rtol·|position| with "
                f"rtol = {settings.rtol:g}, atol = {settings.atol:g} m, is up to {self.real[ig.R_COARSE_RATIO]:.3g}× the "
                f"impact's Hertz penetration, more than {ig.UNRESOLVED_RATIO:g}×): the contact forces of these impacts are "
                "not reliable; "
                "tighten solver.rtol / solver.atol (the defaults are 1e-7 and 1e-10 m)"]

    def episode_log(self) -> EpisodeLog:
        count = int(self.ints[ig.I_LOG])
        joint, onset, loss, speed, mass = (a[:count].copy() for a in self.log)
        return EpisodeLog(joint, onset, loss, speed, mass)

    def _grow_log(self) -> None:
        self.log = [np.concatenate([a, np.zeros_like(a)]) for a in self.log]

    def _advance(self, t_stop: float) -> None:
        started = clock.perf_counter()
        method = int(self.ints[ig.I_METHOD])
        state = (self.y, self.f, self.real, self.ints, self.modes, self.speeds, self.episode_of, *self.log,
                 self.peak_force, self.jacobian, self.jacobian_modes, *self.buffers, t_stop)
        loop = ig.compiled_loop(typeof(self.kernel_arrays), method, self.lubricated, state)
        precompile.compile_addressed(self.kernel_arrays, method, self.lubricated)  # once per process, before a first call
        loop(*ig.loop_arguments(self.kernel_arrays, method, self.lubricated, *state))
        if self.ints[ig.I_STATUS] == ig.FIRST_STEP:  # the first call: loads (or compiles) the loop, one rhs
            self.kernel_time += clock.perf_counter() - started
            self.kernels_compiled = precompile.compilations(self.compiled_kernels) > self.compilations_before
            precompile.reap_helper()
        else:
            self.wall_time += clock.perf_counter() - started

    def _take_samples(self) -> Chunk | None:
        count = int(self.ints[ig.I_SAMPLES])
        if count == 0:
            return None
        times, states, modes, speeds, episodes, qdd, lam, contact, energies = (b[:count].copy() for b in self.buffers)
        self.ints[ig.I_SAMPLES] = 0
        return Chunk(times, states, modes, speeds, episodes, qdd, lam, contact,
                     energies[:, E_KINETIC], energies[:, E_POTENTIAL], energies[:, E_VIOLATION])

    def chunks(self, progress: Callable[[float], None] | None = None) -> Iterator[Chunk]:
        """Integrate to t_end, yielding samples as they come; SolverError on failure (after the samples).

        progress(t) is called at every return of the compiled loop, with or without samples: a run with a tiny
        max_step and a low output rate comes back every STEPS_PER_CALL steps without a sample, and its progress
        bar must still move. Where the loop stops does not change the result: it pauses between steps.
        The pace is judged there too (judge_pace): a collapsed run stops with a SolverError, a slow one warns."""
        t_end = self.real[ig.R_T_END]
        span = t_end / CHUNKS
        next_stop = span
        while True:
            started_at, wall_before = self.time, self.wall_time
            self._advance(next_stop)
            status = int(self.ints[ig.I_STATUS])
            if status == ig.FIRST_STEP:
                self.real[ig.R_STEP] = _initial_step(self.system, self.y, self.f)
                continue
            if status == ig.BUFFER_FULL and self.ints[ig.I_LOG] >= self.log[0].size - len(self.modes) - 1:
                self._grow_log()
            chunk = self._take_samples()
            if chunk is not None:
                yield chunk
            if progress is not None:
                progress(self.time)
            if status == ig.DONE:
                return
            if status not in (ig.CHUNK_END, ig.BUFFER_FULL, ig.PAUSED):
                raise self._failure(status)
            self.judge_pace()
            if status == ig.CHUNK_END:
                span = chunk_span(t_end / CHUNKS, span, self.time - started_at, self.wall_time - wall_before)
                next_stop = min(t_end, next_stop + span)

    def judge_pace(self) -> Pace | None:
        """Every WATCH_STEPS tried steps, the Pace of those steps: hopeless → SolverError; collapsed or slow → a
        warning, once each (kept in `warnings()` and told to `warn`). None between judgements."""
        steps = int(self.ints[ig.I_STEPS] + self.ints[ig.I_REJECTED])
        started_steps, started_time = self.watched
        if steps - started_steps < WATCH_STEPS:
            return None
        self.watched = (steps, self.time)
        pace = pace_of(self.system, steps - started_steps, self.time - started_time, self.time, self.modes,
                       self.episode_of, self.log)
        if pace.hopeless:
            raise self._collapse(pace)
        kind = "collapsed" if pace.collapsed else "slow" if pace.slow else None
        if kind is not None and kind not in self.pace_warned:  # once each: a slow run may collapse later
            self.pace_warned.add(kind)
            self.pace_warnings.append(self._pace_warning(pace))
            if self.warn is not None:
                self.warn(self.pace_warnings[-1])
        return pace

    def _pace_text(self, pace: Pace) -> str:
        """The pace in words: the steps, how far they went, what is left at that pace."""
        scale = (f", {pace.mean_step / pace.contact_time:.1g} of the contact time t_c = {pace.contact_time:.3g} s of "
                 f"joint {self.system.clearance_joints[pace.joint]}" if pace.joint >= 0 else "")
        return (f"the last {pace.steps} steps advanced the time by {pace.advanced:.3g} s, {pace.mean_step:.2g} s a "
                f"step{scale}; at this pace the remaining {pace.remaining_time * 1e3:.4g} ms take "
                f"{pace.remaining_steps:.2g} steps")

    def _causes(self, pace: Pace) -> list[str]:
        """Why the steps are this short: an oil film that holds an explicit method's steps (stiff_films, for a slow
        run too), then, for a collapsed one, the model's likely causes (likely_causes)."""
        films = stiff_films(self.system, self.kernel_arrays, self.y, self.modes, pace.mean_step)
        if not pace.collapsed:
            return films
        return (films + conforming_bores(self.system, self.kernel_arrays, self.y, self.modes)
                + likely_causes(self.system, pace, touching_two_rims(self.system, self.kernel_arrays, self.y)))

    def _pace_warning(self, pace: Pace) -> str:
        text = f"at t = {pace.time * 1e3:.4g} ms {self._pace_text(pace)}"
        causes = self._causes(pace)
        return f"{text}: likely causes: {'; '.join(causes)}" if causes else text

    def _collapse(self, pace: Pace) -> SolverError:
        """A collapsed run as a failure: the joint, the time, the pace, the likely causes and the fix."""
        message = f"the steps collapsed far below the contact time, the run cannot reach t_end: {self._pace_text(pace)}"
        hint = (f"likely causes: {'; '.join(self._causes(pace))}. `clearsim validate` and `clearsim draw` "
                "show the mechanism as read")
        return SolverError(message, time=pace.time, element=self.system.clearance_joints[pace.joint], hint=hint)

    def _failure(self, status: int) -> SolverError:
        """The failure in names: time, the joint involved, what to try."""
        settings = self.system.mechanism.solver
        t = self.time
        joint = self._involved_joint(status)
        messages = {
            ig.MIN_STEP: (f"the step size fell below solver.min_step = {settings.min_step:.3g} s",
                          "a contact stiffer than min_step can resolve, or a force that jumps: lower solver.min_step, "
                          "check the contact stiffness and its units, or raise contact.min_impact_speed"),
            ig.NOT_FINITE: ("the state became NaN or infinite",
                            "check masses, inertias, stiffness and force units for values off by orders of magnitude"),
            ig.DRIFT: ("the constraints could not be satisfied any more (assembly lost)",
                       "the mechanism reaches a toggle or singular position here: check the geometry and the drive stroke"),
            ig.CHATTER: (f"the contact events stopped advancing the time ({ig.STALLED_STEPS} steps in a row shorter than "
                         "solver.min_step)",
                         "the friction of this joint switches between sticking and sliding without end: try "
                         "`friction: {stick: smooth}` on it, or another solver.rtol"),
            ig.TOO_DEEP: ("the penetration exceeded 5 % of the journal radius, far outside any contact law's range",
                          "the contact stiffness is far too low for the load (check `stiffness` and its unit, N/m^1.5), "
                          "or solver.rtol too loose to resolve the impact (try 1e-7)"),
        }
        overrun = puffer_overrun(self.system, self.y[:self.coordinate_count])
        if overrun is not None:
            return SolverError(overrun[1], time=t, element=overrun[0], hint=overrun[2], kind="force")
        message, hint = messages[status]
        pockets = (conforming_bores(self.system, self.kernel_arrays, self.y, self.modes)
                   + worn_pockets(self.system, touching_two_rims(self.system, self.kernel_arrays, self.y)))
        if status in (ig.MIN_STEP, ig.CHATTER) and pockets:
            hint = f"{'; '.join(pockets)}. Otherwise: {hint}"
        elif status == ig.MIN_STEP and all(mode == FREE for mode in self.modes):
            # no contact is closed: the stiff or jumping force is elsewhere (found by the input fuzz: a mass of
            # 1e300 kg stopped here with the contact hint)
            hint = ("no clearance joint is in contact here, so it is not a contact: check masses, inertias, spring "
                    "stiffnesses and forces for values off by orders of magnitude (a unit), and the drive's motion "
                    "for a jump")
        return SolverError(message, time=t, element=joint, hint=hint)

    def _involved_joint(self, status: int) -> str | None:
        system = self.system
        if status == ig.DRIFT:
            m = constraint_count(self.kernel_arrays)
            phi = np.zeros(m)
            evaluate_constraints(self.kernel_arrays, self.time, self.y[: self.coordinate_count], phi)
            return system.row_owners[int(np.argmax(np.abs(phi)))] if m else None
        if status in (ig.TOO_DEEP, ig.CHATTER) and self.ints[ig.I_FAIL_JOINT] >= 0:
            return system.clearance_joints[int(self.ints[ig.I_FAIL_JOINT])]
        in_contact = [k for k, mode in enumerate(self.modes) if mode != FREE]
        if in_contact:
            return f"{system.clearance_joints[in_contact[0]]} (in contact)"
        return None


@dataclass
class History:
    """A whole run's samples (the chunks joined), its episode log and statistics."""

    system: System
    chunk: Chunk
    episodes: EpisodeLog
    statistics: Statistics
    complete: bool
    status: str


def simulate(system: System, progress: Callable[[float], None] | None = None,
             warn: Callable[[str], None] | None = None) -> History:
    """Run to t_end and return the History; SolverError propagates (use Run.chunks to keep partial results)."""
    run = Run(system, warn)
    chunks = []
    for chunk in run.chunks(progress):
        chunks.append(chunk)
    return History(system, Chunk.joined(chunks), run.episode_log(), run.statistics(), True, "complete")
