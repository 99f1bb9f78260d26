"""The Flores slider-crank with a rod–slider clearance joint, in minimal coordinates.

An independent formulation against which clearsim's absolute-coordinate solver is checked
(tests/validation/test_independent_slider_crank.py). Nothing is imported from clearsim: the
kinematics, the equations of motion, the contact geometry, the force laws and the event
handling are written here from scratch.

Mechanism (SI). Crank O–A, r = 0.05, pivot O at the origin, prescribed θ1 = ω t. Rod A–J,
l = 0.12, angle θ2, centre of mass G2 at mid-length. Slider on the x axis at x3 (the bearing
centre; it does not rotate). The journal centre J = A + l u(θ2) sits in the slider's bearing
with radial clearance c = R_B − R_J. Generalised coordinates q = (θ2, x3); the crank's own
dynamics are irrelevant because its motion is prescribed (its torque is whatever it takes).

Kinematics, u = (cos θ2, sin θ2), u⊥ = (−sin θ2, cos θ2):

    A = r (cos θ1, sin θ1)      v_A = r ω (−sin θ1, cos θ1)      a_A = −r ω² (cos θ1, sin θ1)
    J = A + l u                 v_J = v_A + l θ̇2 u⊥
    e = J − (x3, 0)             ė = v_J − (ẋ3, 0)
    δ = |e| − c,  n = e/|e|,  t = (−n_y, n_x),  δ̇ = ė·n,  v_t = ė·t + R_J θ̇2 − R_B·0

Contact force on the journal, applied at its material point P = J + R_J n (the opposite force
acts on the bearing at (x3, 0) + R_B n):  F = −F_n n + F_t t,  F_t = −μ(v_t) F_n.

Rod, rotation about the moving crank pin A (the pin force has no moment about A). With
s = G2 − A = (l/2) u and J_A = J_2 + m_2 l²/4, the moment equation of a rigid body about a
moving point is J_A θ̈2 + m_2 s × a_A = M_A, and s × a_A = −(l/2) r ω² sin(θ1 − θ2):

    J_A θ̈2 = (P − A) × F + m_2 (l/2) r ω² sin(θ1 − θ2)

Slider, translation along x (the guide takes the y force and any moment):

    m_3 ẍ3 = −F_x

Energy: d/dt(T_rod + T_slider) = F_A·v_A + F·v_P(rod) − F·v_P(slider) with the crank-pin
force F_A = m_2 a_G2 − F (Newton for the rod). The contact power is −F_n δ̇ + F_t v_t. With
c_e = 1 and no friction, T + K δ^{5/2}/(5/2) − ∫ F_A·v_A dt is constant; that balance holds
only if the moment equation above is right (tests/validation/test_independent_slider_crank.py).

Events. Each segment integrates one smooth right-hand side (free flight, or contact with
its stored δ̇⁻). Onset: δ rises through 0 in free flight; loss: δ falls through −ε in contact,
ε = LOSS_HYSTERESIS = 1e-12 m. The state at a switch carries an integration error of up to
~1e-13 m in δ; without the hysteresis a journal that dips a few 1e-16 m out of the wall and
comes straight back would start its free flight at δ ≥ 0, and the rise through 0 that marks
the next onset would never be seen. Contact forces vanish for δ ≤ 0, so ε changes nothing
but the bookkeeping (such a dip is not counted as a new episode).
scipy looks for sign changes only at step ends, so a graze that enters and leaves within a
step is caught through the extrema of δ (δ̇ = 0): a free-flight maximum with δ ≥ 0, or a
contact minimum with δ ≤ −ε, means a switch was stepped over; it is then located on the dense
output between the start of that step and the extremum. Every switch is reached by
integrating again from the start of the step that holds it up to the switch time, so the
restart state is an integrator state, not an interpolation.
"""

from dataclasses import dataclass, field
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

RPM = 2.0 * math.pi / 60.0
LOSS_HYSTERESIS = 1e-12  # m, ε: contact is lost when δ falls through −ε


@dataclass(frozen=True)
class Parameters:
    crank_length: float = 0.05  # r, m
    rod_length: float = 0.12  # l, m (crank pin A to journal centre J)
    rod_mass: float = 0.21  # kg
    slider_mass: float = 0.14  # kg
    rod_inertia: float = 0.00025  # kg m², about the rod's centre of mass (mid-length)
    crank_speed: float = 5000.0 * RPM  # ω, rad/s, θ1 = ω t
    bearing_radius: float = 0.010  # R_B, m (on the slider)
    journal_radius: float = 0.0095  # R_J, m (on the rod)
    youngs_modulus: float = 207e9  # Pa, both bodies
    poisson_ratio: float = 0.3
    restitution: float = 0.9  # c_e of the Lankarani–Nikravesh law
    exponent: float = 1.5
    min_impact_speed: float = 1e-3  # m/s, floor of δ̇⁻ in the damping term
    mu_d: float = 0.0  # Ambrósio modified Coulomb; 0 = frictionless
    v_0: float = 1e-4  # m/s, c_d = 0 below
    v_1: float = 1e-3  # m/s, c_d = 1 above

    @property
    def clearance(self):
        return self.bearing_radius - self.journal_radius

    @property
    def stiffness(self):
        """K = 4/(3(σ_B + σ_J)) sqrt(R_B R_J/(R_B − R_J)), σ = (1 − ν²)/E (internal contact)."""
        sigma = (1.0 - self.poisson_ratio**2) / self.youngs_modulus
        radii = self.bearing_radius * self.journal_radius / (self.bearing_radius - self.journal_radius)
        return 4.0 / (3.0 * 2.0 * sigma) * math.sqrt(radii)

    @property
    def hysteresis(self):
        return 0.75 * (1.0 - self.restitution**2)


FRICTIONLESS = Parameters()
FRICTION = Parameters(mu_d=0.01)


def ideal_initial_state(p: Parameters):
    """(θ2, x3, θ̇2, ẋ3) of the ideal mechanism at t = 0 (θ1 = 0): journal centred in the bearing.

    Ideal loop: J_y = r sin θ1 + l sin θ2 = 0, so sin θ2 = −(r/l) sin θ1 and, differentiated,
    r ω cos θ1 + l cos θ2 θ̇2 = 0; x3 = r cos θ1 + l cos θ2, ẋ3 = −r ω sin θ1 − l sin θ2 θ̇2.
    """
    theta1 = 0.0
    theta2 = math.asin(-p.crank_length / p.rod_length * math.sin(theta1))
    rate2 = -p.crank_length * p.crank_speed * math.cos(theta1) / (p.rod_length * math.cos(theta2))
    x3 = p.crank_length * math.cos(theta1) + p.rod_length * math.cos(theta2)
    v3 = -p.crank_length * p.crank_speed * math.sin(theta1) - p.rod_length * math.sin(theta2) * rate2
    return np.array([theta2, x3, rate2, v3])


def normal_force(p: Parameters, penetration, rate, impact_speed):
    """Lankarani–Nikravesh, F_n = K δ^n (1 + 3(1 − c_e²)/4 · δ̇/δ̇⁻) ≥ 0; impact_speed, floored."""
    if penetration <= 0.0:
        return 0.0
    return max(0.0, p.stiffness * penetration**p.exponent * (1.0 + p.hysteresis * rate / impact_speed))


def friction_coefficient(p: Parameters, sliding):
    """Ambrósio modified Coulomb, signed: μ_d c_d(|v|) sign v, c_d 0 below v_0, linear to 1 at v_1."""
    speed = abs(sliding)
    if p.mu_d == 0.0 or speed <= p.v_0:
        return 0.0
    scale = 1.0 if speed >= p.v_1 else (speed - p.v_0) / (p.v_1 - p.v_0)
    return math.copysign(p.mu_d * scale, sliding)


def _cross(a0, a1, b0, b1):
    return a0 * b1 - a1 * b0


def contact_geometry(p: Parameters, t, y):
    """(e, ė, δ, δ̇, n, v_t) of state y = (θ2, x3, θ̇2, ẋ3, …) at time t."""
    theta1 = p.crank_speed * t
    c1, s1 = math.cos(theta1), math.sin(theta1)
    c2, s2 = math.cos(y[0]), math.sin(y[0])
    r, l, w = p.crank_length, p.rod_length, p.crank_speed
    ex = r * c1 + l * c2 - y[1]
    ey = r * s1 + l * s2
    vx = -r * w * s1 - l * y[2] * s2 - y[3]
    vy = r * w * c1 + l * y[2] * c2
    norm = math.hypot(ex, ey)
    if norm == 0.0:  # journal exactly centred (t = 0): any normal, no radial rate
        nx, ny, rate = 1.0, 0.0, 0.0
    else:
        nx, ny = ex / norm, ey / norm
        rate = vx * nx + vy * ny
    sliding = -vx * ny + vy * nx + p.journal_radius * y[2]  # − R_B·ω_slider, ω_slider = 0
    return (ex, ey), (vx, vy), norm - p.clearance, rate, (nx, ny), sliding


def contact_forces(p: Parameters, t, y, impact_speed):
    """(F_n, F_t) for a segment in contact (impact_speed = floored δ̇⁻) or free flight (None)."""
    if impact_speed is None:
        return 0.0, 0.0
    _, _, penetration, rate, _, sliding = contact_geometry(p, t, y)
    fn = normal_force(p, penetration, rate, impact_speed)
    return fn, -friction_coefficient(p, sliding) * fn


def rhs(p: Parameters, t, y, impact_speed, energy=False):
    """ẏ for y = (θ2, x3, θ̇2, ẋ3[, W_pin, W_contact]); impact_speed None in free flight."""
    r, l, w = p.crank_length, p.rod_length, p.crank_speed
    theta1 = w * t
    c2, s2 = math.cos(y[0]), math.sin(y[0])
    pseudo = p.rod_mass * 0.5 * l * r * w * w * math.sin(theta1 - y[0])  # −m₂ s × a_A
    fx = fy = 0.0
    moment = 0.0
    fn = ft = rate = sliding = 0.0
    if impact_speed is not None:
        _, _, penetration, rate, (nx, ny), sliding = contact_geometry(p, t, y)
        fn = normal_force(p, penetration, rate, impact_speed)
        ft = -friction_coefficient(p, sliding) * fn
        fx = -fn * nx - ft * ny  # F = −F_n n + F_t t on the journal, t = (−n_y, n_x)
        fy = -fn * ny + ft * nx
        arm_x = l * c2 + p.journal_radius * nx  # P − A
        arm_y = l * s2 + p.journal_radius * ny
        moment = _cross(arm_x, arm_y, fx, fy)
    inertia_a = p.rod_inertia + p.rod_mass * 0.25 * l * l
    acc2 = (moment + pseudo) / inertia_a
    acc3 = -fx / p.slider_mass
    if not energy:
        return [y[2], y[3], acc2, acc3]
    c1, s1 = math.cos(theta1), math.sin(theta1)
    # a_G2 = a_A + (l/2)(θ̈2 u⊥ − θ̇2² u); crank-pin force on the rod F_A = m₂ a_G2 − F
    agx = -r * w * w * c1 + 0.5 * l * (-acc2 * s2 - y[2] ** 2 * c2)
    agy = -r * w * w * s1 + 0.5 * l * (acc2 * c2 - y[2] ** 2 * s2)
    pin_power = (p.rod_mass * agx - fx) * (-r * w * s1) + (p.rod_mass * agy - fy) * (r * w * c1)
    contact_power = -fn * rate + ft * sliding
    return [y[2], y[3], acc2, acc3, pin_power, contact_power]


def kinetic_energy(p: Parameters, t, y):
    """T of rod and slider (the crank's is constant)."""
    r, l, w = p.crank_length, p.rod_length, p.crank_speed
    theta1 = w * t
    vgx = -r * w * math.sin(theta1) - 0.5 * l * y[2] * math.sin(y[0])
    vgy = r * w * math.cos(theta1) + 0.5 * l * y[2] * math.cos(y[0])
    return 0.5 * p.rod_mass * (vgx**2 + vgy**2) + 0.5 * p.rod_inertia * y[2] ** 2 + 0.5 * p.slider_mass * y[3] ** 2


def contact_energy(p: Parameters, penetration):
    return p.stiffness * penetration ** (p.exponent + 1.0) / (p.exponent + 1.0) if penetration > 0.0 else 0.0


@dataclass
class Episode:
    onset: float  # s
    impact_speed: float  # m/s, δ̇ at onset (raw; the damping uses max(this, min_impact_speed))
    loss: float = math.nan  # s, nan while open at the end of the run
    peak_normal_force: float = math.nan  # N, max of F_n over the episode
    peak_time: float = math.nan  # s


@dataclass
class _Piece:
    t0: float
    t1: float
    sol: object  # scipy OdeSolution, valid on [t0, t1]
    impact_speed: float | None  # floored δ̇⁻ in contact, None in free flight


@dataclass
class MinimalResult:
    parameters: Parameters
    episodes: list
    pieces: list = field(repr=False)
    steps: int = 0
    rhs_evaluations: int = 0

    def _piece_index(self, times):
        starts = np.array([piece.t0 for piece in self.pieces])
        return np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(self.pieces) - 1)

    def states(self, times):
        """(N, 4 or 6) states at `times` from the continuous extension of each smooth segment."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        index = self._piece_index(times)
        out = np.empty((len(times), len(self.pieces[0].sol(self.pieces[0].t0))))
        for k in np.unique(index):
            mine = index == k
            out[mine] = self.pieces[k].sol(times[mine]).T
        return out

    def histories(self, times):
        """Time histories at `times`: state, eccentricity, penetration, rate, forces, sliding velocity."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        states = self.states(times)
        index = self._piece_index(times)
        p = self.parameters
        n = len(times)
        ecc = np.empty((n, 2))
        penetration, rate, sliding, fn, ft = (np.empty(n) for _ in range(5))
        for i, (t, y) in enumerate(zip(times, states)):
            e, _, penetration[i], rate[i], _, sliding[i] = contact_geometry(p, t, y)
            ecc[i] = e
            fn[i], ft[i] = contact_forces(p, t, y, self.pieces[index[i]].impact_speed)
        return {"time": times, "theta2": states[:, 0], "x3": states[:, 1], "theta2_rate": states[:, 2],
                "x3_rate": states[:, 3], "eccentricity": ecc, "penetration": penetration,
                "penetration_rate": rate, "normal_force": fn, "friction_force": ft,
                "sliding_velocity": sliding, "in_contact": np.array([self.pieces[k].impact_speed is not None
                                                                     for k in index]),
                "states": states}


def _peak_force(p, pieces, onset, loss):
    """Max of F_n over [onset, loss] on the contact pieces: step points, then a bounded refinement."""
    best = (-1.0, onset)
    candidates = []
    for piece in pieces:
        grid = np.linspace(piece.t0, piece.t1, 9)
        for sub in range(len(piece.sol.ts) - 1):
            grid = np.append(grid, np.linspace(piece.sol.ts[sub], piece.sol.ts[sub + 1], 9))
        grid = np.unique(np.clip(grid, piece.t0, piece.t1))
        values = [contact_forces(p, t, piece.sol(t), piece.impact_speed)[0] for t in grid]
        k = int(np.argmax(values))
        if values[k] > best[0]:
            best = (values[k], grid[k])
            candidates = [(piece, grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)])]
    for piece, lower, upper in candidates:
        if upper > lower:
            refined = minimize_scalar(
                lambda t: -contact_forces(p, t, piece.sol(t), piece.impact_speed)[0], bounds=(lower, upper),
                method="bounded", options={"xatol": 1e-15})
            if -refined.fun > best[0]:
                best = (-refined.fun, refined.x)
    return best


def simulate(parameters: Parameters = FRICTIONLESS, t_end: float = 0.024, rtol: float = 1e-11,
             atol: float = 1e-15, energy: bool = False, initial_state=None):
    """Integrate the mechanism over [0, t_end]; returns a MinimalResult (episodes, dense output).

    energy=True adds W_pin = ∫ F_A·v_A dt and W_contact = ∫ (−F_n δ̇ + F_t v_t) dt to the state.
    """
    p = parameters
    y = ideal_initial_state(p) if initial_state is None else np.asarray(initial_state, dtype=float)
    if energy:
        y = np.concatenate([y, [0.0, 0.0]])
    # atol: ~1e-15 m on coordinates (θ2 in rad times l ≈ 0.1 m), velocities ~1e4 times larger
    tolerances = np.array([atol / 0.1, atol, atol / 0.1 * 1e4, atol * 1e4, 1e-12, 1e-12][:len(y)])

    def penetration(t, state):
        return contact_geometry(p, t, state)[2]

    def penetration_rate(t, state):
        return contact_geometry(p, t, state)[3]

    t, contact_speed = 0.0, None  # contact_speed: floored δ̇⁻ in contact, None in free flight
    pieces, episodes = [], []
    steps = evaluations = 0
    while t < t_end:
        in_contact = contact_speed is not None

        def fun(tt, state, speed=contact_speed):
            return rhs(p, tt, state, speed, energy)

        def switch(tt, state, shift=LOSS_HYSTERESIS if in_contact else 0.0):
            return penetration(tt, state) + shift

        def extremum(tt, state):
            return penetration_rate(tt, state)

        switch.terminal, switch.direction = True, (-1.0 if in_contact else 1.0)
        extremum.direction = 1.0 if in_contact else -1.0  # contact: minima of δ; free: maxima
        first = None
        if in_contact:  # a fraction of the Hertz time of the impact (m_eff ~ 0.1 kg here)
            first = 3.2 * (0.1 / p.stiffness) ** 0.4 * max(contact_speed, 1e-2) ** -0.2 / 50.0
        res = solve_ivp(fun, (t, t_end), y, method="DOP853", rtol=rtol, atol=tolerances,
                        events=(switch, extremum), dense_output=True, first_step=first)
        if res.status < 0:
            raise RuntimeError(f"integration failed at t = {res.t[-1]:.9e} s: {res.message}")
        steps += len(res.t) - 1
        evaluations += res.nfev
        depth = max(penetration(tt, yy) for tt, yy in zip(res.t, res.y.T))
        if depth > (p.clearance if in_contact else 1e-9):  # journal through the wall: never silent
            raise RuntimeError(f"penetration {depth:.3e} m in {'contact' if in_contact else 'free flight'} "
                               f"between t = {t:.9e} and {res.t[-1]:.9e} s")
        # a switch stepped over: a free maximum with δ ≥ 0 or a contact minimum with δ ≤ 0
        missed = [te for te, ye in zip(res.t_events[1], res.y_events[1])
                  if (switch(te, ye) <= 0.0 if in_contact else switch(te, ye) >= 0.0)]
        t_switch = None
        if missed:
            t_extremum = missed[0]
            k = max(int(np.searchsorted(res.t, t_extremum, side="left")) - 1, 0)
            t_switch = brentq(lambda tt: switch(tt, res.sol(tt)), res.t[k], t_extremum, xtol=1e-18,
                              rtol=4 * np.finfo(float).eps)
        elif res.status == 1:
            t_switch = res.t_events[0][0]
            k = len(res.t) - 2
        if t_switch is None:  # reached t_end
            pieces.append(_Piece(t, res.t[-1], res.sol, contact_speed))
            t = res.t[-1]
            break
        # integrate again from the start of the step that holds the switch up to the switch
        if k > 0:
            pieces.append(_Piece(t, res.t[k], res.sol, contact_speed))
        last = solve_ivp(fun, (res.t[k], t_switch), res.y[:, k], method="DOP853", rtol=rtol, atol=tolerances,
                         dense_output=True, first_step=t_switch - res.t[k])
        steps += len(last.t) - 1
        evaluations += last.nfev
        pieces.append(_Piece(res.t[k], t_switch, last.sol, contact_speed))
        t, y = t_switch, last.y[:, -1]
        if in_contact:
            episodes[-1].loss = t
            contact_speed = None
        else:
            speed = penetration_rate(t, y)
            episodes.append(Episode(onset=t, impact_speed=speed))
            contact_speed = max(speed, p.min_impact_speed)
    result = MinimalResult(p, episodes, pieces, steps, evaluations)
    for episode in episodes:
        end = episode.loss if math.isfinite(episode.loss) else t
        mine = [piece for piece in pieces
                if piece.impact_speed is not None and piece.t0 >= episode.onset and piece.t1 <= end]
        episode.peak_normal_force, episode.peak_time = _peak_force(p, mine, episode.onset, end)
    return result


def energy_balance(result: MinimalResult, times):
    """(T + V_contact − W_pin, T − W_pin − W_contact) at `times`; needs simulate(..., energy=True).

    The first is constant for c_e = 1 without friction, the second always.
    """
    p = result.parameters
    states = result.states(times)
    conserved, power_theorem = [], []
    for t, y in zip(np.atleast_1d(times), states):
        kinetic = kinetic_energy(p, t, y)
        potential = contact_energy(p, contact_geometry(p, t, y)[2])
        conserved.append(kinetic + potential - y[4])
        power_theorem.append(kinetic - y[4] - y[5])
    return np.array(conserved), np.array(power_theorem)


__all__ = ["Parameters", "FRICTIONLESS", "FRICTION", "Episode", "MinimalResult", "simulate",
           "ideal_initial_state", "energy_balance", "kinetic_energy", "contact_geometry"]
