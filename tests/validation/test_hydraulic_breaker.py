"""The UHV breaker driven by its hydraulic operating mechanism, its contact loaded by the puffer's gas and the
fingers' friction (configs/uhv_breaker_hydraulic.yaml; docs/validation.md §6, "Force-driven breaker"): the stroke of
the paper in its time, the energy balance with the cylinder's and the loads' terms, the travel figures in the run
summary, and the mechanism shared with the bundled file. One 150 ms run (≈ 1 s).
"""

import numpy as np
import pytest
import yaml

from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism
from clearsim.runner import BUNDLED_CONFIG, prepare, run_to_file, summarize

HYDRAULIC_CONFIG = BUNDLED_CONFIG.with_name("uhv_breaker_hydraulic.yaml")
SHARED_SECTIONS = ("gravity", "defaults", "points", "bodies", "joints", "sensors", "output")
PAPER_STROKE_M, PAPER_TIME_S = 0.23, 0.085  # eq. (16): the driving link's stroke and its duration
STROKE_TIME_MARGIN_S = 0.003  # the file is stated to give the paper's time within ±3 ms (clearsim: 85.3 ms)
CONTACT_STROKE_M = 0.300  # Fig. 8: the moving contact's stroke


@pytest.fixture(scope="module")
def hydraulic_run(tmp_path_factory):
    """(result file, its datasets) of the hydraulic breaker as bundled."""
    output = tmp_path_factory.mktemp("hydraulic") / "breaker.h5"
    loaded = load_mechanism(HYDRAULIC_CONFIG, ())
    report = run_to_file(prepare(loaded), loaded, output)
    assert report.complete, report.status
    return output, read_result(output)


def first_crossing(time, values, level):
    """The time `values` first reaches `level`, linear between the two samples around it."""
    i = int(np.argmax(values >= level))
    assert values[i] >= level, f"never reaches {level}"
    return float(np.interp(level, values[i - 1:i + 1], time[i - 1:i + 1]))


def test_the_mechanism_is_the_bundled_one():
    """No include in the YAML format: the sections that describe the mechanism are the bundled file's, value for
    value (a change to one file without the other fails here)."""
    bundled, hydraulic = (yaml.safe_load(path.read_text()) for path in (BUNDLED_CONFIG, HYDRAULIC_CONFIG))
    for section in SHARED_SECTIONS:
        assert hydraulic[section] == bundled[section], section
    assert "drivers" not in hydraulic and hydraulic["forces"][0]["type"] == "hydraulic_cylinder"


def test_the_cylinder_gives_the_papers_stroke_in_the_papers_time(hydraulic_run):
    _, data = hydraulic_run
    time, stroke = data["time"], data["drives/operating_cylinder/stroke"]
    stroke_time = first_crossing(time, stroke, PAPER_STROKE_M)
    assert stroke_time == pytest.approx(PAPER_TIME_S, abs=STROKE_TIME_MARGIN_S)  # clearsim: 85.3 ms
    contact = data["sensors/contact_displacement"]
    assert first_crossing(time, contact, CONTACT_STROKE_M) == pytest.approx(PAPER_TIME_S, abs=STROKE_TIME_MARGIN_S)
    settled = time > PAPER_TIME_S + 0.03  # the cushion's trapped oil holds the stroke: 233.0 mm from 109 ms on
    assert np.ptp(stroke[settled]) < 1e-3, np.ptp(stroke[settled])  # clearsim: 0.3 mm
    assert np.max(stroke) < PAPER_STROKE_M + 0.004, np.max(stroke)  # the cushion seals 3 mm past the stroke


def test_the_energy_balance_closes_with_the_drive_and_the_contacts_loads(hydraulic_run):
    _, data = hydraulic_run
    supplied = float(data["energy/hydraulic_supply_work"][-1])
    assert supplied > 5e3, supplied  # clearsim: 11.4 kJ from the accumulator's gas
    assert data["energy/guide_friction_dissipated"][-1] > 10.0  # the contact fingers: 61 J
    assert -data["drives/puffer_gas/force"][-1] > 4e3  # the puffer's gas against the stroke at its end: 5.36 kN
    error = float(np.max(np.abs(data["energy/balance_error"])))
    assert error < 1e-7 * supplied, (error, supplied)  # clearsim: 8.2e-6 J, 7e-10 of the supply work


def test_the_travel_figures_are_in_the_run_summary(hydraulic_run):
    """The summary's figures are those of the contact's travel as sampled: touch at 250 mm, the zone 200–250 mm."""
    path, data = hydraulic_run
    travel = summarize(path).travel
    time, contact = data["time"], data["sensors/contact_displacement"]
    touch = first_crossing(time, contact, 0.250)
    assert travel["sensor"] == "contact_displacement"
    assert travel["operating_time_s"] == pytest.approx(touch, abs=1e-12)  # clearsim: 68.5 ms
    assert travel["zone_speed_m_per_s"] == pytest.approx(0.050 / (touch - first_crossing(time, contact, 0.200)),
                                                         rel=1e-9)  # clearsim: 4.24 m/s
    assert travel["total_travel_m"] == pytest.approx(contact[-1] - contact[0], abs=1e-12)  # clearsim: 303.1 mm
    assert travel["damping_duration_s"] is not None
    assert travel["inside_envelope"] is True


def prescribed_stroke_run(folder, loads):
    """The hydraulic file with its cylinder replaced by the bundled file's stroke law (eq. 16), keeping the moving
    contact's `loads`, A and J at 0.01 mm, over 55 ms."""
    document = yaml.safe_load(HYDRAULIC_CONFIG.read_text())
    document["forces"] = [force for force in document["forces"] if force["name"] in loads]
    document["drivers"] = yaml.safe_load(BUNDLED_CONFIG.read_text())["drivers"]
    document["solver"]["t_end"] = "55 ms"
    if not document["forces"]:
        del document["forces"]
    config = folder / f"stroke-law-{'-'.join(loads) or 'no-loads'}.yaml"
    config.write_text(yaml.safe_dump(document, sort_keys=False))
    loaded = load_mechanism(config, ())
    report = run_to_file(prepare(loaded), loaded, config.with_suffix(".h5"))
    assert report.complete, report.status
    return read_result(config.with_suffix(".h5"))


@pytest.mark.slow
def test_the_gas_load_keeps_j_on_its_wall_and_stops_the_whirl(tmp_path):
    """docs/validation.md §6, "Force-driven breaker": under the prescribed stroke, A's load reversal at mid-stroke
    unloads J, whose journal then rolls round its bore (the whirl, −21 turns in 45–55 ms); the puffer's gas load presses
    the moving contact against its stroke, J keeps ≥ 448 N through A's hits and does not whirl. Two 55 ms runs."""
    from tests.validation.test_paper_trends import orbit_turns

    mid_stroke = slice(3500, 5000)  # 35-50 ms at the file's 100 kHz
    without, with_gas = (prescribed_stroke_run(tmp_path, loads) for loads in ((), ("puffer_gas",)))
    whirling, rolling = orbit_turns(without)
    assert whirling < -10.0 and whirling == pytest.approx(rolling, rel=0.10), (whirling, rolling)
    assert without["joints/J/normal_force"][mid_stroke].min() == 0.0  # J leaves its wall (42.6 ms)
    held, rolling_with_gas = orbit_turns(with_gas)
    assert abs(held) < 2.0 and rolling_with_gas < -10.0, (held, rolling_with_gas)  # clearsim: 0.08 turns, rolling −26.9
    assert with_gas["joints/J/normal_force"][mid_stroke].min() > 300.0  # clearsim: 448 N
