"""Reading a time column and a value column from a CSV file, converted to SI."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from clearsim.units import to_si


def _column_index(header: list[str], column: str | int, path: Path) -> int:
    if isinstance(column, int):
        if not 0 <= column < len(header):
            raise ValueError(f"{path.name} has {len(header)} columns; column {column} does not exist")
        return column
    if column not in header:
        raise ValueError(f"{path.name} has no column '{column}' (columns: {', '.join(header)})")
    return header.index(column)


def _read_rows(path: Path) -> tuple[list[str], np.ndarray]:
    """(header, numeric rows) of a CSV whose first line may be a header."""
    if path.exists() and not path.is_file():  # a named pipe would block the read for ever, a device never end it
        raise ValueError(f"table '{path}' is not a regular file (a folder, a named pipe or a device); give the CSV file")
    try:
        with path.open(newline="") as handle:
            lines = [row for row in csv.reader(handle) if row and not row[0].lstrip().startswith("#")]
    except OSError as exc:
        raise ValueError(f"cannot read table '{path}': {exc.strerror}") from None
    if not lines:
        raise ValueError(f"table '{path}' is empty")
    try:
        float(lines[0][0])
        header, body = [str(i) for i in range(len(lines[0]))], lines
    except ValueError:
        header, body = [h.strip() for h in lines[0]], lines[1:]
    try:
        data = np.array([[float(v) for v in row] for row in body], dtype=float)
    except ValueError:
        raise ValueError(f"table '{path}' has a non-numeric value below its header") from None
    return header, data


def read_table_column(path: Path, time_column, value_column, time_unit: str, value_unit: str,
                      kind: str, where=None, argument_kind: str = "time",
                      argument_name: str = "time") -> tuple[np.ndarray, np.ndarray]:
    """(arguments in SI of `argument_kind`, values in SI of `kind`) from a CSV file; the arguments (times, or
    e.g. strokes) must increase strictly."""
    path = Path(path)
    header, data = _read_rows(path)
    if data.shape[0] < 2:
        raise ValueError(f"table '{path.name}' needs at least two rows")
    times = data[:, _column_index(header, time_column, path)] * to_si(f"1 {time_unit}", argument_kind)
    values = data[:, _column_index(header, value_column, path)] * to_si(f"1 {value_unit}", kind)
    if not np.all(np.isfinite(times)) or not np.all(np.isfinite(values)):
        raise ValueError(f"table '{path.name}' contains NaN or infinite values")
    if np.any(np.diff(times) <= 0.0):
        raise ValueError(f"the {argument_name} column of '{path.name}' must increase strictly")
    return times, values
