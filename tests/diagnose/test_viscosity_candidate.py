"""The oil viscosity of a lubricated joint as a diagnosis candidate: each lubricated clearance joint gets one, written
on that joint alone (over `defaults.lubrication`), and `diagnose` names a hidden thinner oil at its joint.

The diagnosed mechanism: the journal of tests/validation/test_lubricated_joint.py (R_J = 10 mm, c = 50 µm, a 10 mm
short-bearing film of 50 mPa·s, 966 N, 2000 rad/s) started centred, with two proximity probes; the first 10 ms (it
settles within 2 ms), `solver.method: rosenbrock` (the film's squeeze damping is stiff: docs/model-contact.md)."""

import inspect
import json
import re
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from clearsim.cli import app, diagnose
from clearsim.diagnose.candidates import KINDS, VISCOSITY_FACTORS, candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.model.resolve import is_clearance_joint, resolve_clearance

CONFIG = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"
PRESENT = 0.05  # Pa·s
JOURNAL_BENCH = """
name: journal in a lubricated bearing, two proximity probes
gravity: [0 m/s^2, 0 m/s^2]
defaults:
  contact: {law: lankarani_nikravesh, restitution: 0.9, exponent: 1.5, stiffness: 1e12 N/m^1.5}
  friction: {law: coulomb, mu_d: 0.1}
points: {O: [0 m, 0 m]}
bodies:
  - {name: journal, mass: 1 kg, inertia: 1e-4 kg*m^2, position: [0 m, 0 m]}
joints:
  - {name: O, type: revolute, bodies: [ground, journal], at: O, bearing_radius: 10.05 mm, clearance: 0.05 mm,
     lubrication: {viscosity: 50 mPa*s, length: 10 mm}}
drivers:
  - {name: spin, body: journal, coordinate: angle, motion: {law: constant_speed, speed: 2000 rad/s}}
forces:
  - {name: load, type: constant, body: journal, force: [0 N, -966 N]}
sensors:
  - {name: probe_x, type: point_displacement, body: journal, direction: [1, 0]}
  - {name: probe_y, type: point_displacement, body: journal, direction: [0, 1]}
solver: {t_end: 10 ms, output_rate: 50 kHz, method: rosenbrock}
"""
JOURNAL_PROBES = ["--sensors", "probe_x,probe_y", "--rate", "50kHz", "--lowpass", "10kHz", "--trigger-offset", "0.1ms",
                  "--noise", "0.5%", "--seed", "3"]
HIDDEN = 0.028  # Pa·s: the oil 0.56 times as viscous as assumed, 0.054 of the unit range off the scan points


def loaded(overrides):
    result = load_mechanism(CONFIG, list(overrides))
    return result.mechanism, yaml.safe_load(result.resolved_yaml)


def viscosities(document: dict) -> dict[str, float]:
    """Each clearance joint's oil viscosity μ (0: dry) in the mechanism the document describes."""
    mechanism = load_mechanism_text(document_text(document), str(CONFIG), (), CONFIG.parent).mechanism
    return {j.name: resolve_clearance(j, mechanism.defaults).viscosity for j in mechanism.joints
            if is_clearance_joint(j)}


def test_each_lubricated_joint_gets_a_viscosity_candidate_written_on_that_joint_alone():
    """Both pins lubricated through `defaults.lubrication`: a candidate each, 0.1 … 10 × 50 mPa·s, shown in mPa·s;
    a value written into one joint leaves the other's oil as it was."""
    mechanism, document = loaded(["defaults.lubrication={viscosity: 50 mPa*s, length: 9 mm}",
                                  "joints.crank_pin.bearing_radius=10 mm", "joints.crank_pin.clearance=0.1 mm"])
    found = candidates_for(mechanism, document, ["viscosity"], CONFIG.parent)
    assert {c.target for c in found} == {"crank_pin", "slider_pin"}
    for candidate in found:
        assert (candidate.kind, candidate.parameter, candidate.unit, candidate.logarithmic) == (
            "viscosity", "viscosity", "Pa*s", True)
        assert (candidate.current, candidate.low, candidate.high) == (
            pytest.approx(PRESENT), pytest.approx(VISCOSITY_FACTORS[0] * PRESENT),
            pytest.approx(VISCOSITY_FACTORS[1] * PRESENT))
    slider = next(c for c in found if c.target == "slider_pin")
    assert viscosities(slider.applied(document, HIDDEN)) == {"crank_pin": pytest.approx(PRESENT),
                                                             "slider_pin": pytest.approx(HIDDEN, rel=1e-12)}
    assert slider.finding(HIDDEN) == "oil viscosity in joint slider_pin, viscosity = 28 mPa·s"


def test_a_dry_clearance_joint_has_no_viscosity_candidate():
    mechanism, document = loaded([])
    assert candidates_for(mechanism, document, ["viscosity"], CONFIG.parent) == []


def test_a_hidden_thinner_oil_is_named_at_its_joint_and_its_interval_holds_it(tmp_path):
    """A journal bench (a bearing test rig's two proximity probes): the oil at 28 mPa·s where the model says 50 (a hot
    or lighter oil), the journal sinks further under its load; at 0.5 % noise, against the joint's clearance and the
    journal's mass, the viscosity of joint O is named, its interval holds 28 mPa·s and the record is explained."""
    config = tmp_path / "journal.yaml"
    config.write_text(JOURNAL_BENCH)
    runner = CliRunner()
    record = tmp_path / "bench.csv"
    result = runner.invoke(app, ["synthesize", str(config), "--set", f"joints.O.lubrication.viscosity={HIDDEN} Pa*s",
                                 *JOURNAL_PROBES, "-o", str(record)])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["diagnose", str(config), "--measured", str(record), "-o", str(tmp_path / "report"),
                                 "--workers", "2", "--candidates", "viscosity,clearance,mass"])
    assert result.exit_code == 0, result.output
    found = json.loads((tmp_path / "report" / "diagnosis.json").read_text())
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("viscosity", "O")
    low, high = effect["interval"]["viscosity"]
    assert low <= HIDDEN <= high
    assert found["unexplained"] is False


def test_the_candidates_option_names_every_kind():
    """`diagnose --help` lists the kinds `--candidates` takes: every kind registered, viscosity included."""
    listed = inspect.signature(diagnose).parameters["candidates"].default.help
    assert set(KINDS) - set(re.findall(r"[a-z_]+", listed)) == set()
