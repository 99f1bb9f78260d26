"""Candidate kinds of the drive's force elements (hydraulic cylinder, spring drive, dashpot, gas load, guide friction):
each is listed with its range and unit, writes a value that loads, and a hidden change of it is named and fitted from
the travel and speed sensors of a small force-driven mechanism at 1 % noise."""

import json
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose.candidates import candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism_text

from tests.validation.test_drivelines import breaker_driven_by_its_drive_line

from .drive_mechanisms import CYLINDER, SPRING_DRIVE

DRIVE_KINDS = ["port_area", "precharge", "bulk_modulus", "preload", "dashpot", "gas_load", "guide_friction"]
BENCH = ["--sensors", "travel,speed", "--rate", "10kHz", "--noise", "1%", "--seed", "3"]
runner = CliRunner()


def drive_candidates(text: str):
    document = yaml.safe_load(text)
    return document, candidates_for(load_mechanism_text(text, "drive.yaml", (), Path(".")).mechanism, document,
                                    DRIVE_KINDS)


def written(document: dict, candidate, value: float):
    """The mechanism with the candidate's value written, as the diagnosis would run it."""
    return load_mechanism_text(document_text(candidate.applied(document, value)), "drive.yaml", (), Path(".")).mechanism


def test_each_drive_element_has_its_candidates_with_range_and_unit():
    _, cylinder = drive_candidates(CYLINDER)
    _, spring = drive_candidates(SPRING_DRIVE)
    found = {(c.kind, c.target, c.parameter): (c.current, c.low, c.high, c.unit) for c in cylinder + spring}
    assert found == {
        ("port_area", "actuator", "piston port area"): (pytest.approx(20e-6), pytest.approx(5e-6), pytest.approx(80e-6), "m^2"),
        ("port_area", "actuator", "rod port area"): (pytest.approx(20e-6), pytest.approx(5e-6), pytest.approx(80e-6), "m^2"),
        ("precharge", "actuator", "accumulator precharge"): (pytest.approx(100e5), pytest.approx(50e5), pytest.approx(120e5), "Pa"),
        ("bulk_modulus", "actuator", "bulk modulus"): (pytest.approx(1.4e9), pytest.approx(1.4e8), pytest.approx(2.8e9), "Pa"),
        ("preload", "opening_spring", "preload"): (pytest.approx(3000.0), pytest.approx(1500.0), pytest.approx(3600.0), "N"),
        ("dashpot", "end_damper", "damping"): (pytest.approx(800.0), pytest.approx(80.0), pytest.approx(8000.0), "N*s/m"),
        ("gas_load", "puffer", "puffer area"): (pytest.approx(20e-4), pytest.approx(10e-4), pytest.approx(40e-4), "m^2"),
        ("guide_friction", "fingers", "normal force"): (pytest.approx(500.0), pytest.approx(100.0), pytest.approx(2500.0), "N"),
    }


def test_each_drive_candidate_writes_its_value_with_its_unit():
    document, cylinder = drive_candidates(CYLINDER)
    for candidate in cylinder:
        changed = {c.name: c for c in written(document, candidate, 0.8 * candidate.current).forces}["actuator"]
        read = {"piston port area": changed.port_areas.piston, "rod port area": changed.port_areas.rod,
                "accumulator precharge": changed.supply.pressure, "bulk modulus": changed.bulk_modulus}
        assert read[candidate.parameter] == pytest.approx(0.8 * candidate.current, rel=1e-12)
    document, spring = drive_candidates(SPRING_DRIVE)
    for candidate in spring:
        changed = {c.name: c for c in written(document, candidate, 0.8 * candidate.current).forces}[candidate.target]
        read = {"preload": "preload", "damping": "damping", "puffer area": "area", "normal force": "normal_force"}
        assert getattr(changed, read[candidate.parameter]) == pytest.approx(0.8 * candidate.current, rel=1e-12)
    assert "2400.0 N" in document_text(next(c for c in spring if c.kind == "preload").applied(document, 2400.0))


def diagnosed(tmp_path: Path, text: str, hidden: str, kinds: str, bench: list[str] = BENCH) -> dict:
    """Synthesize the record with `hidden` set, diagnose it with the model as written (a file with no `units:`)."""
    config = tmp_path / "drive.yaml"
    config.write_text(text)
    return diagnosed_file(tmp_path, config, hidden, kinds, bench)


def diagnosed_file(tmp_path: Path, config: Path, hidden: str, kinds: str, bench: list[str]) -> dict:
    """Synthesize the bench record of `config` with `hidden` set, diagnose it against `config`; its diagnosis.json."""
    return diagnosis_of(tmp_path, config, recorded(tmp_path, config, ["--set", hidden, *bench]), kinds)


def recorded(tmp_path: Path, truth: Path, options: list[str]) -> Path:
    """The bench record `clearsim synthesize` makes of the mechanism file `truth` with `options`."""
    record = tmp_path / "bench.csv"
    result = runner.invoke(app, ["synthesize", str(truth), *options, "-o", str(record)])
    assert result.exit_code == 0, result.output
    return record


def diagnosis_of(tmp_path: Path, config: Path, record: Path, kinds: str) -> dict:
    """The diagnosis.json of `clearsim diagnose` of `config` against `record` with the candidate `kinds`."""
    result = runner.invoke(app, ["diagnose", str(config), "--measured", str(record), "-o", str(tmp_path / "report"),
                                 "--workers", "2", "--candidates", kinds])
    assert result.exit_code == 0, result.output
    return json.loads((tmp_path / "report" / "diagnosis.json").read_text())


def test_a_hidden_port_area_change_is_named_and_fitted(tmp_path):
    """The piston port 20 % smaller (16 mm² for 20): named among the cylinder's parameters, its interval holds it."""
    found = diagnosed(tmp_path, CYLINDER, "forces.actuator.port_areas.piston=16 mm^2", "port_area,precharge,bulk_modulus")
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("port_area", "actuator")
    low, high = effect["interval"]["piston port area"]
    assert low <= 16e-6 <= high
    assert effect["confirmed"]


def test_a_hidden_preload_loss_is_named_and_fitted(tmp_path):
    """The opening spring's preload 10 % low (2700 N for 3000 N), against the dashpot, the gas load and the guide
    friction as candidates."""
    found = diagnosed(tmp_path, SPRING_DRIVE, "forces.opening_spring.preload=2700 N",
                      "preload,dashpot,gas_load,guide_friction")
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("preload", "opening_spring")
    low, high = effect["interval"]["preload"]
    assert low <= 2700.0 <= high
    assert effect["confirmed"]


HYDRAULIC_BREAKER = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "uhv_breaker_hydraulic.yaml"
BREAKER_BENCH = ["--sensors", "contact_displacement,contact_velocity", "--rate", "10kHz", "--noise", "1%", "--seed", "3"]
BREAKER_KINDS = "port_area,precharge,bulk_modulus,gas_load,guide_friction"


@pytest.mark.parametrize("hidden, kind, parameter, truth", [
    ("forces.operating_cylinder.port_areas.piston=61.6 mm^2", "port_area", "piston port area", 61.6e-6),  # 20 % off 77
    ("forces.operating_cylinder.supply.pressure=288 bar", "precharge", "accumulator precharge", 288e5),  # 10 % lost
])
def test_the_hydraulic_breaker_s_drive_is_diagnosed_from_its_travel_and_speed(tmp_path, hidden, kind, parameter, truth):
    """The bundled force-driven breaker, its moving contact's travel and speed at 1 % noise: a piston port 20 % smaller
    and an accumulator precharge 10 % low are each named against the cylinder's other parameters, the puffer and the
    contact fingers, fitted within 0.1 % (each interval holds the truth), and the record is explained."""
    found = diagnosed_file(tmp_path, HYDRAULIC_BREAKER, hidden, BREAKER_KINDS, BREAKER_BENCH)
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == (kind, "operating_cylinder")
    assert effect["parameters"][parameter] == pytest.approx(truth, rel=1e-3)
    low, high = effect["interval"][parameter]
    assert low <= truth <= high
    assert effect["confirmed"] and found["unexplained"] is False


def test_a_spring_driven_breaker_s_preload_loss_is_diagnosed_from_its_travel_and_speed(tmp_path):
    """The bundled breaker closed by its spring (22 kN preload, with a cushion, the puffer and the contact fingers):
    the preload 10 % low (19.8 kN) is named against the other drive elements from the moving contact's travel and
    speed at 1 % noise, fitted within 1 %, and the record is explained."""
    found = diagnosed(tmp_path, breaker_driven_by_its_drive_line(), "forces.closing_spring.preload=19.8 kN",
                      "preload,gas_load,guide_friction,dashpot", BREAKER_BENCH)
    effect = found["effects"][0]
    assert (effect["kind"], effect["target"]) == ("preload", "closing_spring")
    assert effect["parameters"]["preload"] == pytest.approx(19.8e3, rel=1e-2)
    assert effect["confirmed"] and found["unexplained"] is False
