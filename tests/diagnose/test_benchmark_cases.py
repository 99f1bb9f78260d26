"""The diagnose benchmark's cases (docs/scripts/diagnose_benchmark.py): every candidate kind is hidden in one, and a
wear case writes its worn arc at the angle it states, off the positions the diagnosis screens. Nothing is simulated."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from clearsim.diagnose.candidates import KINDS
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism_text
from clearsim.physics.wear import evaluate_profile

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "scripts"))
import diagnose_benchmark as benchmark  # noqa: E402  (a script beside diagnose_studies.py, which it imports)

ANGLES = np.linspace(0.0, 2.0 * math.pi, 3600, endpoint=False)


def case(name: str) -> benchmark.Case:
    return next(c for c in benchmark.CASES if c.name == name)


def test_every_candidate_kind_is_hidden_in_a_case():
    hidden = {c.hidden[0] for c in benchmark.CASES if c.hidden}
    assert set(KINDS) - hidden == set()


def test_every_hidden_kind_is_among_its_cases_candidates():
    assert all(c.hidden[0] in c.candidates.split(",") for c in benchmark.CASES if c.hidden)


def test_the_wear_case_writes_its_arc_at_its_angle_and_depth_off_the_grid(tmp_path):
    wear = case("crank-wear-mid")
    config = benchmark.model_file(wear, tmp_path)
    document, placement = benchmark.truth_document(wear, config)
    joint = next(j for j in load_mechanism_text(document_text(document), "truth", (), config.parent).mechanism.joints
                 if j.name == "slider_pin")
    depths = evaluate_profile(joint.wear.profile.coefficients(), ANGLES)
    assert math.degrees(ANGLES[np.argmax(depths)]) == pytest.approx(170.0, abs=0.1)
    assert depths.max() == pytest.approx(0.15e-3, rel=1e-3)
    assert placement["off_grid"] >= 0.025
    assert wear.truth == "wear slider_pin depth 0.00015 around 170°"


def test_the_contact_length_case_gives_the_record_a_shorter_cylindrical_pin(tmp_path):
    length = case("crank-contact-length-low")
    config = benchmark.model_file(length, tmp_path)
    document, placement = benchmark.truth_document(length, config)
    contact = next(j for j in document["joints"] if j["name"] == "slider_pin")["contact"]
    assert contact["elastic"] == "liu"
    assert contact["length"] == "0.013 m"
    assert placement["off_grid"] >= 0.025
