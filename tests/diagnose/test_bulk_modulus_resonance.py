"""The oil bulk modulus sets a resonance: a cylinder whose cushion seals rings on its trapped oil, k = β A²/V, f ∝ √β,
and over many cycles a β a few % off rings out of phase with the record, a narrow well in β that the scan misses. The
candidate is screened with frequency-matched values (docs/diagnose.md §4 step 1), as a compliance is."""

from pathlib import Path

import pytest
import yaml

from .drive_mechanisms import CYLINDER
from .test_drive_candidates import diagnosed


def ringing_cylinder() -> str:
    """The block of drive_mechanisms.CYLINDER without its spring, closed onto a cushion that seals 5 mm before the end
    of the stroke: it then rings on the trapped rod-side oil at ~250 Hz, lightly damped, for the last 65 ms of 100 ms."""
    document = yaml.safe_load(CYLINDER)
    cylinder = next(f for f in document["forces"] if f["type"] == "hydraulic_cylinder")
    cylinder.update(dead_volumes=["50 cm^3", "10 cm^3"], valve={"law": "linear", "delay": "0 ms", "opening_time": "5 ms"},
                    cushion={"law": "table", "points": [["50 mm", 1], ["54 mm", 0.3], ["55 mm", 0]]})
    document["name"] = "hydraulic cylinder closing a block onto its oil cushion"
    document["forces"] = [cylinder]
    document["solver"]["t_end"] = "100 ms"
    return yaml.safe_dump(document, sort_keys=False)


def test_a_bulk_modulus_that_sets_the_cushion_ringing_is_found_in_its_narrow_well(tmp_path: Path):
    """β 0.88 GPa hidden (1.4 in the model; off the scan points), 0.1 % noise: the diagnosis finds it within 0.5 %, its
    interval holds it and the record is explained. Scanned only, the fit lands beside the well (0.888 GPa, gap 50.3 →
    3.58, unexplained)."""
    found = diagnosed(tmp_path, ringing_cylinder(), "forces.actuator.bulk_modulus=0.88 GPa", "bulk_modulus,port_area",
                      ["--sensors", "travel,speed", "--rate", "10kHz", "--noise", "0.1%", "--seed", "3"])
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("bulk_modulus", "actuator")
    assert effect["parameters"]["bulk modulus"] == pytest.approx(0.88e9, rel=5e-3)
    low, high = effect["interval"]["bulk modulus"]
    assert low <= 0.88e9 <= high
    assert found["unexplained"] is False and found["gap_after"] < 1.5
