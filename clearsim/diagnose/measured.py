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
HEADER = re.compile(r"^\s*(?P<name>[^\[]+?)\s*(?:\[(?P<unit>[^\]]*)\])?\s*$")

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
                  required: Sequence[str] = ()) -> MeasuredData:
    """Read a CSV or HDF5 record, map its columns to sensors and convert to SI.

    sensor_units: the model's sensors (name → SI unit, see `model_sensor_units`); columns are
    checked against them. Without it every column is a sensor and units only need to be known.
    mapping: column → sensor (or → "time"). units: column → unit, for headers without one.
    required: sensors that must be measured (a missing one is an error).
    """
    path = Path(path)
    if not path.exists():
        raise MeasuredDataError(f"{path}: no such file; check the path of the measured data")
    if path.suffix.lower() in (".h5", ".hdf5", ".hdf"):
        raw = _hdf5_columns(path)
    else:
        raw = _csv_columns(path)
    data = _assemble(path, raw, dict(sensor_units) if sensor_units is not None else None,
                     dict(mapping or {}), dict(units or {}))
    for sensor in required:
        if sensor not in data.values:
            raise MeasuredDataError(f"{path}: missing column for sensor '{sensor}' (columns: {', '.join(raw.columns)}); "
                                    f"add it, or map a column to it: --map <column>={sensor}")
    return data


@dataclass
class _Raw:
    """Columns as read: name → (values, unit written in the file, where row k is: 'line n' / 'sample n')."""

    columns: dict[str, tuple[np.ndarray, str]]
    row_names: list[str]


def _csv_rows(path: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            rows = [(n, row) for n, row in enumerate(csv.reader(handle), start=1)
                    if row and any(c.strip() for c in row) and not row[0].lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as exc:
        raise MeasuredDataError(f"{path}: cannot read the file ({exc}); save it as UTF-8 CSV") from None
    if not rows:
        raise MeasuredDataError(f"{path}: the file is empty; expected a header row such as 'time [ms],<sensor> [mm]'")
    return rows[0][1], rows[1:]


def _number(text: str, path: Path, line: int, column: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise MeasuredDataError(f"{path}:{line}: column '{column}': {text.strip()!r} is not a number; "
                                "write numbers only below the header (comments start with '#')") from None


def _csv_columns(path: Path) -> _Raw:
    header, rows = _csv_rows(path)
    parsed = [HEADER.match(cell) for cell in header]
    names = [m["name"] if m else cell.strip() for m, cell in zip(parsed, header)]
    written = [(m["unit"] or "").strip() if m else "" for m in parsed]
    for line, row in rows:
        if len(row) != len(names):
            raise MeasuredDataError(f"{path}:{line}: {len(row)} values for {len(names)} columns "
                                    f"({', '.join(names)}); every row needs one value per column")
    data = np.array([[_number(v, path, line, names[k]) for k, v in enumerate(row)] for line, row in rows],
                    dtype=float).reshape(len(rows), len(names))
    columns = {name: (data[:, k], written[k]) for k, name in enumerate(names)}
    return _Raw(columns, [f"{path}:{line}" for line, _ in rows])


def _hdf5_columns(path: Path) -> _Raw:
    import h5py

    try:
        handle = h5py.File(path, "r")
    except OSError as exc:
        raise MeasuredDataError(f"{path}: not a readable HDF5 file ({exc})") from None
    with handle:
        group = handle["sensors"] if isinstance(handle.get("sensors"), h5py.Group) else handle
        columns = {}
        if isinstance(handle.get(TIME), h5py.Dataset):
            columns[TIME] = (np.asarray(handle[TIME][()], dtype=float).ravel(), _unit_attr(handle[TIME]))
        for name, node in group.items():
            if isinstance(node, h5py.Dataset) and name != TIME and node.ndim == 1:
                columns[name] = (np.asarray(node[()], dtype=float), _unit_attr(node))
    length = max((len(v) for v, _ in columns.values()), default=0)
    return _Raw(columns, [f"{path}: sample {k}" for k in range(length)])


def _unit_attr(node) -> str:
    unit = node.attrs.get("unit", node.attrs.get("units", ""))
    return unit.decode() if isinstance(unit, bytes) else str(unit)


def _assemble(path: Path, raw: _Raw, sensor_units: dict | None, mapping: dict, units: dict) -> MeasuredData:
    _check_mapping(path, raw, sensor_units, mapping, units)
    target = {column: mapping.get(column, column) for column in raw.columns}
    time_columns = [c for c, t in target.items() if t == TIME]
    if not time_columns:
        raise MeasuredDataError(f"{path}: no time column (columns: {', '.join(raw.columns)}); name it 'time [unit]' "
                                "or map it: --map <column>=time")
    time_column = time_columns[0]
    known = sensor_units if sensor_units is not None else {t: "" for t in target.values() if t != TIME}
    chosen = {c: t for c, t in target.items() if t in known and c != time_column}
    ignored = [c for c, t in target.items() if c != time_column and c not in chosen]
    if not chosen:
        raise MeasuredDataError(f"{path}: no column names a model sensor{_suggestions(ignored, known)}; "
                                f"rename the columns or map them: --map <column>=<sensor> (sensors: {', '.join(known)})")
    time = _converted(path, raw, time_column, "s", units)
    values = {t: _converted(path, raw, c, known[t], units) for c, t in chosen.items()}
    for column in [time_column, *chosen]:
        _check_finite(path, raw, column)
    _check_time(path, raw, time, time_column)
    written = {TIME: units.get(time_column, raw.columns[time_column][1])}
    written.update({t: units.get(c, raw.columns[c][1]) for c, t in chosen.items()})
    return MeasuredData(path, time, values, written, {t: c for c, t in chosen.items()}, ignored)


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
        header_unit = raw.columns[column][1]
        if header_unit and header_unit != unit:
            raise MeasuredDataError(f"{path}: column '{column}' is in [{header_unit}] by its header but in [{unit}] "
                                    "by the option; give the unit in one place only")


def _converted(path: Path, raw: _Raw, column: str, si_unit: str, units: dict) -> np.ndarray:
    values, written = raw.columns[column]
    unit = units.get(column, written)
    if len(values) != len(raw.row_names):
        raise MeasuredDataError(f"{path}: column '{column}' has {len(values)} samples, the time has "
                                f"{len(raw.row_names)}; every sensor needs one value per time")
    return values * _factor(path, column, unit, si_unit)


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


def _check_finite(path: Path, raw: _Raw, column: str) -> None:
    bad = np.flatnonzero(~np.isfinite(raw.columns[column][0]))
    if bad.size:
        raise MeasuredDataError(f"{raw.row_names[bad[0]]}: column '{column}' is not a finite number ({bad.size} "
                                "such value(s)); remove those rows or fill the gap before diagnosing")


def _check_time(path: Path, raw: _Raw, time: np.ndarray, column: str) -> None:
    if len(time) < MIN_SAMPLES:
        raise MeasuredDataError(f"{path}: only {len(time)} samples; at least {MIN_SAMPLES} are needed "
                                "(record longer or sample faster)")
    steps = np.flatnonzero(np.diff(time) <= 0.0)
    if steps.size:
        k = steps[0] + 1
        raise MeasuredDataError(f"{raw.row_names[k]}: time in column '{column}' does not increase "
                                f"({raw.columns[column][0][k - 1]:g} then {raw.columns[column][0][k]:g}); "
                                "sort the rows by time and remove repeated samples")
