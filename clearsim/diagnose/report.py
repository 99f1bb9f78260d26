"""The diagnosis written down: diagnosis.json, report.md with figures, and the augmented model YAML.

Nothing is overwritten silently: an earlier report's files are kept under numbered names.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from clearsim.diagnose.align import INTERVAL_LEVEL, QUIET, REPEATS, TREND, predict, residuals
from clearsim.diagnose.candidates import Candidate
from clearsim.diagnose.evaluate import document_text
from clearsim.diagnose.search import SIGNIFICANCE, JointFit, Scored, smoothed_interval
from clearsim.diagnose.search import robust_to_perturbations, significant_on_both_halves
from clearsim.diagnose.workflow import (Diagnosis, Effect, confirmed, effect_line, ensemble_line, explained_share,
                                       found_effect, refit_line)
from clearsim.io.hdf5 import keep_as_previous
from clearsim.plot.style import LEGEND_WIDTH, legend_beside, new_figure, set_title, wrap_label

REPORT, JSON = "report.md", "diagnosis.json"
NOISE_SOURCES = {TREND: "the record minus its trend", QUIET: "the residual against the model as given",
                 REPEATS: "the spread of the repeated records"}
GAP_AXIS_CHARACTERS = 55  # characters of tick label that fit side by side under the gap axis


def _effect(effect: Effect, d: Diagnosis | None = None) -> dict:
    """An effect as in diagnosis.json; with the diagnosis `d`, its verdict too (confirmed, and on what)."""
    c, scored = effect.candidate, effect.scored
    low, high = effect.interval
    return {"kind": c.kind, "target": c.target, "finding": c.finding(effect.value), "parameters": {c.parameter: effect.value},
            "interval": {c.parameter: [low, high]}, "unit": {c.parameter: c.unit},
            "ambiguous_with": scored.ambiguous_with, "telling_sensor": scored.telling_sensor,
            "delta_bic": scored.delta_bic, "gap": effect.point.fit.gap,
            "delta_chi_square_halves": list(scored.halves) if scored.halves else None,
            "confirmed_on_both_halves": bool(scored.halves and max(scored.halves) < 0.0),
            "delta_chi_square_perturbed": list(scored.perturbed)} | _position(c) | (_verdict_of(effect, d) if d is not None else {})


def _position(c: Candidate) -> dict:
    """A worn arc's angular position in the bearing body's frame (degrees), for an effect that has one."""
    return {"angle_deg": math.degrees(c.angle) % 360.0} if c.angle is not None else {}


def _verdict_of(effect: Effect, d: Diagnosis) -> dict:
    return {"significant_on_both_halves": significant_on_both_halves(effect.scored, d.record),
            "robust_to_perturbations": robust_to_perturbations(effect.scored, d.record),
            "explained_share": explained_share(effect, d.record),
            "confirmed": confirmed(effect, d.check, d.record)}


def _remaining(d: Diagnosis) -> dict:
    """What remains after the effects found: the test against the noise, where, and what would help."""
    test = d.check.test
    return {"gap": d.after.gap, "gaps_settled": test.gaps, "effective_samples": test.effective_samples,
            "p_values": test.p_values, "level": test.level, "beyond_noise": test.failing,
            "chaotic_spread": test.spread,
            "windows": [{"sensor": w.sensor, "start_s": w.start, "end_s": w.end, "peak_noise_levels": w.peak}
                        for w in d.check.windows],
            "helpful_sensors": d.check.helpful_sensors}


def _joint(joint: JointFit | None) -> dict | None:
    """The joint refit: the greedy start, the refitted values, every run ([values…, χ²])."""
    if joint is None:
        return None
    return {"effects": [f"{c.kind} {c.target} {c.parameter}" for c in joint.candidates],
            "greedy": list(joint.start), "refitted": list(joint.best.value),
            "gap_greedy": joint.start_point.fit.gap, "gap_refitted": joint.best.fit.gap, "last_step_unit": joint.step,
            "runs": [[*p.value, p.chi_square if p.fit is not None else None] for p in joint.points]}


def _ranking(scored: list[Scored]) -> list[dict]:
    rows = []
    for s in scored:
        best = s.estimate
        rows.append({"kind": s.candidate.kind, "target": s.candidate.target, "parameter": s.candidate.parameter,
                     "value": best.value if best else None, "fitted": s.fitted,
                     "chi_square": best.chi_square if best else None,
                     "delta_bic": s.delta_bic if np.isfinite(s.delta_bic) else None,
                     "gap": best.fit.gap if best else None, "runs": len(s.points),
                     "failed_runs": sum(p.fit is None for p in s.points),
                     "profile": [[p.value, p.chi_square if p.fit is not None else None,
                                  p.low_band_chi_square if p.low_band is not None else None]
                                 for p in sorted(s.points, key=lambda p: p.value)],
                     "smoothed_in": (None if s.smoothed is None
                                     else "screening band" if s.smoothed_in_low_band else "comparison band"),
                     "smoothed": {("screening band" if band else "comparison band"): _smoothed_value(s, profile)
                                  for band, profile in s.profiles.items()}} | _position(s.candidate))
    return rows


def _smoothed_value(scored: Scored, profile: tuple[float, float]) -> dict:
    """A rough candidate's smoothed minimum in one band, as an SI value with its interval."""
    return {"value": float(scored.candidate.from_unit(profile[0])), "interval": list(smoothed_interval(scored, profile))}


def diagnosis_document(d: Diagnosis) -> dict:
    """The machine-readable diagnosis; `effects`, `gap_before`, `gap_after` and `gaps` are its stable core."""
    return {
        "config": str(d.request.config), "measured": str(d.request.measured), "overrides": list(d.request.overrides),
        "effects": [_effect(e, d) for e in d.effects],
        "unexplained": d.check.unexplained, "remaining": _remaining(d),
        "gap_before": d.before.gap, "gap_after": d.after.gap,
        "gaps": {s: {"before": d.before.gaps[s], "after": d.after.gaps[s]} for s in d.sensors},
        "trigger_offset_s": {"before": d.before.offset, "after": d.after.offset},
        "noise": {s: {"std": n.std, "interval": list(n.interval()), "interval_level": INTERVAL_LEVEL,
                      "degrees_of_freedom": n.degrees_of_freedom, "estimator": n.estimator,
                      "effective_samples": n.effective_samples, "samples": n.samples}
                  for s, n in d.record.noise.items()},
        "repeats": [str(path) for path in d.request.repeats],
        "comparison_lowpass_hz": d.record.cutoff,
        "ensemble": {"runs": d.ensemble.runs, "automatic": d.ensemble.automatic, "twin_gaps": d.ensemble.twin_gaps,
                     "impact_rich": d.ensemble.impact_rich},
        "joint_refit": _joint(d.joint),
        "pairs": [{"effects": [c.label for c in pair.candidates], "values": list(pair.joint.best.value),
                   "delta_bic": pair.delta_bic, "gap": pair.joint.best.fit.gap, "runs": len(pair.joint.points)}
                  for pair in d.pairs],
        "found_as_pair": d.found_as_pair,
        "iterations": [{"gap": it.baseline.gap, "found": _effect(found_effect(it.found, it.baseline)) if it.found else None,
                        "rejected": it.rejected or None, "ranking": _ranking(it.ranked),
                        "windows": [{"sensor": w.sensor, "start_s": w.start, "end_s": w.end, "peak_noise_levels": w.peak}
                                    for w in it.windows]} for it in d.iterations],
        "simulations": d.simulations, "wall_time_s": d.wall_time,
    }


def augmented_yaml(d: Diagnosis) -> str:
    """The model with the effects found, as YAML, with a comment naming each one."""
    lines = [f"# {Path(d.request.config).name} with the effects found by clearsim diagnose "
             f"from {Path(d.request.measured).name}:"]
    lines += [f"#   {i}. {effect_line(e)}" for i, e in enumerate(d.effects, start=1)] or ["#   (none)"]
    if d.request.overrides:
        lines.append(f"# starting model: --set {' '.join(d.request.overrides)}")
    return "\n".join(lines) + "\n" + document_text(d.final)


def write_report(d: Diagnosis, fmt: str = "png") -> list[Path]:
    folder = d.folder
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    json_path = folder / JSON
    keep_as_previous(json_path)
    json_path.write_text(json.dumps(diagnosis_document(d), indent=2, default=_plain) + "\n", encoding="utf-8")
    written.append(json_path)
    model_path = folder / f"{Path(d.request.config).stem}.diagnosed.yaml"
    keep_as_previous(model_path)
    model_path.write_text(augmented_yaml(d), encoding="utf-8")
    written.append(model_path)
    figures = _figures(d, fmt)
    report_path = folder / REPORT
    keep_as_previous(report_path)
    report_path.write_text(_markdown(d, figures, model_path), encoding="utf-8")
    written += [report_path, *figures]
    return written


def _plain(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    raise TypeError(type(value))


def verdict(d: Diagnosis) -> str:
    """One line: the effects (confirmed: "missing effect"; else "not confirmed"), and "unexplained" when what remains
    of the record is not noise."""
    named = "; ".join(f"{'missing effect' if confirmed(e, d.check, d.record) else 'not confirmed'}: {effect_line(e)}"
                      for e in d.effects)
    if not d.effects:
        why = (f"the best candidate is rejected: {d.iterations[-1].rejected}" if d.iterations[-1].rejected
               else "no candidate lowers the BIC by more than the significance margin")
        named = f"no missing effect found: {why}; gap {d.before.gap:.3g}"
    return f"{unexplained_line(d)}; {named}" if d.check.unexplained else named


def unexplained_line(d: Diagnosis) -> str:
    """'unexplained: the record stays 3.5 noise levels from the model …, beyond the noise on x (…); it disagrees most
    at …; sensors that would tell more: …'."""
    test, check = d.check.test, d.check
    failing = ", ".join(f"{s} (gap {test.gaps[s]:.3g}, n_eff {test.effective_samples[s]:.0f}, p {test.p_values[s]:.2g})"
                        for s in test.failing)
    windows = ", ".join(f"{w.sensor} {w.start * 1e3:.3g}–{w.end * 1e3:.3g} ms ({w.peak:.1f}σ̂)" for w in check.windows[:3])
    helpful = ", ".join(check.helpful_sensors) or "none among the model's sensors (add one near those windows)"
    model = "the model with the effects found" if d.effects else "the model"
    beyond = "the noise and the model's chaotic spread" if test.spread else "the noise"
    return (f"unexplained: the record stays {d.after.gap:.3g} noise levels from {model}, beyond {beyond} on {failing} "
            f"(F test at {test.level:g}); it disagrees most at {windows or 'no 1-ms window above 3σ̂'}; "
            f"sensors that would tell more: {helpful}")


def _remaining_lines(d: Diagnosis) -> list[str]:
    """What remains after the effects, against the noise: per sensor the gap without the comparison filter's start-up,
    the residual's n_eff and p; then the verdict in words."""
    test = d.check.test
    out = [f"## What remains: {'unexplained' if d.check.unexplained else 'noise'}", "",
           f"F test of each sensor's residual against the noise at {test.level:g} (shared among the sensors): "
           "gap² against F(n_eff, ν), n_eff from the residual's autocorrelation, ν the degrees of freedom of σ̂ "
           "(docs/diagnose.md §5b).", "", *_spread_lines(test),
           "| sensor | gap | n_eff | p | beyond the noise |", "|---|---|---|---|---|"]
    out += [f"| {s} | {test.gaps[s]:.3g} | {test.effective_samples[s]:.0f} | {test.p_values[s]:.2g} | "
            f"{'yes' if s in test.failing else 'no'} |" for s in test.gaps]
    if d.check.unexplained:
        out += ["", unexplained_line(d) + "."]
    return out + [""]


def _spread_lines(test) -> list[str]:
    """The chaotic spread counted with the noise, when the test counted one."""
    if not test.spread:
        return []
    strays = ", ".join(f"{s} {stray:.3g}" for s, stray in test.spread.items())
    return [f"Each residual sample is set against σ̂² + the spread of the final model's re-rolled twins there (they "
            f"stray {strays} noise levels, RMS): impacts the record replays otherwise are no model error.", ""]


def _markdown(d: Diagnosis, figures: list[Path], model_path: Path) -> str:
    out = [f"# Diagnosis of {Path(d.request.config).name} against {Path(d.request.measured).name}", "",
           f"**{verdict(d)}**", "",
           f"{d.simulations} simulations, {d.wall_time:.0f} s. Gap = RMS residual / noise level (docs/diagnose.md).", "",
           f"| sensor | noise σ̂ ({INTERVAL_LEVEL:.0%} interval) | estimated from | n_eff / N | gap before | gap after |",
           "|---|---|---|---|---|---|"]
    for s in d.sensors:
        n = d.record.noise[s]
        low, high = n.interval()
        out.append(f"| {s} | {n.std:.3g} ({low:.3g}–{high:.3g}) {d.units.get(s, '')} | {NOISE_SOURCES[n.estimator]} | "
                   f"{n.effective_samples:.0f} / {n.samples} | {d.before.gaps[s]:.3g} | {d.after.gaps[s]:.3g} |")
    out += [f"| combined | | | | {d.before.gap:.3g} | {d.after.gap:.3g} |", "",
            f"Trigger offset: {d.before.offset * 1e3:.3f} ms (fitted as a nuisance).", "",
            f"{ensemble_line(d.ensemble).capitalize()}.", "", *_remaining_lines(d),
            *_joint_lines(d),
            "## Where the model and the record disagree (before)", "",
            "| sensor | feature | measured | model | unit |", "|---|---|---|---|---|"]
    out += [f"| {f.sensor} | {f.name} | {f.measured:.4g} | {f.model:.4g} | {f.unit} |" for f in d.iterations[0].features]
    out += ["", "Windows where the 1-ms RMS residual exceeds 3 noise levels: "
            + (", ".join(f"{w.sensor} {w.start * 1e3:.2f}–{w.end * 1e3:.2f} ms ({w.peak:.1f}σ̂)"
                         for w in d.iterations[0].windows[:8]) or "none"), ""]
    for number, it in enumerate(d.iterations, start=1):
        out += [f"## Iteration {number}: candidates ranked", "",
                "| candidate | parameter | best value | ΔBIC | gap | runs |", "|---|---|---|---|---|---|"]
        for s, (name, _) in zip(it.ranked, ranked_rows(it.ranked)):
            best = s.estimate
            value = s.candidate.shown(best.value) if best else "—"
            delta = f"{s.delta_bic:.1f}" if np.isfinite(s.delta_bic) else "—"
            gap = f"{best.fit.gap:.3g}" if best else "run failed"
            out.append(f"| {name} | {s.candidate.parameter} | {value} | {delta} | {gap} | {len(s.points)} |")
        out.append("")
    out += ["## Figures", ""] + [f"![{p.stem}]({p.name})" for p in figures]
    out += ["", f"Augmented model: `{model_path.name}`.", ""]
    return "\n".join(out)


def _joint_lines(d: Diagnosis) -> list[str]:
    if d.joint is None:
        return []
    if d.found_as_pair:
        return [f"Neither effect alone beat the model significantly; the pairwise search fitted them together "
                f"({len(d.joint.points)} runs: a coarse grid, then refined), ΔBIC {d.effects[0].scored.delta_bic:.0f} "
                "counting both parameters. ΔBIC and the halves above are the pair's.", ""]
    return [f"The {len(d.effects)} effects were found one after another, then {refit_line(d.joint, d.effects)}. "
            "The values, intervals and gaps above are the refitted ones; ΔBIC is the evidence of the step that "
            "found each effect.", ""]


@dataclass
class SensorComparison:
    """One sensor of the comparison figure: the record and the model before and after, in the record's unit."""
    sensor: str
    unit: str
    measured: np.ndarray
    before: np.ndarray
    after: np.ndarray
    residual_before: np.ndarray  # / the noise level σ̂
    residual_after: np.ndarray
    gap_before: float
    gap_after: float


def _comparisons(d: Diagnosis) -> list[SensorComparison]:
    before, after = d.iterations[0].baseline_prediction, d.after_prediction
    aligned_before = predict(d.record, before.time, before.sensors, d.before.offset)
    aligned_after = predict(d.record, after.time, after.sensors, d.after.offset)
    res_before, res_after = residuals(d.record, aligned_before), residuals(d.record, aligned_after)
    return [SensorComparison(s, d.units.get(s, ""), d.record.values[s], aligned_before[s], aligned_after[s],
                             res_before[s] / d.record.noise[s].std, res_after[s] / d.record.noise[s].std,
                             d.before.gaps[s], d.after.gaps[s]) for s in d.sensors]


def comparison_figure(time_ms: np.ndarray, comparisons: list[SensorComparison], title: str):
    """Record and model before / after the effects found (left), residuals in noise levels (right)."""
    figure = new_figure((10.0 + 2 * LEGEND_WIDTH, 3.2 * len(comparisons) + 0.9))
    axes = figure.subplots(len(comparisons), 2, squeeze=False, sharex=True)
    for (left, right), c in zip(axes, comparisons):
        left.plot(time_ms, c.measured, color="0.6", lw=0.8, label="measured")
        left.plot(time_ms, c.before, lw=1.0, label="model as given")
        left.plot(time_ms, c.after, lw=1.0, ls="--", label="with the effects found")
        left.set_ylabel(f"{c.sensor} ({c.unit})" if c.unit else c.sensor)
        right.plot(time_ms, c.residual_before, lw=0.8, label=f"before (gap {c.gap_before:.3g})")
        right.plot(time_ms, c.residual_after, lw=1.0, ls="--", label=f"after (gap {c.gap_after:.3g})")
        right.axhspan(-3, 3, color="0.9", label="±3 noise levels")
        right.set_ylabel("residual / σ̂")
        legend_beside(left), legend_beside(right)
    for ax in axes[-1]:
        ax.set_xlabel("time (ms)")
    set_title(figure, title)
    return figure


def ranked_rows(ranked: list[Scored]) -> list[tuple[str, float]]:
    """(candidate as report.md names it, ΔBIC or NaN) for every ranked candidate, in the report's order."""
    return [(f"{s.candidate.label}{'' if s.fitted else ' (screened)'}", s.delta_bic) for s in ranked]


def ranking_figure(rows: list[tuple[str, float]], gaps: list[tuple[str, float]], title: str):
    """ΔBIC of every ranked candidate (a candidate whose runs failed: no bar, "—"), and the gap after each effect."""
    figure = new_figure((12.0, max(4.0, 0.28 * len(rows) + 1.8)))
    rank_ax, gap_ax = figure.subplots(1, 2, width_ratios=(1.6, 1.0))
    names = [name for name, _ in rows][::-1]
    values = np.array([value for _, value in rows][::-1], dtype=float)
    shown = np.where(np.isfinite(values), values, 0.0)
    rank_ax.barh(names, shown)
    for position, value in enumerate(values):
        if not np.isfinite(value):
            rank_ax.annotate("— (runs failed)", (0.0, position), xytext=(4, 0), textcoords="offset points",
                             va="center", fontsize=8)
    rank_ax.axvline(-SIGNIFICANCE, color="k", ls=":", lw=0.8)
    rank_ax.set_xscale("symlog", linthresh=SIGNIFICANCE)  # −230 and +9000 on one axis, the margin still readable
    rank_ax.set_ylim(-0.6, len(names) - 0.4)
    rank_ax.set_xlabel(f"ΔBIC vs the model as given (below −{SIGNIFICANCE:g}: significant; linear within ±{SIGNIFICANCE:g}, "
                       "logarithmic beyond)")
    rank_ax.set_title("candidates ranked (iteration 1 of report.md)")
    gap_ax.plot(range(len(gaps)), [gap for _, gap in gaps], "o-")
    characters = max(8, GAP_AXIS_CHARACTERS // len(gaps) - 2)  # each label's lines fit its share of the axis
    gap_ax.set_xticks(range(len(gaps)), [wrap_label(name, characters) for name, _ in gaps])
    gap_ax.set_xlim(-0.5, len(gaps) - 0.5)
    gap_ax.set_ylabel("combined gap")
    gap_ax.set_title("combined gap after each effect added")
    gap_ax.axhline(1.0, color="0.5", ls=":")
    set_title(figure, title)
    return figure


def _figures(d: Diagnosis, fmt: str) -> list[Path]:
    name = f"{Path(d.request.config).name} against {Path(d.request.measured).name}"
    comparison = comparison_figure(d.record.time * 1e3, _comparisons(d),
                                   f"{name}\nrecord and model before and after the effects found; residuals in noise "
                                   "levels σ̂")
    gaps = [("as given", d.before.gap)] + [(e.candidate.label, e.point.fit.gap) for e in d.effects]
    ranking = ranking_figure(ranked_rows(d.iterations[0].ranked), gaps, f"{name}\ncandidate effects and the gap")
    return [_save(comparison, d.folder / f"diagnose-comparison.{fmt}"),
            _save(ranking, d.folder / f"diagnose-ranking.{fmt}")]


def _save(fig, path: Path) -> Path:
    keep_as_previous(path)
    fig.savefig(path, dpi=110)
    return path
