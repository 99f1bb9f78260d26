"""Unit strings → SI floats, and errors that name the expected kind."""

import math

import pytest

from clearsim.units import UnitError, contact_stiffness_to_si, parse_quantity, to_si


@pytest.mark.parametrize("text, kind, si", [
    ("0.01 mm", "length", 1e-5),
    ("5000 rpm", "angular_speed", 5000 * 2 * math.pi / 60),  # 523.598... rad/s
    ("30 deg", "angle", math.pi / 6),  # 0.5236 rad
    ("207 GPa", "pressure", 207e9),
    ("85 ms", "time", 0.085),
    ("100 kHz", "frequency", 1e5),
    ("1e-4 m/s", "speed", 1e-4),
    ("0.044 kg*m^2", "inertia", 0.044),
    ("3.67 kg", "mass", 3.67),
])
def test_unit_strings_convert_to_si(text, kind, si):
    assert to_si(text, kind) == pytest.approx(si, rel=1e-12)


def test_rpm_and_degrees_by_hand():
    assert to_si("5000 rpm", "angular_speed") == pytest.approx(523.5987756, rel=1e-9)
    assert to_si("30 deg", "angle") == pytest.approx(0.5235987756, rel=1e-9)


def test_a_bare_number_is_si():
    assert to_si(0.25, "length") == 0.25
    assert to_si(3, "mass") == 3.0


def test_contact_stiffness_in_n_per_m_to_the_exponent():
    assert contact_stiffness_to_si("1.205e12 N/m^1.5", 1.5) == pytest.approx(1.205e12, rel=1e-12)
    # Meng 2015 Table 2: K = 3.81e7 in Adams' N/mm^1.5 is 3.81e7 · 1000^1.5 N/m^1.5
    assert contact_stiffness_to_si("3.81e7 N/mm^1.5", 1.5) == pytest.approx(3.81e7 * 1000**1.5, rel=1e-12)
    assert contact_stiffness_to_si(2e9, 1.0) == 2e9


def test_contact_stiffness_of_the_wrong_exponent_is_an_error():
    with pytest.raises(UnitError, match=r"N/m\^1\.5"):
        contact_stiffness_to_si("1e5 N/m", 1.5)


def test_wrong_kind_names_the_expected_kind():
    with pytest.raises(UnitError) as info:
        to_si("0.01 kg", "length")
    message = str(info.value)
    assert "expected a length" in message and "0.01 mm" in message and "'0.01 kg'" in message


def test_unknown_unit_is_an_error():
    with pytest.raises(UnitError, match="unknown unit"):
        to_si("3 furlongz", "length")


def test_a_boolean_is_not_a_number():
    with pytest.raises(UnitError):
        to_si(True, "length")


@pytest.mark.parametrize("value, kind", [
    (math.nan, "length"), (math.inf, "mass"), ("nan mm", "length"), ("-inf N", "force"),
    ("1e400 m", "length"),  # beyond floating point as written
    ("1e307 km", "length"),  # beyond floating point once converted to SI
    (10**400, "time"),  # an integer too large for a float
], ids=["nan", "inf", "nan mm", "-inf N", "1e400 m", "1e307 km", "10**400"])
def test_a_value_that_is_not_a_finite_number_is_an_error(value, kind):
    with pytest.raises(UnitError, match="expected a finite number"):
        to_si(value, kind)


def test_a_contact_stiffness_that_is_not_finite_is_an_error():
    with pytest.raises(UnitError, match="expected a finite number"):
        contact_stiffness_to_si("inf N/m^1.5", 1.5)


def test_the_unit_registry_loads_from_its_cache_and_converts_the_same(tmp_path):
    """pint's parsed definitions are cached (0.15 s saved per process); a registry from the cache converts alike."""
    from clearsim.units import new_registry

    fresh = new_registry(tmp_path / "pint")
    assert any((tmp_path / "pint").iterdir())  # the cache was written
    cached = new_registry(tmp_path / "pint")
    plain = new_registry(None)
    for text in ("0.01 mm", "5000 rpm", "30 deg", "6.6e10 N/m^1.5", "2 kN*m", "1 bar"):
        values = [float(r.Quantity(text).to_base_units().magnitude) for r in (fresh, cached, plain)]
        assert values[0] == values[1] == values[2], text


def test_a_cache_folder_that_cannot_be_made_or_is_damaged_only_costs_time(tmp_path):
    from clearsim.units import new_registry

    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert new_registry(blocker / "pint").Quantity("1 mm").to_base_units().magnitude == 0.001
    folder = tmp_path / "pint"
    new_registry(folder)
    for entry in folder.iterdir():
        entry.write_bytes(b"damaged")
    assert new_registry(folder).Quantity("1 mm").to_base_units().magnitude == 0.001


@pytest.mark.parametrize("text", ["0.8 0.9", "0.01;0.02", "0.01 mm 2", "0.1 mm 0.2 mm", "3 kg @ 2"])
def test_a_value_is_one_number_with_a_unit(text):
    """pint multiplies what it is given: '0.8 0.9' read as 0.72, '0.01;0.02' as 0.0002 — now a message."""
    with pytest.raises(UnitError, match="expected one number with a unit"):
        parse_quantity(text)


@pytest.mark.parametrize("text, si", [("6.6e10 N/m^1.5", 6.6e10), ("1e-4 kg m^2", 1e-4), ("5 1/s", 5.0),
                                      ("2 kN*m", 2000.0), ("-0.5 mm", -5e-4)])
def test_units_with_digits_and_products_still_read(text, si):
    assert float(parse_quantity(text).to_base_units().magnitude) == pytest.approx(si, rel=1e-15)
