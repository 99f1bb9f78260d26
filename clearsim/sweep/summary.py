"""The sweep's summary: one row per case (summary.csv), and percentiles for Monte Carlo (percentiles.csv)."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from clearsim.sweep.figures import CaseRecord, relative_figures
from clearsim.sweep.plan import SweepPlan
from clearsim.sweep.worker import NOT_RUN, CaseOutcome

SUMMARY_FILE = "summary.csv"
PERCENTILES_FILE = "percentiles.csv"
PERCENTILES = (5, 25, 50, 75, 95)
FIGURES = ("peak_acceleration_m_s2", "acceleration_ratio", "start_delay_ms", "end_error_percent")
JOINT_FIGURES = ("max_contact_force_N", "free_percent", "impact_percent", "contact_percent")
# summary column → (`travel_figures` key, scale from SI): the travel figures of a mechanism with a `travel:` block
TRAVEL_FIGURES = {"operating_time_ms": ("operating_time_s", 1e3), "zone_speed_m_s": ("zone_speed_m_per_s", 1.0),
                  "overtravel_mm": ("overtravel_m", 1e3), "rebound_mm": ("rebound_m", 1e3)}
ENVELOPE_COLUMN = "inside_envelope"
TAIL = ("steps", "rejected_steps", "wall_time_s", "reused", "error", "warnings")


def joint_column(figure: str, joint: str) -> str:
    return f"{figure}[{joint}]"


def clearance_joints(outcomes: dict[str, CaseOutcome]) -> list[str]:
    joints = [j for o in outcomes.values() if o.record is not None for j in o.record.contact]
    return list(dict.fromkeys(joints))


def has_travel(outcomes: dict[str, CaseOutcome]) -> bool:
    """Whether any case's result has travel figures (its mechanism a `travel:` block)."""
    return any(o.record is not None and o.record.travel for o in outcomes.values())


def columns(plan: SweepPlan, joints: list[str], travel: bool = False) -> list[str]:
    per_joint = [joint_column(f, j) for j in joints for f in JOINT_FIGURES]
    travel_columns = [*TRAVEL_FIGURES, ENVELOPE_COLUMN] if travel else []
    return ["case", "reference", *plan.labels, "status", *FIGURES, *per_joint, *travel_columns, *TAIL]


def _travel_cells(travel: dict) -> dict:
    """The travel figures in the summary's units (NaN: not reached), and whether the curve kept to its envelope
    (yes / no; blank without an envelope or when the run ended before it began)."""
    cells = {column: math.nan if travel.get(key) is None else travel[key] * scale
             for column, (key, scale) in TRAVEL_FIGURES.items()}
    inside = travel.get("inside_envelope")
    return cells | {ENVELOPE_COLUMN: "" if inside is None else "yes" if inside else "no"}


def _joint_cells(record: CaseRecord, joints: list[str]) -> dict:
    cells = {}
    for joint in joints:
        force, free, impact, contact = record.contact.get(joint, (math.nan,) * 4)
        cells.update({joint_column("max_contact_force_N", joint): force,
                      joint_column("free_percent", joint): free * 100, joint_column("impact_percent", joint): impact * 100,
                      joint_column("contact_percent", joint): contact * 100})
    return cells


def case_row(plan: SweepPlan, name: str, outcomes: dict[str, CaseOutcome], joints: list[str]) -> dict:
    """A case's row: swept values, status, figures (blank when the case did not complete)."""
    case = plan.case(name)
    outcome = outcomes.get(name)
    row = {"case": name, "reference": case.reference or "", **case.values,
           "status": outcome.state if outcome else NOT_RUN, "error": outcome.error if outcome else ""}
    record = outcome.record if outcome else None
    if record is None:
        return row
    row.update({"steps": record.steps, "rejected_steps": record.rejected_steps, "wall_time_s": record.wall_time,
                "reused": "yes" if not outcome.ran else "no", "warnings": record.warnings})
    if record.complete:
        reference = outcomes.get(case.reference) if case.reference else None
        ideal = reference.record if reference is not None else (record if case.ideal else None)
        row["peak_acceleration_m_s2"] = record.peak_acceleration
        row.update(relative_figures(record, ideal, plan.delay_fraction))
        row.update(_joint_cells(record, joints))
        row.update(_travel_cells(record.travel) if record.travel else {})
    return row


def summary_rows(plan: SweepPlan, outcomes: dict[str, CaseOutcome]) -> tuple[list[str], list[dict]]:
    joints = clearance_joints(outcomes)
    return columns(plan, joints, has_travel(outcomes)), [case_row(plan, case.name, outcomes, joints) for case in plan.cases]


def _cell(value) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return "" if value is None else str(value)


def write_csv(path: Path, header: list[str], rows: list[dict]) -> Path:
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows([[_cell(row.get(key)) for key in header] for row in rows])
    return path


def percentiles(plan: SweepPlan, header: list[str], rows: list[dict]) -> list[dict]:
    """Per figure of merit, over the complete non-ideal cases: count and percentiles."""
    figures = [key for key in header if key in FIGURES or key in TRAVEL_FIGURES or key.split("[")[0] in JOINT_FIGURES]
    sampled = [row for row in rows if not plan.case(row["case"]).ideal and row.get("status") == "complete"]
    table = []
    for figure in figures:
        values = np.array([row.get(figure, math.nan) for row in sampled], dtype=float)
        values = values[np.isfinite(values)]
        entry = {"figure": figure, "cases": len(values)}
        entry.update({f"p{p}": float(np.percentile(values, p)) if len(values) else math.nan for p in PERCENTILES})
        table.append(entry)
    return table


def percentile_header() -> list[str]:
    return ["figure", "cases", *(f"p{p}" for p in PERCENTILES)]
