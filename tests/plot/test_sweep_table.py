"""The sweep's summary table never splits a number, in an 80-column terminal or a pipe."""

import io
import re

import pytest
from rich.console import Console

from clearsim.runner import BUNDLED_CONFIG
from clearsim.sweep import display
from clearsim.sweep.plan import SweepRequest, plan_sweep

JOINTS = ("A", "J")


def rows_of(plan) -> tuple[list[str], list[dict]]:
    header = ["case", "peak_acceleration_m_s2", "acceleration_ratio", "start_delay_ms", "end_error_percent"]
    header += [f"{figure}[{j}]" for j in JOINTS
               for figure in ("max_contact_force_N", "free_percent", "impact_percent", "contact_percent")]
    rows = []
    for k, case in enumerate(plan.cases, start=1):
        row = {"case": case.name, "status": "complete", "peak_acceleration_m_s2": 108869.0 * k,
               "acceleration_ratio": 12.34 * k, "start_delay_ms": 0.0273789, "end_error_percent": 0.104425,
               "steps": 1234567, **case.values}
        for j in JOINTS:
            row.update({f"max_contact_force_N[{j}]": 26282.6 * k, f"free_percent[{j}]": 22.3,
                        f"impact_percent[{j}]": 18.7, f"contact_percent[{j}]": 58.9})
        rows.append(row)
    return header, rows


def rendered(renderable, console: Console) -> str:
    console.print(renderable)
    return console.file.getvalue()


@pytest.mark.parametrize("console", [Console(file=io.StringIO(), width=80, force_terminal=True, color_system=None),
                                     Console(file=io.StringIO())], ids=["terminal-80", "pipe"])
def test_every_number_of_the_sweep_table_is_printed_whole(tmp_path, console):
    plan = plan_sweep(SweepRequest(None, [], "0.01,0.03,0.1", out=tmp_path / "sweep"), BUNDLED_CONFIG)
    header, rows = rows_of(plan)
    table = display.rich_table(plan, header, rows)
    text = rendered(table, console)
    numbers = {cell for column in table.columns for cell in column.cells if re.fullmatch(r"[\d./]+", cell)}
    printed = set(re.findall(r"[\d./]+", text))
    assert "108869" in numbers and "1234567" in numbers
    assert numbers <= printed, sorted(numbers - printed)  # each number a whole word of the output
    assert max(len(line.rstrip()) for line in text.splitlines()) <= 80
