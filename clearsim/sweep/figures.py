"""Figures of merit of a case, read against its ideal reference (definitions: docs/sweeps.md).

`read_record` (or `kept_record`, from what the run kept in memory of the file it wrote) runs where the case ran (a
pool or Dask worker) and keeps only what the summary needs; the figures that compare with the ideal case are taken
as soon as both records are in (`settled`), and the case's histories dropped then.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from clearsim.io.hdf5 import read_result
from clearsim.runner import Kept, summarize, summary_dataset, summary_of

NAN = math.nan
NO_SAMPLES = np.empty(0)


@dataclass
class CaseRecord:
    """One result file, reduced: the output histories and the per-run figures."""

    complete: bool
    status: str
    time: np.ndarray
    velocity: np.ndarray | None  # the output velocity sensor, m/s
    displacement: np.ndarray | None  # the output displacement sensor, m
    peak_acceleration: float  # max |output acceleration|, m/s²
    contact: dict[str, tuple[float, float, float, float]] = field(default_factory=dict)  # F_max, free, impact, contact
    steps: int = 0
    rejected_steps: int = 0
    wall_time: float = NAN
    warnings: str = ""  # the result file's `warnings` attribute
    travel: dict = field(default_factory=dict)  # the `travel_figures` attribute (clearsim.travel), SI; {} without
    relative: dict | None = None  # relative_figures against its ideal case, once taken (`settled`); None before


def settled(record: CaseRecord, ideal: CaseRecord | None, fraction: float) -> CaseRecord:
    """The record with its figures against `ideal` taken and its histories dropped: what the summary needs of it. A
    sweep keeps every record until it ends; the histories (24 bytes a sample, 0.2 MB for a UHV case) of 10 000 cases
    would take 2 GB."""
    return replace(record, time=NO_SAMPLES, velocity=None, displacement=None,
                   relative=relative_figures(record, ideal, fraction))


def _sensor(data: dict, name: str | None) -> np.ndarray | None:
    key = f"sensors/{name}"
    return np.asarray(data[key], dtype=float) if name and key in data else None


RECORD_JOINT_DATASETS = ("/normal_force", "/mode")  # of the summary_dataset histories, what a record reads per joint


def record_dataset(output):
    """Whether a dataset is read for a record: the time, the output sensors, each clearance joint's normal force and
    mode (the other sensors and the stick flags are left unread: a UHV case's figures file reads in 36 ms instead of 46)."""
    sensors = {f"sensors/{name}" for name in (output.displacement, output.velocity, output.acceleration) if name}
    return lambda name: name == "time" or name in sensors or (summary_dataset(name)
                                                               and name.endswith(RECORD_JOINT_DATASETS))


def read_record(path: Path, output) -> CaseRecord:
    """The record of a result file; `output` is the mechanism's OutputSensors."""
    data = read_result(path, record_dataset(output))
    return _record(data, summarize(path, data), output)


def kept_record(kept: Kept, roles: dict, output) -> CaseRecord:
    """read_record of the file a run has just written, from what it kept in memory of it (run_to_file with
    keep=record_dataset(output)): `roles` is the file's `output:` block (role → sensor name), `output` the mechanism's
    OutputSensors. The same record, without opening the file again (8 ms of a UHV case's 270)."""
    return _record(kept.data, summary_of(kept.data, roles, kept.episode_peaks), output)


def _record(data: dict, summary, output) -> CaseRecord:
    attrs = data["attrs"]
    contact = {joint: (force, *summary.contact_time_share[joint]) for joint, force in summary.peak_contact_force.items()}
    return CaseRecord(
        complete=bool(attrs.get("complete", False)), status=str(attrs.get("status", "")),
        time=np.asarray(data.get("time", np.empty(0)), dtype=float),
        velocity=_sensor(data, output.velocity), displacement=_sensor(data, output.displacement),
        peak_acceleration=summary.peak_acceleration[1] if summary.peak_acceleration else NAN,
        contact=contact, steps=int(attrs.get("steps", 0)), rejected_steps=int(attrs.get("rejected_steps", 0)),
        wall_time=float(attrs.get("wall_time_s", NAN)), warnings=" ".join(summary.warnings), travel=summary.travel)


def start_time(time: np.ndarray, velocity: np.ndarray, threshold: float, sign: float) -> float:
    """First time sign·v(t) reaches `threshold`, linearly interpolated between samples; NaN if never."""
    signed = sign * velocity
    above = np.flatnonzero(signed >= threshold)
    if not len(above):
        return NAN
    k = above[0]
    if k == 0:
        return float(time[0])
    v0, v1 = signed[k - 1], signed[k]
    return float(time[k - 1] + (threshold - v0) / (v1 - v0) * (time[k] - time[k - 1]))


def start_delay(case: CaseRecord, ideal: CaseRecord, fraction: float) -> float:
    """Delay (ms) of the case's output velocity in reaching `fraction` of the ideal peak velocity."""
    if case.velocity is None or ideal.velocity is None or not len(ideal.velocity) or not len(case.velocity):
        return NAN
    peak = int(np.argmax(np.abs(ideal.velocity)))
    sign = 1.0 if ideal.velocity[peak] >= 0 else -1.0
    threshold = fraction * abs(ideal.velocity[peak])
    if threshold == 0.0:
        return NAN
    reference = start_time(ideal.time, ideal.velocity, threshold, sign)
    return (start_time(case.time, case.velocity, threshold, sign) - reference) * 1e3


def end_error(case: CaseRecord, ideal: CaseRecord) -> float:
    """|x(t_end) − x_ideal(t_end)| as % of the ideal stroke (the range of the ideal output displacement)."""
    if case.displacement is None or ideal.displacement is None or not len(case.time) or not len(ideal.time):
        return NAN
    t_end = case.time[-1]
    if t_end > ideal.time[-1] + 1e-12:
        return NAN
    stroke = float(np.ptp(ideal.displacement))
    if stroke == 0.0:
        return NAN
    ideal_end = float(np.interp(t_end, ideal.time, ideal.displacement))
    return abs(float(case.displacement[-1]) - ideal_end) / stroke * 100.0


def relative_figures(case: CaseRecord, ideal: CaseRecord | None, fraction: float) -> dict[str, float]:
    """The figures read against the ideal case: NaN without a complete ideal case."""
    if case.relative is not None:
        return case.relative
    if ideal is None or not ideal.complete or not case.complete:
        return {"acceleration_ratio": NAN, "start_delay_ms": NAN, "end_error_percent": NAN}
    ratio = case.peak_acceleration / ideal.peak_acceleration if ideal.peak_acceleration > 0 else NAN
    return {"acceleration_ratio": ratio, "start_delay_ms": start_delay(case, ideal, fraction),
            "end_error_percent": end_error(case, ideal)}
