"""Candidates of the beam links and of the cylindrical contact laws: a beam link's bending stiffness E·I (and no axial
compliance candidate on its segments), a pin's contact length where the joint's elastic law is cylindrical (and no
contact stiffness written there: that law has none)."""

from pathlib import Path

import pytest
import yaml

from clearsim.diagnose.candidates import BEAM_STIFFNESS_BOUNDS, CONTACT_LENGTH_FACTORS, candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.model.resolve import resolve_clearance

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
FLEXIBLE_UHV = CONFIGS / "uhv_breaker_flexible.yaml"
SLIDER_CRANK = CONFIGS / "slider_crank_flores.yaml"
CYLINDRICAL_PIN = ["joints.slider_pin.contact={elastic: liu, length: 50 mm}"]


def loaded(config: Path, overrides=()):
    result = load_mechanism(config, list(overrides))
    return result.mechanism, yaml.safe_load(result.resolved_yaml)


def reloaded(document: dict, config: Path):
    return load_mechanism_text(document_text(document), str(config), (), config.parent).mechanism


def test_each_beam_link_has_a_bending_stiffness_candidate_that_scales_its_modulus():
    mechanism, document = loaded(FLEXIBLE_UHV)
    beams = candidates_for(mechanism, document, ["beam_stiffness"], CONFIGS)
    assert {c.target for c in beams} == {"lower_turn_arm", "main_crank_arm"}
    assert all((c.low, c.high, c.current, c.logarithmic) == (*BEAM_STIFFNESS_BOUNDS, 1.0, True) for c in beams)
    arm = next(c for c in beams if c.target == "main_crank_arm")
    changed = {b["name"]: b for b in arm.applied(document, 0.5)["bodies"]}["main_crank_arm"]["flexible"]
    assert changed["youngs_modulus"] == "103500000000.0 Pa"
    assert changed["second_moment_of_area"] == {b["name"]: b for b in document["bodies"]}["main_crank_arm"]["flexible"][
        "second_moment_of_area"]
    reloaded(arm.applied(document, 0.5), FLEXIBLE_UHV)


def test_no_compliance_candidate_splits_a_beam_segment():
    mechanism, document = loaded(FLEXIBLE_UHV)
    segments = {b.name for b in mechanism.bodies if b.name.startswith(("lower_turn_arm", "main_crank_arm"))}
    assert len(segments) == 8
    assert not {c.target for c in candidates_for(mechanism, document, ["compliance"], CONFIGS)} & segments


def test_a_cylindrical_pin_gets_a_length_candidate_and_no_stiffness_candidate():
    mechanism, document = loaded(SLIDER_CRANK, CYLINDRICAL_PIN)
    found = candidates_for(mechanism, document, ["stiffness", "contact_length"], CONFIGS)
    assert [(c.kind, c.target) for c in found] == [("contact_length", "slider_pin")]
    length = found[0]
    assert (length.current, length.low, length.high, length.unit) == (
        pytest.approx(0.05), pytest.approx(CONTACT_LENGTH_FACTORS[0] * 0.05), pytest.approx(CONTACT_LENGTH_FACTORS[1] * 0.05), "m")
    changed = reloaded(length.applied(document, 0.02), SLIDER_CRANK)
    pin = next(j for j in changed.joints if j.name == "slider_pin")
    assert resolve_clearance(pin, changed.defaults).length == pytest.approx(0.02)
    assert resolve_clearance(pin, changed.defaults).elastic == "liu"


def test_every_contact_candidate_of_a_mechanism_with_a_cylindrical_pin_writes_a_valid_file():
    """The stiffness candidate wrote `contact.stiffness` onto the cylindrical pin, which the file rejects at that key."""
    mechanism, document = loaded(SLIDER_CRANK, CYLINDRICAL_PIN)
    for candidate in candidates_for(mechanism, document, ["stiffness", "restitution", "contact_length"], CONFIGS):
        reloaded(candidate.applied(document, candidate.high), SLIDER_CRANK)
