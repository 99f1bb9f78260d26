"""Engineering units for axes: SI values in the file, mm / ms / µm / kN / deg on the figures.

A `Scale` multiplies SI values into the unit written on the axis. The choice depends on the
unit of the dataset (its `unit` attribute) and, for lengths and forces, on the magnitude, so
that tick labels stay short: a 0.01 mm clearance is drawn in µm, a 0.3 m stroke in mm, a 45 kN
contact force in kN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PRETTY = {"m/s^2": "m/s²", "rad/s^2": "rad/s²", "N*m": "N·m", "kg*m^2": "kg·m²"}


@dataclass(frozen=True)
class Scale:
    factor: float  # SI value × factor = value on the axis
    unit: str

    def __call__(self, values):
        return np.asarray(values, dtype=float) * self.factor

    def label(self, quantity: str) -> str:
        return f"{quantity} ({self.unit})" if self.unit else quantity


TIME = Scale(1e3, "ms")
FREQUENCY = Scale(1e-3, "kHz")


def _peak(values) -> float:
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    return float(np.max(np.abs(finite))) if finite.size else 0.0


def length_scale(values) -> Scale:
    """µm below 0.1 mm, mm up to 10 m."""
    peak = _peak(values)
    if peak < 1e-4:
        return Scale(1e6, "µm")
    return Scale(1e3, "mm") if peak < 10.0 else Scale(1.0, "m")


def force_scale(values) -> Scale:
    return Scale(1e-3, "kN") if _peak(values) >= 1e4 else Scale(1.0, "N")


def scale_for(unit: str, values=None) -> Scale:
    """The axis scale of a dataset with SI `unit` (as written in its `unit` attribute)."""
    unit = (unit or "").strip()
    if unit == "m":
        return length_scale(values if values is not None else [1.0])
    if unit == "s":
        return TIME
    if unit == "N":
        return force_scale(values if values is not None else [1.0])
    if unit == "rad":
        return Scale(180.0 / np.pi, "deg")
    return Scale(1.0, PRETTY.get(unit, unit))
