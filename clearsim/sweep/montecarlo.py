"""Monte Carlo cases: values drawn from the `tolerances:` of the mechanism file.

Sample k draws from its own generator, seeded with (seed, k): the same seed gives the same
values, and a larger --sample keeps the first cases of a smaller one (a sweep grown from 50 to
200 samples into the same folder recomputes nothing). Each drawn value is written in the unit
of its distribution's first bound or mean and applied as `--set path=value`, so it goes through
the same unit and schema checks as a value written by hand.
"""

from __future__ import annotations

import numpy as np

from clearsim.errors import InputError, Problem
from clearsim.sweep.grid import IDEAL, Case, SweepOptionError, joint_of
from clearsim.units import parse_quantity

SIGNIFICANT = 6
MAX_REDRAWS = 1000


def _unit_text(quantity) -> str:
    return f"{quantity.units:~C}" if str(quantity.units) != "dimensionless" else ""


def _in(quantity, unit) -> float:
    return float(quantity.to(unit).magnitude) if unit is not None else float(quantity.magnitude)


def draw(tolerance, rng: np.random.Generator) -> str:
    """One value of a tolerance, as text with its unit ('0.0231456 mm')."""
    first = parse_quantity(tolerance.low if tolerance.distribution == "uniform" else tolerance.mean)
    unit = first.units if str(first.units) != "dimensionless" else None
    bound = {key: _in(parse_quantity(getattr(tolerance, key)), unit)
             for key in ("low", "high", "mean", "std") if getattr(tolerance, key) is not None}
    if tolerance.distribution == "uniform":
        value = rng.uniform(bound["low"], bound["high"])
    else:
        value = _truncated_normal(rng, bound["mean"], bound["std"], bound.get("low", -np.inf), bound.get("high", np.inf))
    text = f"{value:.{SIGNIFICANT}g}"
    return f"{text} {_unit_text(first)}".strip()


def _truncated_normal(rng, mean: float, std: float, low: float, high: float) -> float:
    """A normal draw kept within [low, high] by redrawing (the bounds are physical limits, e.g. c ≥ 0)."""
    for _ in range(MAX_REDRAWS):
        value = rng.normal(mean, std)
        if low <= value <= high:
            return value
    raise OutsideBounds(f"mean {mean:g} ± std {std:g} almost never falls within [{low:g}, {high:g}]")


class OutsideBounds(ValueError):
    """A truncated normal whose bounds hold (almost) none of its distribution."""


def sample_cases(tolerances, count: int, seed: int, fixed: list[str], zeroed: list[str],
                 with_ideal: bool = True) -> list[Case]:
    """The nominal ideal case (clearances 0, every other value as in the file), then `count` samples."""
    zero = tuple(f"joints.{j}.clearance=0" for j in zeroed)
    cases = [Case(IDEAL, {}, (*fixed, *zero), True)] if with_ideal else []
    width = max(4, len(str(count)))
    for k in range(count):
        rng = np.random.default_rng([seed, k])
        values = {}
        for index, tolerance in enumerate(tolerances):
            try:
                values[tolerance.path] = draw(tolerance, rng)
            except OutsideBounds as exc:  # was: the mean clipped to a bound, so every sample the same
                raise SweepOptionError(f"--sample: tolerances[{index}] ({tolerance.path}): {exc} (in the unit of its "
                                       "mean)\n  hint: check the mean, std, low and high of that tolerance") from None
        overrides = tuple(f"{path}={text}" for path, text in values.items())
        cases.append(Case(f"sample-{k + 1:0{width}d}", values, (*fixed, *overrides), False,
                          IDEAL if with_ideal else None))
    return cases


def sampled_joints(tolerances) -> list[str]:
    return [joint_of(t.path) for t in tolerances if t.path.endswith(".clearance") and joint_of(t.path)]


def tolerance_problems(tolerances, error: InputError) -> list[Problem]:
    """Problems of a trial load with each tolerance's value, moved to the tolerance that caused them."""
    problems = []
    for problem in error.problems:
        text = problem.override or (error.source.override_for(problem.path) if error.source else None)
        index = next((k for k, t in enumerate(tolerances) if text and text.startswith(f"{t.path}=")), None)
        if index is None:
            problems.append(problem)
        else:
            problems.append(Problem(("tolerances", index, "path"), problem.message, problem.hint))
    return problems
