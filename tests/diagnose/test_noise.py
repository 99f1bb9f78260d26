"""The noise level σ̂ of a record whose clearance joint rattles: the rattle is the model's dynamics, not noise.

The record is the slider-crank with its 0.5 mm clearance (it rattles through the whole crank revolution), its
sensors through the bench's 10 kHz low-pass, plus Gaussian noise of a known level through the same filter: the
truth is the standard deviation of that filtered noise. The record minus its trend counts the rattle as noise
(4× to 10× the truth); the residual against the model and the spread of repeated records do not.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt
from typer.testing import CliRunner

from clearsim.cli import app
from clearsim.diagnose import read_measured

from clearsim.diagnose.align import (QUIET, REPEATS, TREND, equivalent_bandwidth, estimate_noise, prepare_record,
                                     repeat_noise, residual_noise)
from clearsim.diagnose.synthesize import SynthesisRequest, synthesize

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
SLIDER_CRANK = CONFIGS / "slider_crank_flores.yaml"
SENSORS = ["slider_velocity", "slider_acceleration"]
RATE = 50e3
NOISE = 0.005  # of each signal's range, before the bench's filter


def bench_filter(values: np.ndarray) -> np.ndarray:
    return sosfiltfilt(butter(4, 10e3, fs=RATE, output="sos"), values)


@pytest.fixture(scope="module")
def rattling(tmp_path_factory):
    """The model's sensors (unfiltered, at the record's rate), and two records of the same test: the bench's filter
    on the model plus two draws of noise (each also through the filter)."""
    out = tmp_path_factory.mktemp("noise") / "model.csv"
    model = synthesize(SynthesisRequest(config=SLIDER_CRANK, sensors=SENSORS, rate="50kHz", output=out))
    rng = np.random.default_rng(1)
    noises = [{s: bench_filter(rng.normal(0.0, NOISE * np.ptp(model.values[s]), len(model.time))) for s in SENSORS}
              for _ in range(2)]
    records = [{s: bench_filter(model.values[s]) + noise[s] for s in SENSORS} for noise in noises]
    return model, records, noises


def test_the_trend_estimate_counts_the_rattle_as_noise(rattling):
    """What the residual and repeat estimates below are measured against: the record minus its trend is off by > 2×."""
    model, records, noises = rattling
    for s in SENSORS:
        assert estimate_noise(records[0][s], RATE).std > 2.0 * np.std(noises[0][s])


def rattle_and_noise(seed: int, noise_std: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """24 ms at the bench's 50 kHz: impacts (an impulse every 0.5 ms on average, random sizes and signs) ringing
    through a 4th-order 1.5 kHz low-pass, 30 × the noise's RMS, whose spectrum falls as f⁻⁸ above that; and white
    noise of `noise_std`; both through the bench's 10 kHz filter. Returns (record, noise alone)."""
    rng = np.random.default_rng(seed)
    count = int(0.024 * RATE)
    impulses = np.where(rng.random(count) < 1.0 / (0.5e-3 * RATE), rng.normal(size=count), 0.0)
    from scipy.signal import sosfilt
    rattle = sosfilt(butter(4, 1.5e3, fs=RATE, output="sos"), impulses)
    rattle *= 30.0 * noise_std / np.std(rattle)
    noise = bench_filter(rng.normal(0.0, noise_std, count))
    return bench_filter(rattle) + noise, noise


def test_the_noise_floor_under_a_rattle_is_the_noise_not_the_rattle():
    """A record whose rattle fills the flat part of its spectrum below ~5 kHz, over white noise up to the bench's
    10 kHz filter: σ̂ in the 500 Hz comparison band is within 0.7–1.3 × that of the noise alone in 8 records (measured
    0.77–1.20; 20–50× with the flat part's mean as the floor), and the bench's bandwidth is found."""
    for seed in range(8):
        record, noise = rattle_and_noise(seed)
        truth = estimate_noise(noise, RATE)
        found = estimate_noise(record, RATE)
        ratio = found.filtered(500.0, RATE).std / truth.filtered(500.0, RATE).std
        assert 0.7 < ratio < 1.3, (seed, ratio)
        assert found.bandwidth == pytest.approx(10e3, rel=0.2)


def test_the_residual_against_the_model_leaves_the_rattle_out(rattling):
    model, records, noises = rattling
    record = prepare_record(model.time, records[0])
    assert all(n.estimator == TREND for n in record.noise.values())
    estimates = residual_noise(record, model.time, model.values, 0.0)
    for s in SENSORS:
        truth = np.std(noises[0][s])
        low, high = estimates[s].interval()
        assert estimates[s].estimator == QUIET
        assert low <= truth <= high, (s, estimates[s].std / truth, low / truth, high / truth)
        assert high / low < 1.4  # an interval that says something (ν ≈ 150)


def test_repeated_records_give_the_noise_whatever_the_model(rattling):
    model, records, noises = rattling
    for s in SENSORS:
        estimate = repeat_noise([records[0][s], records[1][s]], RATE)
        truth = np.std(noises[0][s])
        low, high = estimate.interval()
        assert estimate.estimator == REPEATS
        assert low <= truth <= high, (s, estimate.std / truth, low / truth, high / truth)


def test_the_interval_covers_the_noise_of_pure_noise_records():
    """σ̂ in a 2 kHz comparison band of white noise, 1200 samples (a record's length): the 95 % χ² interval holds the
    true in-band σ in at least 90 % of 200 records, and is not wider than needed (its half-width ≈ 2 standard
    deviations of σ̂/σ over the records)."""
    rng = np.random.default_rng(7)
    truth = np.sqrt(2.0 / RATE * equivalent_bandwidth(2e3))
    estimates = [estimate_noise(rng.normal(size=1200), RATE).filtered(2e3, RATE) for _ in range(200)]
    covered = np.mean([low <= truth <= high for low, high in (e.interval() for e in estimates)])
    spread = np.std([e.std / truth for e in estimates])
    half_width = np.mean([(e.interval()[1] - e.interval()[0]) / (2.0 * e.std) for e in estimates])
    assert covered >= 0.9
    assert half_width < 3.0 * spread


def test_diagnose_takes_the_noise_from_repeated_records(tmp_path):
    """`--measured` twice: the noise from the repeats' spread, stated with its interval in diagnosis.json, which holds
    the true noise in the comparison band (the noisy record minus the noiseless one of the same seed)."""
    runner = CliRunner()
    bench = ["--sensors", "slider_velocity", "--rate", "50kHz", "--noise", "0.5%", "--lowpass", "10kHz"]
    records = []
    for seed in (3, 4):
        records.append(tmp_path / f"bench-{seed}.csv")
        made = runner.invoke(app, ["synthesize", str(SLIDER_CRANK), *bench, "--seed", str(seed), "-o", str(records[-1])])
        assert made.exit_code == 0, made.output
    result = runner.invoke(app, ["diagnose", str(SLIDER_CRANK), "--measured", str(records[0]), "--measured",
                                 str(records[1]), "--candidates", "mass", "--workers", "1", "-o", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    found = json.loads((tmp_path / "out" / "diagnosis.json").read_text())
    noise = found["noise"]["slider_velocity"]
    assert noise["estimator"] == REPEATS and found["repeats"] == [str(records[1])]
    assert noise["interval"][0] < noise["std"] < noise["interval"][1]
    clean = tmp_path / "clean.csv"
    made = runner.invoke(app, ["synthesize", str(SLIDER_CRANK), *bench[:-4], "--lowpass", "10kHz", "--noise", "0%",
                               "--seed", "3", "-o", str(clean)])
    assert made.exit_code == 0, made.output
    first, noiseless = (read_measured(path, {"slider_velocity": "m/s"}) for path in (records[0], clean))
    truth = estimate_noise(first.values["slider_velocity"] - noiseless.values["slider_velocity"], RATE)
    assert noise["interval"][0] < truth.filtered(found["comparison_lowpass_hz"], RATE).std < noise["interval"][1]
    assert "the spread of the repeated records" in (tmp_path / "out" / "report.md").read_text()


def test_diagnose_does_not_count_a_rattle_it_does_not_replay_as_noise(tmp_path):
    """The slider-crank's 0.5 mm slider pin rattling, the record's journal started 1 µm off (a realisation of the chaotic
    impacts that no model run repeats, as on a bench), slider displacement and velocity, 0.5 % noise through a 10 kHz
    filter: σ̂ of each sensor in diagnosis.json is within 1.5× the true noise's in the comparison band (measured: the
    velocity 1.18, 8.8 with the flat part's mean as the floor: the residual against the model holds both rattles, the
    record minus its trend the record's; the displacement 1.06). The true noise is the noisy record minus the
    noiseless one of the same seed."""
    runner = CliRunner()
    bench = ["--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz", "--seed", "3",
             "--set", "joints.slider_pin.initial_eccentricity=[1e-6 m, 0 m]"]
    for name, noise in (("noisy.csv", "0.5%"), ("clean.csv", "0%")):
        made = runner.invoke(app, ["synthesize", str(SLIDER_CRANK), *bench, "--noise", noise, "-o", str(tmp_path / name)])
        assert made.exit_code == 0, made.output
    result = runner.invoke(app, ["diagnose", str(SLIDER_CRANK), "--measured", str(tmp_path / "noisy.csv"), "--candidates",
                                 "restitution", "--fit-top", "1", "--ensemble", "1", "--workers", "2",
                                 "-o", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    found = json.loads((tmp_path / "out" / "diagnosis.json").read_text())
    units = {"slider_displacement": "m", "slider_velocity": "m/s"}
    noisy, clean = (read_measured(tmp_path / name, units) for name in ("noisy.csv", "clean.csv"))
    band = found["comparison_lowpass_hz"]
    for sensor in units:
        truth = estimate_noise(noisy.values[sensor] - clean.values[sensor], RATE).filtered(band, RATE).std
        ratio = found["noise"][sensor]["std"] / truth
        assert 1.0 / 1.5 < ratio < 1.5, (sensor, ratio, found["noise"][sensor]["estimator"])


def test_a_repeat_without_a_sensor_of_the_first_record_is_one_message(tmp_path):
    first, second = tmp_path / "a.csv", tmp_path / "b.csv"
    first.write_text("time [ms],slider_velocity [m/s]\n" + "".join(f"{k * 0.02},{k}\n" for k in range(1201)))
    second.write_text("time [ms],slider_displacement [mm]\n" + "".join(f"{k * 0.02},{k}\n" for k in range(1201)))
    result = CliRunner().invoke(app, ["diagnose", str(SLIDER_CRANK), "--measured", str(first), "--measured",
                                      str(second), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "b.csv: missing column for sensor 'slider_velocity'" in result.output
    assert "Traceback" not in result.output
