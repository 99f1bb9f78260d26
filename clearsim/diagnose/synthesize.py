"""Measured-like data from a model: the way to test diagnosis on data with a known, hidden effect.

The measurement model of docs/diagnose.md, applied in this order:

    measured(t_k) = lowpass( sensor(t_k − τ) + noise_k ),   t_k = k / rate,  0 ≤ t_k ≤ t_end + τ

- the sensor is interpolated linearly between the run's samples (the run is written at no less
  than the requested rate); before the model's start (t − τ < 0) it holds its initial value,
  the mechanism waiting for the trigger;
- noise_k is white and Gaussian, the sensor's own noise: its standard deviation is given as a % of
  each signal's range (max − min of the clean signal) or absolutely with a unit. It is drawn with
  `numpy.random.default_rng(seed)`, so a seed gives the same record every time;
- the bench's low-pass filter (4th-order Butterworth, run forward and backward: zero phase)
  colours the noise and lowers its standard deviation roughly by √(2 f_c / rate).

The CSV has the time in ms and each sensor in a bench unit, written in the header.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from clearsim.diagnose.measured import SENSOR_TYPE_UNITS, UNIT_KINDS
from clearsim.errors import ClearsimError, did_you_mean
from clearsim.io.files import same_file
from clearsim.units import UnitError, to_si

FILTER_ORDER = 4
MAX_SAMPLES = 10_000_000  # a record of 10 million rows is ~300 MB of CSV: beyond any bench, and a run at that rate
# SI unit → (unit written in the CSV, SI value of one of it)
BENCH_UNITS = {"m": ("mm", 1e-3), "m/s": ("m/s", 1.0), "m/s^2": ("m/s^2", 1.0), "rad": ("deg", np.pi / 180.0),
               "rad/s": ("rad/s", 1.0), "rad/s^2": ("rad/s^2", 1.0), "N": ("N", 1.0)}


class SynthesisError(ClearsimError):
    """A synthesize request that cannot be carried out (bad option, unknown sensor, existing output)."""


@dataclass
class SynthesisRequest:
    config: Path
    overrides: list[str] = field(default_factory=list)
    sensors: list[str] = field(default_factory=list)  # empty: the model's output sensors
    rate: str = "15 kHz"
    noise: str = "0"  # "1%" of each signal's range, or absolute with a unit ("0.02 mm")
    lowpass: str | None = None
    trigger_offset: str = "0 ms"
    seed: int = 0
    output: Path = Path("bench.csv")
    force: bool = False


@dataclass
class Synthesized:
    output: Path
    time: np.ndarray  # s
    values: dict  # sensor → SI values as written (after noise and filter)
    noise_std: dict  # sensor → standard deviation of the added noise before the filter, SI
    units: dict  # sensor → SI unit


def _quantity(text: str, kind: str, option: str) -> float:
    try:
        return to_si(text, kind)
    except UnitError as exc:
        raise SynthesisError(f"{option} {text!r}: {exc}") from None


def _settings(request: SynthesisRequest) -> tuple[float, float | None, float]:
    if request.seed < 0:
        raise SynthesisError(f"--seed {request.seed}: the seed must be 0 or more")
    rate = _quantity(request.rate, "frequency", "--rate")
    if rate <= 0.0:
        raise SynthesisError(f"--rate {request.rate!r}: the sampling rate must be positive, e.g. --rate 15kHz")
    lowpass = None if request.lowpass is None else _quantity(request.lowpass, "frequency", "--lowpass")
    if lowpass is not None and not 0.0 < lowpass < rate / 2.0:
        raise SynthesisError(f"--lowpass {request.lowpass!r}: the cut-off must lie between 0 and half the rate "
                             f"({rate / 2e3:g} kHz)")
    return rate, lowpass, _quantity(request.trigger_offset, "time", "--trigger-offset")


def _chosen_sensors(mechanism, names: list[str]) -> list[str]:
    known = {s.name: s for s in mechanism.sensors}
    if not names:
        out = mechanism.output
        names = [n for n in (out.displacement, out.velocity) if n] or list(known)
    for name in names:
        if name not in known:
            raise SynthesisError(f"--sensors: the model has no sensor '{name}'{did_you_mean(name, known)} "
                                 f"(sensors: {', '.join(known)})")
    return names


def _noise_std(text: str, clean: np.ndarray, si_unit: str, sensor: str) -> float:
    text = text.strip()
    if text.endswith("%"):
        try:
            fraction = float(text[:-1]) / 100.0
        except ValueError:
            raise SynthesisError(f"--noise {text!r}: expected a percentage such as 1% or a value with a unit") from None
        if not np.isfinite(fraction):
            raise SynthesisError(f"--noise {text!r}: expected a finite percentage such as 1%")
        if fraction < 0.0:
            raise SynthesisError(f"--noise {text!r}: the noise level cannot be negative")
        std = fraction * float(np.ptp(clean))
    else:
        kind = UNIT_KINDS.get(si_unit)
        if kind is None:
            raise SynthesisError(f"--noise {text!r}: give the noise of '{sensor}' [{si_unit}] as a % of its range")
        try:
            std = to_si(text, kind)
        except UnitError as exc:
            raise SynthesisError(f"--noise {text!r} for sensor '{sensor}' [{si_unit}]: {exc}; "
                                 "give it as a % of each signal's range when the sensors differ in kind") from None
    if std < 0.0:
        raise SynthesisError(f"--noise {text!r}: the noise level cannot be negative")
    return std


def _checked_record(request: SynthesisRequest, loaded, rate: float, offset: float) -> list[str]:
    """The sensors to record, once everything that can be checked before the run is: the record's length
    (t_end + τ at the rate) and each sensor's --noise."""
    sensors = _chosen_sensors(loaded.mechanism, request.sensors)
    t_end = loaded.mechanism.solver.t_end
    if t_end + offset <= 0.0:
        raise SynthesisError(f"--trigger-offset {request.trigger_offset!r}: a record that starts "
                             f"{-offset * 1e3:g} ms after the trigger misses the whole run (solver.t_end = "
                             f"{t_end * 1e3:g} ms); give an offset above {-t_end * 1e3:g} ms")
    count = (t_end + offset) * rate
    if count > MAX_SAMPLES:
        raise SynthesisError(f"--rate {request.rate!r} with --trigger-offset {request.trigger_offset!r}: the record "
                             f"would hold {count:.3g} samples over {(t_end + offset) * 1e3:g} ms, more than "
                             f"{MAX_SAMPLES:.0e}; lower --rate or the trigger offset (a bench records at 1–100 kHz)")
    units = {s.name: SENSOR_TYPE_UNITS[s.type] for s in loaded.mechanism.sensors}
    for name in sensors:  # the syntax, sign and unit of --noise; a % of the range is applied after the run
        _noise_std(request.noise, np.zeros(2), units[name], name)
    return sensors


def _run_model(request: SynthesisRequest, rate: float, loaded, sensors: list[str]):
    """(mechanism, /time, {sensor: values}) of a run written at no less than `rate`."""
    from clearsim.io.hdf5 import read_result
    from clearsim.model.loader import load_mechanism
    from clearsim.runner import prepare, run_to_file
    from clearsim.solver.outputs import output_rate

    system = prepare(loaded)
    if output_rate(system) < rate:
        loaded = load_mechanism(request.config, [*request.overrides, f"solver.output_rate={rate!r} Hz"])
        system = prepare(loaded)
    with tempfile.TemporaryDirectory(prefix="clearsim-synthesize-") as folder:
        report = run_to_file(system, loaded, Path(folder) / "model.h5")
        if report.error is not None:
            raise report.error
        result = read_result(report.output)
    return loaded.mechanism, result["time"], {name: result[f"sensors/{name}"] for name in sensors}


def _record_times(t_end: float, rate: float, offset: float) -> np.ndarray:
    count = int(np.floor((t_end + offset) * rate * (1.0 + 1e-12))) + 1
    return np.arange(max(count, 0)) / rate


def _lowpass(values: np.ndarray, cutoff: float, rate: float) -> np.ndarray:
    from scipy.signal import butter, sosfiltfilt

    sos = butter(FILTER_ORDER, cutoff, btype="low", fs=rate, output="sos")
    padlen = 3 * (2 * len(sos) + 1)
    if len(values) <= padlen:
        raise SynthesisError(f"the record has {len(values)} samples, too few for the low-pass filter "
                             f"(more than {padlen} needed); raise --rate or solver.t_end")
    return sosfiltfilt(sos, values)


def synthesize(request: SynthesisRequest) -> Synthesized:
    """Run the model and write a measured-like CSV (see the module docstring)."""
    from clearsim.model.loader import load_mechanism

    output = Path(request.output)
    if output.is_dir():
        raise SynthesisError(f"-o {output}: is a folder; give the file to write, e.g. -o {output / 'bench.csv'}")
    if same_file(output, Path(request.config)):
        raise SynthesisError(f"-o {output}: that is the mechanism file being read; the record would take its place "
                             "(--force or not)\n  hint: give the record its own name, e.g. -o bench.csv")
    if output.exists() and not request.force:
        raise SynthesisError(f"{output} exists; choose another -o or pass --force to overwrite it")
    rate, cutoff, offset = _settings(request)
    loaded = load_mechanism(request.config, request.overrides)
    sensors = _checked_record(request, loaded, rate, offset)
    mechanism, model_time, signals = _run_model(request, rate, loaded, sensors)
    time = _record_times(float(model_time[-1]), rate, offset)
    if len(time) < 20:
        raise SynthesisError(f"only {len(time)} samples at {rate:g} Hz over the run and trigger offset; "
                             "raise --rate or solver.t_end")
    rng = np.random.default_rng(request.seed)
    units = {s.name: SENSOR_TYPE_UNITS[s.type] for s in mechanism.sensors if s.name in signals}
    values, noise_std = {}, {}
    for name, signal in signals.items():
        clean = np.interp(time - offset, model_time, signal)  # holds the first value before the start
        noise_std[name] = _noise_std(request.noise, clean, units[name], name)
        measured = clean + rng.normal(0.0, noise_std[name], len(time)) if noise_std[name] > 0 else clean
        values[name] = _lowpass(measured, cutoff, rate) if cutoff is not None else measured
    _write_csv(output, time, values, units, request)
    return Synthesized(output, time, values, noise_std, units)


def _write_csv(output: Path, time: np.ndarray, values: dict, units: dict, request: SynthesisRequest) -> None:
    header = ["time [ms]"] + [f"{name} [{BENCH_UNITS[units[name]][0]}]" for name in values]
    columns = [time * 1e3] + [v / BENCH_UNITS[units[name]][1] for name, v in values.items()]
    settings = (f"# synthesized by clearsim from {request.config}; --set {' '.join(request.overrides) or '(none)'}; "
                f"rate {request.rate}, noise {request.noise}, lowpass {request.lowpass or 'none'}, "
                f"seed {request.seed}")
    output.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(output, np.column_stack(columns), delimiter=",", fmt="%.10g",
               header=settings + "\n" + ",".join(header), comments="")
