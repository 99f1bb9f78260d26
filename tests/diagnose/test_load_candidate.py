"""An unmodelled constant load on a sliding part as a diagnosis candidate: each body sliding in a prismatic joint on
the ground gets one, a force along the joint's axis over −F_max … F_max with F_max = E_max / s (the mechanism's peak
kinetic energy over the slider's travel, from a run of the model as given), and `diagnose` names a hidden load on the
spring-driven block of tests/diagnose/drive_mechanisms.py."""

import pytest
import yaml

from clearsim.diagnose.candidates import candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism_text
from tests.diagnose.drive_mechanisms import SPRING_DRIVE
from tests.diagnose.test_drive_candidates import diagnosis_of, recorded

PUSH = 50.0  # N, the pushed block's only force: the work-energy theorem makes E_max / s exactly this
PUSHED_BLOCK = f"""
name: a block pushed along an inclined guide, a rider on it in a guide of its own
points: {{O: [0 m, 0 m]}}
bodies:
  - {{name: block, mass: 2 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}}
  - {{name: rider, mass: 0.5 kg, inertia: 0.001 kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: guide, type: prismatic, bodies: [ground, block], at: O, axis: [0.6, 0.8]}}
  - {{name: rail, type: prismatic, bodies: [block, rider], at: O, axis: [0.6, 0.8]}}
forces:
  - {{name: push, type: constant, body: block, force: [{0.6 * PUSH} N, {0.8 * PUSH} N]}}
sensors:
  - {{name: travel, type: point_displacement, body: block, direction: [0.6, 0.8]}}
solver: {{t_end: 20 ms, output_rate: 10 kHz}}
"""
HIDDEN = -250.0  # N on the spring-driven block, against its spring: 0.39 of the unit range (F_max 1115 N), 0.04 off
BLOCK_BENCH = ["--sensors", "travel,speed", "--rate", "10kHz", "--noise", "0.5%", "--seed", "3"]


def loaded(text: str):
    result = load_mechanism_text(text)
    return result.mechanism, yaml.safe_load(result.resolved_yaml)


def test_a_ground_slider_gets_a_load_along_its_axis_scaled_by_the_work_of_its_motion():
    """The block pushed from rest by 50 N along [0.6, 0.8]: its kinetic energy (with the rider it carries) is the push's
    work, so E_max / s = 50 N and the range is ±50 N; the rider slides on the moving block, not on the ground: no
    candidate. A value is written as a `constant` force along the axis, present value 0 N."""
    mechanism, document = loaded(PUSHED_BLOCK)
    found = candidates_for(mechanism, document, ["load"])
    assert [c.target for c in found] == ["block"]
    candidate = found[0]
    assert (candidate.kind, candidate.parameter, candidate.unit, candidate.logarithmic, candidate.current) == (
        "load", "force", "N", False, 0.0)
    assert (candidate.low, candidate.high) == (pytest.approx(-PUSH, rel=1e-3), pytest.approx(PUSH, rel=1e-3))
    applied = candidate.applied(document, -20.0)
    assert applied["forces"][-1] == {"type": "constant", "name": "diagnose_load_block", "body": "block",
                                     "force": ["-12.0 N", "-16.0 N"]}
    again = candidate.applied(applied, 10.0)  # a second value replaces the first
    assert [f["name"] for f in again["forces"]] == ["push", "diagnose_load_block"]
    loads = load_mechanism_text(document_text(again)).mechanism.forces
    assert loads[-1].force == (pytest.approx(6.0), pytest.approx(8.0))
    assert candidate.finding(-20.0) == "constant load of block, force = -20 N"


def test_a_hidden_constant_load_on_the_spring_driven_block_is_named_and_its_interval_holds_it(tmp_path):
    """250 N against the block's opening spring (a seal's drag the model lacks), travel and speed at 10 kHz, 0.5 %
    noise: against the dashpot and the puffer, the block's load is named, its interval holds −250 N and the record is
    explained."""
    model = tmp_path / "block.yaml"
    model.write_text(SPRING_DRIVE)
    mechanism, document = loaded(SPRING_DRIVE)
    truth = tmp_path / "truth.yaml"
    truth.write_text(document_text(candidates_for(mechanism, document, ["load"])[0].applied(document, HIDDEN)))
    found = diagnosis_of(tmp_path, model, recorded(tmp_path, truth, BLOCK_BENCH), "load,dashpot,gas_load")
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("load", "block")
    low, high = effect["interval"]["force"]
    assert low <= HIDDEN <= high
    assert found["unexplained"] is False
