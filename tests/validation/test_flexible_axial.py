"""The axial flexible link (`flexible: {model: axial, ...}`): a two-joint link as two halves sliding along the
line between its joints, joined by k = E A / L and c = 2 ζ √(k m/4). A mass on such a link oscillates at
√(k/m), stretches F L / (E A) under F, conserves energy undamped and closes the balance damped; the Flores
slider-crank tends to the rigid one as E A grows; bad input is refused with a located message."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.candidates import candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism, load_mechanism_text

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"

E, AREA, LENGTH = 200e9, 1e-6, 0.5  # Pa, m², m: k = E A / L = 4e5 N/m
STIFFNESS = E * AREA / LENGTH
TIP, LINK = 2.0, 1e-3  # kg: the mass at the free end, and the link's own mass

# A link pinned to ground at O, a mass pinned at its free end A: with the mass moving along the link and no
# gravity nothing turns, and the far half of the link (m/2) moves with the mass: ω² = k / (M + m/2).
MASS_ON_LINK = f"""
name: mass on an axial flexible link
units: SI
points: {{O: [0, 0], A: [{LENGTH}, 0]}}
bodies:
  - name: link
    mass: {LINK}
    inertia: 2e-5
    position: [{LENGTH / 2}, 0]
    flexible: {{model: axial, youngs_modulus: {E / 1e9:g} GPa, area: {AREA * 1e6:g} mm^2, stiffness_damping: BETA}}
  - {{name: tip, mass: {TIP}, inertia: 1e-3, position: [{LENGTH}, 0], velocity: [VELOCITY, 0]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, link], at: O}}
  - {{name: A, type: revolute, bodies: [link, tip], at: A}}
forces:
  - {{type: constant, name: push, body: tip, force: [0, 0]}}
sensors:
  - {{name: stretch, type: point_displacement, body: tip, direction: [1, 0]}}
solver: {{t_end: T_END, output_rate: 200 kHz, rtol: 1e-10, atol: 1e-13, max_step: 1e-4}}
"""
OMEGA = np.sqrt(STIFFNESS / (TIP + LINK / 2))
PERIOD = 2 * np.pi / OMEGA  # ≈ 14 ms


def mass_on_link(zeta=0.0, velocity=0.0, periods=100):
    """The model; `zeta`: the damping ratio of the mass's oscillation, by Rayleigh's β = 2 ζ / ω."""
    text = MASS_ON_LINK.replace("BETA", repr(float(2 * zeta / OMEGA))).replace("VELOCITY", repr(velocity))
    return text.replace("T_END", repr(float(periods * PERIOD)))


def with_pull_ramped_from_zero(text: str, folder, pull: float, on: str = "body: tip") -> str:
    """The model with `push` replaced by a pull along x that rises from 0 to `pull` over the first 10 ms (the link
    starts unloaded, so unstretched) and then stays."""
    table = folder / "pull.csv"
    table.write_text(f"time,force\n0,0\n0.01,{pull}\n")
    return text.replace("{type: constant, name: push, body: tip, force: [0, 0]}",
                        f"{{type: tabulated, name: pull, {on}, direction: [1, 0], file: '{table}'}}")


def upward_crossings(t, x):
    """Times where x crosses 0 upwards, linearly interpolated."""
    k = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    return t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])


def test_a_mass_on_a_flexible_link_oscillates_at_the_square_root_of_k_over_m(simulate):
    result = simulate(mass_on_link(velocity=0.01))
    crossings = upward_crossings(result["time"], result["sensors/stretch"])
    assert len(crossings) >= 90
    measured = 2 * np.pi * (len(crossings) - 1) / (crossings[-1] - crossings[0])
    assert measured == pytest.approx(OMEGA, rel=1e-3)


def test_a_load_stretches_the_link_by_f_l_over_e_a(simulate, tmp_path):
    pull = 1000.0  # N: 2.5 mm
    result = simulate(with_pull_ramped_from_zero(mass_on_link(zeta=0.3, periods=40), tmp_path, pull))
    settled = result["sensors/stretch"][-1]
    assert settled == pytest.approx(pull * LENGTH / (E * AREA), rel=1e-4)


def test_energy_is_conserved_without_damping(simulate):
    result = simulate(mass_on_link(velocity=0.01))
    energy = result["energy/kinetic"] + result["energy/potential"]
    scale = np.max(result["energy/kinetic"])
    assert scale > 0.5 * 0.5 * (TIP + LINK / 2) * 0.01 ** 2  # it moved: the energy given
    assert np.max(np.abs(energy - energy[0])) <= 1e-6 * scale


def test_the_damping_dissipation_closes_the_energy_balance(simulate):
    result = simulate(mass_on_link(zeta=0.02, velocity=0.01, periods=30))
    lost = result["energy/damping_dissipated"][-1]
    given = 0.5 * (TIP + LINK / 2) * 0.01 ** 2
    assert lost > 0.9 * given  # 30 periods at 2 %: e^(-2·0.02·2π·30) ≈ 5e-4 left
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-6 * lost


FLORES_ROD = "{name: rod, mass: 0.21 kg, inertia: 0.00025 kg*m^2, position: [0.11 m, 0 m]}"


def flores_with_flexible_rod(flexible: str) -> str:
    text = (CONFIGS / "slider_crank_flores.yaml").read_text()
    assert FLORES_ROD in text
    return text.replace(FLORES_ROD, FLORES_ROD[:-1] + f", flexible: {flexible}}}")


CLEARANCE_AT_THE_FIRST_END = ("joints.slider_pin.clearance=0", "joints.crank_pin.bearing_radius=10 mm",
                              "joints.crank_pin.clearance=0.5 mm", "sensors.pin_normal_force.joint=crank_pin")


@pytest.mark.parametrize("overrides", [(), CLEARANCE_AT_THE_FIRST_END], ids=["clearance at the second end", "at the first"])
def test_the_flexible_slider_crank_closes_the_energy_balance(simulate, overrides):
    """A steel rod (E = 207 GPa, A = 1 cm², L = 0.12 m: k = 1.7e8 N/m), 2 % damping, a clearance joint at either end."""
    result = simulate(flores_with_flexible_rod("{model: axial, youngs_modulus: 207 GPa, area: 1 cm^2, damping_ratio: 0.02}"),
                      *overrides)
    assert len(result["joints/" + ("crank_pin" if overrides else "slider_pin") + "/episodes/onset"]) > 0  # it hit
    assert result["energy/damping_dissipated"][-1] > 0  # the rod's damper worked
    assert np.max(np.abs(result["energy/balance_error"])) <= 1e-5 * np.max(result["energy/kinetic"])


def test_the_flexible_slider_crank_tends_to_the_rigid_one_as_the_rod_stiffens(simulate):
    """Peak contact force against the rigid rod's 45.60 kN: −4.3 % at 1e10 N/m, −0.27 % at 1000× a steel rod's
    1.7e8 N/m, −0.042 % at 1e12 N/m (≈ 6000×)."""
    rigid = np.max(simulate("slider_crank_flores.yaml")["sensors/pin_normal_force"])
    errors = [abs(np.max(simulate(flores_with_flexible_rod(f"{{model: axial, axial_stiffness: {k:g} N/m}}"))
                         ["sensors/pin_normal_force"]) / rigid - 1) for k in (1e10, 1.7e11, 1e12)]
    assert errors[1] <= 5e-3 and errors[2] <= 5e-3  # 1000× and ≈ 6000× the steel rod
    assert errors[2] < errors[1] < errors[0]  # converging


def test_loads_and_sensors_on_the_links_own_points_follow_its_ends(simulate, tmp_path):
    """A pull on the link's own point A (its second joint) stretches it; a sensor there sees F L / (E A), one at
    its first joint O sees nothing."""
    pull = 1000.0
    text = mass_on_link(zeta=0.3, periods=40).replace(f"position: [{LENGTH / 2}, 0]\n",
                                                     f"position: [{LENGTH / 2}, 0]\n    points: {{O: [{-LENGTH / 2}, 0], A: [{LENGTH / 2}, 0]}}\n")
    text = with_pull_ramped_from_zero(text, tmp_path, pull, on="body: link, point: A")
    text = text.replace("  - {name: stretch, type: point_displacement, body: tip, direction: [1, 0]}",
                        "  - {name: stretch, type: point_displacement, body: link, point: A, direction: [1, 0]}\n"
                        "  - {name: root, type: point_displacement, body: link, point: O, direction: [1, 0]}")
    assert text.count("body: link") == 3
    result = simulate(text)
    assert result["sensors/stretch"][-1] == pytest.approx(pull * LENGTH / (E * AREA), rel=1e-4)
    assert np.max(np.abs(result["sensors/root"])) <= 1e-12


def write(tmp_path, text: str):
    path = tmp_path / "flexible.yaml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("change, place, words", [
    (("youngs_modulus: 200 GPa", "youngs_modulus: -200 GPa"), "flexible → youngs_modulus", "greater than 0"),
    (("area: 1 mm^2", "area: 0 mm^2"), "flexible → area", "greater than 0"),
    (("youngs_modulus: 200 GPa, ", ""), "flexible", "youngs_modulus missing"),
    (("  - {name: A, type: revolute, bodies: [link, tip], at: A}\n", ""), "flexible", "exactly two revolute joints"),
])
def test_bad_flexible_input_is_refused_with_its_place(tmp_path, change, place, words):
    text = mass_on_link().replace(f"youngs_modulus: {E / 1e9:g} GPa, area: {AREA * 1e6:g} mm^2",
                                  "youngs_modulus: 200 GPa, area: 1 mm^2")
    assert change[0] in text
    result = CliRunner().invoke(app, ["validate", str(write(tmp_path, text.replace(*change)))])
    assert result.exit_code == 2
    assert f"bodies[0] 'link' → {place}" in result.output and words in result.output
    assert "Traceback" not in result.output


def test_diagnose_compliance_candidate_is_the_same_element(tmp_path):
    """The candidate writes the element: the same split, spring law and initial tension (the declared link's joints
    are also put in chain order for the solver, flexible.chain_ordered: the same joints)."""
    loaded = load_mechanism(CONFIGS / "slider_crank_flores.yaml")
    document = yaml.safe_load(loaded.resolved_yaml)
    candidate = next(c for c in candidates_for(loaded.mechanism, document, ["compliance"], CONFIGS) if c.target == "rod")
    fitted = load_mechanism_text(document_text(candidate.applied(document, 1e9))).mechanism.model_dump()
    declared = load_mechanism_text(flores_with_flexible_rod("{model: axial, axial_stiffness: 1e9 N/m, damping_ratio: 0.02}"))
    declared = declared.mechanism.model_dump()
    springs = [next(f for f in model["forces"] if f["name"] == "rod_compliance") for model in (fitted, declared)]
    assert springs[0]["free_length"] < 0.12 - 1e-6  # ℓ₀ = L − T₀/k: the rod is compressed at t = 0 …
    for model in (fitted, declared):
        model["joints"].sort(key=lambda joint: joint["name"])
    assert fitted == declared  # … in both


def test_a_link_loaded_at_t0_starts_carrying_its_load(simulate):
    """The positions in the file are those of t = 0 with the loads of t = 0 acting: the spring starts at the
    rigid link's tension (ℓ₀ = L − T₀/k), so a link pulled from the start by 1 kN does not ring (unstretched at
    t = 0 it would swing 5 mm peak to peak)."""
    result = simulate(mass_on_link(periods=10).replace("force: [0, 0]}", "force: [1000.0, 0]}"))
    assert np.max(np.abs(result["sensors/stretch"])) <= 1e-9
