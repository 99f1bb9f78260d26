"""A run whose steps collapse far below the contact time stops early, with the joint, the time and the likely cause;
a healthy run is never judged so (docs/model.md §4 "Progress")."""

from pathlib import Path

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.errors import SolverError
from clearsim.model.loader import load_mechanism
from clearsim.runner import prepare, simulate_config
from clearsim.solver import integrator as ig
from clearsim.solver import simulate as sim
from tests.support.worn_bore import pocket_model

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
FRICTION = CONFIGS / "slider_crank_flores_friction.yaml"
# the radii written in m where mm were meant: a 10 m journal in its bearing, c = 0.5 mm, with friction. Its steps
# fall to ~2e-12 s at the first contact (t ≈ 0.25 ms), a millionth of the contact time: before the pace was judged
# such a run ground for minutes (millions of steps, no output) before it stopped at min_step, or never did
METRES_FOR_MM = ["joints.slider_pin.bearing_radius=10m", "joints.slider_pin.journal_radius=9.9995m"]


def tried_steps(statistics) -> int:
    return statistics.steps + statistics.rejected_steps


def test_collapsed_steps_stop_the_run_within_two_judgements(tmp_path):
    report = simulate_config(FRICTION, METRES_FOR_MM, tmp_path / "r.h5")
    assert not report.complete
    assert isinstance(report.error, SolverError), report.status
    text = str(report.error)
    assert "slider_pin" in text and "collapsed" in text and "contact time" in text
    assert "bearing radius is 10 m" in text  # the likely cause, from the joint's parameters
    assert "slider_crank_flores_friction.yaml:" in text  # located in the file
    assert report.error.time < 0.3e-3  # where the steps collapsed, not at t_end
    # fast: within two judgements of the pace (plus one call of the loop), not after millions of steps
    assert tried_steps(report.statistics) <= 2 * sim.WATCH_STEPS + ig.STEPS_PER_CALL
    with h5py.File(report.output, "r") as result:  # the partial result is written and flagged
        assert not result.attrs["complete"] and "collapsed" in result.attrs["status"]
        assert 0 < len(result["time"]) and result["time"][-1] < 0.3e-3


def test_the_cli_stops_a_collapsed_run_with_exit_2_and_no_traceback(tmp_path):
    result = CliRunner().invoke(app, ["run", str(FRICTION), "-o", str(tmp_path / "r.h5"),
                                      *[a for s in METRES_FOR_MM for a in ("--set", s)]])
    assert result.exit_code == 2, result.output
    assert "error:" in result.output and "collapsed" in result.output and "Traceback" not in result.output
    assert (tmp_path / "r.h5").exists()


def test_a_collapsed_run_that_could_still_finish_warns_as_soon_as_it_is_seen(monkeypatch):
    """Not hopeless (monkeypatched: any number of steps left is affordable): one warning, at the first judgement
    that sees the collapse, naming the joint, the time and the likely causes; the run goes on."""
    monkeypatch.setattr(sim, "HOPELESS_STEPS", np.inf)
    warned = []

    class Seen(Exception):
        pass

    def warn(text):
        warned.append((text, tried_steps(run.statistics())))
        raise Seen

    run = sim.Run(prepare(load_mechanism(FRICTION, METRES_FOR_MM)), warn)
    with pytest.raises(Seen):
        for _ in run.chunks():
            pass
    (text, steps), = warned
    assert steps <= 2 * sim.WATCH_STEPS + ig.STEPS_PER_CALL
    assert text.startswith("at t = 0.2") and "joint slider_pin" in text and "likely causes" in text
    assert "bearing radius is 10 m" in text and "friction" in text
    assert run.warnings() == [text]  # also in the result file's warnings


@pytest.mark.parametrize("config, overrides", [
    (CONFIGS / "uhv_breaker.yaml", []),
    (CONFIGS / "uhv_breaker.yaml", ["joints.A.clearance=0.1mm", "joints.J.clearance=0.1mm"]),
    (CONFIGS / "slider_crank_flores.yaml", []),
    (FRICTION, []),
    (CONFIGS / "uhv_breaker.yaml", ["solver.rtol=1e-9", "solver.atol=1e-12"]),
])
def test_healthy_runs_judged_every_500_steps_never_warn(monkeypatch, config, overrides):
    """The bundled models, judged 40× more often than by default: over any 500 steps their mean step is at least
    1.08 % of the contact time (the UHV at rtol 1e-9; 2.4 % at the default tolerances); collapsed is below 0.1 %."""
    monkeypatch.setattr(sim, "WATCH_STEPS", 500)
    monkeypatch.setattr(sim, "PROGRESS_SECONDS", 0.0)  # the loop returns every 1 % of t_end: judged that often
    run = sim.Run(prepare(load_mechanism(config, overrides)), warn=pytest.fail)
    judged = []
    original = run.judge_pace
    monkeypatch.setattr(run, "judge_pace", lambda: judged.append(original()))
    for _ in run.chunks():
        pass
    paces = [p for p in judged if p is not None]
    assert len(paces) >= 3  # it was judged
    assert not any(p.collapsed or p.slow for p in paces) and run.pace_warnings == []
    in_contact = [p for p in paces if p.joint >= 0]
    assert in_contact and min(p.mean_step / p.contact_time for p in in_contact) > 5 * sim.COLLAPSED


def pace(mean_step, contact_time, joint=0, remaining=0.02):
    return sim.Pace(0.001, 1000, 1000 * mean_step, remaining, joint, contact_time)


def test_pace_verdicts():
    assert pace(1e-12, 1e-6).collapsed and pace(1e-12, 1e-6).hopeless  # 2e10 steps left
    assert not pace(1e-12, 1e-6, remaining=1e-6).hopeless  # collapsed, but 1e6 steps finish it: a warning
    assert not pace(1e-8, 1e-6, remaining=1.0).collapsed and pace(1e-8, 1e-6, remaining=1.0).slow  # 1 % of t_c, 1e8 steps
    no_contact = pace(1e-15, np.inf, joint=-1)
    assert not no_contact.collapsed and not no_contact.hopeless and no_contact.slow  # no contact time: never stopped
    assert pace(0.0, 1e-6).remaining_steps == np.inf


def test_likely_causes_are_read_from_the_joints_parameters():
    """A stiffness above any steel contact and a min_step below its default are named; the bundled model has none of
    the causes a parameter can show (its friction-free joint, its 10 mm bearing, its stiffness from `auto`)."""
    stiff = prepare(load_mechanism(CONFIGS / "slider_crank_flores.yaml",
                                   ["defaults.contact.stiffness=1e20N/m^1.5", "solver.min_step=1e-16s"]))
    causes = sim.likely_causes(stiff, pace(1e-15, 1e-9))
    assert any("contact stiffness 1e+20 N/m^1.5" in c for c in causes)
    assert any("solver.min_step = 1e-16 s" in c for c in causes)
    assert sim.likely_causes(prepare(load_mechanism(CONFIGS / "slider_crank_flores.yaml")), pace(1e-15, 1e-9)) == []
    free = sim.likely_causes(stiff, pace(1e-15, np.inf, joint=-1))
    assert "no clearance joint is in contact" in free[0]


def test_a_slow_run_warns_once_with_its_pace_and_finishes(monkeypatch):
    """With 10 steps called too many to wait for, the healthy slider-crank (2126 steps) is slow at every judgement:
    one warning with the pace, told at once, and the run completes (slow is not collapsed)."""
    monkeypatch.setattr(sim, "WATCH_STEPS", 500)
    monkeypatch.setattr(sim, "PROGRESS_SECONDS", 0.0)
    monkeypatch.setattr(sim, "HOPELESS_STEPS", 10)
    warned = []
    history = sim.simulate(prepare(load_mechanism(CONFIGS / "slider_crank_flores.yaml")), warn=warned.append)
    assert history.complete and history.chunk.times[-1] == pytest.approx(0.024)
    (text,) = warned
    assert text.startswith("at t = ") and "at this pace the remaining" in text and "likely causes" not in text




UHV = CONFIGS / "uhv_breaker.yaml"
# an oval 20 µm deep at A and J (radius of curvature 49.9601 mm at its bottom, against the journal's 49.9900 mm): the
# journal pressed into it touches both rims (at A at 0.785 ms: 48° either side of the bottom, 8.8 and 8.3 µm deep)
OVAL_POCKET = [f"joints.{joint}.wear.profile.cos=[0.02mm, 0, 0.02mm]" for joint in "AJ"]
POCKET = "a worn bore with a pocket tighter than its journal at joint A (smallest radius of curvature 49.9601 mm"
# a journal dropped onto the axis of a pocket tighter than itself, damped, with exact sticking: landing on both rims
# at ~10 ms, equally near and sliding at them in opposite directions, the nearer rim changes with every rounding and
# the steps reach min_step
STICKING = "{law: stiction_step, mu_s: 0.2, mu_d: 0.15, v_s: 1e-4 m/s, v_d: 1e-2 m/s}"
DAMPED = "{law: lankarani_nikravesh, restitution: 0.5, exponent: 1.5, stiffness: auto}"


def test_a_run_stopped_in_a_worn_pocket_names_the_pocket_first(tmp_path):
    """The stop's likely causes give the pocket, its radius against the journal's and the fixes, before the other
    causes; the partial result is written and flagged."""
    config = tmp_path / "pocket.yaml"
    config.write_text(pocket_model(DAMPED, STICKING, t_end="60 ms", start=2e-4))
    report = simulate_config(config, [], tmp_path / "r.h5")
    assert not report.complete and isinstance(report.error, SolverError), report.status
    text = str(report.error)
    assert report.error.time < 20e-3
    pocket = "a worn bore with a pocket tighter than its journal at joint J (smallest radius of curvature 7.9729 mm"
    assert text.index(pocket) < text.index("Otherwise")
    assert "against the journal's 9.5000 mm" in text and "R_B + h + h'' >= R_J" in text and "stick: smooth" in text
    with h5py.File(report.output, "r") as result:
        assert not result.attrs["complete"] and pocket in result.attrs["status"]


def test_a_stop_at_min_step_names_a_pocket_first_only_where_its_journal_touches_two_rims():
    """At 0.785 ms A's journal is pressed into its oval pocket on both rims: a stop there names the pocket first. At
    t = 0 no journal touches two rims, and a stop there is not the pocket's (the fixed-width life's operation that
    stops at min_step with A resting in its groove on one rim, docs/life.md)."""
    run = sim.Run(prepare(load_mechanism(UHV, OVAL_POCKET)))
    run.modes[:] = 1  # in contact
    assert sim.touching_two_rims(run.system, run.kernel_arrays, run.y) == set()
    text = str(run._failure(ig.MIN_STEP))
    assert "solver.min_step" in text and "pocket" not in text
    pressed = sim.Run(prepare(load_mechanism(UHV, OVAL_POCKET + ["solver.t_end=0.785ms"])))
    for _ in pressed.chunks():
        pass
    assert 0 in sim.touching_two_rims(pressed.system, pressed.kernel_arrays, pressed.y)
    text = str(pressed._failure(ig.MIN_STEP))
    assert "solver.min_step" in text and text.index(POCKET) < text.index("Otherwise: a contact stiffer")


def test_collapsed_steps_in_a_worn_pocket_give_the_pocket_as_the_first_likely_cause():
    system = prepare(load_mechanism(UHV, OVAL_POCKET))
    pace = sim.Pace(time=4e-3, steps=20_000, advanced=1e-4, remaining_time=81e-3, joint=0, contact_time=1.6e-4)
    causes = sim.likely_causes(system, pace)
    assert causes[0].startswith(POCKET) and any("friction" in cause for cause in causes[1:])
    assert sim.likely_causes(prepare(load_mechanism(UHV)), pace)[0].startswith("friction")  # no pocket, no such cause


# the bundled breaker greased at A and J: squeeze films of b = π μ R L³/(2 c³) = 9.82e8 N·s/m at a centred journal
# (Ocvirk's short bearing, half-Sommerfeld: its pressure over the half circle ahead of the squeeze), which hold an
# explicit method's steps at ~5 ns, where rosenbrock takes the stroke in 1 973 steps (docs/model.md §4 "Progress")
GREASED = ["defaults.lubrication={viscosity: 0.1 Pa*s, length: 50 mm}"]


@pytest.fixture(scope="module")
def greased_run():
    """The greased breaker after its first 10 µs (its journals near the bearings' centres), and the mean step."""
    run = sim.Run(prepare(load_mechanism(UHV, GREASED + ["solver.t_end=10us"])))
    for _ in run.chunks():
        pass
    return run, 10e-6 / tried_steps(run.statistics())


def test_a_centred_journals_squeeze_damping_is_the_short_bearings_closed_form(greased_run):
    run, _ = greased_run
    n = run.system.coordinate_count
    viscosity, radius, length, clearance = 0.1, 0.05, 0.05, 1e-5
    for k in range(2):
        damping = sim.squeeze_damping(run.system, run.kernel_arrays, k, run.y[:n].copy(), run.y[n:2 * n].copy())
        assert damping == pytest.approx(np.pi * viscosity * radius * length**3 / (2 * clearance**3), rel=1e-3)


def test_the_film_that_holds_an_explicit_runs_steps_is_named_with_the_fix(greased_run):
    """J's film (m = 5.2 kg: 3.3 m/b = 17 ns) holds DOPRI5's ~5 ns steps; A's (m = 111 kg: 370 ns, 70× the steps) does
    not; steps far below every film's bound, or a rosenbrock run, name none."""
    run, mean_step = greased_run
    assert 1e-9 < mean_step < 1e-8
    (cause,) = sim.stiff_films(run.system, run.kernel_arrays, run.y, run.modes, mean_step)
    assert "the oil film at joint J (b = 9.82e+08 N·s/m" in cause and "joint A" not in cause
    assert "set `solver: {method: rosenbrock}`" in cause
    assert sim.stiff_films(run.system, run.kernel_arrays, run.y, run.modes, mean_step / 100) == []
    rosenbrock = prepare(load_mechanism(UHV, GREASED + ["solver.method=rosenbrock"]))
    assert sim.stiff_films(rosenbrock, run.kernel_arrays, run.y, run.modes, mean_step) == []


def test_a_run_held_by_an_oil_film_warns_with_the_film_and_rosenbrock():
    """The greased stroke with DOPRI5 (1.6e7 steps left at the first judgement): the slow warning names J's film and
    the method that takes its steps by the accuracy."""
    warned = []
    run = sim.Run(prepare(load_mechanism(UHV, GREASED)), warn=warned.append)
    for _ in run.chunks():
        if warned:
            break
    (text,) = warned
    assert "at this pace the remaining" in text
    assert "likely causes: the oil film at joint J" in text and "`solver: {method: rosenbrock}`" in text


def oval_profile(theta):
    """h, h', h'' of OVAL_POCKET's profile, 0.02 mm (1 + cos 2θ)."""
    return 2e-5 * (1 + np.cos(2 * theta)), -4e-5 * np.sin(2 * theta), -8e-5 * np.cos(2 * theta)


@pytest.fixture(scope="module")
def pressed_oval():
    """The oval-pocket breaker at 0.785 ms: A's journal pressed into its pocket."""
    run = sim.Run(prepare(load_mechanism(UHV, OVAL_POCKET + ["solver.t_end=0.785ms"])))
    for _ in run.chunks():
        pass
    return run


def test_the_curvature_lever_is_the_distance_to_the_bores_centre_of_curvature_at_the_contact(pressed_oval):
    """ℓ = ρ_c − d at the nearest bore point, against the reference geometry of tests/support/worn_bore (a dense
    polygon, Newton's method, ρ_c = |r'|³/|r' × r''| of the explicitly differentiated profile)."""
    from clearsim.assembly.forces import clearance_kinematics
    from tests.support.worn_bore import _curve, bore_contacts, rotate

    run = pressed_oval
    n = run.system.coordinate_count
    q, qd = run.y[:n].copy(), run.y[n:2 * n].copy()
    lever, penetration = sim.curvature_lever(run.system, run.kernel_arrays, 0, q, qd)
    ex, ey = clearance_kinematics(run.kernel_arrays, 0, q, qd)[:2]
    bearing = int(run.system.arrays.clearance_bodies[0, 0])
    local_e = rotate(-q[3 * bearing + 2], np.array([ex, ey]))
    reference_depth, _, theta = bore_contacts(oval_profile, 0.05, 0.04999, local_e)[0]
    r, first, second = _curve(oval_profile, 0.05, theta)
    radius_of_curvature = np.hypot(*first) ** 3 / abs(first[0] * second[1] - first[1] * second[0])
    assert penetration == pytest.approx(reference_depth, rel=1e-6)
    assert lever == pytest.approx(radius_of_curvature - np.hypot(*(r - local_e)), rel=1e-6)
    assert 0.0 < lever < 1e-3


def test_a_journal_near_its_bores_centre_of_curvature_is_named_as_a_conforming_bore(pressed_oval, monkeypatch):
    """A's journal pressed into the oval lies ℓ from the centre of curvature at its contact: named when ℓ is below
    CONFORMING times its penetration (here with the factor raised above ℓ/δ), not otherwise; first among a stop's
    causes."""
    run = pressed_oval
    q, qd = sim.positions_and_rates(run.system, run.y)
    lever, penetration = sim.curvature_lever(run.system, run.kernel_arrays, 0, q, qd)
    assert sim.conforming_bores(run.system, run.kernel_arrays, run.y, run.modes) == []
    monkeypatch.setattr(sim, "CONFORMING", 1.01 * lever / penetration)
    (cause,) = sim.conforming_bores(run.system, run.kernel_arrays, run.y, run.modes)
    assert cause.startswith(f"a worn bore conforming to its journal at joint A ({lever * 1e9:.3g} nm from it")
    assert "`archard.width`" in cause
    assert str(run._failure(ig.MIN_STEP)).index("conforming") < str(run._failure(ig.MIN_STEP)).index("Otherwise")


def test_a_journal_resting_at_its_grooves_centre_of_curvature_is_named_and_one_farther_is_not():
    """A's bore worn to an oval h = a (1 + cos 2θ) whose bottom's radius of curvature ρ²/(ρ − ρ'') is R_J − 2 µm, and
    A's journal put on the groove's axis ℓ from that centre (the journal body moved, nothing else): ℓ = 0.1 µm
    (penetration 2.1 µm) is named as a conforming bore, ℓ = 1 µm (3 µm) is not; curvature_lever finds both ℓ."""
    from scipy.optimize import brentq

    from clearsim.assembly.forces import clearance_kinematics
    from tests.support.worn_bore import rotate

    bearing_radius, journal_radius, rest = 0.05, 0.04999, 2e-6
    bottom_curvature = lambda a: (bearing_radius + 2 * a) ** 2 / (bearing_radius + 2 * a + 4 * a)  # noqa: E731
    depth = brentq(lambda a: bottom_curvature(a) - (journal_radius - rest), 1e-7, 1e-4)
    run = sim.Run(prepare(load_mechanism(UHV, [f"joints.A.wear.profile.cos=[{depth!r} m, 0, {depth!r} m]"])))
    n = run.system.coordinate_count
    bearing, journal = (int(body) for body in run.system.arrays.clearance_bodies[0])
    for lever, named in ((1e-7, True), (1e-6, False)):
        y = run.y.copy()
        ex, ey = clearance_kinematics(run.kernel_arrays, 0, y[:n].copy(), y[n:2 * n].copy())[:2]
        local = np.array([bearing_radius + 2 * depth - bottom_curvature(depth) + lever, 0.0])
        target = rotate(y[3 * bearing + 2], local)
        y[3 * journal:3 * journal + 2] += target - np.array([ex, ey])
        q, qd = sim.positions_and_rates(run.system, y)
        found, penetration = sim.curvature_lever(run.system, run.kernel_arrays, 0, q, qd)
        assert found == pytest.approx(lever, rel=1e-4)
        assert penetration == pytest.approx(rest + lever, rel=1e-6)
        causes = sim.conforming_bores(run.system, run.kernel_arrays, y, np.array([1, 0]))
        assert bool(causes) is named
        if named:
            assert causes[0].startswith(f"a worn bore conforming to its journal at joint A ({lever * 1e9:.3g} nm")
