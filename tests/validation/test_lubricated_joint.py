"""A lubricated clearance joint against closed forms: Ocvirk's steady eccentricity, the squeeze-film approach,
and the switch between the film and the dry contact (docs/model-contact.md, lubricated joints).

The journal (mass m) sits in a bearing fixed to the ground, R = 10 mm, c = 50 µm, L = 10 mm, loaded by a constant
force W along −y; gravity is off.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

VISCOSITY, RADIUS, LENGTH, CLEARANCE = 0.05, 0.01, 0.01, 5e-5  # Pa·s, m (journal), m, m
DRY_BELOW = 1.5e-6  # m, the default film threshold

JOURNAL = """
name: journal in a lubricated bearing
gravity: [0 m/s^2, 0 m/s^2]
defaults:
  contact: {{law: lankarani_nikravesh, restitution: 0.9, exponent: 1.5, stiffness: 1e12 N/m^1.5}}
  friction: {{law: coulomb, mu_d: 0.1}}
points: {{O: [0 m, 0 m]}}
bodies:
  - {{name: journal, mass: {mass} kg, inertia: 1e-4 kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, journal], at: O, bearing_radius: 10.05 mm, clearance: 0.05 mm,
     initial_velocity: [0 m/s, {speed} m/s], lubrication: {{viscosity: {viscosity} Pa*s, length: 10 mm{model}}}}}
drivers:
  - {{name: spin, body: journal, coordinate: angle, motion: {{law: constant_speed, speed: {spin} rad/s}}}}
forces:
  - {{name: load, type: constant, body: journal, force: [0 N, {load} N]}}
solver: {{t_end: {t_end} ms, output_rate: {rate} kHz, rtol: 1e-9, atol: 1e-13, max_step: 0.1 ms}}
"""


def journal(load, t_end_ms, spin=0.0, mass=1.0, speed=0.0, viscosity=VISCOSITY, rate=10, model=""):
    return JOURNAL.format(load=-load, t_end=t_end_ms, spin=spin, mass=mass, speed=-speed, viscosity=viscosity,
                          rate=rate, model=f", model: {model}" if model else "")


def eccentricity_ratio(result):
    e = result["joints/O/eccentricity"]
    return np.hypot(e[:, 0], e[:, 1]) / CLEARANCE


def ocvirk_load(eps, spin):
    """W(ε) of the short bearing: μωRL³/(4c²) · ε/(1−ε²)² · √(16ε² + π²(1−ε²)) (Ocvirk 1952; Hamrock 2004)."""
    scale = VISCOSITY * spin * RADIUS * LENGTH ** 3 / (4 * CLEARANCE ** 2)
    return scale * eps / (1 - eps * eps) ** 2 * math.sqrt(16 * eps * eps + math.pi ** 2 * (1 - eps * eps))


def sommerfeld_load(eps, spin):
    """W(ε) of the long bearing, half film: 6μωR³L ε √(π²(1−ε²) + 4ε²) / (c² (2+ε²)(1−ε²)) (Hamrock 2004)."""
    return (6 * VISCOSITY * spin * RADIUS ** 3 * LENGTH * eps * math.sqrt(math.pi ** 2 * (1 - eps * eps) + 4 * eps * eps)
            / (CLEARANCE ** 2 * (2 + eps * eps) * (1 - eps * eps)))


@pytest.mark.parametrize("model, load_law", [("", ocvirk_load), ("long_bearing", sommerfeld_load)])
def test_a_loaded_journal_in_a_spinning_film_settles_at_the_closed_form_eccentricity(simulate, model, load_law):
    spin, load = 2000.0, round(load_law(0.7, 2000.0))  # 966 N (short), 8296 N (long)
    result = simulate(journal(load, 30.0, spin=spin, model=model))
    expected = brentq(lambda eps: load_law(eps, spin) - load, 1e-9, 1 - 1e-9, xtol=1e-14)
    eps = eccentricity_ratio(result)
    assert np.all(result["joints/O/mode"] == 0)  # the film carries it throughout: no dry contact
    assert abs(eps[-1] - expected) <= 1e-3 * expected
    assert abs(eps[-1] - eps[-20]) <= 1e-6  # settled, not passing through
    if not model:  # Ocvirk's attitude angle: tan ψ = π √(1 − ε²) / (4 ε), measured from the load line
        e = result["joints/O/eccentricity"][-1]
        attitude = math.atan2(e[0], -e[1])
        assert attitude == pytest.approx(math.atan(math.pi * math.sqrt(1 - expected ** 2) / (4 * expected)), rel=1e-3)


def squeeze_time(eps, load):
    """t(ε) of a massless journal pressed from the centre by W, no rotation (short bearing, half film):
    W = μRL³ε̇/c² ∫_{−π/2}^{π/2} cos²θ/(1 − ε cos θ)³ dθ, integrated in ε in closed form:
    t = μRL³/(c²W) · ((J₂ − J₁)/(2ε) − 1), J₁ = 4 atan(√((1+ε)/(1−ε)))/s, J₂ = (2ε + J₁)/s², s = √(1 − ε²)."""
    s = math.sqrt(1 - eps * eps)
    j1 = 4 * math.atan(math.sqrt((1 + eps) / (1 - eps))) / s
    j2 = (2 * eps + j1) / (s * s)
    return VISCOSITY * RADIUS * LENGTH ** 3 / (CLEARANCE ** 2 * load) * ((j2 - j1) / (2 * eps) - 1)


def test_a_pure_squeeze_approach_follows_the_closed_form_time_history(simulate):
    load = 100.0
    mass = 0.005  # m/b ≈ 8e-7 s: the inertial lag is 1e-4 of the times compared
    t_end = squeeze_time(0.9, load)
    result = simulate(journal(load, 1e3 * t_end, mass=mass, rate=20))
    eps = eccentricity_ratio(result)
    time = result["time"]
    compared = (time > 0.05 * t_end) & (eps < 0.9)
    assert np.count_nonzero(compared) > 50 and eps[-1] > 0.85  # precondition: the approach is sampled to ε = 0.9
    expected = np.array([squeeze_time(x, load) for x in eps[compared]])
    assert np.max(np.abs(time[compared] - expected) / expected) <= 1e-3
    assert np.all(result["joints/O/mode"] == 0)


def test_film_and_dry_contact_take_turns_and_the_energy_balance_closes(simulate):
    """A spinning journal thrown at the wall: the squeeze film cannot stop it, it strikes the asperities (dry
    contact and friction), rebounds into the film and settles there; every switch is at h = dry_below."""
    result = simulate(journal(50.0, 20.0, spin=300.0, speed=2.0, viscosity=5e-4, rate=200))
    mode = result["joints/O/mode"]
    film = CLEARANCE - eccentricity_ratio(result) * CLEARANCE
    assert np.any(mode != 0) and np.any(mode[np.argmax(mode != 0):] == 0)  # precondition: film → dry → film
    assert len(result["joints/O/episodes/onset"]) >= 1
    assert np.all(result["joints/O/normal_force"][mode == 0] == 0.0)  # no dry force while the film acts
    assert np.min(film[mode == 0]) >= DRY_BELOW - 1e-11  # the film acts only above its threshold ...
    assert np.max(film[mode != 0]) <= DRY_BELOW + 1e-11  # ... and the dry contact only below it
    lost = result["energy/contact_dissipated"][-1] + result["energy/friction_dissipated"][-1]
    assert lost > 0.1 * 0.5 * 1.0 * 2.0 ** 2  # precondition: the film and the impacts took a good part of ½ m v²
    scale = max(lost, np.max(np.abs(result["energy/driver_work"])))
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-6 * scale


BAD_LUBRICATION = {  # name: (text, line marker, fragments of the message)
    "negative viscosity": (journal(10.0, 1.0).replace("viscosity: 0.05 Pa*s", "viscosity: -0.05 Pa*s"),
                           "lubrication:", ["joints[0] 'O' → lubrication → viscosity", "must be at least 0"]),
    "negative length": (journal(10.0, 1.0).replace("length: 10 mm", "length: -10 mm"), "lubrication:",
                        ["joints[0] 'O' → lubrication → length", "must be greater than 0"]),
    "no length": (journal(10.0, 1.0).replace(", length: 10 mm", ""), "lubrication:",
                  ["lubrication → viscosity", "needs the pin's length", "length: 50 mm` to the joint's contact"]),
    "threshold beyond the clearance": (journal(10.0, 1.0).replace("length: 10 mm", "length: 10 mm, dry_below: 0.05 mm"),
                                       "lubrication:", ["lubrication → dry_below", "smaller than the clearance 0.05 mm"]),
    "no clearance": (journal(10.0, 1.0).replace("bearing_radius: 10.05 mm, clearance: 0.05 mm,", ""), "lubrication:",
                     ["joints[0] 'O' → lubrication", "lubricated but has no clearance", "clearance: 0.05 mm"]),
}


@pytest.mark.parametrize("case", list(BAD_LUBRICATION), ids=list(BAD_LUBRICATION))
def test_bad_lubrication_input_exits_2_with_one_located_message(tmp_path, case):
    from typer.testing import CliRunner

    from clearsim.cli import app

    text, marker, fragments = BAD_LUBRICATION[case]
    config = tmp_path / "bad.yaml"
    config.write_text(text)
    output = tmp_path / "never.h5"
    result = CliRunner().invoke(app, ["run", str(config), "-o", str(output)])
    line = next(n for n, content in enumerate(text.splitlines(), 1) if marker in content)
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and f"bad.yaml:{line}:" in result.output, result.output
    for fragment in fragments:
        assert fragment in result.output, result.output
    assert not output.exists()


def test_the_film_takes_the_pins_contact_length_unless_its_own_is_given():
    from clearsim.model.loader import load_mechanism_text
    from clearsim.model.resolve import resolve_clearance

    def film_length(text):
        mechanism = load_mechanism_text(text).mechanism
        return resolve_clearance(mechanism.joints[0], mechanism.defaults).film_length

    pin = journal(10.0, 1.0).replace("stiffness: 1e12 N/m^1.5", "stiffness: 1e12 N/m^1.5, length: 40 mm")
    assert film_length(pin) == pytest.approx(0.010)  # the lubrication block's own
    assert film_length(pin.replace(", length: 10 mm", "")) == pytest.approx(0.040)  # the contact's


def test_the_dry_modes_ignore_the_oil_and_the_film_mode_carries_it_alone():
    """At one state near the wall: in the dry contact mode the forces do not depend on the viscosity; in the
    film mode they are the film's alone (linear in μ, no dry force although the film is thinner than c)."""
    from clearsim.assembly.arrays import for_kernels
    from clearsim.assembly.dynamics import generalized_forces
    from clearsim.assembly.forces import CONTACT, FREE
    from clearsim.model.loader import load_mechanism_text
    from clearsim.runner import prepare

    text = journal(0.0, 1.0, spin=500.0, speed=0.3).replace(
        "initial_velocity:", f"initial_eccentricity: [0 m, {-(CLEARANCE - DRY_BELOW + 1e-7)} m], initial_velocity:")

    def forces(viscosity, mode):
        system = prepare(load_mechanism_text(text, overrides=(f"joints.O.lubrication.viscosity={viscosity} Pa*s",)))
        modes = np.array([mode], dtype=np.int64)
        generalized, *powers = generalized_forces(for_kernels(system.arrays), 0.0, system.q0, system.qd0, modes,
                                                  np.array([0.3]))
        return generalized, powers[2]

    dry, dry_loss = forces(0.05, CONTACT)
    assert np.linalg.norm(dry[:2]) > 0.0  # precondition: δ = 0.1 µm past the threshold, a dry force acts
    assert np.array_equal(forces(0.5, CONTACT)[0], dry)
    thin, thin_loss = forces(0.05, FREE)
    thick, thick_loss = forces(0.5, FREE)
    assert np.linalg.norm(thin[:2]) > 0.0 and thin_loss > 0.0
    np.testing.assert_allclose(thick, 10.0 * thin, rtol=1e-12)
    assert thick_loss == pytest.approx(10.0 * thin_loss, rel=1e-12)


def test_a_film_model_outside_its_length_to_diameter_ratio_warns_in_the_run_summary(tmp_path):
    """L = 10 mm, D = 20 mm: L/D = 0.5 suits the short bearing, not the long one."""
    from typer.testing import CliRunner

    from clearsim.cli import app

    for model, warned in (("short_bearing", False), ("long_bearing", True)):
        path = tmp_path / f"{model}.yaml"
        path.write_text(journal(10.0, 0.2, spin=100.0, model=model))
        result = CliRunner().invoke(app, ["run", str(path), "-o", str(tmp_path / f"{model}.h5")])
        assert result.exit_code == 0, result.output
        assert ("long_bearing film assumes L/D >= 2" in " ".join(result.output.split())) == warned, result.output


def film_force_global(result, joint="O"):
    """The recorded film force on the journal in global components, from its (n, t) components (a centred journal
    takes n = x, as the solver does)."""
    e = result[f"joints/{joint}/eccentricity"]
    length = np.hypot(e[:, 0], e[:, 1])
    n = np.where(length[:, None] > 1e-300, e / np.maximum(length, 1e-300)[:, None], [1.0, 0.0])
    t = np.stack([-n[:, 1], n[:, 0]], axis=1)
    force = result[f"joints/{joint}/film_force"]
    return force[:, :1] * n + force[:, 1:] * t


def test_the_recorded_film_force_carries_the_load_at_equilibrium(simulate):
    """The spinning journal of the Ocvirk test: once settled, the film force written to the result file balances
    the load; at every sample it is what accelerates the journal with the load (m q̈ = F_film + W)."""
    spin, load, mass = 2000.0, 966.0, 1.0
    result = simulate(journal(load, 30.0, spin=spin))
    force = film_force_global(result)
    assert np.all(result["joints/O/film_active"] == 1)  # the film carries it throughout
    np.testing.assert_allclose(force[-1], [0.0, load], rtol=0, atol=1e-6 * load)
    np.testing.assert_allclose(mass * result["bodies/journal/qdd"][:, :2], force + [0.0, -load], rtol=0,
                               atol=1e-6 * load)  # q̈ is stored in float32
    eccentricity = np.hypot(*result["joints/O/eccentricity"].T)
    np.testing.assert_allclose(result["joints/O/film_thickness"], CLEARANCE - eccentricity, rtol=1e-6)


def test_the_recorded_regime_switches_at_the_contact_events(simulate):
    """The journal thrown at the wall: the film acts (and is recorded) exactly at the samples outside the dry
    contact episodes [onset, loss), with zero film force inside them and zero dry force outside."""
    result = simulate(journal(50.0, 20.0, spin=300.0, speed=2.0, viscosity=5e-4, rate=200))
    time = result["time"]
    onset, loss = result["joints/O/episodes/onset"], result["joints/O/episodes/loss"]
    loss = np.where(np.isfinite(loss), loss, np.inf)  # an episode still open at the end
    dry = np.any((time[:, None] >= onset[None, :]) & (time[:, None] < loss[None, :]), axis=1)
    active = result["joints/O/film_active"]
    assert np.any(dry) and np.any(~dry)  # precondition: both regimes sampled
    assert np.array_equal(active == 1, ~dry)
    assert np.all(result["joints/O/film_force"][dry] == 0.0) and np.all(result["joints/O/normal_force"][~dry] == 0.0)
    assert np.all(np.hypot(*result["joints/O/film_force"][~dry & (time > 0)].T) > 0.0)
    film = result["joints/O/film_thickness"]
    assert np.min(film[~dry]) >= DRY_BELOW - 1e-11 and np.max(film[dry]) <= DRY_BELOW + 1e-11


def test_a_dry_joint_writes_no_film_datasets(simulate):
    result = simulate(journal(10.0, 1.0).replace(", lubrication: {viscosity: 0.05 Pa*s, length: 10 mm}", ""))
    assert "joints/O/normal_force" in result and not any("/film_" in name for name in result)


PIN_SENSORS = """sensors:
  - {name: pin_load, type: joint_force, joint: O}
  - {name: pin_x, type: joint_force, joint: O, component: x}
  - {name: pin_y, type: joint_force, joint: O, component: y}
"""


def test_a_joint_force_sensor_on_a_lubricated_joint_measures_the_film_force_too(simulate):
    """The force in a lubricated joint is the film's while it carries the journal: the settled Ocvirk journal's pin
    force sensor reads its 966 N load, and its x, y components are the recorded film force's."""
    load = 966.0
    result = simulate(journal(load, 30.0, spin=2000.0) + PIN_SENSORS)
    assert result["sensors/pin_load"][-1] == pytest.approx(load, rel=1e-6)
    force = film_force_global(result)
    np.testing.assert_allclose(np.stack([result["sensors/pin_x"], result["sensors/pin_y"]], axis=1), force,
                               rtol=0, atol=1e-9 * load)
