"""The baseline: the slider-crank as a researcher writes it by hand with scipy.integrate.solve_ivp.

The equations are those of tests/support/slider_crank_minimal.py (minimal coordinates θ2, x3; DOP853;
contact onset and loss as solve_ivp events; each switch re-integrated up to its time), reused as they
are. Accuracy is checked as clearsim's is: each rtol of RTOL_LADDER against a run at rtol/100 and
atol/100, on the peak slider acceleration (on clearsim's 100 kHz output grid) and the max contact force
(each episode's peak, refined on the dense output). The largest rtol whose contact-force error is within
clearsim's is timed `repeats` times.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from tests.support.slider_crank_minimal import FRICTION, FRICTIONLESS, rhs, simulate

RTOL_LADDER = (1e-8, 1e-9, 1e-10, 1e-11)  # looser runs can step through the wall (a row then says so)
ATOL_PER_RTOL = 1e-4  # atol = 1e-4 rtol (m), as the minimal model's default 1e-15 for rtol 1e-11
OUTPUT_PERIOD = 1e-5  # s, clearsim's 100 kHz


def run(friction: bool, t_end: float, rtol: float) -> dict:
    """One run: wall time, steps, max contact force, peak slider acceleration on the output grid."""
    p = FRICTION if friction else FRICTIONLESS
    started = time.perf_counter()
    result = simulate(p, t_end=t_end, rtol=rtol, atol=ATOL_PER_RTOL * rtol)
    force = max((episode.peak_normal_force for episode in result.episodes), default=0.0)
    wall = time.perf_counter() - started
    return {"rtol": rtol, "wall_s": wall, "steps": result.steps, "rhs_evaluations": result.rhs_evaluations,
            "max_contact_force": float(force), "peak_acceleration": _peak_slider_acceleration(result, t_end)}


def _peak_slider_acceleration(result, t_end: float) -> float:
    times = np.arange(0.0, t_end + 0.5 * OUTPUT_PERIOD, OUTPUT_PERIOD)
    states = result.states(times)
    index = result._piece_index(times)
    accelerations = [rhs(result.parameters, t, y, result.pieces[k].impact_speed)[3]
                     for t, y, k in zip(times, states, index)]
    return float(np.max(np.abs(accelerations)))


def _errors(row: dict, tight: dict) -> dict:
    return {key: abs(row[name] - tight[name]) / tight[name] for key, name in
            (("error_max_contact_force", "max_contact_force"), ("error_peak_acceleration", "peak_acceleration"))}


def compare_case(friction: bool, clearsim, repeats: int, quick: bool) -> dict:
    """Ladder rows (each vs its own 100× tighter run), the matched rtol timed, the wall-time ratio."""
    t_end = clearsim.simulated_time_s
    rows = []
    for rtol in RTOL_LADDER[2:3] if quick else RTOL_LADDER:
        try:
            row = run(friction, t_end, rtol)
            tight = run(friction, t_end, rtol / 100.0)
        except RuntimeError as exc:  # the hand-written model stops when a step jumps through the wall
            rows.append({"rtol": rtol, "failed": str(exc)[:160]})
            continue
        rows.append({**row, **_errors(row, tight)})
    target = clearsim.error_max_contact_force
    matched = next((r for r in rows if "failed" not in r and r["error_max_contact_force"] <= target), None)
    out = {"case": clearsim.case, "t_end_s": t_end, "rows": rows, "matched": matched,
           "clearsim_error_max_contact_force": target,
           "clearsim_error_peak_acceleration": clearsim.error_peak_acceleration}
    if matched is None:
        return out
    walls = [run(friction, t_end, matched["rtol"])["wall_s"] for _ in range(repeats)]
    out.update(wall_median_s=statistics.median(walls), wall_min_s=min(walls), wall_max_s=max(walls),
               clearsim_wall_median_s=clearsim.wall_median_s, ratio=statistics.median(walls) / clearsim.wall_median_s)
    return out


def baseline(quick: bool, folder, measurements, repeats: int = 1) -> dict:
    """Study entry for the harness: both slider-crank cases against their clearsim measurement."""
    from benchmarks.suite import crank_study

    return crank_study(compare_case, measurements, repeats, quick, folder)
