"""Values that are valid but look like a misread unit: warnings with their place and fix, never on the bundled models."""

from pathlib import Path

import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.model.plausibility import plausibility_warnings, warning_text

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
FLORES = (CONFIGS / "slider_crank_flores.yaml").read_text()


def edited(*edits: tuple[str, str], text: str = FLORES) -> str:
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return "units: SI\n" + text


def warnings_of(text: str) -> str:
    loaded = load_mechanism_text(text, "sc.yaml")
    return warning_text(plausibility_warnings(loaded.mechanism), loaded)


# A slider-crank of crank 0.17 m and rod 0.4 m: at 300 rad/s its crank pin moves at 51 m/s (the issue's 50 m/s)
LONG_CRANK = [("A: [0.05 m, 0 m]", "A: [0.17 m, 0 m]"), ("B: [0.17 m, 0 m]", "B: [0.57 m, 0 m]"),
              ("position: [0.025 m, 0 m]", "position: [0.085 m, 0 m]"),
              ("position: [0.11 m, 0 m]", "position: [0.37 m, 0 m]"),
              ("inertia: 0.0001 kg*m^2, position: [0.17 m, 0 m]", "inertia: 0.0001 kg*m^2, position: [0.57 m, 0 m]")]


@pytest.mark.parametrize("config", sorted(CONFIGS.glob("*.yaml")), ids=lambda p: p.name)
def test_no_warning_on_the_bundled_models(config):
    assert plausibility_warnings(load_mechanism(config).mechanism) == []


def test_a_flexible_link_gives_no_warning():
    """Its halves each have their pin and the slide at one place: on the breaker's pole, 'its joints span 1.11e-13 mm'
    (round-off of the pole's 90° angle) was a false alarm."""
    pole = "position: [0.177 m, 1.574 m], angle: 90 deg}"
    text = (CONFIGS / "uhv_breaker.yaml").read_text()
    assert text.count(pole) == 1
    text = text.replace(pole, pole[:-1] + ", flexible: {model: axial, youngs_modulus: 40 GPa, area: 3.1e-3 m^2}}")
    loaded = load_mechanism_text(text, "uhv.yaml")
    assert warning_text(plausibility_warnings(loaded.mechanism), loaded) == ""


def test_the_meant_values_of_the_issue_give_no_warning():
    assert warnings_of(edited(*LONG_CRANK, ("speed: 5000 rpm", "speed: 31.4"))) == ""  # 300 rpm


def test_a_bearing_radius_in_mm_read_as_metres_is_larger_than_its_links():
    text = warnings_of(edited(("bearing_radius: 10 mm", "bearing_radius: 10")))
    assert "sc.yaml:28:21  joints[2] 'slider_pin' → bearing_radius\n  bearing radius 10 m is larger than body 'rod' " \
           "that the joint joins (120 mm between its joints)\n  hint: check the unit" in text
    assert "joints[2] 'slider_pin' → journal_radius\n  c/R_B = 1 (clearance 9.99 m, bearing radius 10 m)" in text


def test_a_crank_speed_in_rpm_read_as_rad_per_second_moves_its_pin_too_fast():
    text = warnings_of(edited(*LONG_CRANK, ("speed: 5000 rpm", "speed: 300")))
    assert "drivers[0] 'crank_drive' → motion → speed\n  the driver moves a point at 51 m/s (300 rad/s (2865 rpm) " \
           "at 170 mm from its pivot), faster than a racing engine's crank pin" in text
    assert "hint: check the unit: `300 rpm` is 31.4 rad/s" in text


def test_a_position_in_mm_read_as_metres_puts_the_centre_of_mass_far_from_its_joints():
    text = warnings_of(edited(("position: [0.11 m, 0 m]", "position: [25, 43.3]")))
    assert "bodies[1] 'rod' → position\n  the centre of mass of 'rod' is 49.9 m from its nearest joint, while its " \
           "joints span 120 mm\n  hint: check the unit of `position`" in text


@pytest.mark.parametrize("old, new, expected", [
    ("stiffness: auto", "stiffness: 3.81e7", "contact stiffness 3.81e+07 N/m^1.5 of joint 'slider_pin' is 0.00058 "
                                             "times the Hertz value"),
    ("youngs_modulus: 207 GPa", "youngs_modulus: 207", "Young's modulus 207 Pa is outside the range of solids"),
    ("journal_radius: 9.5 mm", "journal_radius: 9.99999 mm", "c/R_B = 1e-06 (clearance 1e-05 mm"),
], ids=["stiffness in N/mm^1.5", "modulus in GPa", "clearance"])
def test_stiffness_modulus_and_clearance_far_outside_the_physical_range(old, new, expected):
    assert expected in warnings_of(edited((old, new)))


@pytest.mark.parametrize("harmonics, expected", [
    # at the deepest point ρ = R_B + 2a = 10.04 mm, radius of curvature ρ²/(ρ + m² a) for a cos mθ
    ("0.02 mm, 0, 0.02 mm", ""),  # an oval pocket (m = 2): 9.96 mm
    ("0.02 mm, 0, 0, 0, 0, 0, 0, 0, 0.02 mm",  # m = 8; the radii to 0.1 µm, which tells them apart near R_B too
     "the worn bore of joint 'slider_pin' has a pocket tighter than its journal "
     "(smallest radius of curvature 8.9047 mm against the journal's 9.5000 mm)"),
], ids=["wider than the journal", "tighter than the journal"])
def test_a_worn_pocket_tighter_than_the_journal(harmonics, expected):
    """The slider pin's journal is 9.5 mm in a 10 mm bore: a pocket whose radius of curvature falls below 9.5 mm
    touches it at two points (the contact's normal then flips between them and the run crawls)."""
    text = warnings_of(edited(("journal_radius: 9.5 mm ", f"wear: {{profile: {{cos: [{harmonics}]}}}}\n    journal_radius: 9.5 mm ")))
    if expected:
        assert "joints[2] 'slider_pin' → wear → profile" in text and expected in text
    else:
        assert text == ""


def test_validate_prints_the_warnings_and_still_succeeds(tmp_path):
    config = tmp_path / "sc.yaml"
    config.write_text(edited(*LONG_CRANK, ("speed: 5000 rpm", "speed: 300")))
    result = CliRunner().invoke(app, ["validate", str(config)])
    assert result.exit_code == 0, result.output
    assert f"warning: {config}:32:82  drivers[0] 'crank_drive' → motion → speed" in result.output
    assert "OK — 3" in result.output


def test_run_prints_the_warnings_before_it_starts(tmp_path):
    config = tmp_path / "sc.yaml"
    config.write_text(edited(("position: [0.11 m, 0 m]", "position: [25, 43.3]")))
    result = CliRunner().invoke(app, ["run", str(config), "-o", str(tmp_path / "sc.h5"), "--set", "solver.t_end=0.1ms"])
    assert result.exit_code == 0, result.output
    warning = result.output.index("warning: ")
    assert "the centre of mass of 'rod'" in result.output[warning:] and warning < result.output.index("complete →")
