"""The flexible links' axial modes and what they are near (clearsim.model.modes): the mode of a mass on a link, and
of two links in series each with the other held, against their closed forms; the "near" classification on
constructed numbers; the run's summary line and `flexible_modes` attribute, there for a flexible model only."""

import json
import math

import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism_text
from clearsim.model.flexible import flexible_link_names
from clearsim.model.modes import (JointFrequencies, axial_mode_frequencies, mode_lines,
                                  mode_report, near)

from tests.validation.test_flexible_axial import LINK, OMEGA, PERIOD, STIFFNESS, TIP, mass_on_link

# two links in series along x, O–A and A–B, pinned to ground at O, a mass M pinned at B; no gravity. With the second
# link held rigid the first one's slide carries its own far half, the whole second link and M: m_eff = m₁/2 + m₂ + M;
# the second one's, with the first held, its far half and M: m_eff = m₂/2 + M.
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
    report = mode_report({"pole": 412.0, "board": 1600.0}, joints)
    assert [(entry["near_contacts"], entry["near_whirls"]) for entry in report] == [([], []), (["A"], ["J"])]
    lines = mode_lines(json.dumps(report))
    assert lines[0] == ("flexible link pole: axial mode 412 Hz, near no contact or whirl frequency (within ×√2); "
                        "joint J: contacts 6–8 kHz, whirl 2.1 kHz; joint A: contacts 900 Hz – 1.2 kHz")
    assert lines[1].startswith("flexible link board: axial mode 1.6 kHz, near joint A's contacts and joint J's whirl")


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
    assert "flexible link link: axial mode 71.2 Hz" in " ".join(printed.split())


def test_a_rigid_model_has_no_mode_line_and_no_attribute(tmp_path):
    rigid = "\n".join(line for line in mass_on_link(velocity=0.01, periods=2).splitlines()
                      if not line.strip().startswith("flexible:"))
    assert "flexible:" not in rigid
    printed, attributes = run_cli(tmp_path, rigid)
    assert "flexible_modes" not in attributes
    assert "axial mode" not in printed
