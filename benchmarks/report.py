"""Markdown tables from a results JSON (for docs/performance.md): `python -m benchmarks.report FILE.json`."""

from __future__ import annotations

import json
import sys
from pathlib import Path


def _cases(document: dict) -> list[str]:
    lines = ["| case | simulated | wall median [min, max] | integration | steps (rejected) | RHS | contact events | µs/step "
             "| peak traced memory | error peak acc. | error max F_n |", "|" + "---|" * 11]
    for m in document["cases"]:
        lines.append(f"| {m['case']} | {m['simulated_time_s'] * 1e3:g} ms | {m['wall_median_s']:.3f} s [{m['wall_min_s']:.3f}, "
                     f"{m['wall_max_s']:.3f}] | {m['integration_median_s']:.3f} s | {m['steps']} ({m['rejected_steps']}) | "
                     f"{m['rhs_evaluations']} | {m['contact_events']} | {m['us_per_step']:.1f} | {m['peak_memory_mb']:.0f} MB | "
                     f"{m['error_peak_acceleration']:.1e} | {m['error_max_contact_force']:.1e} |")
    sweep = document.get("sweep")
    if sweep:
        lines.append(f"| sweep-8 ({sweep['workers']} workers) | | {sweep['wall_s']:.1f} s | | | | | | | "
                     f"{sweep['cases_per_minute']:.1f} cases/min | {sweep['failed']} failed |")
    return lines


SIDE_BY_SIDE = (  # study key, tool, its setting, the prefix of the clearsim errors it is matched against
    ("peer", "Exudyn 1.13.6", lambda r: f"RK44, h = {r['step_s']:g} s", "clearsim_"),
    ("baseline", "solve_ivp minimal", lambda r: f"DOP853, rtol = {r['rtol']:g}", "clearsim_"),
    ("baseline-cartesian", "solve_ivp Cartesian", lambda r: f"DOP853, rtol = {r['rtol']:g}", "clearsim_reference_"),
)


def _side_by_side(document: dict) -> list[str]:
    lines = ["| case | tool | setting | wall median [min, max] | error peak acc. | error max F_n | its wall / clearsim's |",
             "|" + "---|" * 7]
    for key, tool, setting, prefix in SIDE_BY_SIDE:
        study = document.get(key) or {}
        for case in study.get("cases", []):
            m = case["matched"]
            if m is None:
                lines.append(f"| {case['case']} | {tool} | nothing tried matched | | | | |")
                continue
            lines.append(f"| {case['case']} | {tool} | {setting(m)} | {case['wall_median_s']:.3f} s [{case['wall_min_s']:.3f}, "
                         f"{case['wall_max_s']:.3f}] | {m['error_peak_acceleration']:.1e} | {m['error_max_contact_force']:.1e} | "
                         f"**{case['ratio']:.1f}×** |")
            lines.append(f"| | clearsim | rtol = 1e-7 | {case['clearsim_wall_median_s']:.3f} s | "
                         f"{case[prefix + 'error_peak_acceleration']:.1e} | {case[prefix + 'error_max_contact_force']:.1e} | 1 |")
            s = case.get("settled") or {}
            if "ratio" in s:  # a tighter rung from which on every rung is as accurate (errors not monotone)
                lines.append(f"| | {tool} | {setting(s)} and tighter | {s['wall_median_s']:.3f} s [{s['wall_min_s']:.3f}, "
                             f"{s['wall_max_s']:.3f}] | {s['error_peak_acceleration']:.1e} | {s['error_max_contact_force']:.1e} | "
                             f"**{s['ratio']:.1f}×** |")
                lines.append(f"| | clearsim | rtol = 1e-7 | {s['clearsim_wall_median_s']:.3f} s | | | 1 |")
    return lines


def _cartesian_ladder(document: dict) -> list[str]:
    lines = ["| case | rtol | wall (one run) | steps | RHS | contact events | max F_n | error acc. / F_n vs reference "
             "| error acc. / F_n vs own rtol/100 | max \\|Φ\\| |", "|" + "---|" * 10]
    for case in (document.get("baseline-cartesian") or {}).get("cases", []):
        lines.append(f"| {case['case']} | clearsim 1e-7 | | | | | | {case['clearsim_reference_error_peak_acceleration']:.1e} / "
                     f"{case['clearsim_reference_error_max_contact_force']:.1e} | {case['clearsim_error_peak_acceleration']:.1e} / "
                     f"{case['clearsim_error_max_contact_force']:.1e} | |")
        for r in case["rows"]:
            if "failed" in r:
                lines.append(f"| {case['case']} | {r['rtol']:g} | failed: {r['failed'][:70]} | | | | | | | |")
                continue
            lines.append(f"| {case['case']} | {r['rtol']:g} | {r['wall_s']:.3f} s | {r['steps']} | {r['rhs_evaluations']} | "
                         f"{r['contact_events']} | {r['max_contact_force']:.1f} N | {r['error_peak_acceleration']:.1e} / "
                         f"{r['error_max_contact_force']:.1e} | {r['self_error_peak_acceleration']:.1e} / "
                         f"{r['self_error_max_contact_force']:.1e} | {r['constraint_drift']:.1e} |")
    return lines if len(lines) > 2 else []


def _at_peer_accuracy(document: dict) -> list[str]:
    lines = ["| case | Exudyn step | Exudyn wall | its errors (acc. / F_n) | clearsim rtol | clearsim wall | its errors (acc. / F_n) "
             "| Exudyn / clearsim |", "|" + "---|" * 8]
    for case in (document.get("peer") or {}).get("cases", []):
        for r in case.get("at_peer_accuracy", []):
            mine = r["clearsim"]
            theirs = f"{r['error_peak_acceleration']:.1e} / {r['error_max_contact_force']:.1e}"
            if mine is None:
                lines.append(f"| {case['case']} | {r['step_s']:g} s | {r['wall_s']:.3f} s | {theirs} | none as accurate | | | |")
                continue
            lines.append(f"| {case['case']} | {r['step_s']:g} s | {r['wall_s']:.3f} s | {theirs} | {mine['rtol']:g} | "
                         f"{mine['wall_s']:.3f} s | {mine['error_peak_acceleration']:.1e} / {mine['error_max_contact_force']:.1e} | "
                         f"**{r['ratio']:.1f}×** |")
    return lines if len(lines) > 2 else []


def _ladders(document: dict) -> list[str]:
    lines = ["| case | tool | setting | wall (one run) | max F_n | error max F_n | error peak acc. |", "|" + "---|" * 7]
    for key, tool, name in (("peer", "Exudyn", "step_s"), ("baseline", "solve_ivp", "rtol")):
        for case in (document.get(key) or {}).get("cases", []):
            for r in case["rows"]:
                if "failed" in r:
                    lines.append(f"| {case['case']} | {tool} | {name} = {r[name]:g} | failed: {r['failed'][:70]} | | | |")
                else:
                    lines.append(f"| {case['case']} | {tool} | {name} = {r[name]:g} | {r['wall_s']:.3f} s | {r['max_contact_force']:.1f} N "
                                 f"| {r['error_max_contact_force']:.1e} | {r['error_peak_acceleration']:.1e} |")
    return lines if len(lines) > 2 else []


def _scaling(document: dict) -> list[str]:
    result = document.get("scaling")
    if not result:
        return []
    lines = ["| N bars | bodies | K | steps | RHS | integration | µs/step | µs/RHS |", "|" + "---|" * 8]
    for r in result["rows_by_size"] + result["rows_by_clearances"]:
        lines.append(f"| {r['bars']} | {r['bodies']} | {r['clearance_joints']} | {r['steps']} | {r['rhs_evaluations']} | "
                     f"{r['integration_s']:.4f} s | {r['us_per_step']:.0f} | {r['us_per_rhs']:.1f} |")
    lines.append("")
    lines += [f"- {k}: **{v:.2f}**" for k, v in result["orders"].items() if v is not None]
    return lines


def _diagnose(document: dict) -> list[str]:
    from benchmarks.extras import describe

    return [f"- {describe('diagnose', document['diagnose'])}"] if document.get("diagnose") else []


def render(document: dict) -> str:
    parts = [_cases(document), _side_by_side(document), _at_peer_accuracy(document), _ladders(document),
             _cartesian_ladder(document), _scaling(document), _diagnose(document)]
    return "\n\n".join("\n".join(p) for p in parts if p) + "\n"


if __name__ == "__main__":
    sys.stdout.write(render(json.loads(Path(sys.argv[1]).read_text())))
