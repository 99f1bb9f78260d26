"""Measured data (a bench record) read, mapped to the model's sensors and converted to SI.

CSV: a header row, then one row per sample; lines starting with `#` are comments. The time
column is `time` (or the column mapped to `time`); every other column is a sensor, named after
the model's sensor or mapped to it with `column=sensor`. Units are written in the header,
`time [ms]`, `sealing_rod_displacement [mm]`, or given separately (`units={"time": "ms"}`); a
column with neither is taken as SI (s, m, m/s, rad, N ...). Columns that name no model sensor
are left out (listed in `MeasuredData.ignored`).

HDF5: a clearsim result file (/time and /sensors/<name>, units in the `unit` attributes), or a
plain file with a `time` dataset and one 1-D dataset per sensor (`unit` attribute optional).

Every problem is a `MeasuredDataError` that names the file, the column or row, and the fix.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from clearsim.errors import ClearsimError, did_you_mean
from clearsim.units import DIMENSIONS, UnitError, to_si

MIN_SAMPLES = 20
TIME = "time"
HEADER = re.compile(r"^\s*(?P<name>[^\[\(]+?)\s*(?:[\[\(](?P<unit>[^\]\)]*)[\]\)])?\s*$")
DELIMITERS = (",", ";", "\t")
MAX_MAGNITUDE = 1e100  # SI: far beyond any bench, far below where squares and sums of squares overflow (1e154)
GAP_FACTOR = 10.0  # a time step this many times the record's median step is a gap (or a change of time unit)

# SI unit of each sensor type (as written in /sensors/<name>.attrs["unit"]) and the unit's kind
SENSOR_TYPE_UNITS = {
    "point_displacement": "m", "point_velocity": "m/s", "point_acceleration": "m/s^2",
    "body_angle": "rad", "body_angular_velocity": "rad/s", "body_angular_acceleration": "rad/s^2",
    "joint_force": "N",
}
UNIT_KINDS = {"s": "time", "m": "length", "m/s": "speed", "m/s^2": "acceleration", "rad": "angle",
              "rad/s": "angular_speed", "N": "force"}


class MeasuredDataError(ClearsimError):
    """Measured data that cannot be used: the message names the file, the place and the fix."""


@dataclass
class MeasuredData:
    """A bench record in SI: `values[sensor]` sampled at `time` (s, strictly increasing)."""

    path: Path
    time: np.ndarray
    values: dict[str, np.ndarray]
    units: dict[str, str]  # sensor (and "time") → unit as written in the file or given ("" = SI)
    columns: dict[str, str] = field(default_factory=dict)  # sensor → column it was read from
    ignored: list[str] = field(default_factory=list)  # columns that name no model sensor


def model_sensor_units(mechanism) -> dict[str, str]:
    """Sensor name → SI unit for the sensors of a validated mechanism spec."""
    return {s.name: SENSOR_TYPE_UNITS[s.type] for s in mechanism.sensors}


def parse_mapping(items: Sequence[str], what: str = "--map") -> dict[str, str]:
    """["col=sensor", ...] (or "a=b,c=d") → {col: sensor}."""
    out = {}
    for item in (part for text in items for part in text.split(",") if part.strip()):
        name, sep, target = item.partition("=")
        if not sep or not name.strip() or not target.strip():
            raise MeasuredDataError(f"{what} {item!r}: expected column=value, e.g. {what} 'Weg=sealing_rod_displacement'")
        out[name.strip()] = target.strip()
    return out


def read_measured(path: Path | str, sensor_units: Mapping[str, str] | None = None,
                  mapping: Mapping[str, str] | None = None, units: Mapping[str, str] | None = None,
                  required: Sequence[str] = (), *, first_column_time: bool = False, mappable: bool = True,
                  min_samples: int = MIN_SAMPLES, sensors_of: str | None = None) -> MeasuredData:
    """Read a CSV or HDF5 record, map its columns to sensors and convert to SI.

    sensor_units: the model's sensors (name → SI unit, see `model_sensor_units`); columns are
    checked against them. Without it every column is a sensor and units only need to be known.
    mapping: column → sensor (or → "time"). units: column → unit, for headers without one.
    required: sensors that must be measured (a missing one is an error).
    first_column_time: without a `time` column the first column is the time (`clearsim plot`).
    mappable: the hints may offer --map (False where the command has no such option).
    sensors_of: what the sensors belong to, for the messages (None: the model; "results/run.h5").
    """
    path = Path(path)
    if not path.exists():
        raise MeasuredDataError(f"{path}: no such file; check the path of the measured data")
    if path.is_dir():
        raise MeasuredDataError(f"{path} is a folder; give the measured record itself (a CSV or HDF5 file)")
    if not path.is_file():  # a named pipe would block the read for ever, a device never end it
        raise MeasuredDataError(f"{path}: not a regular file (a named pipe or a device); give the measured record "
                                "itself (a CSV or HDF5 file)")
    if path.suffix.lower() in (".h5", ".hdf5", ".hdf"):
        raw = _hdf5_columns(path)
    else:
        raw = _csv_columns(path)
    mapping = dict(mapping or {})
    if first_column_time and raw.columns and TIME not in raw.columns and TIME not in mapping.values():
        mapping[next(iter(raw.columns))] = TIME
    data = _assemble(path, raw, dict(sensor_units) if sensor_units is not None else None,
                     mapping, dict(units or {}), mappable, min_samples, sensors_of)
    for sensor in required:
        if sensor not in data.values:
            raise MeasuredDataError(f"{path}: missing column for sensor '{sensor}' (columns: {', '.join(raw.columns)}); "
                                    f"add it, or map a column to it: --map <column>={sensor}")
    return data


@dataclass
class _Raw:
    """Columns as read: name → unit written in the file; values parsed when a column is used (a text column
    that names no sensor is no error); row k is at `row_names[k]` ('file:line' / 'file: sample n')."""

    units: dict[str, str]
    row_names: list[str]
    values: dict[str, np.ndarray] = field(default_factory=dict)
    text: dict[str, tuple[int, list[tuple[int, str]]]] = field(default_factory=dict)  # CSV: column index, (line, cell)
    path: Path | None = None

    @property
    def columns(self) -> dict[str, str]:
        return self.units

    def array(self, column: str) -> np.ndarray:
        if column not in self.values:
            _, cells = self.text[column]
            self.values[column] = np.array([_number(cell, self.path, line, column) for line, cell in cells], dtype=float)
        return self.values[column]


def _decoded(path: Path) -> str:
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise MeasuredDataError(f"{path}: cannot read the file ({exc.strerror or exc}); check that it exists and "
                                "can be read") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise MeasuredDataError(f"{path}:{line}: byte 0x{data[exc.start]:02x} is not UTF-8 text (is this a CSV file?); "
                                "save the record as UTF-8 CSV (e.g. 'CSV UTF-8' in a spreadsheet)") from None


def _delimiter(line: str) -> str:
    """The separator of a CSV: the one of , ; tab that the header line holds most of (a comma if none)."""
    counts = {d: line.count(d) for d in DELIMITERS}
    best = max(DELIMITERS, key=lambda d: counts[d])
    return best if counts[best] else ","


def _csv_rows(path: Path) -> tuple[int, list[str], list[tuple[int, list[str]]], str]:
    text = _decoded(path)
    lines = [(n, line) for n, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise MeasuredDataError(f"{path}: the file is empty; expected a header row such as 'time [ms],<sensor> [mm]'")
    delimiter = _delimiter(lines[0][1])
    reader = csv.reader([line for _, line in lines], delimiter=delimiter)
    rows = [(n, row) for (n, _), row in zip(lines, reader) if any(c.strip() for c in row)]
    if not rows:
        raise MeasuredDataError(f"{path}: the file holds only separators, no header or numbers; expected a header row "
                                "such as 'time [ms],<sensor> [mm]'")
    return rows[0][0], rows[0][1], rows[1:], delimiter


def _number(text: str, path: Path, line: int, column: str) -> float:
    try:
        return float(text)
    except ValueError:
        hint = ("write decimals with a point (0.5, not 0,5)" if re.fullmatch(r"\s*[-+]?\d*,\d+\s*", text)
                else "write numbers only below the header (comments start with '#')")
        raise MeasuredDataError(f"{path}:{line}: column '{column}': {text.strip()!r} is not a number; {hint}") from None


def _csv_columns(path: Path) -> _Raw:
    header_line, header, rows, delimiter = _csv_rows(path)
    parsed = [HEADER.match(cell) for cell in header]
    names = [m["name"] if m else cell.strip() for m, cell in zip(parsed, header)]
    written = [(m["unit"] or "").strip() if m else "" for m in parsed]
    for line, row in rows:
        if len(row) != len(names):
            raise MeasuredDataError(f"{path}:{line}: {len(row)} values for {len(names)} columns "
                                    f"({', '.join(names)}); every row needs one value per column")
    kept = [k for k, name in enumerate(names) if name or any(row[k].strip() for _, row in rows)]
    for k in kept:  # an unnamed column with values: named by its place
        if not names[k]:
            names[k] = f"(column {k + 1})"
    seen: dict[str, int] = {}
    for k in kept:
        if names[k] in seen:
            raise MeasuredDataError(f"{path}:{header_line}: columns {seen[names[k]] + 1} and {k + 1} are both named "
                                    f"'{names[k]}'; which one is meant is ambiguous: rename or remove one of them")
        seen[names[k]] = k
    raw = _Raw({names[k]: written[k] for k in kept}, [f"{path}:{line}" for line, _ in rows], path=path)
    raw.text = {names[k]: (k, [(line, row[k]) for line, row in rows]) for k in kept}
    return raw


def _hdf5_columns(path: Path) -> _Raw:
    import h5py

    try:
        handle = h5py.File(path, "r")
    except OSError as exc:
        raise MeasuredDataError(f"{path}: not a readable HDF5 file ({exc}); give a CSV record or an HDF5 file with a "
                                "'time' dataset and one 1-D dataset per sensor") from None
    units, values = {}, {}
    try:
        with handle:
            if "clearsim_version" in handle.attrs and not bool(handle.attrs.get("complete", True)):
                status = handle.attrs.get("status", "unknown")
                status = status.decode() if isinstance(status, bytes) else str(status)
                raise MeasuredDataError(f"{path}: a clearsim result flagged incomplete (complete = false, status: "
                                        f"{status}); its record stops where the run did: run it to the end "
                                        "(`clearsim run`) before using it as measured data")
            group = handle["sensors"] if isinstance(handle.get("sensors"), h5py.Group) else handle
            nodes = {}
            if isinstance(handle.get(TIME), h5py.Dataset):
                nodes[TIME] = handle[TIME]
            nodes.update({name: node for name, node in group.items()
                          if isinstance(node, h5py.Dataset) and name != TIME and node.ndim == 1})
            for name, node in nodes.items():
                if node.dtype.kind not in "iuf":
                    if name == TIME:
                        raise MeasuredDataError(f"{path}: dataset '{node.name}' holds {node.dtype} values, not numbers; "
                                                "write the time as numbers")
                    continue  # a text dataset names no sensor
                values[name] = np.asarray(node[()], dtype=float).ravel()
                units[name] = _unit_attr(node)
    except (OSError, KeyError, RuntimeError) as exc:  # a damaged or truncated file fails as it is read
        raise MeasuredDataError(f"{path}: the HDF5 file is damaged ({exc}); write the record again") from None
    length = len(values[TIME]) if TIME in values else max((len(v) for v in values.values()), default=0)
    return _Raw(units, [f"{path}: sample {k}" for k in range(length)], values, path=path)


def _unit_attr(node) -> str:
    unit = node.attrs.get("unit", node.attrs.get("units", ""))
    return unit.decode() if isinstance(unit, bytes) else str(unit)


def _how(column: str, mapping: dict) -> str:
    return f"--map {column}={mapping[column]}" if column in mapping else "by its name"


def _assemble(path: Path, raw: _Raw, sensor_units: dict | None, mapping: dict, units: dict, mappable: bool = True,
              min_samples: int = MIN_SAMPLES, sensors_of: str | None = None) -> MeasuredData:
    _check_mapping(path, raw, sensor_units, mapping, units)
    target = {column: mapping.get(column, column) for column in raw.columns}
    time_columns = [c for c, t in target.items() if t == TIME]
    if not time_columns:
        map_hint = " or map it: --map <column>=time" if mappable else ""
        raise MeasuredDataError(f"{path}: no time column (columns: {', '.join(raw.columns)}); name it 'time [unit]'"
                                f"{map_hint}")
    known = sensor_units if sensor_units is not None else {t: "" for t in target.values() if t != TIME}
    _check_unambiguous(path, target, known, mapping, mappable)
    time_column = time_columns[0]
    chosen = {c: t for c, t in target.items() if t in known and c != time_column}
    ignored = [c for c, t in target.items() if c != time_column and c not in chosen]
    if not chosen:
        fix = "rename the columns or map them: --map <column>=<sensor>" if mappable else "rename the columns"
        what = "a model sensor" if sensors_of is None else f"a sensor of {sensors_of}"
        raise MeasuredDataError(f"{path}: no column names {what}{_suggestions(ignored, known)}; "
                                f"{fix} (sensors: {', '.join(known)})")
    time = _converted(path, raw, time_column, "s", units)
    values = {t: _converted(path, raw, c, known[t], units) for c, t in chosen.items()}
    for column in [time_column, *chosen]:
        _check_finite(path, raw, column, column == time_column)
    for column, converted in [(time_column, time), *((c, values[t]) for c, t in chosen.items())]:
        _check_magnitude(raw, column, converted)
    for column in chosen:
        _check_alive(path, raw, column, units)
    _check_time(path, raw, time, time_column, min_samples, units)
    written = {TIME: units.get(time_column, raw.columns[time_column])}
    written.update({t: units.get(c, raw.columns[c]) for c, t in chosen.items()})
    return MeasuredData(path, time, values, written, {t: c for c, t in chosen.items()}, ignored)


def _check_unambiguous(path: Path, target: dict, known: dict, mapping: dict, mappable: bool) -> None:
    """Two columns for the time or for one sensor: which one is meant cannot be guessed."""
    by_target: dict[str, list[str]] = {}
    for column, sensor in target.items():
        if sensor == TIME or sensor in known:
            by_target.setdefault(sensor, []).append(column)
    for sensor, columns in by_target.items():
        if len(columns) > 1:
            first, second = columns[:2]
            fix = (f"remove or rename one of them, or map it to another sensor with --map"
                   if mappable else "remove or rename one of them")
            what = "the time" if sensor == TIME else f"sensor '{sensor}'"
            raise MeasuredDataError(f"{path}: columns '{first}' ({_how(first, mapping)}) and '{second}' "
                                    f"({_how(second, mapping)}) both give {what}; which one is meant is ambiguous: "
                                    f"{fix}")


def _suggestions(columns: list[str], known: Mapping[str, str]) -> str:
    hints = [f"'{c}'{did_you_mean(c, known)}" for c in columns if did_you_mean(c, known)]
    return f" ({', '.join(hints)})" if hints else ""


def _check_mapping(path: Path, raw: _Raw, sensor_units: dict | None, mapping: dict, units: dict) -> None:
    for column in [*mapping, *units]:
        if column not in raw.columns:
            raise MeasuredDataError(f"{path}: missing column '{column}'{did_you_mean(column, raw.columns)} "
                                    f"(columns: {', '.join(raw.columns)}); check the header or the --map/--unit option")
    for column, sensor in mapping.items():
        if sensor != TIME and sensor_units is not None and sensor not in sensor_units:
            raise MeasuredDataError(f"{path}: --map {column}={sensor}: the model has no sensor '{sensor}'"
                                    f"{did_you_mean(sensor, sensor_units)} (sensors: {', '.join(sensor_units)})")
    for column, unit in units.items():
        header_unit = raw.columns[column]
        if header_unit and header_unit != unit:
            raise MeasuredDataError(f"{path}: column '{column}' is in [{header_unit}] by its header but in [{unit}] "
                                    "by the option; give the unit in one place only")


def _converted(path: Path, raw: _Raw, column: str, si_unit: str, units: dict) -> np.ndarray:
    unit = units.get(column, raw.columns[column])
    factor = _factor(path, column, unit, si_unit)
    values = raw.array(column)
    if len(values) != len(raw.row_names):
        raise MeasuredDataError(f"{path}: column '{column}' has {len(values)} samples, the time has "
                                f"{len(raw.row_names)}; every sensor needs one value per time")
    with np.errstate(over="ignore"):  # a sample its unit turns into inf is reported by _check_magnitude
        return values * factor


def _factor(path: Path, column: str, unit: str, si_unit: str) -> float:
    """SI value of one `unit`, checked to be of the kind of `si_unit` (no unit: already SI)."""
    if not unit:
        return 1.0
    kind = UNIT_KINDS.get(si_unit) or _kind_of(unit)
    if kind is None:
        raise MeasuredDataError(f"{path}: column '{column}': cannot use the unit [{unit}] here; "
                                f"write it in {si_unit or 'SI units'} or a unit of the same kind")
    try:
        return to_si(f"1 {unit}", kind)
    except UnitError as exc:
        expected = f"[{si_unit}] or a unit of the same kind" if si_unit else "a known unit"
        raise MeasuredDataError(f"{path}: column '{column}': unit [{unit}] does not fit ({exc}); "
                                f"write the column in {expected}") from None


def _kind_of(unit: str) -> str | None:
    """The DIMENSIONS kind of a unit when the model gives none (first kind that accepts it)."""
    for kind in ("time", "length", "speed", "acceleration", "angle", "angular_speed", "force", *DIMENSIONS):
        try:
            to_si(f"1 {unit}", kind)
            return kind
        except UnitError:
            continue
    return None


def _check_finite(path: Path, raw: _Raw, column: str, is_time: bool = False) -> None:
    values = raw.array(column)
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size and bad.size == values.size and not is_time:
        raise MeasuredDataError(f"{path}: column '{column}' holds no numbers (all {values.size} values are NaN or "
                                "empty): a dead channel; remove the column, or record that sensor again")
    if bad.size:
        raise MeasuredDataError(f"{raw.row_names[bad[0]]}: column '{column}' is not a finite number ({bad.size} "
                                "such value(s)); remove those rows or fill the gap before using the record")


def _check_magnitude(raw: _Raw, column: str, si_values: np.ndarray) -> None:
    """A sample beyond MAX_MAGNITUDE in SI (or one its unit turned into inf) is no measurement: squared in the noise
    estimate or the fit, it overflows."""
    bad = np.flatnonzero(~(np.abs(si_values) <= MAX_MAGNITUDE))
    if bad.size:
        written = raw.array(column)[bad[0]]
        raise MeasuredDataError(f"{raw.row_names[bad[0]]}: column '{column}': {written:g} is beyond any measured value "
                                f"(more than {MAX_MAGNITUDE:g} in SI units; {bad.size} such value(s)); correct those "
                                "samples, or remove their rows")


def _check_alive(path: Path, raw: _Raw, column: str, units: dict) -> None:
    """A sensor column that never changes is a dead channel: it carries no motion and no noise to weigh it by."""
    values = raw.array(column)
    if len(values) > 1 and np.ptp(values) == 0.0:
        unit = units.get(column, raw.columns[column])
        raise MeasuredDataError(f"{path}: column '{column}' is constant ({values[0]:g}{f' {unit}' if unit else ''} "
                                f"in all {len(values)} samples): a dead channel; remove the column, or record "
                                "that sensor again")


def _check_time(path: Path, raw: _Raw, time: np.ndarray, column: str, min_samples: int = MIN_SAMPLES,
                units: dict | None = None) -> None:
    if len(time) == 0:
        raise MeasuredDataError(f"{path}: no samples below the header; write one row of numbers per sample")
    if len(time) < min_samples:
        raise MeasuredDataError(f"{path}: only {len(time)} samples; at least {min_samples} are needed "
                                "(record longer or sample faster)")
    written = raw.array(column)
    steps = np.flatnonzero(np.diff(time) <= 0.0)
    if steps.size:
        k = steps[0] + 1
        raise MeasuredDataError(f"{raw.row_names[k]}: time in column '{column}' does not increase "
                                f"({written[k - 1]:g} then {written[k]:g}); "
                                "sort the rows by time and remove repeated samples")
    if len(time) < 3:
        return
    step = np.diff(time)
    usual = float(np.median(step))
    odd = np.flatnonzero((step > GAP_FACTOR * usual) | (step < usual / GAP_FACTOR))
    if odd.size:
        k = odd[0] + 1
        unit = (units or {}).get(column, raw.columns[column])
        unit = f" {unit}" if unit else " s"
        raise MeasuredDataError(f"{raw.row_names[k]}: time in column '{column}' goes from {written[k - 1]:g} to "
                                f"{written[k]:g}{unit}, a step {step[k - 1] / usual:.3g} times the usual one of "
                                f"{float(np.median(np.diff(written))):.3g}{unit} ({odd.size} such step(s)); samples "
                                "are missing there or the time changes unit (e.g. s written as ms): fix the time "
                                "column, or cut the record there")
