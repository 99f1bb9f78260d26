"""solver.method: rosenbrock (ROS34PW2, docs/model.md §4) through the whole integration loop: its order on a stiff
linear problem against the closed form, the ideal slider-crank's closed form, the lubricated joint's squeeze film
with far fewer steps than dopri5 and the same history, the film ↔ dry switches with the energy balance closed; and
dopri5, the default, unchanged."""

import hashlib

import numpy as np
import pytest

from tests.validation.test_ideal_kinematics import closed_form
from tests.validation.test_lubricated_joint import CLEARANCE, eccentricity_ratio, journal, squeeze_time

MASS, STIFFNESS, DAMPING, STRETCH = 1.0, 1e6, 2e5, 1e-3  # kg, N/m, N·s/m, m

BLOCK = """
name: overdamped block
gravity: [0 m/s^2, 0 m/s^2]
points: {{W: [-1 m, 0 m], O: [0 m, 0 m]}}
bodies:
  - {{name: block, mass: 1 kg, inertia: 1 kg*m^2, position: [0 m, 0 m]}}
forces:
  - {{name: spring, type: spring_damper, bodies: [ground, block], at: [W, O], stiffness: 1e6 N/m, damping: 2e5 N*s/m,
     free_length: 0.999 m}}
solver: {{t_end: 200 ms, output_rate: 1 kHz, rtol: 0.5, atol: 1, max_step: {step} ms, initial_step: {step} ms,
          method: {method}}}
"""


def block_position(t):
    """x(t) of the block pulled from x = 0 at rest towards x = −STRETCH (where the spring is at its free length):
    u = x + STRETCH obeys m ü + c u̇ + k u = 0, eigenvalues λ_s = −5.000 and λ_f = −2.0e5 1/s,
    u = STRETCH (λ_f e^{λ_s t} − λ_s e^{λ_f t}) / (λ_f − λ_s)."""
    fast, slow = sorted(np.roots([MASS, DAMPING, STIFFNESS]).real)
    return -STRETCH + STRETCH * (fast * np.exp(slow * t) - slow * np.exp(fast * t)) / (fast - slow)


def test_fixed_steps_on_a_stiff_linear_problem_converge_with_order_3(simulate):
    """|hλ| = 100 … 400 on the fast mode: explicit steps would blow up; the error at t_end falls ×8 per halving."""
    errors = []
    for step in ("2", "1", "0.5"):
        result = simulate(BLOCK.format(step=step, method="rosenbrock"))
        t, x = result["time"], result["bodies/block/q"][:, 0]
        assert t[-1] == pytest.approx(0.2)
        errors.append(abs(x[-1] - block_position(t[-1])))
    assert errors[0] > 1e-12  # precondition: above round-off
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    assert all(6.0 < r < 11.0 for r in ratios), (errors, ratios)


def test_the_ideal_slider_crank_matches_its_closed_form(simulate):
    result = simulate("slider_crank_flores.yaml", "joints.slider_pin.clearance=0", "solver.t_end=12ms",
                      "solver.method=rosenbrock")
    x, v, a = closed_form(result["time"])
    assert np.max(np.abs(result["sensors/slider_displacement"] - (x - x[0]))) <= 1e-6 * np.ptp(x)
    assert np.max(np.abs(result["sensors/slider_velocity"] - v)) <= 1e-6 * np.max(np.abs(v))
    assert np.max(np.abs(result["sensors/slider_acceleration"] - a)) <= 1e-6 * np.max(np.abs(a))


def test_the_squeeze_film_approach_takes_far_fewer_steps_and_follows_dopri5(simulate_with_statistics):
    """The squeeze film of tests/validation/test_lubricated_joint.py from ε = 0.8 to 0.82, where it is stiff (b/m ≈
    1.6e7 1/s: dopri5's steps are bounded by ~3.3 m/b), with both methods."""
    load, start, stop = 100.0, 0.8, 0.82
    t_end = squeeze_time(stop, load) - squeeze_time(start, load)
    text = journal(load, 1e3 * t_end, mass=0.005, rate=20 / (1e3 * t_end)).replace(
        "initial_velocity:", f"initial_eccentricity: [0 m, {-start * CLEARANCE} m], initial_velocity:")
    explicit, explicit_statistics = simulate_with_statistics(text, "solver.method=dopri5")
    implicit, implicit_statistics = simulate_with_statistics(text, "solver.method=rosenbrock")
    eps_explicit, eps_implicit = eccentricity_ratio(explicit), eccentricity_ratio(implicit)
    assert eps_explicit[-1] == pytest.approx(stop, abs=1e-4)  # precondition: the closed form's approach
    np.testing.assert_allclose(eps_implicit, eps_explicit, rtol=0, atol=1e-9)
    assert implicit_statistics.steps * 50 < explicit_statistics.steps, (implicit_statistics, explicit_statistics)


def test_the_whole_squeeze_approach_follows_the_closed_form(simulate):
    load = 100.0
    t_end = squeeze_time(0.9, load)
    result = simulate(journal(load, 1e3 * t_end, mass=0.005, rate=20), "solver.method=rosenbrock")
    eps, time = eccentricity_ratio(result), result["time"]
    compared = (time > 0.05 * t_end) & (eps < 0.9)
    assert np.count_nonzero(compared) > 50 and eps[-1] > 0.85
    expected = np.array([squeeze_time(x, load) for x in eps[compared]])
    assert np.max(np.abs(time[compared] - expected) / expected) <= 1e-3


def test_film_and_dry_contact_take_turns_and_the_energy_balance_closes(simulate):
    result = simulate(journal(50.0, 20.0, spin=300.0, speed=2.0, viscosity=5e-4, rate=200), "solver.method=rosenbrock")
    mode = result["joints/O/mode"]
    assert np.any(mode != 0) and np.any(mode[np.argmax(mode != 0):] == 0)  # film → dry → film
    lost = result["energy/contact_dissipated"][-1] + result["energy/friction_dissipated"][-1]
    assert lost > 0.1 * 0.5 * 1.0 * 2.0 ** 2
    scale = max(lost, np.max(np.abs(result["energy/driver_work"])))
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-6 * scale


def _digest(result):
    return hashlib.sha256(b"".join(np.ascontiguousarray(result[key]).tobytes() for key in sorted(result)
                                   if isinstance(result[key], np.ndarray))).hexdigest()


def test_dopri5_is_the_default_and_integrates_as_before(simulate_with_statistics):
    """Pinned: the friction slider-crank's first 20 ms (35 impacts with stick–slip) with dopri5 takes the steps it took
    before the rosenbrock method existed, and the default is that method, bit for bit. (A deliberate change of
    the physics changes these numbers: pin them anew from a run of the unchanged solver.)"""
    default, default_statistics = simulate_with_statistics("slider_crank_flores_friction.yaml", "solver.t_end=20ms")
    explicit, explicit_statistics = simulate_with_statistics("slider_crank_flores_friction.yaml", "solver.t_end=20ms",
                                                            "solver.method=dopri5")
    assert _digest(default) == _digest(explicit)
    statistics = explicit_statistics
    assert (statistics.steps, statistics.rejected_steps, statistics.rhs_evaluations, statistics.contact_events) == (
        1818, 325, 15523, 35)
    assert statistics.peak_normal_force[0] == 45888.57381462873


def test_the_ideal_flexible_breaker_follows_dopri5_and_closes_its_energy_balance(simulate):
    """The flexible breaker (125 states, the beams' bending modes) with ideal pins over its first 20 ms."""
    overrides = ("joints.A.clearance=0", "joints.J.clearance=0", "solver.t_end=20ms", "solver.output_rate=10kHz")
    explicit = simulate("uhv_breaker_flexible.yaml", *overrides, "solver.method=dopri5")
    implicit = simulate("uhv_breaker_flexible.yaml", *overrides, "solver.method=rosenbrock")
    travel = explicit["sensors/contact_displacement"]
    assert np.ptp(travel) > 1e-3  # precondition: the contact has moved (m)
    # measured: 5.7e-8 of the travel, 2.9e-7 of the peak speed, balance 2.4e-8 of the driver's work (dopri5: 5e-12)
    np.testing.assert_allclose(implicit["sensors/contact_displacement"], travel, rtol=0, atol=2e-7 * np.ptp(travel))
    np.testing.assert_allclose(implicit["sensors/contact_velocity"], explicit["sensors/contact_velocity"], rtol=0,
                               atol=1e-6 * np.max(np.abs(explicit["sensors/contact_velocity"])))
    scale = np.max(np.abs(implicit["energy/driver_work"]))
    assert np.max(np.abs(implicit["energy/balance_error"])) <= 1e-7 * scale


LUBRICATED_BREAKER = ("defaults.lubrication.viscosity=0.1Pa*s", "defaults.lubrication.length=50mm",
                      "joints.A.initial_eccentricity=[0 m, -1 um]", "joints.J.initial_eccentricity=[0 m, -1 um]",
                      "solver.t_end=0.3ms")


def test_the_lubricated_breakers_sampled_accelerations_follow_dopri5(simulate_with_statistics):
    """The bundled breaker with greased pins (b ≈ 1e9 N·s/m at A and J): the samples' accelerations are f at the
    sample's state, where a stiff component's error comes back multiplied by its rate constant (~3e8 1/s); each
    sample is a step of its own, not a point of the step's Hermite extension."""
    explicit, explicit_statistics = simulate_with_statistics("uhv_breaker.yaml", *LUBRICATED_BREAKER)
    implicit, implicit_statistics = simulate_with_statistics("uhv_breaker.yaml", *LUBRICATED_BREAKER,
                                                            "solver.method=rosenbrock")
    expected = explicit["sensors/contact_acceleration"]
    assert np.max(np.abs(expected)) > 100.0  # precondition: the stroke has begun (m/s²)
    np.testing.assert_allclose(implicit["sensors/contact_displacement"], explicit["sensors/contact_displacement"],
                               rtol=0, atol=1e-6 * np.ptp(explicit["sensors/contact_displacement"]))
    np.testing.assert_allclose(implicit["sensors/contact_acceleration"], expected, rtol=0,
                               atol=0.015 * np.max(np.abs(expected)))  # 4.8e-3 measured; 6.3 from the Hermite points
    assert implicit_statistics.steps * 100 < explicit_statistics.steps, (implicit_statistics, explicit_statistics)


def test_the_greased_breakers_accelerations_at_the_default_tolerance_match_a_100_times_tighter_run(
        simulate_with_statistics):
    """The greased breaker's first 5 ms at the default rtol 1e-7 against rtol 1e-9: the output acceleration is f at
    the state, in which the films (λ ≈ 3e8 1/s) multiply an error of the relative velocity at the pins; a Jacobian
    whose film block is a forward difference (~1 % off: rosenbrock.evaluate_jacobian) left the samples ringing,
    peak 187.2 against 183.3 m/s² (2.2 %), samples up to 15 m/s² off. Measured now: peak 4e-7, samples 0.25 % of
    the peak."""
    window = (*LUBRICATED_BREAKER[:-1], "solver.t_end=5ms", "solver.method=rosenbrock")
    default, _ = simulate_with_statistics("uhv_breaker.yaml", *window)
    tighter, _ = simulate_with_statistics("uhv_breaker.yaml", *window, "solver.rtol=1e-9", "solver.atol=1e-12",
                                          "solver.min_step=1e-13 s")  # the film's start-up transient at rtol 1e-9
    acceleration, expected = default["sensors/contact_acceleration"], tighter["sensors/contact_acceleration"]
    peak = np.max(np.abs(expected))
    assert peak > 150.0  # precondition: the stroke has begun (m/s²)
    assert np.max(np.abs(acceleration)) == pytest.approx(peak, rel=1e-3)
    np.testing.assert_allclose(acceleration, expected, rtol=0, atol=0.01 * peak)
    deviation = np.sqrt(np.mean((acceleration - expected) ** 2))
    # each sample inside a step stepped from the sample before it (integrator.emit_samples): 9.7e-5 measured; 4.8e-4
    # with each stepped from the step's start, the fast film transient of a long sub-step left in it
    assert deviation <= 2.5e-4 * peak
    for joint in "AJ":
        film, film_expected = (np.hypot(*run[f"joints/{joint}/film_force"].T) for run in (default, tighter))
        np.testing.assert_allclose(film, film_expected, rtol=0, atol=0.01 * np.max(film_expected))


def test_the_greased_breaker_started_centred_runs_like_one_started_off_centre(simulate_with_statistics):
    """Journals exactly at their bearings' centres (e = 0: the film's line of centres is then taken along ė,
    lubrication.line_of_centres). Before, the film ignored ė across an arbitrary n there and the run stopped at
    t = 14 ns with the step at min_step; now its first ms follows the run started 1 µm off-centre (measured:
    0.07 m/s², 100 steps)."""
    centred, statistics = simulate_with_statistics("uhv_breaker.yaml", *LUBRICATED_BREAKER[:2], "solver.t_end=1ms",
                                                   "solver.method=rosenbrock")
    off_centre, _ = simulate_with_statistics("uhv_breaker.yaml", *LUBRICATED_BREAKER[:-1], "solver.t_end=1ms",
                                             "solver.method=rosenbrock")
    assert np.all(centred["joints/J/eccentricity"][0] == 0.0)  # precondition: started exactly centred
    expected = off_centre["sensors/contact_acceleration"]
    np.testing.assert_allclose(centred["sensors/contact_acceleration"], expected, rtol=0,
                               atol=0.005 * np.max(np.abs(expected)))
    assert statistics.rejected_steps < statistics.steps
