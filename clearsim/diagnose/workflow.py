"""`clearsim diagnose`: align, locate, fit candidate effects, name the missing one, add it, repeat.

    diagnosis = diagnose(DiagnoseRequest(config, measured, max_effects=2), say=print)

Greedy forward selection: each iteration fits every candidate effect to the record on top of the
model as it stands (the original plus the effects found so far), keeps the best one if its BIC
beats the model's by SIGNIFICANCE, and stops when none does or `max_effects` are found. Several
effects found are then refitted together (search.refit_jointly); their reported values, intervals
and gaps are the joint ones, their evidence (ΔBIC, ties, halves) the greedy step's that found them. When the first
iteration finds nothing and the model misses the record by more than the noise, with max_effects ≥ 2 the most promising
pairs of candidates are fitted together (pairwise_search). Runs per candidate value: the ensemble chosen from the
model's re-rolled twins (chosen_ensemble).
"""

from __future__ import annotations

import time as clock
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import yaml

from clearsim.diagnose.align import (ChaoticSpread, Fit, NoiseEstimate, NoiseTest, Record, fit_offset, noise_test, predict,
                                    prepare_record, repeat_noise, residual_noise, residuals)
from clearsim.diagnose.candidates import KINDS, Candidate, candidates_for, perturbed, wear_between, with_effects
from clearsim.diagnose.evaluate import Evaluator, Prediction, document_text
from clearsim.diagnose.features import Feature, Window, disagreement_windows, features
from clearsim.diagnose.measured import MeasuredData, model_sensor_units, parse_mapping, read_measured
from clearsim.diagnose.search import (AS_GIVEN, PERTURBATIONS, SIGNIFICANCE, Ensembled, JointFit, PairFit, Point, Scored,
                                     SearchProgress, candidate_pairs, fit_pair, no_change, reaches_no_change, unbounded,
                                     Tracked, aligned_residuals, chaotic_spread, halves_improved, judge, keeps_its_gain, low_band_best,
                                     mark_ties, median_change, profile_threshold, refine, refit_jointly,
                                     robust_to_perturbations, score_point, screen, seen_by_sensors, setting,
                                     significant_on_both_halves, to_fit, twin_gaps)
from clearsim.errors import ClearsimError, did_you_mean
from clearsim.model.loader import load_mechanism, load_mechanism_text
from clearsim.model.resolve import is_clearance_joint
from clearsim.units import UnitError, to_si

RESULTS = Path("results")
FIT_TOP = 3
MIN_SAMPLES = 200  # the noise spectrum and the comparison filter need a few hundred samples
MIN_CYCLES = 2  # --lowpass: cycles of the cut-off over the record (n_eff ≈ 2·f_c·T)
MIN_COVERAGE = 0.1  # of the simulated window the record must cover, and of the record that must lie in the window


class DiagnoseError(ClearsimError):
    """A diagnosis that cannot start or continue (bad option, a model that does not run)."""


@dataclass
class DiagnoseRequest:
    config: Path
    measured: Path
    overrides: list[str] = field(default_factory=list)
    mapping: list[str] = field(default_factory=list)  # column=sensor
    candidates: str | None = None  # "clearance,friction": kinds to try (default all)
    max_effects: int = 1
    out: Path | None = None
    workers: int | None = None
    scheduler: str | None = None
    lowpass: str | None = None  # the bench's filter if known
    fit_top: int = FIT_TOP
    repeats: list[Path] = field(default_factory=list)  # further records of the same test: the noise from their spread
    ensemble: int | None = None  # runs per candidate value (the given one and perturbed twins): its cost is their
    # median; None: chosen from the model's twins (AUTO_ENSEMBLE on an impact-rich record, else 1)


@dataclass
class Iteration:
    baseline: Fit
    baseline_prediction: Prediction
    ranked: list[Scored]
    found: Scored | None
    features: list[Feature]
    windows: list[Window]
    rejected: str = ""  # why its best candidate, significant by the BIC, is not named (none: "")


@dataclass
class Effect:
    """An effect as reported: the greedy iteration that found it (its evidence: ΔBIC, ties, halves), and
    its value, interval and fit — after the joint refit when several effects were found."""

    scored: Scored
    value: float
    interval: tuple[float, float]
    point: Point  # the model with this effect and those found before it
    before: Fit  # the model with the effects found before it

    @property
    def candidate(self) -> Candidate:
        return self.scored.candidate


def found_effect(scored: Scored, before: Fit) -> Effect:
    """The effect as the greedy iteration fitted it."""
    return Effect(scored, scored.estimate.value, scored.interval, scored.estimate, before)


@dataclass(frozen=True)
class EnsembleChoice:
    """Runs per candidate value (K) and why: given with --ensemble, or chosen from how far the model's re-rolled twins
    stray from it on each sensor (search.twin_gaps; empty when not measured: given, or no clearance joint)."""

    runs: int
    twin_gaps: dict[str, float]
    automatic: bool

    @property
    def impact_rich(self) -> list[str]:
        """The sensors on which the twins stray by more than the noise."""
        return [s for s, gap in self.twin_gaps.items() if gap > IMPACT_RICH]


AUTO_ENSEMBLE = 3  # runs per value on an impact-rich record: the median of three outvotes one lucky realisation
IMPACT_RICH = 1.0  # a sensor on which the model's twins stray by more than one noise level (RMS) is impact-rich
HELPFUL_SENSORS = 2  # model sensors named as the ones to add to the bench
SENSED = 1e-4  # of a sensor's range: an effect that changes it by less (RMS) leaves it as it is
ENSEMBLE_SEED = 100  # the ensemble's twins are seeded 101, 102, …: other draws than the robustness check's 1, 2, 3
VERDICT_TWINS = 4  # re-rolled twins of the final model whose spread the verdict adds to the noise (§5b)
VERDICT_SEED = 200  # seeded 201, 202, …
VERDICT_PERTURBATION = 1e-6  # m: their journals' start off the given place; 1 nm twins stay together for longer
MOST = 0.5  # of the excess χ² over n_eff: the share a confirmed effect explains while the record stays unexplained


@dataclass
class RecordCheck:
    """After the search: is what remains of the record noise? (align.noise_test on the final model's residual)."""

    test: NoiseTest
    windows: list[Window]  # where the final model and the record disagree beyond 3 noise levels (1-ms RMS)
    helpful_sensors: list[str]  # model sensors not measured on which the effects tried differ most from the model

    @property
    def unexplained(self) -> bool:
        return not self.test.consistent


@dataclass
class Diagnosis:
    request: DiagnoseRequest
    folder: Path
    measured: MeasuredData
    record: Record
    sensors: list[str]
    original: dict  # the document as given (with --set)
    final: dict  # with the effects found
    iterations: list[Iteration]
    effects: list[Effect]  # in the order found; values after the joint refit
    joint: JointFit | None  # the joint refit (two effects or more)
    simulations: int
    wall_time: float
    units: dict
    check: RecordCheck
    ensemble: EnsembleChoice
    pairs: list[PairFit]  # the pairs fitted together when no single effect was significant (--max-effects ≥ 2)

    @property
    def found_as_pair(self) -> bool:
        """The effects were found together by the pairwise search, not one after another."""
        pair = significant_pair(self.pairs)
        return pair is not None and self.joint is pair.joint

    @property
    def before(self) -> Fit:
        return self.iterations[0].baseline

    @property
    def after(self) -> Fit:
        return self.effects[-1].point.fit if self.effects else self.before

    @property
    def after_prediction(self) -> Prediction:
        return self.effects[-1].point.prediction if self.effects else self.iterations[0].baseline_prediction


def chosen_kinds(text: str | None) -> list[str]:
    if not text:
        return list(KINDS)
    kinds = [k.strip() for k in text.split(",") if k.strip()]
    if not kinds:
        raise DiagnoseError(f"--candidates {text!r}: names no kind of effect; give some of {', '.join(KINDS)}, "
                            "or leave the option out for all")
    for kind in kinds:
        if kind not in KINDS:
            raise DiagnoseError(f"--candidates: unknown kind '{kind}'{did_you_mean(kind, KINDS)} "
                                f"(kinds: {', '.join(KINDS)})")
    return kinds


def _cutoff(text: str | None) -> float | None:
    if text is None:
        return None
    try:
        value = to_si(text, "frequency")
    except UnitError as exc:
        raise DiagnoseError(f"--lowpass {text!r}: {exc}") from None
    if value <= 0:
        raise DiagnoseError(f"--lowpass {text!r}: the cut-off must be positive, e.g. --lowpass 2kHz")
    return value


def _executor(request: DiagnoseRequest):
    from clearsim.sweep import DaskCluster, LocalPool

    if request.scheduler is not None:  # "" is a malformed address (DaskCluster says so), not "no cluster"
        executor = DaskCluster(request.scheduler, request.workers)
        executor.connect()
        return executor
    return LocalPool(request.workers).open()


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:.4g} ms"


def check_window(measured: MeasuredData, t_end: float) -> None:
    """The record must cover the simulated window 0…t_end (the model is held at its first and last values
    outside it): with at least MIN_SAMPLES samples inside it, over at least MIN_COVERAGE of it, and with at
    least MIN_COVERAGE of the record inside it. A time column off by a unit fails one of these."""
    time, path = measured.time, measured.path
    where = f"{path}: column '{measured.columns.get('time', 'time')}'"
    spans = f"the record spans {_ms(time[0])} to {_ms(time[-1])}, the model 0 to {_ms(t_end)} (solver.t_end)"
    unit = measured.units.get("time") or "s"
    ratio = (time[-1] - time[0]) / t_end
    hint = (f"; is the time in [{unit}]? a time unit off by 1000 (s written as ms or ms as s) looks like this"
            if ratio > 100 or ratio < 0.01 else "")
    inside = np.count_nonzero((time >= 0.0) & (time <= t_end))
    if time[-1] < 0.0 or time[0] > t_end:
        raise DiagnoseError(f"{where}: {spans}: the record does not cover the simulated window{hint}; the time must "
                            "be 0 at the trigger, where the model starts (shift the time column)")
    if inside < MIN_SAMPLES:
        raise DiagnoseError(f"{where}: {spans}: only {inside} samples lie in the simulated window, too few to compare "
                            f"(at least {MIN_SAMPLES}){hint}; record the motion the model simulates, at a few kHz "
                            "or more, or set solver.t_end to the recorded span")
    covered = (min(time[-1], t_end) - max(time[0], 0.0)) / t_end
    if covered < MIN_COVERAGE:
        raise DiagnoseError(f"{where}: {spans}: the record covers {covered:.1%} of the simulated window, too short to "
                            f"compare (at least {MIN_COVERAGE:.0%}){hint}; record the whole motion, or lower "
                            f"solver.t_end (--set solver.t_end=...) to the recorded span")
    share = inside / len(time)
    if share < MIN_COVERAGE:
        raise DiagnoseError(f"{where}: {spans}: only {share:.1%} of the record lies in the simulated window, the "
                            f"rest would be compared with a model at rest{hint}; raise solver.t_end "
                            "(--set solver.t_end=...) or cut the record to the motion")


def default_folder(request: DiagnoseRequest) -> Path:
    return RESULTS / f"diagnose-{Path(request.config).stem}-{Path(request.measured).stem}"


def diagnose(request: DiagnoseRequest, say: Callable[[str], None] = lambda text: None,
             progress: Callable[[SearchProgress], None] = lambda progress: None) -> Diagnosis:
    """The whole workflow; every input problem is a ClearsimError raised before any run. progress(state) is called
    whenever runs are asked for or one finishes, and at each stage (SearchProgress: runs done of those planned so far,
    the best gap and its model)."""
    started = clock.perf_counter()
    if request.max_effects < 1:
        raise DiagnoseError(f"--max-effects must be at least 1, got {request.max_effects}")
    if request.ensemble is not None and request.ensemble < 1:
        raise DiagnoseError(f"--ensemble must be at least 1 (runs per candidate value), got {request.ensemble}")
    if request.fit_top < 1:
        raise DiagnoseError(f"--fit-top must be at least 1 (the candidates fitted in full per iteration), "
                            f"got {request.fit_top}")
    if request.out is not None and Path(request.out).exists() and not Path(request.out).is_dir():
        raise DiagnoseError(f"-o {request.out}: is a file, not a folder; give the folder for the report "
                            "(new, or one of an earlier diagnosis)")
    kinds = chosen_kinds(request.candidates)
    cutoff = _cutoff(request.lowpass)
    loaded = load_mechanism(request.config, request.overrides)
    measured = read_measured(request.measured, model_sensor_units(loaded.mechanism), parse_mapping(request.mapping))
    sensors = list(measured.values)
    if len(measured.time) < MIN_SAMPLES:
        raise DiagnoseError(f"{request.measured}: only {len(measured.time)} samples; diagnosing needs at least "
                            f"{MIN_SAMPLES} (record the whole motion, at a few kHz or more)")
    check_window(measured, loaded.mechanism.solver.t_end)
    span = float(measured.time[-1] - measured.time[0])
    if cutoff is not None and cutoff * span < MIN_CYCLES:
        raise DiagnoseError(f"--lowpass {request.lowpass!r}: below {MIN_CYCLES} cycles over the record "
                            f"({span * 1e3:.4g} ms), the comparison would keep no independent samples; give at "
                            f"least {MIN_CYCLES / span:.3g} Hz, or leave the option out to estimate it from the record")
    repeats = [read_repeat(path, measured, loaded.mechanism, request) for path in request.repeats]
    record = prepare_record(measured.time, measured.values, cutoff)
    units = model_sensor_units(loaded.mechanism)
    document = yaml.safe_load(loaded.resolved_yaml)
    original = document
    folder = Path(request.out) if request.out else default_folder(request)
    executor = _executor(request)
    evaluator = Tracked(Evaluator(folder / "runs", str(request.config), Path(request.config).parent, executor,
                                  record.rate), progress)
    iterations: list[Iteration] = []
    joint = None
    pairs: list[PairFit] = []
    try:
        evaluator.stage("estimating the noise")
        noise = record_noise(evaluator, record, sensors, document, repeats, request)
        record = prepare_record(measured.time, measured.values, cutoff, noise)
        say(_record_line(record))
        ensemble = chosen_ensemble(evaluator, record, document, request)
        say(ensemble_line(ensemble))
        tracked = evaluator  # one run per document: the verdict's twins (record_check)
        if ensemble.runs > 1:
            evaluator = Ensembled(evaluator, lambda document: ensemble_copies(document, request, ensemble.runs))
        found_keys: set = set()
        for number in range(1, request.max_effects + 1):
            iteration = _iterate(evaluator, record, sensors, document, kinds, found_keys, units, request, number, say)
            iterations.append(iteration)
            if iteration.found is None:
                break
            found_keys.add(iteration.found.candidate.key)
            document = iteration.found.candidate.applied(document, iteration.found.estimate.value)
        effects = [found_effect(it.found, it.baseline) for it in iterations if it.found is not None]
        if not effects and request.max_effects >= 2:
            pairs = pairwise_search(evaluator, record, sensors, original, iterations[0], say)
            best_pair = significant_pair(pairs)
            if best_pair is not None:
                joint = best_pair.joint
                effects = pair_effects(evaluator, record, sensors, original, best_pair, iterations[0])
                document = with_effects(original, best_pair.candidates, [e.value for e in effects])
                say(f"  found together: {'; '.join(effect_line(e) for e in effects)} (ΔBIC {best_pair.delta_bic:.0f})")
        elif len(effects) >= 2:
            evaluator.stage(f"refitting {len(effects)} effects together")
            joint = refit_jointly(evaluator, record, sensors, original, [e.candidate for e in effects],
                                  [e.value for e in effects])
            effects = refitted(evaluator, record, sensors, original, effects, joint)
            document = with_effects(original, [e.candidate for e in effects], [e.value for e in effects])
            say(f"  {refit_line(joint, effects)}")
        final = effects[-1].point if effects else None
        prediction = final.prediction if final else iterations[0].baseline_prediction
        offset = final.fit.offset if final else iterations[0].baseline.offset
        check = record_check(tracked, record, sensors, document, prediction, offset, iterations[0], request)
    finally:
        executor.close()
    return Diagnosis(request, folder, measured, record, sensors, original, document, iterations, effects, joint,
                     evaluator.simulations, clock.perf_counter() - started, units, check, ensemble, pairs)


def record_check(evaluator, record: Record, sensors: list[str], document: dict, prediction: Prediction, offset: float,
                 first: Iteration, request: DiagnoseRequest) -> RecordCheck:
    """The final model's residual against the noise, where it disagrees, and the sensors that would help. When it is
    beyond the noise and the final model has a clearance joint, again against the noise and the chaotic spread of the
    model's realisations (verdict_spread): an impact sequence the record replays otherwise is no model error."""
    residual = aligned_residuals(record, prediction, offset)
    test = noise_test(record, residual)
    if not test.consistent:
        spread = verdict_spread(evaluator, record, document, prediction, offset, request)
        test = noise_test(record, residual, spread) if spread is not None else test
    tried = [s.estimate.prediction for s in first.ranked if s.fitted and s.estimate is not None]
    return RecordCheck(test, disagreement_windows(record, residual),
                       helpful_sensors(first.baseline_prediction, tried, sensors))


def verdict_spread(evaluator, record: Record, document: dict, prediction: Prediction, offset: float,
                   request: DiagnoseRequest) -> ChaoticSpread | None:
    """The chaotic spread of the final model (search.chaotic_spread) from VERDICT_TWINS twins whose clearance journals
    start VERDICT_PERTURBATION off (seeds VERDICT_SEED + 1, …; one parallel batch); None without a clearance joint."""
    mechanism = _mechanism(document, request)
    if not has_clearance_joint(mechanism):
        return None
    evaluator.stage(f"the verdict: re-rolling the impacts {VERDICT_TWINS} times")
    seeds = range(VERDICT_SEED + 1, VERDICT_SEED + VERDICT_TWINS + 1)
    twins = evaluator.evaluate([perturbed(mechanism, document, seed, VERDICT_PERTURBATION) for seed in seeds],
                               lambda i, twin: twin, [f"the final model, re-rolled ({seed})" for seed in seeds])
    return chaotic_spread(record, prediction, twins, offset)


def helpful_sensors(model: Prediction, tried: list[Prediction], measured: list[str]) -> list[str]:
    """The model's sensors not measured, ranked by how much the effects tried change them (the largest RMS change
    over the sensor's range): where the candidates differ most, a sensor tells them apart; HELPFUL_SENSORS of them."""
    def change(name: str) -> float:
        scale = float(np.ptp(model.sensors[name])) or 1.0
        return max((float(np.sqrt(np.mean((np.interp(model.time, p.time, p.sensors[name]) - model.sensors[name]) ** 2)))
                    / scale for p in tried if name in p.sensors), default=0.0)

    unmeasured = [name for name in model.sensors if name not in measured]
    ranked = sorted(unmeasured, key=change, reverse=True)
    return [name for name in ranked if change(name) > SENSED][:HELPFUL_SENSORS]


def explained_share(effect: Effect, record: Record) -> float:
    """The share of what the model before it missed that the effect explains: (χ²_before − χ²_with) / (χ²_before − n_eff),
    n_eff being what noise alone leaves."""
    excess = effect.before.chi_square - record.effective_samples
    return float((effect.before.chi_square - effect.point.fit.chi_square) / excess) if excess > 0.0 else 0.0


def confirmed(effect: Effect, check: RecordCheck, record: Record) -> bool:
    """An effect is confirmed when the record, with it, is explained down to the noise; or, while the record stays
    unexplained, when it is significant on both halves of the record, robust to re-rolled impact sequences, and
    explains most (MOST) of what the model missed: a stand-in for an effect outside the candidates' kinds (a mass
    taking up part of a force) explains a little of it, on both halves and in every realisation alike."""
    return (not check.unexplained
            or significant_on_both_halves(effect.scored, record) and robust_to_perturbations(effect.scored, record)
            and explained_share(effect, record) >= MOST)


def refitted(evaluator, record: Record, sensors: list[str], document: dict, effects: list[Effect],
             joint: JointFit) -> list[Effect]:
    """The effects at the jointly refitted values: each with the fit of the model with it and the effects
    before it (one parallel batch for those nested models), and its interval from the joint refit."""
    values = joint.best.value
    candidates = [e.candidate for e in effects]
    nested = evaluator.evaluate([with_effects(document, candidates[:k], values[:k]) for k in range(1, len(effects))],
                                lambda i, prediction: score_point(record, sensors, values[:i + 1], prediction),
                                [setting(candidates[:k], values[:k]) for k in range(1, len(effects))])
    points = nested + [joint.best]
    failed = next((p for p in points if p.fit is None), None)
    if failed is not None:
        raise DiagnoseError(f"the model with the refitted effects {failed.value} does not run: {failed.error}")
    allowance = profile_threshold(joint.best.chi_square, record)
    befores = [effects[0].before] + [p.fit for p in points[:-1]]
    return [Effect(e.scored, v, i, p, b)
            for e, v, i, p, b in zip(effects, values, joint.intervals(allowance), points, befores)]


def pairwise_search(evaluator, record: Record, sensors: list[str], document: dict, first: Iteration,
                    say: Callable[[str], None]) -> list[PairFit]:
    """When no single effect is significant but the model as given misses the record by more than the noise
    (align.noise_test), the PAIRS most promising pairs of the fitted candidates (search.candidate_pairs), each fitted
    together (search.fit_pair); none when the model's gap is noise."""
    residual = aligned_residuals(record, first.baseline_prediction, first.baseline.offset)
    if noise_test(record, residual).consistent:
        return []
    pairs = candidate_pairs([s for s in first.ranked if s.fitted], first.baseline.chi_square)
    fits = []
    for number, pair in enumerate(pairs, start=1):
        evaluator.stage(f"pairwise search: pair {number} of {len(pairs)}")
        fit = fit_pair(evaluator, record, sensors, document, pair, first.baseline)
        if fit is not None:
            fits.append(fit)
            say(f"  pair: {setting(fit.candidates, fit.joint.best.value)}: ΔBIC {fit.delta_bic:.0f}, "
                f"gap {first.baseline.gap:.3g} → {fit.joint.best.fit.gap:.3g} ({len(fit.joint.points)} runs)")
    return fits


def significant_pair(pairs: list[PairFit]) -> PairFit | None:
    """The pair of lowest BIC if it beats the model by SIGNIFICANCE (its BIC counting both parameters)."""
    best = min(pairs, key=lambda pair: pair.bic, default=None)
    return best if best is not None and best.delta_bic < -SIGNIFICANCE else None


def pair_effects(evaluator, record: Record, sensors: list[str], document: dict, pair: PairFit,
                 first: Iteration) -> list[Effect]:
    """The pair's two effects as reported (refitted: each with the model with it and the one before it), their evidence
    the pair's: its ΔBIC and its improvement on each half of the record."""
    baseline = Point(0.0, first.baseline, first.baseline_prediction)
    halves = halves_improved(record, baseline, pair.joint.best)
    evidence = [Scored(s.candidate, list(s.points), fitted=True, bic=pair.bic, delta_bic=pair.delta_bic, halves=halves)
                for s in pair.scored]
    start = [Effect(e, v, (v, v), pair.joint.best, first.baseline) for e, v in zip(evidence, pair.joint.best.value)]
    return refitted(evaluator, record, sensors, document, start, pair.joint)


def refit_line(joint: JointFit, effects: list[Effect]) -> str:
    """'refitted together (27 runs): drive of hydraulic_drive (lag) 1.71 ms → 1.98 ms, …; gap 3.75 → 1.1'."""
    changes = ", ".join(f"{e.candidate.label} {e.candidate.shown(v0)} → {e.candidate.shown(e.value)}"
                        for e, v0 in zip(effects, joint.start))
    return (f"refitted together ({len(joint.points)} runs): {changes}; "
            f"gap {joint.start_point.fit.gap:.3g} → {joint.best.fit.gap:.3g}")


def read_repeat(path: Path, measured: MeasuredData, mechanism, request: DiagnoseRequest) -> MeasuredData:
    """A further record of the same test (`--measured` given again): the same sensors, over the first record's span."""
    repeat = read_measured(path, model_sensor_units(mechanism), parse_mapping(request.mapping), required=list(measured.values))
    step = float(np.median(np.diff(measured.time)))
    if repeat.time[0] > measured.time[0] + step or repeat.time[-1] < measured.time[-1] - step:
        raise DiagnoseError(f"{path}: a repeat spans {_ms(repeat.time[0])} to {_ms(repeat.time[-1])}, the first record "
                            f"({request.measured}) {_ms(measured.time[0])} to {_ms(measured.time[-1])}; repeats of one "
                            "test must cover its span (cut the first record, or give a repeat that covers it)")
    return repeat


def record_noise(evaluator, record: Record, sensors: list[str], document: dict, repeats: list[MeasuredData],
                 request: DiagnoseRequest) -> dict[str, NoiseEstimate]:
    """σ̂ of each sensor (docs/diagnose.md §1): from the spread of the repeated records when there are any, else the
    lower of the record minus its trend and the residual against the model as given (one run: the screening reuses
    it), which leaves out the model's own rattle and ringing."""
    if repeats:
        return {s: repeat_noise([record.unfiltered[s]] + [np.interp(record.time, r.time, r.values[s]) for r in repeats],
                                record.rate) for s in sensors}
    model = evaluator.evaluate([document], lambda i, prediction: prediction, [AS_GIVEN])[0]
    check_model(model, request)
    fit = fit_offset(record, model.time, {s: model.sensors[s] for s in sensors})
    return residual_noise(record, model.time, model.sensors, fit.offset)


def check_model(prediction: Prediction, request: DiagnoseRequest) -> None:
    if not prediction.ok:
        raise DiagnoseError(f"{request.config}: the model does not run to the end ({prediction.error}); "
                            "fix it with `clearsim run` first")


def _record_line(record: Record) -> str:
    parts = [f"{s}: σ̂ = {n.std:.3g} ({n.interval()[0]:.3g}–{n.interval()[1]:.3g}, {n.estimator}), "
             f"n_eff = {n.effective_samples:.0f} of {n.samples}" for s, n in record.noise.items()]
    band = f"; comparison low-pass {record.cutoff:.0f} Hz" if record.cutoff else ""
    return f"record: {len(record.time)} samples at {record.rate:.0f} Hz{band}; " + "; ".join(parts)


def _mechanism(document: dict, request: DiagnoseRequest):
    return load_mechanism_text(document_text(document), str(request.config), (), Path(request.config).parent).mechanism


def _iterate(evaluator, record, sensors, document, kinds, found_keys, units, request, number, say) -> Iteration:
    candidates = [c for c in candidates_for(_mechanism(document, request), document, kinds, Path(request.config).parent) if c.key not in found_keys]
    evaluator.stage(f"iteration {number}: screening {candidates_count(len(candidates))}")
    base_point, scored = screen(evaluator, record, sensors, candidates, document,
                                lambda prediction: check_model(prediction, request))
    base_prediction = base_point.prediction
    baseline = base_point.fit
    aligned = predict(record, base_prediction.time, {s: base_prediction.sensors[s] for s in sensors}, baseline.offset)
    found_features = features(record, aligned, units)
    windows = disagreement_windows(record, residuals(record, aligned))
    say(f"iteration {number}: gap {baseline.gap:.3g} (trigger offset {baseline.offset * 1e3:.3f} ms), "
        f"{len(windows)} window(s) outside the noise band")
    visible = [s for s in scored if seen_by_sensors(s, baseline.chi_square)]
    chosen = to_fit(visible, base_point, record, request.fit_top)
    chosen += clearances_of_worn_joints(chosen, visible)
    say(f"  screened {len(candidates)} candidates ({len(visible)} visible to the sensors); fitting "
        + ", ".join(s.candidate.label for s in chosen))
    evaluator.stage(f"iteration {number}: fitting {candidates_count(len(chosen))}")
    refine(evaluator, record, sensors, chosen, document)
    ranked = judge(scored, baseline, record)
    between = worn_arcs_between(ranked, _mechanism(document, request), {s.candidate.key for s in scored})
    if between:
        evaluator.stage(f"iteration {number}: refining the worn arc's angle ({candidates_count(len(between))})")
        refine(evaluator, record, sensors, between, document)
        scored += between
        ranked = judge(scored, baseline, record)
    winner = ranked[0] if ranked and ranked[0].fitted and ranked[0].delta_bic < -SIGNIFICANCE else None
    rejected = ""  # why the significant winner is not named (§4 steps 3 and 5)
    if (winner is not None and rattles(winner)
            and not seen_below_chaos(winner, base_point, record)):
        rejected = (f"{winner.candidate.label} fits better (ΔBIC {winner.delta_bic:.0f}) only above the screening band "
                    f"({record.low_band.cutoff:.0f} Hz; there χ² {low_band_best(winner):.1f} against the model's "
                    f"{base_point.low_band_chi_square:.1f}): chaotic detail of the impacts, not a missing effect")
    lucky = needle(winner) if winner is not None and not rejected else None
    if lucky:
        rejected = (f"{winner.candidate.label} fits better (ΔBIC {winner.delta_bic:.0f}) but its interval "
                    f"({winner.candidate.shown(winner.interval[0])}–{winner.candidate.shown(winner.interval[1])}) "
                    f"{lucky}: its runs scatter as much as it improves, one lucky run, not a missing effect")
    if winner is not None and not rejected:
        evaluator.stage(f"iteration {number}: re-rolling the impacts {PERTURBATIONS} times")
        winner.perturbed = perturbed_changes(evaluator, record, sensors, document, winner, base_point, request)
        if not keeps_its_gain(winner, baseline.chi_square):
            rejected = (f"{winner.candidate.label} fits better (Δχ² "
                        f"{winner.estimate.chi_square - baseline.chi_square:.0f}) but only by {median_change(winner):.0f} "
                        f"with the impacts re-rolled (median of {PERTURBATIONS} runs): one lucky realisation, not a "
                        "missing effect")
    if rejected:
        say(f"  {rejected}")
        winner = None
    if winner is not None:
        mark_ties(ranked, {s: float(np.ptp(v)) for s, v in base_prediction.sensors.items()})
        winner.halves = halves_improved(record, base_point, winner.estimate)
        say(f"  found: {effect_line(found_effect(winner, baseline))}")
    else:
        say("  no candidate beats the model significantly")
    return Iteration(baseline, base_prediction, ranked, winner, found_features, windows, rejected)


def needle(scored: Scored) -> str | None:
    """Why the candidate's best run is a needle, not a basin (docs/diagnose.md §4 step 3), or None: its interval reaches
    the lower bound of an effect the model lacks (search.reaches_no_change), or spans its whole range
    (search.unbounded)."""
    if reaches_no_change(scored):
        return f"reaches {scored.candidate.shown(no_change(scored.candidate))}, none of it"
    if unbounded(scored):
        return "spans the whole range"
    return None


def clearances_of_worn_joints(chosen: list[Scored], visible: list[Scored]) -> list[Scored]:
    """The clearance candidate of each joint a chosen worn arc is in, when not chosen itself: a uniform clearance
    change is a worn arc's mean term alone, so an arc is judged against it (the arc fits better only when the record
    shows a direction)."""
    worn = {s.candidate.target for s in chosen if s.candidate.kind == "wear"}
    return [s for s in visible if s.candidate.kind == "clearance" and s.candidate.target in worn and s not in chosen]


def worn_arcs_between(ranked: list[Scored], mechanism, known: set) -> list[Scored]:
    """When the best fitted candidate is a worn arc, its joint's arcs halfway to the positions beside it (φ ± 15°), to
    be fitted as it was: the angle refined once."""
    if not ranked or not ranked[0].fitted or ranked[0].candidate.kind != "wear":
        return []
    return [Scored(c) for c in wear_between(mechanism, ranked[0].candidate) if c.key not in known]


def ensemble_copies(document: dict, request: DiagnoseRequest, runs: int) -> list[dict]:
    """The document and its runs − 1 perturbed twins (seeds 101, 102, …); without a clearance joint, nothing chaotic to
    re-roll: the document alone."""
    mechanism = _mechanism(document, request)
    if not has_clearance_joint(mechanism):
        return [document]
    return [document] + [perturbed(mechanism, document, ENSEMBLE_SEED + seed) for seed in range(1, runs)]


def chosen_ensemble(evaluator, record: Record, document: dict, request: DiagnoseRequest) -> EnsembleChoice:
    """K as given (--ensemble), else from the model as given and its AUTO_ENSEMBLE − 1 twins (the ensemble's own, so the
    screening reuses their runs): AUTO_ENSEMBLE when they stray from the model by more than the noise on a sensor
    (IMPACT_RICH), 1 when they do not or the model has no clearance joint (nothing chaotic to re-roll)."""
    if request.ensemble is not None:
        return EnsembleChoice(request.ensemble, {}, automatic=False)
    copies = ensemble_copies(document, request, AUTO_ENSEMBLE)
    if len(copies) == 1:
        return EnsembleChoice(1, {}, automatic=True)
    model, *twins = evaluator.evaluate(copies, lambda i, prediction: prediction,
                                       [AS_GIVEN] + [f"{AS_GIVEN}, re-rolled ({n})" for n in range(1, len(copies))])
    check_model(model, request)
    offset = fit_offset(record, model.time, {s: model.sensors[s] for s in record.values}).offset
    gaps = twin_gaps(record, model, twins, offset)
    rich = any(gap > IMPACT_RICH for gap in gaps.values())
    return EnsembleChoice(AUTO_ENSEMBLE if rich else 1, gaps, automatic=True)


def ensemble_line(choice: EnsembleChoice) -> str:
    """'ensemble: 3 runs per value (impact-rich: slider_velocity; twins stray 0.31, 2.4 noise levels)'."""
    runs = f"ensemble: {choice.runs} run{'' if choice.runs == 1 else 's'} per value"
    if not choice.automatic:
        return f"{runs} (--ensemble)"
    if not choice.twin_gaps:
        return f"{runs} (no clearance joint: nothing chaotic to re-roll)"
    strays = ", ".join(f"{s} {gap:.3g}" for s, gap in choice.twin_gaps.items())
    rich = ", ".join(choice.impact_rich)
    return f"{runs} ({'impact-rich: ' + rich if rich else 'no sensor impact-rich'}; re-rolled twins stray {strays} noise levels)"


def perturbed_changes(evaluator, record: Record, sensors: list[str], document: dict, winner: Scored, baseline: Point,
                      request: DiagnoseRequest) -> list[float]:
    """Δχ² over the model of the winner's estimate in PERTURBATIONS copies no bench could tell apart (each clearance
    joint's journal started 1 nm off, candidates.perturbed): each re-rolls a chaotic impact sequence."""
    value = winner.estimate.value
    applied = winner.candidate.applied(document, value)
    mechanism = _mechanism(applied, request)
    copies = [perturbed(mechanism, applied, seed) for seed in range(1, PERTURBATIONS + 1)]
    points = evaluator.evaluate(copies, lambda i, prediction: score_point(record, sensors, value, prediction),
                                [f"{setting([winner.candidate], [value])}, re-rolled ({seed})"
                                 for seed in range(1, PERTURBATIONS + 1)])
    return [p.chi_square - baseline.chi_square for p in points]


def candidates_count(count: int) -> str:
    return f"{count} candidate{'' if count == 1 else 's'}"


def has_clearance_joint(mechanism) -> bool:
    """A clearance joint: impacts whose chaotic sequence a run replays only as one realisation of it."""
    return any(is_clearance_joint(j) for j in mechanism.joints)


def rattles(scored: Scored) -> bool:
    """The run the candidate reports (its estimate) has impacts: a clearance joint's journal strikes its wall
    (Prediction.impacts). Only then can a run match the record's impact sequence by chance, and only then does
    seen_below_chaos apply. Without impacts, a lower χ² in the comparison band alone is the candidate's signature, not
    luck: a drive lag's start-up transient (over before the screening band's compared samples begin) in a mechanism
    without clearance, an oil film's response in a lubricated joint whose film carries the load, or whose journal rides
    its wall in continuous contact."""
    return scored.estimate.prediction.impacts > 0


def seen_below_chaos(scored: Scored, baseline: Point, record: Record) -> bool:
    """A found effect must also explain the record in the screening band, below the chaotic detail of single
    impacts: its lowest χ² there beats the model's by the same BIC margin (ln n_eff of that band + SIGNIFICANCE).
    A run that matches the record's impact sequence by chance improves only the comparison band."""
    if record.low_band is None or record.low_band.cutoff is None:
        return True
    margin = np.log(max(record.low_band.effective_samples, 2.0)) + SIGNIFICANCE
    return low_band_best(scored) < baseline.low_band_chi_square - margin


def effect_line(effect: Effect) -> str:
    """'clearance in joint B, clearance = 0.082 mm (0.071–0.094 mm); gap 14.2 → 1.3 (−91%)', 'joint B worn 0.05 mm
    around 120° (0.04–0.06 mm); …'."""
    c, scored = effect.candidate, effect.scored
    low, high = effect.interval
    before, after = effect.before.gap, effect.point.fit.gap
    change = (after - before) / before if before > 0 else 0.0
    tie = f"; fits as well: {', '.join(scored.ambiguous_with)}" if scored.ambiguous_with else ""
    tell = f" (tell apart with sensor {scored.telling_sensor})" if scored.telling_sensor else ""
    if scored.halves is not None and max(scored.halves) >= 0.0:
        tell += "; it does not improve both halves of the record"
    if scored.perturbed and max(scored.perturbed) >= 0.0:
        tell += "; with the impacts re-rolled it fits worse than the model"
    return (f"{c.finding(effect.value)} ({c.shown(low)}–{c.shown(high)}); "
            f"gap {before:.3g} → {after:.3g} ({change:+.0%}){tie}{tell}")
