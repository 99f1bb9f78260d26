"""Drive-line elements (spring drive, dashpot, gas load, guide friction) against closed-form solutions."""

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app

# a block on a horizontal guide through O; W a ground point 0.2 m behind it: the elements act between W and the
# block's centre, so that a lengthening stroke is the block's x
BLOCK = """
name: block on a guide
points: {O: [0 m, 0 m], W: [-0.2 m, 0 m]}
bodies:
  - {name: block, mass: 2 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m], velocity: [SPEED, 0 m/s]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [1, 0]}
forces:
  - FORCE
sensors:
  - {name: x, type: point_displacement, body: block, direction: [1, 0]}
  - {name: v, type: point_velocity, body: block, direction: [1, 0]}
  - {name: a, type: point_acceleration, body: block, direction: [1, 0]}
solver: {t_end: END, output_rate: 2 kHz, rtol: 1e-11, atol: 1e-13, max_step: 1 ms}
"""
MASS = 2.0


def block(force: str, speed: str = "0 m/s", end: str = "0.1 s") -> str:
    return BLOCK.replace("FORCE", force).replace("SPEED", speed).replace("END", end)


def energy_scale(result) -> float:
    return max(np.max(np.abs(result["energy/kinetic"])), np.max(np.abs(result["energy/potential"])))


def assert_balance_closes(result, tolerance=1e-6):
    assert np.max(np.abs(result["energy/balance_error"])) <= tolerance * energy_scale(result)


# --- spring drive -----------------------------------------------------------------------------------


def test_linear_spring_drive_releases_the_block_as_the_closed_form(simulate):
    result = simulate(block("{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], "
                            "stiffness: 800 N/m, preload: 100 N}"))
    t, k, preload = result["time"], 800.0, 100.0
    expected = preload / k * (1.0 - np.cos(np.sqrt(k / MASS) * t))  # m ẍ = P − k x, x(0) = ẋ(0) = 0
    assert np.max(np.abs(result["sensors/x"] - expected)) <= 1e-9 * 2 * preload / k
    stored = 0.5 * k * (preload / k - result["sensors/x"]) ** 2
    assert result["energy/potential"] == pytest.approx(stored, rel=1e-12, abs=1e-15)
    assert_balance_closes(result, 1e-9)


def test_free_length_gives_the_same_spring_as_its_preload(simulate):
    result = simulate(block("{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], sense: "
                            "shortening, stiffness: 800 N/m, free_length: 75 mm}"))  # pulls: P = k (0.2 − 0.075) m
    t = result["time"]
    expected = -0.125 * (1.0 - np.cos(np.sqrt(800.0 / MASS) * t))
    assert np.max(np.abs(result["sensors/x"] - expected)) <= 1e-9 * 0.25


def test_a_latched_spring_holds_no_force_until_its_release_and_the_latch_work_closes_the_balance(simulate):
    release, speed, k, preload = 0.02, 0.5, 800.0, 100.0
    result = simulate(block(f"{{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], "
                            f"stiffness: {k} N/m, preload: {preload} N, release_time: {release} s}}", f"{speed} m/s"))
    t, x = result["time"], result["sensors/x"]
    latched = t <= release
    assert np.max(np.abs(x[latched] - speed * t[latched])) <= 1e-12
    omega, start = np.sqrt(k / MASS), speed * release
    tau = t[~latched] - release
    expected = preload / k + (start - preload / k) * np.cos(omega * tau) + speed / omega * np.sin(omega * tau)
    assert np.max(np.abs(x[~latched] - expected)) <= 1e-9 * 0.3
    latch_work = 0.5 * k * (preload / k - start) ** 2 - 0.5 * k * (preload / k) ** 2  # ΔU while latched: the latch takes it
    assert result["energy/applied_work"][-1] == pytest.approx(latch_work, rel=1e-8)
    assert_balance_closes(result, 1e-9)


def piecewise_linear_integral(xs, ys, a, b):
    """∫_a^b of the function linear between the points (xs, ys) and held beyond them: the trapezoid rule on the
    pieces, exact for each."""
    lo, hi = min(a, b), max(a, b)
    nodes = np.concatenate([[lo], xs[(xs > lo) & (xs < hi)], [hi]])
    values = np.interp(nodes, xs, ys)
    integral = float(np.sum(0.5 * np.diff(nodes) * (values[1:] + values[:-1])))
    return integral if b >= a else -integral


TABLE = [(-0.01, 150.0), (0.0, 120.0), (0.02, 95.0), (0.05, 70.0), (0.08, 20.0)]  # m, N


@pytest.mark.parametrize("shift", [0.0, 0.015])  # the table's first row before s = 0, and after it (held below)
def test_tabulated_spring_stores_the_integral_of_its_table(simulate, shift):
    table = [(s + shift, f) for s, f in TABLE]
    rows = ", ".join(f"[{s * 1e3:g} mm, {f:g} N]" for s, f in table)
    result = simulate(block(f"{{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], "
                            f"table: {{rows: [{rows}]}}}}"))
    strokes, forces = np.array(table).T

    x = result["sensors/x"]
    assert x.max() > strokes[-1] + 0.01  # it passes every row and goes beyond the last one
    expected = np.array([piecewise_linear_integral(strokes, forces, s, strokes[-1]) for s in x])
    assert result["energy/potential"] == pytest.approx(expected, rel=1e-12, abs=1e-12 * expected.max())
    assert_balance_closes(result, 1e-7)  # the steps across the table's kinks: up to 3e-9 of the energy at rtol 1e-11


def test_a_spring_table_from_a_csv_file_is_the_inline_table(simulate, tmp_path):
    (tmp_path / "spring.csv").write_text("stroke,force\n" + "".join(f"{s * 1e3:g},{f / 1e3:g}\n" for s, f in TABLE))
    config = tmp_path / "spring.yaml"
    config.write_text(block("{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], table: "
                            "{file: spring.csv, stroke_column: stroke, value_column: force, stroke_unit: mm, "
                            "value_unit: kN}}"))
    rows = ", ".join(f"[{s * 1e3:g} mm, {f:g} N]" for s, f in TABLE)
    inline = simulate(block(f"{{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], "
                            f"table: {{rows: [{rows}]}}}}"))
    assert simulate(str(config))["sensors/x"] == pytest.approx(inline["sensors/x"], rel=1e-12, abs=1e-15)


# --- dashpot ----------------------------------------------------------------------------------------


def test_linear_dashpot_slows_the_block_exponentially(simulate):
    c, v0 = 8.0, 0.5
    result = simulate(block(f"{{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], damping: {c} N*s/m}}",
                            f"{v0} m/s"))
    expected = v0 * np.exp(-c * result["time"] / MASS)
    assert np.max(np.abs(result["sensors/v"] - expected)) <= 1e-8 * v0
    dissipated = 0.5 * MASS * (v0 ** 2 - expected ** 2)
    assert result["energy/dashpot_dissipated"] == pytest.approx(dissipated, rel=1e-8, abs=1e-12)
    assert np.all(result["energy/damping_dissipated"] == 0.0)  # the dashpot's own slot, not the spring-dampers'
    assert_balance_closes(result, 1e-9)


def test_orifice_dashpot_follows_the_quadratic_law(simulate):
    rho, piston, orifice, cd, v0 = 870.0, 1e-3, 2e-5, 0.7, 0.8
    b = rho * piston ** 3 / (2 * cd ** 2 * orifice ** 2)  # N s²/m², F = b ṡ²
    result = simulate(block(f"{{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], piston_area: "
                            f"{piston} m^2, orifice_area: {orifice} m^2, discharge_coefficient: {cd}, "
                            f"density: {rho} kg/m^3}}", f"{v0} m/s"))
    expected = v0 / (1.0 + b * v0 * result["time"] / MASS)
    assert np.max(np.abs(result["sensors/v"] - expected)) <= 1e-8 * v0
    dissipated = 0.5 * MASS * (v0 ** 2 - expected ** 2)
    assert result["energy/dashpot_dissipated"] == pytest.approx(dissipated, rel=1e-6, abs=1e-12)
    assert_balance_closes(result, 1e-6)


@pytest.mark.parametrize("ramp", [0.0, 0.004])
def test_dashpot_acts_only_inside_its_engagement_range(simulate, ramp):
    c, v0, start, end = 20.0, 1.0, 0.01, 0.03
    result = simulate(block(f"{{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], sense: lengthening, "
                            f"damping: {c} N*s/m, engaged: [{start * 1e3:g} mm, {end * 1e3:g} mm], "
                            f"engagement_length: {ramp * 1e3:g} mm}}", f"{v0} m/s", "0.08 s"))
    x, v = result["sensors/x"], result["sensors/v"]
    before, after = x < start, x > end
    assert before.any() and after.any()
    assert np.max(np.abs(v[before] - v0)) <= 1e-12
    # m dv/dx = −c w(x): the speed drops by c/m ∫ w dx = c/m (end − start − ramp) through the range
    assert np.max(np.abs(v[after] - (v0 - c / MASS * (end - start - ramp)))) <= 1e-8 * v0
    assert_balance_closes(result, 1e-8)


# --- gas load ---------------------------------------------------------------------------------------


def puffer_pressure(s, p0, volume, area, gamma):
    return p0 * (volume / (volume - area * s)) ** gamma


@pytest.mark.parametrize("gamma", [1.4, 1.0])
def test_adiabatic_puffer_compresses_as_p_v_gamma(simulate, gamma):
    p0, volume, area, ambient, v0 = 2e5, 2e-4, 1e-3, 1e5, 3.0
    result = simulate(block(f"{{name: puffer, type: gas_load, body: block, direction: [1, 0], area: {area} m^2, "
                            f"volume: {volume * 1e3} L, initial_pressure: {p0} Pa, p_ambient: {ambient} Pa, "
                            f"gamma: {gamma}, stroke: 150 mm}}", f"{v0} m/s", "0.05 s"))
    s = result["sensors/x"]
    assert s.max() > 0.05  # a real compression: V falls by more than a quarter
    force = (puffer_pressure(s, p0, volume, area, gamma) - ambient) * area
    assert np.max(np.abs(result["sensors/a"] + force / MASS)) <= 1e-8 * np.max(force) / MASS
    ratio = volume / (volume - area * s)
    gas_work = p0 * volume * np.log(ratio) if gamma == 1.0 else p0 * volume / (gamma - 1) * (ratio ** (gamma - 1) - 1)
    assert result["energy/potential"] == pytest.approx(gas_work - ambient * area * s, rel=1e-12, abs=1e-12)
    assert_balance_closes(result, 1e-9)


def test_spring_drive_and_puffer_stored_energies_are_written_apart_and_sum_to_the_potential(simulate):
    """The block on its horizontal guide has no gravity energy: the potential is the spring's and the gas's."""
    k, preload, p0, volume, area, gamma = 800.0, 100.0, 1e5, 1e-3, 1e-3, 1.4
    result = simulate(block(f"{{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], "
                            f"stiffness: {k} N/m, preload: {preload} N}}\n"
                            f"  - {{name: puffer, type: gas_load, body: block, direction: [1, 0], area: {area} m^2, "
                            f"volume: {volume * 1e3} L, initial_pressure: {p0} Pa, p_ambient: {p0} Pa, "
                            f"gamma: {gamma}, stroke: 500 mm}}"))
    s = result["sensors/x"]
    assert s.max() > 0.05  # both elements work
    spring = result["energy/drive_spring_stored"]
    gas = result["energy/gas_stored"]
    assert result["energy/potential"] == pytest.approx(spring + gas, rel=1e-12, abs=1e-15)
    ratio = volume / (volume - area * s)
    gas_work = p0 * volume / (gamma - 1) * (ratio ** (gamma - 1) - 1) - p0 * area * s
    samples = np.linspace(0, len(s) - 1, 5).astype(int)
    assert spring[samples] == pytest.approx(0.5 * k * (preload / k - s[samples]) ** 2, rel=1e-9)
    assert gas[samples] == pytest.approx(gas_work[samples], rel=1e-9, abs=1e-15)
    assert_balance_closes(result, 1e-9)  # counted once: inside the potential


def test_a_model_without_spring_drive_or_gas_load_writes_no_stored_energy_entries(simulate):
    result = simulate(block("{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], sense: lengthening, "
                            "damping: 4 N*s/m}", "1 m/s", "0.01 s"))
    assert "energy/drive_spring_stored" not in result and "energy/gas_stored" not in result


def test_pressure_table_gas_load_stores_its_integral(simulate):
    area, ambient = 2e-3, 1e5
    table = [(0.0, 1.0e5), (0.02, 1.5e5), (0.04, 3.0e5)]
    rows = ", ".join(f"[{s * 1e3:g} mm, {p / 1e3:g} kPa]" for s, p in table)
    result = simulate(block(f"{{name: gas, type: gas_load, body: block, direction: [1, 0], area: {area} m^2, "
                            f"p_ambient: {ambient} Pa, pressure_table: {{rows: [{rows}]}}}}", "3 m/s", "0.05 s"))
    strokes, pressures = np.array(table).T
    s = result["sensors/x"]
    assert s.max() > 0.04  # beyond the last row
    expected = [piecewise_linear_integral(strokes, (pressures - ambient) * area, 0.0, value) for value in s]
    assert result["energy/potential"] == pytest.approx(expected, rel=1e-12, abs=1e-12 * max(expected))
    assert_balance_closes(result, 1e-7)  # the steps across the table's kinks: 4e-9 of the energy at rtol 1e-11


# --- guide friction -----------------------------------------------------------------------------------

GUIDE = """
name: block on an inclined guide with friction
points: {O: [0 m, 0 m]}
bodies:
  - {name: block, mass: 2 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m], velocity: [0.6 m/s, 0.8 m/s]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [0.6, 0.8]}
forces:
  - {name: fingers, type: guide_friction, joint: guide, normal_force: 40 N,
     friction: {law: ambrosio, mu_d: 0.15, v_0: 0 m/s, v_1: 0.1 mm/s}}
sensors:
  - {name: v, type: point_velocity, body: block, direction: [0.6, 0.8]}
solver: {t_end: 0.5 s, output_rate: 2 kHz, rtol: 1e-11, atol: 1e-13, max_step: 1 ms}
"""


def test_guide_friction_decelerates_at_mu_n_over_m_and_stops(simulate):
    result = simulate(GUIDE)
    t, v = result["time"], result["sensors/v"]
    deceleration = 0.15 * 40.0 / MASS  # 3 m/s²: stops at t = 1/3 s
    sliding = v > 1e-4
    assert np.max(np.abs(v[sliding] - (1.0 - deceleration * t[sliding]))) <= 1e-9
    assert abs(v[-1]) < 1e-6 and t[sliding].max() < 1.0 / 3.0
    assert result["energy/guide_friction_dissipated"][-1] == pytest.approx(0.5 * MASS * 1.0, rel=1e-6)
    assert_balance_closes(result, 1e-8)


# --- bad input ----------------------------------------------------------------------------------------

BAD = [
    ("{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], damping: -5 N*s/m}",
     ["forces[0] 'damper' → damping", "must be at least 0"]),
    ("{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], damping: 5 N*s/m, engaged: [30 mm, 10 mm]}",
     ["forces[0] 'damper' → engaged", "needs end > start"]),
    ("{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], piston_area: -1e-3 m^2, orifice_area: "
     "1e-5 m^2, density: 870 kg/m^3}", ["forces[0] 'damper' → piston_area", "must be greater than 0"]),
    ("{name: puffer, type: gas_load, body: block, direction: [1, 0], area: 0 m^2, volume: 0.2 L, gamma: 1.4, "
     "stroke: 10 mm}", ["forces[0] 'puffer' → area", "must be greater than 0"]),
    ("{name: puffer, type: gas_load, body: block, direction: [1, 0], area: 1e-3 m^2, volume: 0.2 L, gamma: 1.4, "
     "stroke: 250 mm}", ["forces[0] 'puffer' → stroke", "used up at a stroke of V0/A = 200 mm"]),
    ("{name: fingers, type: guide_friction, joint: guid, normal_force: 50 N, friction: {law: ambrosio, mu_d: 0.1, "
     "v_0: 0 m/s, v_1: 1 mm/s}}", ["forces[0] 'fingers' → joint", "unknown joint 'guid'"]),
    ("{name: fingers, type: guide_friction, joint: pivot, normal_force: 50 N, friction: {law: ambrosio, mu_d: 0.1, "
     "v_0: 0 m/s, v_1: 1 mm/s}}", ["forces[0] 'fingers' → joint", "is a revolute joint"]),
    ("{name: fingers, type: guide_friction, joint: guide, normal_force: 50 N, friction: {law: coulomb, mu_d: 0.1}}",
     ["forces[0] 'fingers' → friction", "stick: smooth"]),
    ("{name: spring, type: spring_drive, bodies: [block, block], stiffness: 1 N/m, preload: 1 N}",
     ["forces[0] 'spring' → bodies", "connects two different bodies"]),
    ("{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], stiffness: 1 N/m}",
     ["forces[0] 'spring'", "either `preload:` or `free_length:`"]),
    ("{name: damper, type: dashpot, bodies: [ground, block], at: [O, O], damping: 1 N*s/m}",
     ["forces[0] 'damper' → at", "the two ends of the dashpot coincide"]),
]


@pytest.mark.parametrize("force, expected", BAD)
def test_bad_elements_give_located_messages_and_exit_2(tmp_path, force, expected):
    text = block(force).replace("joints:\n", "joints:\n  - {name: pivot, type: revolute, bodies: [ground, arm], at: W}\n")
    text = text.replace("bodies:\n", "bodies:\n  - {name: arm, mass: 1 kg, inertia: 0.01 kg*m^2, position: [-0.2 m, 0 m]}\n", 1)
    config = tmp_path / "bad.yaml"
    config.write_text(text)
    out = tmp_path / "never.h5"
    result = CliRunner().invoke(app, ["run", str(config), "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    for fragment in expected:
        assert fragment in result.output
    assert not out.exists()


def test_an_invalid_force_before_a_guide_friction_does_not_shift_the_place_of_its_message(tmp_path):
    force = ("{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], damping: -5 N*s/m}\n"
             "  - {name: fingers, type: guide_friction, joint: guid, normal_force: 50 N, friction: {law: ambrosio, "
             "mu_d: 0.1, v_0: 0 m/s, v_1: 1 mm/s}}")
    config = tmp_path / "bad.yaml"
    config.write_text(block(force))
    result = CliRunner().invoke(app, ["run", str(config), "-o", str(tmp_path / "never.h5")])
    assert result.exit_code == 2
    assert "forces[1] 'fingers' → joint" in result.output and "unknown joint 'guid'" in result.output


OVERRUN = """
name: a drive that pushes the puffer past its stated stroke
points: {O: [0 m, 0 m]}
bodies:
  - {name: block, mass: 2 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}
joints:
  - {name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [1, 0]}
drivers:
  - {name: push, joint: guide, motion: {law: stroke, stroke: 250 mm, duration: 50 ms}}
forces:
  - {name: puffer, type: gas_load, body: block, direction: [1, 0], area: 1e-3 m^2, volume: 0.2 L, gamma: 1.4,
     stroke: 150 mm}
solver: {t_end: 60 ms}
"""


def test_a_puffer_compressed_past_its_stroke_stops_the_run_with_a_located_message(tmp_path):
    config = tmp_path / "overrun.yaml"
    config.write_text(OVERRUN)
    out = tmp_path / "overrun.h5"
    result = CliRunner().invoke(app, ["run", str(config), "-o", str(out)])
    assert result.exit_code == 2 and "Traceback" not in result.output
    message = " ".join(result.output.split())
    assert "forces[0] 'puffer'" in message and "past its stated stroke of 150 mm" in message
    assert "used up at V0/A = 200 mm" in message
    with h5py.File(out) as written:  # the partial result is kept, flagged
        assert not written.attrs["complete"] and written["time"][-1] > 0.03


def test_the_energy_figure_shows_the_dashpot_and_guide_friction_dissipation(simulate, tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    from clearsim.plot.data import load_run
    from clearsim.plot.history import plot_energies

    config = tmp_path / "both.yaml"
    config.write_text(GUIDE.replace("forces:\n", "forces:\n  - {name: damper, type: dashpot, bodies: [ground, block], "
                                    "at: [[-0.6 m, -0.8 m], O], damping: 2 N*s/m}\n"))
    simulate(str(config))
    ax = plot_energies(load_run(next(tmp_path.glob("run*.h5"))))
    labels = {line.get_label() for line in ax.get_lines()}
    assert {"dashpot dissipated", "guide friction dissipated"} <= labels


DRIVE_LINE = [
    {"name": "closing_spring", "type": "spring_drive", "bodies": ["ground", "driving_link"],
     "at": [["0.6 m", "-0.222 m"], "A"], "stiffness": "40 kN/m", "preload": "22 kN"},
    {"name": "cushion", "type": "dashpot", "bodies": ["ground", "driving_link"], "at": [["0.6 m", "-0.222 m"], "A"],
     "sense": "lengthening", "piston_area": "20 cm^2", "orifice_area": "0.3 cm^2", "density": "870 kg/m^3",
     "engaged": ["200 mm", "400 mm"], "engagement_length": "5 mm"},
    {"name": "puffer", "type": "gas_load", "body": "moving_contact", "direction": [0, 1], "area": "80 cm^2",
     "volume": "4 L", "gamma": 1.1, "initial_pressure": "0.6 MPa", "p_ambient": "0.6 MPa", "stroke": "0.3 m"},
    {"name": "fingers", "type": "guide_friction", "joint": "contact_guide", "normal_force": "2 kN",
     "friction": {"law": "ambrosio", "mu_d": 0.15, "v_0": "0 m/s", "v_1": "1 mm/s"}},
]


def breaker_driven_by_its_drive_line() -> str:
    """The bundled breaker's YAML without its prescribed drive, driven by DRIVE_LINE over 120 ms."""
    import yaml

    from clearsim.runner import BUNDLED_CONFIG

    document = yaml.safe_load(BUNDLED_CONFIG.read_text())
    document["drivers"] = []
    document["forces"] = (document.get("forces") or []) + DRIVE_LINE
    document["solver"]["t_end"] = "120 ms"
    return yaml.safe_dump(document, sort_keys=False)


def test_the_breaker_driven_by_its_drive_line_closes_its_energy_balance(simulate):
    """The bundled breaker without its prescribed drive: a closing spring, an end-of-stroke cushion, the puffer and
    the contact fingers' friction, with the clearance joints A and J."""
    result = simulate(breaker_driven_by_its_drive_line())
    travel = result["sensors/contact_displacement"]
    assert 0.3 < travel[-1] < 0.4  # the spring closes the breaker, the cushion stops it
    for kind in ("dashpot_dissipated", "guide_friction_dissipated", "friction_dissipated"):
        assert result[f"energy/{kind}"][-1] > 10.0  # J: every element works
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-6 * np.max(result["energy/kinetic"])


SPINNING_GUIDE = """
name: a slider on a spinning arm, with friction on the arm's guide
points: {O: [0 m, 0 m], S: [0.3 m, 0 m]}
bodies:
  - {name: arm, mass: 3 kg, inertia: 0.09 kg*m^2, position: [0.25 m, 0 m], angular_velocity: 5 rad/s}
  - {name: slider, mass: 1 kg, inertia: 0.002 kg*m^2, position: [0.3 m, 0 m], velocity: [1 m/s, 1.5 m/s],
     angular_velocity: 5 rad/s}
joints:
  - {name: pivot, type: revolute, bodies: [ground, arm], at: O}
  - {name: slide, type: prismatic, bodies: [arm, slider], at: S, axis: [1, 0]}
forces:
  - {name: fingers, type: guide_friction, joint: slide, normal_force: 20 N,
     friction: {law: ambrosio, mu_d: 0.2, v_0: 0 m/s, v_1: 1 mm/s}}
sensors:
  - {name: r, type: point_displacement, body: slider, direction: [1, 0]}
solver: {t_end: 0.2 s, output_rate: 2 kHz, rtol: 1e-11, atol: 1e-13, max_step: 1 ms}
"""


def test_guide_friction_on_a_turning_guide_slides_at_the_relative_speed(simulate):
    """The sliding speed is that of the slider relative to the arm's material point under it: the friction's power
    on the two bodies is then −μ N |v|, and the balance closes."""
    result = simulate(SPINNING_GUIDE)
    assert result["energy/guide_friction_dissipated"][-1] > 0.1  # J: it slides and rubs
    assert_balance_closes(result, 1e-8)


@pytest.mark.parametrize("table, content, expected", [
    ("table", None, ["forces[0] 'spring' → table → file", "cannot read table"]),
    ("table", "stroke,force\n0,5\n0,3\n", ["forces[0] 'spring' → table → file", "the stroke column", "increase strictly"]),
    ("force_table", "stroke,force\n0,5\n", ["forces[0] 'spring' → force_table → file", "at least two rows"]),
])
def test_a_bad_stroke_table_file_is_located_at_its_key(tmp_path, table, content, expected):
    if content is not None:
        (tmp_path / "table.csv").write_text(content)
    force = (f"{{name: spring, type: spring_drive, bodies: [ground, block], at: [W, O], table: {{file: table.csv}}}}"
             if table == "table" else
             "{name: spring, type: gas_load, body: block, direction: [1, 0], force_table: {file: table.csv}}")
    config = tmp_path / "bad.yaml"
    config.write_text(block(force))
    result = CliRunner().invoke(app, ["run", str(config), "-o", str(tmp_path / "never.h5")])
    assert result.exit_code == 2 and "Traceback" not in result.output
    message = " ".join(result.output.split())
    for fragment in expected:
        assert fragment in message


def test_each_element_writes_its_stroke_and_force(simulate):
    c, v0, release = 8.0, 0.5, 0.02
    result = simulate(block(f"{{name: damper, type: dashpot, bodies: [ground, block], at: [W, O], sense: lengthening, "
                            f"damping: {c} N*s/m}}\n  - {{name: spring, type: spring_drive, bodies: [ground, block], "
                            f"at: [W, O], stiffness: 100 N/m, preload: 10 N, release_time: {release} s}}\n"
                            "  - {name: fingers, type: guide_friction, joint: guide, normal_force: 10 N, "
                            "friction: {law: ambrosio, mu_d: 0.1, v_0: 0 m/s, v_1: 1 mm/s}}", f"{v0} m/s"))
    t, x, v = result["time"], result["sensors/x"], result["sensors/v"]
    assert result["drives/damper/stroke"] == pytest.approx(x, abs=1e-15)
    assert result["drives/damper/force"] == pytest.approx(-c * v, rel=1e-12, abs=1e-15)
    spring = result["drives/spring/force"]
    assert np.all(spring[t < release] == 0.0)  # latched
    assert spring[t > release] == pytest.approx(10.0 - 100.0 * x[t > release], rel=1e-12)
    assert result["drives/fingers/sliding_velocity"] == pytest.approx(v, rel=1e-12, abs=1e-15)
    assert result["drives/fingers/force"][v > 1e-3] == pytest.approx(-1.0, rel=1e-12)
