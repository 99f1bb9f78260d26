"""The flexible links' modes and what they are near (clearsim.model.modes): the axial mode of a mass on a link, and
of two links in series each with the other held, against their closed forms; a simply supported beam link's bending
modes against Euler–Bernoulli; the "near" classification and the modes listed on constructed numbers; the run's
summary line and `flexible_modes` attribute, there for a flexible model only."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import clearsim
from clearsim.cli import app
from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism_text
from clearsim.model.flexible import flexible_link_names
from clearsim.model.modes import (MODES_REPORTED, JointFrequencies, axial_mode_frequencies,
                                  linearised_link_modes, mode_lines, mode_report, near, reported_modes)

from tests.validation.test_flexible_axial import LINK, OMEGA, PERIOD, STIFFNESS, TIP, mass_on_link
from tests.validation.test_flexible_beam import BENDING, LENGTH, MASS_PER_LENGTH, cantilever

# two links in series along x, O–A and A–B, pinned to ground at O, a mass M pinned at B; no gravity. With the second
# link held rigid the first one's slide carries its own far half, the whole second link and M: m_eff = m₁/2 + m₂ + M;
# the second one's, with the first held, its far half and M: m_eff = m₂/2 + M.
CONFIGS = Path(clearsim.__file__).parent / "configs"
K1, K2, M1, M2, TIP_MASS = 4e5, 9e5, 0.3, 0.5, 2.0
TWO_LINKS = f"""
name: two axial flexible links in series
units: SI
points: {{O: [0, 0], A: [0.5, 0], B: [1.1, 0]}}
bodies:
  - {{name: first, mass: {M1}, inertia: 1e-3, position: [0.25, 0], flexible: {{model: axial, axial_stiffness: {K1}}}}}
  - {{name: second, mass: {M2}, inertia: 1e-3, position: [0.8, 0], flexible: {{model: axial, axial_stiffness: {K2}}}}}
  - {{name: tip, mass: {TIP_MASS}, inertia: 1e-3, position: [1.1, 0]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, first], at: O}}
  - {{name: A, type: revolute, bodies: [first, second], at: A, clearance: 0.1 mm, bearing_radius: 0.02}}
  - {{name: B, type: revolute, bodies: [second, tip], at: B}}
solver: {{t_end: 1 ms}}
"""


def modes_of(text: str) -> dict[str, float]:
    loaded = load_mechanism_text(text)
    return axial_mode_frequencies(loaded.mechanism, flexible_link_names(loaded.document), loaded.base_dir)


def test_a_mass_on_a_flexible_link_has_its_axial_mode_at_the_square_root_of_k_over_m():
    assert modes_of(mass_on_link()) == {"link": pytest.approx(OMEGA / (2 * math.pi), rel=1e-9)}
    assert OMEGA == pytest.approx(math.sqrt(STIFFNESS / (TIP + LINK / 2)))


def test_each_of_two_links_in_series_has_its_mode_with_the_other_held_and_its_clearance_joint_closed():
    modes = modes_of(TWO_LINKS)
    assert modes["first"] == pytest.approx(math.sqrt(K1 / (M1 / 2 + M2 + TIP_MASS)) / (2 * math.pi), rel=1e-9)
    assert modes["second"] == pytest.approx(math.sqrt(K2 / (M2 / 2 + TIP_MASS)) / (2 * math.pi), rel=1e-9)


@pytest.mark.parametrize("mode, lowest, highest, expected", [
    (100.0, 141.0, 200.0, True),  # 141/√2 = 99.7 Hz
    (100.0, 142.0, 200.0, False),  # 142/√2 = 100.4 Hz
    (282.0, 141.0, 200.0, True),  # 200 √2 = 282.8 Hz
    (284.0, 141.0, 200.0, False),
    (150.0, 141.0, 200.0, True),
    (math.nan, 141.0, 200.0, False),
])
def test_a_mode_is_near_a_frequency_range_within_a_factor_of_the_square_root_of_two(mode, lowest, highest, expected):
    assert near(mode, lowest, highest) is expected


def test_the_report_names_the_joints_whose_contacts_or_whirl_lie_near_each_mode():
    joints = [JointFrequencies("J", (6000.0, 8000.0), (2100.0,)), JointFrequencies("A", (900.0, 1200.0), ())]
    report = mode_report({"pole": [412.0], "board": [1600.0]}, joints)
    assert [(entry["near_contacts"], entry["near_whirls"]) for entry in report] == [([], []), (["A"], ["J"])]
    lines = mode_lines(json.dumps(report))
    assert lines[0] == ("flexible link pole: axial mode 412 Hz, near no contact or whirl frequency (within ×√2); "
                        "joint J: contacts 6–8 kHz, whirl 2.1 kHz; joint A: contacts 900 Hz – 1.2 kHz")
    assert lines[1].startswith("flexible link board: axial mode 1.6 kHz, near joint A's contacts and joint J's whirl")


# the cantilever of test_flexible_beam.py unclamped and carried at x = L by a roller (a slider on a horizontal guide):
# simply supported, its bending modes ω_k = (kπ)² √(E I/(ρ A L⁴)); the roller's mass moves only along the axis, which
# the inextensible chain holds still to first order
SUPPORTED_MODES = (np.array([1, 2, 3]) * math.pi) ** 2 * math.sqrt(
    BENDING / (MASS_PER_LENGTH * LENGTH ** 4)) / (2 * math.pi)  # Hz: 15.7, 62.8, 141


def simply_supported(segments: int) -> str:
    document = yaml.safe_load(cantilever(f", segments: {segments}"))
    del document["drivers"], document["sensors"]
    document["bodies"].append({"name": "roller", "mass": 0.01, "inertia": 1e-6, "position": [LENGTH, 0]})
    document["joints"] += [{"name": "end", "type": "revolute", "bodies": ["beam", "roller"], "at": [LENGTH, 0]},
                           {"name": "guide", "type": "prismatic", "bodies": ["ground", "roller"], "at": [LENGTH, 0],
                            "axis": [1, 0]}]
    return yaml.safe_dump(document)


def supported_beam_errors(segments: int) -> np.ndarray:
    """The relative errors of the simply supported beam link's three lowest modes as linearised_link_modes gives
    them, cut into `segments` elements."""
    loaded = load_mechanism_text(simply_supported(segments))
    modes = linearised_link_modes(loaded.mechanism, ["beam"], loaded.base_dir)["beam"]
    assert len(modes) == segments  # n hinges between two supports: n transverse modes, every one the beam's
    return np.array(modes[:3]) / SUPPORTED_MODES - 1


def test_a_simply_supported_beam_links_modes_match_euler_bernoulli_and_converge():
    """At the default n = 10: −6.9·10⁻⁶, −1.2·10⁻⁴, −6.7·10⁻⁴ (the pinned ends sit on the springs' symmetric pattern,
    so the error falls as 1/n⁴, 16× per doubling, where a cantilever's falls as 1/n²)."""
    errors = np.array([supported_beam_errors(n) for n in (5, 10, 20)])
    assert np.all(np.abs(errors[1]) <= 1e-3)
    assert np.all(np.abs(errors[1:]) * 8 < np.abs(errors[:-1]))


def test_a_link_that_owns_no_mode_of_the_linearised_model_gets_the_coupled_mode_it_holds_most_of():
    """The flexible breaker with its arms cut into 10 segments: the lower linking board's axial spring holds 40 % of
    the strain energy of the 2.33 kHz mode and the lower turn arm's bending springs 58 %, so the board owns no mode;
    it is given that coupled mode (also the arm's), not none."""
    path = CONFIGS / "uhv_breaker_flexible.yaml"
    loaded = load_mechanism_text(path.read_text().replace("segments: 3", "segments: 10"), base_dir=CONFIGS)
    links = flexible_link_names(loaded.document, "axial") + flexible_link_names(loaded.document, "beam")
    modes = linearised_link_modes(loaded.mechanism, links, loaded.base_dir)
    assert all(len(modes[link]) >= 1 and math.isfinite(modes[link][0]) for link in links)
    board = modes["lower_linking_board"]
    assert len(board) == 1 and board[0] in modes["lower_turn_arm"] and 2000.0 < board[0] < 2700.0


def test_the_modes_listed_are_the_lowest_few_up_to_the_contacts_band():
    joints = [JointFrequencies("J", (2000.0, 3000.0), ()), JointFrequencies("A", (900.0, 1200.0), ())]
    ceiling = math.sqrt(2) * 3000.0  # 4243 Hz: the top of the band near the highest contact frequency
    assert reported_modes([559.0, 2143.0, 4200.0, 4300.0], joints) == [559.0, 2143.0, 4200.0]
    assert reported_modes([100.0, 200.0, 300.0, 400.0], joints) == [100.0, 200.0, 300.0][:MODES_REPORTED]
    assert reported_modes([ceiling * 1.01, ceiling * 2], joints) == []
    assert reported_modes([559.0, 2143.0], []) == [559.0]  # no clearance joint: the lowest mode


def test_the_report_and_the_summary_line_give_each_listed_mode_and_what_it_is_near():
    joints = [JointFrequencies("J", (2000.0, 3000.0), (2100.0,)), JointFrequencies("A", (900.0, 1200.0), ())]
    report = mode_report({"arm": [559.0, 2143.0, 3199.0, 6658.0]}, joints, "bending")
    assert report[0]["bending_mode_hz"] == 559.0 and report[0]["near_contacts"] == []
    assert [(m["hz"], m["near_contacts"], m["near_whirls"]) for m in report[0]["modes"]] == [
        (559.0, [], []), (2143.0, ["J"], ["J"]), (3199.0, ["J"], [])]
    assert mode_lines(json.dumps(report))[0] == (
        "flexible link arm: bending mode 559 Hz, near no contact or whirl frequency (within ×√2); higher modes "
        "2.1 kHz (near joint J's contacts and joint J's whirl), 3.2 kHz (near joint J's contacts); "
        "joint J: contacts 2–3 kHz, whirl 2.1 kHz; joint A: contacts 900 Hz – 1.2 kHz")


def test_a_summary_attribute_without_the_modes_list_still_gives_its_line():
    """A result file written before `modes` was listed: the lowest mode's line as before."""
    entry = {"link": "pole", "axial_mode_hz": 412.0, "near_contacts": [], "near_whirls": [],
             "contacts_hz": {"J": [6000.0, 8000.0]}, "whirls_hz": {}}
    assert mode_lines(json.dumps([entry])) == [
        "flexible link pole: axial mode 412 Hz, near no contact or whirl frequency (within ×√2); "
        "joint J: contacts 6–8 kHz"]


def run_cli(tmp_path, text: str):
    config, output = tmp_path / "model.yaml", tmp_path / "run.h5"
    config.write_text(text)
    result = CliRunner().invoke(app, ["run", str(config), "-o", str(output)])
    assert result.exit_code == 0, result.output
    return result.output, read_result(output)["attrs"]


def test_the_run_summary_and_the_file_give_each_flexible_links_mode(tmp_path):
    printed, attributes = run_cli(tmp_path, mass_on_link(velocity=0.01, periods=2))
    report = json.loads(attributes["flexible_modes"])
    assert [entry["link"] for entry in report] == ["link"]
    assert report[0]["axial_mode_hz"] == pytest.approx(1 / PERIOD, rel=1e-9)
    assert [mode["hz"] for mode in report[0]["modes"]] in ([], [report[0]["axial_mode_hz"]])
    assert "flexible link link: axial mode 71.2 Hz" in " ".join(printed.split())


def test_a_rigid_model_has_no_mode_line_and_no_attribute(tmp_path):
    rigid = "\n".join(line for line in mass_on_link(velocity=0.01, periods=2).splitlines()
                      if not line.strip().startswith("flexible:"))
    assert "flexible:" not in rigid
    printed, attributes = run_cli(tmp_path, rigid)
    assert "flexible_modes" not in attributes
    assert "axial mode" not in printed
