"""What a run writes by default: the output rate from the model's time scales, float32 only where precision allows,
compressed histories, the summary line with the file's real size, and files of the older layout still read."""

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.physics import contact
from clearsim.runner import prepare, run_to_file, summarize, written_line
from clearsim.solver.outputs import derived_output_rate, output_rate
from clearsim.solver.simulate import simulate

from .conftest import CONFIGS

CLEARANCE = 5e-3  # m: the journal flies 5 ms at 1 m/s before its one impact


def journal_yaml(stiffness=1e9, mass=1.0, law="hertz", solver=""):
    """A free journal (no gravity) centred in a bearing on the ground, hitting its wall once at 1 m/s."""
    return f"""
name: one journal
points: {{O: [0 m, 0 m]}}
defaults:
  contact: {{law: {law}, restitution: 0.8, exponent: 1.5, stiffness: {stiffness} N/m^1.5, min_impact_speed: 1e-9 m/s}}
bodies:
  - {{name: journal, mass: {mass} kg, inertia: {mass * 1e-4} kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: O, type: revolute, bodies: [ground, journal], at: O, bearing_radius: 20 mm,
      clearance: {CLEARANCE} m, initial_velocity: [1 m/s, 0 m/s]}}
sensors:
  - {{name: journal_acceleration, type: point_acceleration, body: journal, direction: [1, 0]}}
output: {{acceleration: journal_acceleration}}
solver: {{t_end: 6 ms, rtol: 1e-10, atol: 1e-13, max_step: 1 ms{solver}}}
"""


def driven_yaml(motion: str, joint="revolute"):
    """One body on the ground, turned (revolute) or pushed (prismatic) by a driver with the given motion law."""
    extra = ", axis: [1, 0]" if joint == "prismatic" else ""
    return f"""
name: driven body
points: {{O: [0 m, 0 m]}}
bodies:
  - {{name: body, mass: 1 kg, inertia: 0.01 kg*m^2, position: [0 m, 0 m]}}
joints:
  - {{name: J, type: {joint}, bodies: [ground, body], at: O{extra}}}
drivers:
  - {{name: drive, joint: J, motion: {motion}}}
solver: {{t_end: 10 ms}}
"""


def system_of(text: str, *overrides):
    return prepare(load_mechanism_text(text, overrides=overrides))


def test_the_default_rate_samples_the_shortest_contact_twenty_times():
    """A journal of 1 kg against the ground: t_c = 3.218 (m/K)^(2/5) v^(-1/5) at the reference 1 m/s (the closed
    form of clearsim.physics.contact), 0.808 ms at K = 1e9 N/m^1.5 → 20 / t_c = 24.75 kHz; a stiffer contact or a
    lighter journal samples faster, up to the 100 kHz ceiling. (The rate takes t_H = 2.943 δ_max/v of the contact
    modes, the closed form's 2.94328 to four digits: 1e-4 apart.)"""
    t_c = contact.hertz_contact_time(1.0, 1e9, 1.0)
    assert derived_output_rate(system_of(journal_yaml())) == pytest.approx(20.0 / t_c, rel=2e-4)
    assert 20.0 / t_c == pytest.approx(24_750, rel=1e-3)
    lighter = contact.hertz_contact_time(0.2, 1e9, 1.0)
    assert derived_output_rate(system_of(journal_yaml(mass=0.2))) == pytest.approx(20.0 / lighter, rel=2e-4)
    assert derived_output_rate(system_of(journal_yaml(stiffness=1e12))) == 1e5


def test_the_default_rate_samples_a_stroke_or_a_revolution_a_thousand_times():
    """With no clearance joint the drive sets the rate: 1000 samples per stroke time or per revolution of a
    constant-speed rotary drive, never below 1 kHz; a linear constant-speed drive has no time scale."""
    revolution = driven_yaml("{law: constant_speed, speed: 600 rpm}")  # 0.1 s a revolution
    assert derived_output_rate(system_of(revolution)) == pytest.approx(1e4, rel=1e-12)
    stroke = driven_yaml("{law: stroke, stroke: 0.1 m, duration: 200 ms}", "prismatic")
    assert derived_output_rate(system_of(stroke)) == pytest.approx(5e3, rel=1e-12)
    slow = driven_yaml("{law: stroke, stroke: 0.1 m, duration: 100 s}", "prismatic")
    assert derived_output_rate(system_of(slow)) == 1e3
    linear = driven_yaml("{law: constant_speed, speed: 2 m/s}", "prismatic")
    assert derived_output_rate(system_of(linear)) == 1e3


def test_the_bundled_models_are_sampled_at_100_kHz_by_their_time_scales():
    """The UHV breaker's joints A and J and the slider-crank's pin ask for more than 100 kHz (t_c ≈ 60–80 µs at
    1 m/s): the ceiling, the rate their files also set explicitly."""
    for name in ("uhv_breaker.yaml", "slider_crank_flores.yaml"):
        assert derived_output_rate(prepare(load_mechanism(CONFIGS / name))) == 1e5


def test_an_explicit_output_rate_is_honoured_and_the_file_says_where_its_rate_came_from(tmp_path):
    derived = load_mechanism_text(journal_yaml())
    explicit = load_mechanism_text(journal_yaml(), overrides=["solver.output_rate=3kHz"])
    assert output_rate(prepare(explicit)) == 3e3
    for loaded, rate, source in ((derived, derived_output_rate(prepare(derived)), "derived"),
                                 (explicit, 3e3, "solver.output_rate")):
        out = tmp_path / f"{source}.h5"
        assert run_to_file(prepare(loaded), loaded, out).complete
        data = read_result(out)
        assert data["attrs"]["output_rate_hz"] == rate and data["attrs"]["output_rate_source"] == source
        assert len(data["time"]) == int(np.floor(0.006 * rate + 1e-9)) + 1
        assert np.diff(data["time"]) == pytest.approx(1.0 / rate, rel=1e-9)


def test_the_peak_force_and_the_peak_acceleration_do_not_depend_on_the_output_rate(tmp_path):
    """A Hertz impact at 1 m/s: the peak contact force is located within the steps, the peak acceleration of the
    output sensor is taken at every step's end; both agree with the closed form F_max (F_max/m) at 2 kHz, where no
    sample falls inside the 0.8 ms impact, as at the default 24.7 kHz and at 1 MHz."""
    peak_force = contact.hertz_peak_force(1.0, 1e9, 1.0)
    summaries = {}
    for rate in ("2kHz", None, "1MHz"):
        loaded = load_mechanism_text(journal_yaml(), overrides=[f"solver.output_rate={rate}"] if rate else [])
        out = tmp_path / f"{rate}.h5"
        assert run_to_file(prepare(loaded), loaded, out).complete
        summaries[rate] = summarize(out)
    for summary in summaries.values():
        assert summary.peak_contact_force["O"] == pytest.approx(peak_force, rel=1e-6)
        assert 0.99 * peak_force <= summary.peak_acceleration[1] <= peak_force * (1 + 1e-6)
    assert summaries["2kHz"].peak_acceleration == summaries[None].peak_acceleration
    assert summaries["2kHz"].peak_contact_force == summaries[None].peak_contact_force


FULL_PRECISION = ("time", "bodies/rod/q", "joints/slider_pin/eccentricity", "joints/slider_pin/penetration",
                  "joints/slider_pin/normal_force", "joints/slider_pin/friction_force", "sensors/slider_displacement",
                  "energy/kinetic")
SINGLE_PRECISION = ("bodies/rod/qd", "bodies/rod/qdd", "joints/crank_pin/reaction", "joints/slider_pin/sliding_velocity",
                    "joints/slider_pin/penetration_rate", "drivers/crank_drive/effort", "constraints/violation")


@pytest.fixture(scope="module")
def crank_file(tmp_path_factory):
    """The slider-crank's first 3 ms (its first impact at 0.23 ms) written to a file, and its in-memory history."""
    loaded = load_mechanism(CONFIGS / "slider_crank_flores.yaml", ["solver.t_end=3ms"])
    out = tmp_path_factory.mktemp("crank") / "sc.h5"
    assert run_to_file(prepare(loaded), loaded, out).complete
    return out, simulate(prepare(loaded))


def test_positions_time_and_the_journals_eccentricity_round_trip_bit_for_bit(crank_file):
    """A clearance of 0.5 mm in coordinates of 0.17 m: float32 positions would lose the eccentricity (their
    resolution 1.5e-8 m there, far coarser for a larger mechanism), so q, the time, the eccentricity, the penetration,
    the contact forces, the energies and the sensors are float64, q and the time equal to the solver's values bit for
    bit; velocities, accelerations, reactions, rates are float32."""
    path, history = crank_file
    with h5py.File(path) as handle:
        assert all(handle[name].dtype == np.float64 for name in FULL_PRECISION)
        assert all(handle[name].dtype == np.float32 for name in SINGLE_PRECISION)
        assert handle["joints/slider_pin/mode"].dtype == np.int8
        stored_q = handle["bodies/rod/q"][()]
        stored_time = handle["time"][()]
    n = history.system.coordinate_count
    rod = history.system.body_names.index("rod")
    assert np.array_equal(stored_q, history.chunk.states[:, :n][:, 3 * rod:3 * rod + 3])
    assert np.array_equal(stored_time, history.chunk.times)
    data = read_result(path)  # read back as float64, float32 histories within their precision
    assert data["bodies/rod/qd"].dtype == np.float64
    assert data["bodies/rod/qd"] == pytest.approx(history.chunk.states[:, n:2 * n][:, 3 * rod:3 * rod + 3], rel=1e-7)


def test_every_history_is_compressed_and_the_file_is_smaller_than_its_values(crank_file):
    """gzip after the byte shuffle on every per-sample history (the episode tables are a few rows); the stored bytes
    below the values' (the first 3 ms of the slider-crank, 301 samples: 73 %; its whole 24 ms: 60 %)."""
    path, _ = crank_file
    raw = stored = 0
    with h5py.File(path) as handle:
        histories = []
        handle.visititems(lambda name, node: histories.append(node) if isinstance(node, h5py.Dataset)
                          and "/episodes/" not in name else None)
        for dataset in histories:
            assert (dataset.compression, dataset.shuffle) == ("gzip", True), dataset.name
            raw += dataset.size * dataset.dtype.itemsize
            stored += dataset.id.get_storage_size()
    assert len(histories) == 36 and stored < 0.8 * raw


def test_the_run_summary_says_what_was_written_and_how_big(tmp_path):
    out = tmp_path / "sc.h5"
    result = CliRunner().invoke(app, ["run", str(CONFIGS / "slider_crank_flores.yaml"), "-o", str(out),
                                      "--set", "solver.t_end=3ms"])
    assert result.exit_code == 0, result.output
    megabytes = out.stat().st_size / 2**20
    line = f"{out}: {megabytes:.1f} MB, 301 samples at 100 kHz, 3 bodies, 4 joints, 5 sensors"
    assert line in result.output.replace("\n", "")
    derived = tmp_path / "one.yaml"
    derived.write_text(journal_yaml())
    assert "(from the model's time scales)" in written_line(_run(derived, tmp_path / "one.h5"))


def _run(config, out):
    loaded = load_mechanism(config)
    assert run_to_file(prepare(loaded), loaded, out).complete
    return out


def as_older_layout(source, target):
    """A copy of a result file as clearsim wrote it before: every history float64, contiguous and uncompressed, no
    output_rate_hz / output_rate_source attributes."""
    with h5py.File(source) as old, h5py.File(target, "w") as new:
        for key, value in old.attrs.items():
            if not key.startswith("output_rate"):
                new.attrs[key] = value

        def copy(name, node):
            if isinstance(node, h5py.Group):
                new.require_group(name).attrs.update(node.attrs)
            else:
                values = node[()]
                new.create_dataset(name, data=values.astype(np.float64) if values.dtype.kind == "f" else values)
                new[name].attrs.update(node.attrs)

        old.visititems(copy)
    return target


def test_a_file_of_the_older_layout_reads_summarises_and_plots_as_before(crank_file, tmp_path):
    from clearsim.plot.data import load_run

    path, _ = crank_file
    older = as_older_layout(path, tmp_path / "older.h5")
    with h5py.File(older) as handle:
        assert handle["energy/kinetic"].dtype == np.float64 and handle["energy/kinetic"].compression is None
    new, old = read_result(path), read_result(older)
    assert set(new) == set(old) and all(np.array_equal(new[name], old[name]) for name in new if name != "attrs")
    assert summarize(older) == summarize(path)
    assert f"{older}: " in written_line(older) and "301 samples at 100 kHz" in written_line(older)
    assert load_run(older).time == pytest.approx(load_run(path).time, rel=0, abs=0)
