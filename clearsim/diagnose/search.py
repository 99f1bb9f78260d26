"""Fitting and ranking candidate effects (docs/diagnose.md §"Fit and rank").

Each candidate has one parameter. The cost (χ² at the best trigger offset) of a clearance is not
smooth — impacts come and go as c changes — so the fit is a search on a grid that is refined
around its best point, never a gradient method:

    screen   two values per candidate (at 30 % and 75 % of its range): is it visible at all, and how good?
             For a stiffness that sets a resonance (a compliance), two more rounds of values whose
             ringing frequency matches the record's residual peak (f ∝ √k): its cost is a narrow well
             (a few % wide) that no grid finds
    scan     six more values over the range for the most promising candidates (chosen by χ² in the
             comparison band and in the screening band, Record.low_band: frequency continuation; one per effect,
             the worn arcs of a joint being one)
    valley   three values about the minimum of the profile in the screening band, where a clearance's
             cost is a smooth valley (in the comparison band it can be narrower than a scan step), and the
             midpoints between its lowest run there and that run's neighbours (the valley is within one step of
             it, on a side the parabola can guess wrong)
    zoom     four, then two values between each of the two lowest local minima and their neighbours
    vertex   one value at the vertex of a parabola through the profile near its best point (the
             minimum with the chaotic scatter of single runs smoothed out), each run weighted by its χ²'s
             standard deviation, refitted through fewer runs about each new vertex (`profile_vertex`)

A rough candidate (friction: its cost is a comb of narrow minima, the teeth far narrower than any
affordable grid step) is not zoomed: after the scan, two rounds of evenly spread values in a window
about the smoothed minimum (a least-squares parabola through every run in the window), the window
halved each round, in both bands (a window each), then one run at the last parabola's vertex of the band
where it is better determined (smaller uncertainty). That run is the estimate (not the
lowest run, which is whichever tooth the grid happened to hit), its interval the vertex ± its
uncertainty (standard error and the width the comb's scatter leaves).

After greedy selection has found several effects, `refit_jointly` refits all their values together
(each was fitted with the earlier ones held at their own single-effect fits, which biases them):
a stencil around the best values in the candidates' unit coordinates, a quadratic surface through it
and a run at its minimum, the step halved each round.

When greedy selection finds nothing, `fit_pair` fits a pair of candidates together: a coarse 4 × 4 grid in their unit
coordinates, then the joint refit's stencil rounds (`refine_jointly`) about its best point.

Candidates are ranked by the Bayesian information criterion BIC = χ² + k ln n_eff of the run each reports (its
lowest; a rough candidate's at its smoothed minimum; k = 1 fitted parameter; the trigger offset is fitted in every
model alike), so a candidate must lower χ² by more than ln n_eff + SIGNIFICANCE to count as found: noise alone does
not pass.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from scipy.stats import chi2, norm
from scipy.stats import f as fisher
from scipy.stats import t as student

from clearsim.diagnose.align import (INTERVAL_LEVEL, ChaoticSpread, Fit, Record, chi_square_halves, fit_at, fit_offset,
                                    predict, residual_effective_samples, residuals, sensor_gaps)
from clearsim.diagnose.candidates import Candidate, with_effects
from clearsim.diagnose.evaluate import Evaluator, Prediction
from clearsim.diagnose.features import WINDOW_SECONDS, dominant_frequency

SCREEN_POINTS = (0.3, 0.75)  # of the range (in log units for scale parameters)
SCAN_POINTS = 6
ZOOM_ROUNDS = (4, 2)
ZOOM_MINIMA = 2  # zoom around the two lowest local minima of the profile
SIGNIFICANCE = 10.0  # ΔBIC below −10: "very strong" evidence (Kass & Raftery 1995)
TIE = 6.0  # BIC within 6 of the best: the data do not tell the two apart
PROFILE_POINTS = 7  # points of the local parabola through the profile
VERTEX_POINTS = 5  # the fewest runs of profile_vertex's refits (2 residual degrees of freedom)
VERTEX_ITERATIONS = 8  # refits of profile_vertex at most
VERTEX_TOLERANCE = 1e-4  # of the unit range: profile_vertex's vertex has settled when it moves less
VISIBLE = 1.0  # |Δχ²| below 1 at both screening values: the sensors do not see the candidate
RESONANCE_ROUNDS = 2  # rounds of frequency-matched values for a resonant candidate in screening
ROUGH_ROUNDS = 2  # rounds of a rough candidate's window about its smoothed minimum
ROUGH_POINTS = 8  # new values per round, evenly spread inside the window
REFIT_ROUNDS = 3
REFIT_STEP = 0.04  # first stencil step of the joint refit, in unit coordinates (4 % of each range)
REFIT_REACH = 2.0  # the quadratic's minimum is looked for within 2 steps of the best point
PERTURBATIONS = 3  # re-rolled impact sequences (candidates.perturbed) in which a found effect must still beat the model
RETAINED = 0.5  # of its improvement over the model, the share a found effect must keep in its median re-rolled run


@dataclass
class Point:
    value: float  # the candidate's value; for a joint refit, a tuple: one value per effect
    fit: Fit | None  # None: the run failed
    prediction: Prediction
    error: str = ""
    low_band: Fit | None = None  # the fit in the record's screening band (Record.low_band)

    @property
    def chi_square(self) -> float:
        return self.fit.chi_square if self.fit is not None else np.inf

    @property
    def low_band_chi_square(self) -> float:
        return self.low_band.chi_square if self.low_band is not None else np.inf

    def chi_square_in(self, low_band: bool) -> float:
        """χ² in the screening band (low_band) or in the comparison band."""
        return self.low_band_chi_square if low_band else self.chi_square


@dataclass
class Scored:
    """A candidate's evaluations and verdict."""

    candidate: Candidate
    points: list[Point] = field(default_factory=list)
    fitted: bool = False  # scanned and zoomed, not only screened
    bic: float = np.inf
    delta_bic: float = np.inf  # BIC − BIC of the baseline
    interval: tuple[float, float] | None = None
    ambiguous_with: list[str] = field(default_factory=list)
    telling_sensor: str | None = None
    halves: tuple[float, float] | None = None  # Δχ² on the first and second half of the record
    windows: dict[bool, tuple[float, float]] = field(default_factory=dict)  # rough: per band (low_band?), centre
    # and half-width (unit range) of its window
    profiles: dict[bool, tuple[float, float]] = field(default_factory=dict)  # rough: per band, smoothed vertex, error
    perturbed: list[float] = field(default_factory=list)  # Δχ² over the model of its estimate, impacts re-rolled

    @property
    def smoothed_in_low_band(self) -> bool:
        """A rough candidate's estimate comes from the band where its smoothed minimum is better determined."""
        return min(self.profiles, key=lambda band: self.profiles[band][1])

    @property
    def smoothed(self) -> tuple[float, float] | None:
        """A rough candidate's smoothed vertex and its uncertainty (unit range) in that band; None otherwise."""
        return self.profiles[self.smoothed_in_low_band] if self.profiles else None

    @property
    def best(self) -> Point | None:
        finished = [p for p in self.points if p.fit is not None]
        return min(finished, key=lambda p: p.chi_square) if finished else None

    @property
    def estimate(self) -> Point | None:
        """The point reported and added: the lowest χ² of all runs (grid, zooms, the profile's vertex); for a
        rough candidate, the run at the smoothed profile's vertex."""
        if self.smoothed is not None:
            value = float(self.candidate.from_unit(self.smoothed[0]))
            at_vertex = [p for p in self.points if p.fit is not None and p.value == value]
            if at_vertex:
                return at_vertex[0]
        return self.best

    allowance: float = 1.0  # Δχ² of the profile interval, set by `judge`


@dataclass
class SearchProgress:
    """What a diagnosis has run so far (its progress bar and heartbeat)."""

    stage: str = "starting"
    planned: int = 0  # model runs asked for so far: each batch adds its own when it is asked for
    done: int = 0  # of those, finished (run, reused or failed)
    best_gap: float = np.inf  # the lowest gap of a finished run so far
    best_label: str = ""  # its model: "the model as given", or the candidate's setting(s)


class Tracked:
    """An Evaluator that counts the runs asked for and finished and keeps the best fit so far, and calls
    report(progress) at each change. `evaluate` takes a label per document (the variant in words, `setting`)."""

    def __init__(self, evaluator: Evaluator, report: Callable[[SearchProgress], None] = lambda progress: None):
        self.evaluator, self.report = evaluator, report
        self.progress = SearchProgress()

    @property
    def simulations(self) -> int:
        return self.evaluator.simulations

    def stage(self, text: str) -> None:
        self.progress.stage = text
        self.report(self.progress)

    def evaluate(self, documents: list[dict], then: Callable, labels: list[str]) -> list:
        progress = self.progress
        progress.planned += len(documents)
        self.report(progress)

        def counted(i: int, prediction: Prediction):
            result = then(i, prediction)
            progress.done += 1
            fit = getattr(result, "fit", None)
            if fit is not None and fit.gap < progress.best_gap:
                progress.best_gap, progress.best_label = fit.gap, labels[i]
            self.report(progress)
            return result

        return self.evaluator.evaluate(documents, counted)


class Ensembled:
    """A Tracked evaluator that scores every document over an ensemble of copies no bench could tell apart
    (`copies(document)`: the document and its perturbed twins, candidates.perturbed): each document's result is
    the member with the median χ² (comparison band), so a value's cost is not one realisation of a chaotic impact
    sequence — a lucky run among them is outvoted. Results that are no Points (a bare prediction) are the first
    member's. Everything else (stage, progress, simulations) is the Tracked evaluator's."""

    def __init__(self, tracked: Tracked, copies: Callable[[dict], list[dict]]):
        self.tracked, self.copies = tracked, copies

    def __getattr__(self, name):
        return getattr(self.tracked, name)

    def evaluate(self, documents: list[dict], then: Callable, labels: list[str]) -> list:
        groups = [self.copies(d) for d in documents]
        owner = [i for i, group in enumerate(groups) for _ in group]
        members = self.tracked.evaluate([c for group in groups for c in group],
                                        lambda k, prediction: then(owner[k], prediction),
                                        [f"{labels[i]} ({n + 1} of {len(g)})" for i, g in enumerate(groups)
                                         for n in range(len(g))])
        results, start = [], 0
        for group in groups:
            results.append(median_member(members[start:start + len(group)]))
            start += len(group)
        return results


def median_member(members: list):
    """The member with the median χ² (the lower middle one of an even count); a failed run counts as the worst."""
    if not all(isinstance(m, Point) for m in members):
        return members[0]
    ranked = sorted(members, key=lambda p: p.chi_square)
    return ranked[(len(ranked) - 1) // 2]


def twin_gaps(record: Record, model: Prediction, twins: list[Prediction], offset: float) -> dict[str, float]:
    """Per sensor, how far the model's re-rolled twins (candidates.perturbed: no bench could tell them from it) stray
    from it: the largest RMS difference of a twin's prediction from the model's in the comparison band, over the
    compared samples and both at the model's trigger offset, in noise levels σ̂_s (D1's gap, with a twin in the
    record's place; a twin that fails counts as infinitely far). Above 1 the sensor is impact-rich: one run's
    sample-wise cost there is one realisation of a chaotic impact sequence."""
    if not all(twin.ok for twin in twins):
        return {s: np.inf for s in record.values}
    own = aligned_prediction(record, model, offset)
    strays = [sensor_gaps(record, {s: own[s] - m for s, m in aligned_prediction(record, twin, offset).items()})
              for twin in twins]
    return {s: max((stray[s] for stray in strays), default=0.0) for s in record.values}


def chaotic_spread(record: Record, reported: Prediction, twins: list[Prediction], offset: float) -> ChaoticSpread | None:
    """The variance the model's realisations add to the residual, per sensor and compared sample (docs/diagnose.md
    §5b): D_k = the moving average over WINDOW_SECONDS of mean_j (m_twin,j − m)_k², both in the comparison band at the
    reported run's trigger offset. A residual against one realisation when the record is another has the expectation
    σ² + 2V_k, and so has (m_twin − m)²: D_k is added to σ̂² as it is. Its degrees of freedom ν_D = Σ_j n_eff of twin
    j's difference (D6). Twins that failed are left out; None when none ran."""
    ran = [twin for twin in twins if twin.ok]
    if not ran:
        return None

    own = aligned_prediction(record, reported, offset)
    differences = [{s: (m - own[s])[record.compared] for s, m in aligned_prediction(record, twin, offset).items()}
                   for twin in ran]
    width = max(int(round(WINDOW_SECONDS * record.rate)), 1)
    variance = {s: moving_mean(np.mean([d[s] ** 2 for d in differences], axis=0), width) for s in record.values}
    dof = {s: float(sum(residual_effective_samples(d[s]) for d in differences)) for s in record.values}
    return ChaoticSpread(variance, dof, len(ran))


def moving_mean(values: np.ndarray, width: int) -> np.ndarray:
    """The mean over the `width` samples centred on each one (fewer at the ends: the mean of those there)."""
    kernel = np.ones(min(width, len(values)))
    return np.convolve(values, kernel, mode="same") / np.convolve(np.ones_like(values), kernel, mode="same")


AS_GIVEN = "the model as given"


def setting(candidates: list[Candidate], values) -> str:
    """'clearance in joint B, clearance = 0.082 mm' (several effects: joined by '; ')."""
    return "; ".join(c.finding(v) for c, v in zip(candidates, values))


def evaluate_points(evaluator: Tracked, record: Record, sensors: list[str],
                    jobs: list[tuple[Scored, float]], document: dict) -> None:
    """Run candidate values (all at once, in parallel) and append the fitted points (each scored as its run ends)."""
    points = evaluator.evaluate([scored.candidate.applied(document, value) for scored, value in jobs],
                                lambda i, prediction: score_point(record, sensors, jobs[i][1], prediction),
                                [setting([scored.candidate], [value]) for scored, value in jobs])
    for (scored, _), point in zip(jobs, points):
        scored.points.append(point)


def score_point(record: Record, sensors: list[str], value: float, prediction: Prediction) -> Point:
    if not prediction.ok:
        return Point(value, None, prediction, prediction.error)
    model = {s: prediction.sensors[s] for s in sensors}
    fit = fit_offset(record, prediction.time, model)
    low_band = fit_at(record.low_band, prediction.time, model, fit.offset) if record.low_band is not None else None
    return Point(value, fit, prediction, low_band=low_band)


def aligned_prediction(record: Record, prediction: Prediction, offset: float) -> dict[str, np.ndarray]:
    """The prediction of the record's sensors at trigger offset `offset`, on the record's samples in the comparison
    band (D0)."""
    return predict(record, prediction.time, {s: prediction.sensors[s] for s in record.values}, offset)


def aligned_residuals(record: Record, prediction: Prediction, offset: float) -> dict[str, np.ndarray]:
    """The record minus the prediction at trigger offset `offset`, both in the comparison band (D0)."""
    return residuals(record, aligned_prediction(record, prediction, offset))


def screen(evaluator, record, sensors, candidates: list[Candidate], document,
           check_model: Callable[[Prediction], None]) -> tuple[Point, list[Scored]]:
    """The model as given and each candidate at the screening points, in one parallel batch, then the resonant
    candidates' frequency-matched rounds; returns the model's point and the screened candidates. The model's run is
    the batch's first, and check_model sees its prediction as soon as it ends: an error raised there stops the batch
    (the screening runs do not wait for the model's, so no worker idles while it runs alone)."""
    scored = [Scored(c) for c in candidates]
    jobs = [(s, v) for s in scored for v in s.candidate.from_unit(SCREEN_POINTS)]

    def point(i: int, prediction: Prediction) -> Point:
        if i == 0:
            check_model(prediction)
        return score_point(record, sensors, jobs[i - 1][1] if i else 0.0, prediction)

    points = evaluator.evaluate([document] + [s.candidate.applied(document, v) for s, v in jobs], point,
                                [AS_GIVEN] + [setting([s.candidate], [v]) for s, v in jobs])
    for (s, _), screened in zip(jobs, points[1:]):
        s.points.append(screened)
    baseline = points[0]
    resonant = [s for s in scored if s.candidate.resonant]
    for _ in range(RESONANCE_ROUNDS if resonant else 0):
        latest = {id(s): len(s.points) for s in resonant}
        jobs = [(s, v) for s in resonant for v in resonance_seeds(record, baseline, s.points[-2:], s.candidate)]
        evaluate_points(evaluator, record, sensors, jobs, document)
        resonant = [s for s in resonant if len(s.points) > latest[id(s)]]
    return baseline, scored


def resonance_seeds(record: Record, baseline: Point, points: list[Point], candidate: Candidate) -> list[float]:
    """For each run, the value whose ringing would match the record's: k (f_record / f_run)², where f_record is the
    peak of the residual of the model as given and f_run that of the run's change to the model (both in the
    comparison band, at the model's trigger offset). New values only, within the bounds."""
    base = aligned_residuals(record, baseline.prediction, baseline.fit.offset)
    target = dominant_frequency(record, base)
    seeds = []
    for point in points:
        if point.fit is None or target is None:
            continue
        change = aligned_residuals(record, point.prediction, baseline.fit.offset)
        own = dominant_frequency(record, {s: base[s] - change[s] for s in base})
        if own:
            seeds.append(float(np.clip(point.value * (target / own) ** 2, candidate.low, candidate.high)))
    return [v for v in dict.fromkeys(seeds) if v not in {p.value for p in points}]


def seen_by_sensors(scored: Scored, baseline: float) -> bool:
    return any(p.fit is not None and abs(p.chi_square - baseline) > VISIBLE for p in scored.points)


def to_fit(screened: list[Scored], baseline: Point, record: Record, count: int) -> list[Scored]:
    """The candidates to fit: the `count` with the lowest screening χ², the `count` with the lowest χ² in
    the screening band among those that lower it there (frequency continuation: below the chaotic detail of
    single impacts a clearance's cost is smooth, so two screening values can tell a joint whose valley they
    miss in the comparison band), and one more chosen by its sensitivity (the largest |Δχ²| of its
    screening runs): the one whose sensitivity is nearest above what is left to explain (χ² − n_eff), else
    the most sensitive. A candidate whose change is of the size of the gap can reach the valley, while one
    that barely moves χ² cannot explain the gap, however lucky its screening.
    Each place goes to a distinct effect (`distinct`: one candidate per Candidate.quantity): the worn arcs of one
    joint at twelve angles are one effect, represented by its best member, not twelve chances to take every place."""
    by_screening = sorted(screened, key=lambda s: s.best.chi_square)
    chosen = distinct(by_screening)[:count]
    lowering = [s for s in screened if low_band_best(s) < baseline.low_band_chi_square - VISIBLE]
    chosen += distinct(distinct(sorted(lowering, key=low_band_best))[:count], chosen)
    excess = max(baseline.chi_square - record.effective_samples, 0.0)

    def sensitivity(s: Scored) -> float:
        return max(abs(p.chi_square - baseline.chi_square) for p in s.points if p.fit is not None)

    rest = [s for s in distinct(by_screening, chosen) if sensitivity(s) > VISIBLE]
    reaching = [s for s in rest if sensitivity(s) >= excess]
    extra = min(reaching, key=sensitivity) if reaching else max(rest, key=sensitivity, default=None)
    return chosen + ([extra] if extra is not None and excess > 0.0 else [])


def distinct(ranked: list[Scored], taken: list[Scored] = ()) -> list[Scored]:
    """The first of each quantity (Candidate.quantity) in `ranked`, in its order, leaving out the quantities of
    `taken`: the worn arcs of one joint are represented by the best of them."""
    seen = {s.candidate.quantity for s in taken}
    first = []
    for s in ranked:
        if s.candidate.quantity not in seen:
            seen.add(s.candidate.quantity)
            first.append(s)
    return first


BANDS = (False, True)  # a rough candidate's profile is smoothed in the comparison band and in the screening band


def lowest(scored: Scored, low_band: bool) -> Point:
    """The run with the lowest χ² in the comparison band, or in the screening band."""
    return min((p for p in scored.points if p.fit is not None), key=lambda p: p.chi_square_in(low_band))


def low_band_best(scored: Scored) -> float:
    """The lowest χ² of the candidate's runs in the screening band."""
    return lowest(scored, True).low_band_chi_square


def refine(evaluator, record, sensors, chosen: list[Scored], document) -> None:
    """Scan, then the screening band's valley and two zooms around each candidate's best points, or for a rough
    one two rounds about its smoothed minimum (each round one parallel batch for all candidates)."""
    evaluate_points(evaluator, record, sensors, [(s, v) for s in chosen for v in s.candidate.grid(SCAN_POINTS)], document)
    smooth = [s for s in chosen if not s.candidate.rough]
    rough = [s for s in chosen if s.candidate.rough]
    for s in rough:
        s.windows = {band: (float(s.candidate.to_unit(lowest(s, band).value)), 1.0 / (SCAN_POINTS + 1)) for band in BANDS}
    evaluate_points(evaluator, record, sensors, [(s, v) for s in smooth for v in low_band_values(s)], document)
    for round_ in range(max(len(ZOOM_ROUNDS), ROUGH_ROUNDS)):
        jobs = [(s, v) for s in smooth if round_ < len(ZOOM_ROUNDS) for v in _zoom(s, ZOOM_ROUNDS[round_])]
        jobs += [(s, v) for s in rough if round_ < ROUGH_ROUNDS for v in _window_values(s)]
        evaluate_points(evaluator, record, sensors, jobs, document)
        for s in rough if round_ < ROUGH_ROUNDS else []:
            s.profiles = {band: _smoothed_minimum(s, *s.windows[band], band) for band in BANDS}
            s.windows = {band: (s.profiles[band][0], s.windows[band][1] / 2.0) for band in BANDS}
    jobs = [(s, v) for s in smooth if (v := profile_vertex(s, record.effective_samples)) is not None]
    jobs += [(s, float(s.candidate.from_unit(s.smoothed[0]))) for s in rough]
    evaluate_points(evaluator, record, sensors, jobs, document)
    for s in chosen:
        s.fitted = True


def _window_values(scored: Scored) -> list[float]:
    """ROUGH_POINTS values evenly spread inside each band's window of the rough candidate (ends excluded), within
    the bounds, new ones only."""
    spread = np.linspace(-1.0, 1.0, ROUGH_POINTS + 2)[1:-1]
    units = [centre + half * u for centre, half in scored.windows.values() for u in spread]
    known = {p.value for p in scored.points}
    values = [float(scored.candidate.from_unit(u)) for u in units if 0.0 <= u <= 1.0]
    return [v for v in dict.fromkeys(values) if v not in known]


def _smoothed_minimum(scored: Scored, centre: float, half: float, low_band: bool) -> tuple[float, float]:
    """Minimum of the profile (χ² in the comparison band, or in the screening band) smoothed over
    [centre − half, centre + half] (unit range): the vertex of a least-squares parabola a (u − v)² + c through
    every run in it, and its uncertainty √(σ_v² + s/a): σ_v the vertex's standard error (delta method, the
    comb's scatter about the parabola taken as the noise), √(s/a) the half-width where the parabola rises by s,
    the RMS of that scatter (values the comb does not tell apart). When the parabola is not convex or its
    vertex leaves the window: the lowest run in the window, with the window's half-width as the uncertainty."""
    points = [p for p in scored.points if p.fit is not None]
    units = scored.candidate.to_unit([p.value for p in points])
    chi = np.array([p.chi_square_in(low_band) for p in points])
    inside = np.abs(units - centre) <= half * (1.0 + 1e-9)
    if inside.sum() >= 6:  # polyfit's covariance needs more points than coefficients + 2
        coefficients, covariance = np.polyfit(units[inside] - centre, chi[inside], 2, cov=True)
        a, b, _ = coefficients
        vertex = -b / (2.0 * a) if a > 0.0 else np.inf
        if abs(vertex) <= half:
            gradient = np.array([b / (2.0 * a * a), -1.0 / (2.0 * a), 0.0])
            scatter = np.sqrt(np.mean((chi[inside] - np.polyval(coefficients, units[inside] - centre)) ** 2))
            error = float(np.sqrt(max(gradient @ covariance @ gradient, 0.0) + scatter / a))
            return float(np.clip(centre + vertex, 0.0, 1.0)), error
    lowest = np.flatnonzero(inside)[np.argmin(chi[inside])] if inside.any() else int(np.argmin(chi))
    return float(units[lowest]), half


def profile_vertex(scored: Scored, effective_samples: float) -> float | None:
    """Vertex of the profile's local parabola in the comparison band (`effective_samples`: its n_eff; settled_vertex):
    the minimum of the profile with the chaotic scatter of single runs smoothed out, set by the runs where the profile
    is locally quadratic. None when the first parabola is not convex or its vertex leaves its runs' span."""
    profile = finite_profile(scored, low_band=False)
    vertex = settled_vertex(*profile, effective_samples) if profile is not None else None
    return float(scored.candidate.from_unit(vertex)) if vertex is not None else None


def screening_vertex(scored: Scored) -> float | None:
    """Vertex of the screening band's profile: the parabola through the PROFILE_POINTS runs nearest its lowest,
    unweighted. There χ² is a few n_eff and its run-to-run scatter the chaotic impacts', not the noise's: weighted by
    1/σ(χ²) the vertex falls on the luckiest run. None when the parabola is not convex or its vertex leaves its runs'
    span."""
    profile = finite_profile(scored, low_band=True)
    if profile is None:
        return None
    units, chi = profile
    near = np.argsort(np.abs(units - units[np.argmin(chi)]))[:PROFILE_POINTS]
    vertex = parabola_vertex(units[near], chi[near], np.ones(len(near)))
    return float(scored.candidate.from_unit(vertex)) if vertex is not None else None


def finite_profile(scored: Scored, low_band: bool) -> tuple[np.ndarray, np.ndarray] | None:
    """The finished runs' values (unit range) and χ² (in the comparison or the screening band); None when fewer than 4
    or any χ² is not finite."""
    points = [p for p in scored.points if p.fit is not None]
    chi = np.array([p.chi_square_in(low_band) for p in points])
    if len(points) < 4 or not np.all(np.isfinite(chi)):
        return None
    return scored.candidate.to_unit([p.value for p in points]), chi


def settled_vertex(units: np.ndarray, chi: np.ndarray, effective_samples: float) -> float | None:
    """The vertex (unit range) of the parabola through the PROFILE_POINTS runs nearest the lowest, each weighted by
    1/σ(χ²) (chi_square_spread), refitted about each new vertex through one run fewer each time down to VERTEX_POINTS
    until it moves by less than VERTEX_TOLERANCE (VERTEX_ITERATIONS fits at most). When it does not settle, the runs
    nearest it alternate (their scatter outweighs the curvature there): the vertex of the parabola through the runs of
    the last two fits. A refit that is not convex, or whose vertex leaves its runs' span, keeps the vertex before it;
    None when the first is."""
    weights = 1.0 / chi_square_spread(chi, effective_samples)
    vertex, fitted = None, []
    centre = float(units[np.argmin(chi)])
    for count in vertex_point_counts():
        near = np.argsort(np.abs(units - centre))[:count]
        moved = parabola_vertex(units[near], chi[near], weights[near])
        if moved is None:
            return vertex
        settled = vertex is not None and count == VERTEX_POINTS and abs(moved - vertex) < VERTEX_TOLERANCE
        vertex = centre = moved
        fitted.append(near)
        if settled:
            return vertex
    alternating = np.union1d(*fitted[-2:])
    both = parabola_vertex(units[alternating], chi[alternating], weights[alternating])
    return both if both is not None else vertex


def vertex_point_counts() -> list[int]:
    """The runs of each fit of settled_vertex: PROFILE_POINTS, one fewer each time down to VERTEX_POINTS, then
    VERTEX_POINTS until VERTEX_ITERATIONS."""
    return [max(PROFILE_POINTS - i, VERTEX_POINTS) for i in range(VERTEX_ITERATIONS)]


def parabola_vertex(units: np.ndarray, chi: np.ndarray, weights: np.ndarray) -> float | None:
    """Vertex (unit range) of the parabola fitted to the runs' χ² by least squares, each residual times its weight;
    None when it is not convex or the vertex leaves the runs' span."""
    if np.ptp(units) <= 0.0:
        return None
    centre = float(np.mean(units))
    a, b, _ = np.polyfit(units - centre, chi, 2, w=weights)
    if a <= 0.0:
        return None
    vertex = centre - b / (2.0 * a)
    return float(vertex) if units.min() <= vertex <= units.max() else None


def chi_square_spread(chi: np.ndarray, effective_samples: float) -> np.ndarray:
    """σ(χ²) = √(2 n_eff + 4 λ), λ = max(χ² − n_eff, 0): a non-central χ²'s (n_eff degrees of freedom, non-centrality
    λ: a run missing the record by λ beyond the noise; Johnson, Kotz & Balakrishnan 1995, ch. 29; docs/diagnose.md D9)."""
    return np.sqrt(2.0 * effective_samples + 4.0 * np.maximum(chi - effective_samples, 0.0))


def low_band_values(scored: Scored) -> list[float]:
    """Values about the minimum of the candidate's profile in the screening band, where the valley of the comparison
    band lies when the scan missed it: the profile's vertex there (screening_vertex) and ± a quarter of a scan step,
    and the midpoints between the lowest run there and its neighbours on either side (`bracket_midpoints`)."""
    centres = []
    vertex = screening_vertex(scored)
    if vertex is not None:
        centre, quarter = float(scored.candidate.to_unit(vertex)), 0.25 / (SCAN_POINTS + 1)
        centres = [centre - quarter, centre, centre + quarter]
    known = {p.value for p in scored.points}
    values = [float(scored.candidate.from_unit(u)) for u in centres + bracket_midpoints(scored, True) if 0.0 <= u <= 1.0]
    return [v for v in dict.fromkeys(values) if v not in known]


def bracket_midpoints(scored: Scored, low_band: bool) -> list[float]:
    """Midpoints (unit range) between the lowest run (in the comparison or the screening band) and its neighbours:
    the minimum lies within one grid step of the lowest run, on a side that a parabola through the points guesses
    wrong when the valley is skewed (steep on one side; the bundled UHV's clearance B, docs/diagnose.md)."""
    points = sorted((p for p in scored.points if p.fit is not None), key=lambda p: p.value)
    if len(points) < 2:
        return []
    units = scored.candidate.to_unit([p.value for p in points])
    k = int(np.argmin([p.chi_square_in(low_band) for p in points]))
    return [0.5 * (units[k] + units[j]) for j in (k - 1, k + 1) if 0 <= j < len(points)]


def _zoom(scored: Scored, count: int) -> list[float]:
    """`count` new values between each of the ZOOM_MINIMA lowest local minima of the profile and
    their neighbours (in the candidate's unit range): the cost of a clearance has several."""
    points = sorted((p for p in scored.points if p.fit is not None), key=lambda p: p.value)
    if not points:
        return []
    units = scored.candidate.to_unit([p.value for p in points])
    chi = np.array([p.chi_square for p in points])
    minima = [k for k in range(len(chi)) if (k == 0 or chi[k] <= chi[k - 1]) and (k + 1 == len(chi) or chi[k] <= chi[k + 1])]
    new = []
    for k in sorted(minima, key=lambda k: chi[k])[:ZOOM_MINIMA]:
        below = units[k - 1] if k > 0 else 0.0
        above = units[k + 1] if k + 1 < len(units) else 1.0
        half = count // 2
        new += [units[k] - (units[k] - below) * (i + 1) / (half + 1) for i in range(half)]
        new += [units[k] + (above - units[k]) * (i + 1) / (count - half + 1) for i in range(count - half)]
    return [float(scored.candidate.from_unit(u)) for u in new if 0.0 <= u <= 1.0]


def judge(scored: list[Scored], baseline: Fit, record: Record) -> list[Scored]:
    """BIC, ΔBIC, interval for every candidate; ranked best first; ties marked on the best."""
    penalty = np.log(max(record.effective_samples, 2.0))
    for s in scored:
        if s.best is None:
            continue
        s.allowance = profile_threshold(s.best.chi_square, record)
        s.bic = s.estimate.chi_square + penalty * s.candidate.parameters  # the evidence: the run reported and added (a
        # rough candidate's at its smoothed minimum, not the comb's lowest tooth; any other's is its lowest run)
        s.delta_bic = s.bic - baseline.chi_square
        s.interval = interval(s, record) if s.smoothed is None else smoothed_interval(s)
    ranked = sorted(scored, key=lambda s: (not s.fitted, s.bic))
    return ranked


def profile_threshold(chi_square_min: float, record: Record, level: float = INTERVAL_LEVEL) -> float:
    """Δχ² of the profile interval at `level` (D7): the F(1, ν) quantile — χ²₁'s when σ̂ is exact, wider by σ̂'s own
    uncertainty (ν: the smallest of the sensors' noise degrees of freedom) — times the Birge ratio χ²_min/n_eff when
    the best model still misses the record by more than the noise."""
    dof = min((n.degrees_of_freedom for n in record.noise.values()), default=np.inf)
    quantile = chi2.ppf(level, 1) if not np.isfinite(dof) else fisher.ppf(level, 1, dof)
    return float(quantile * max(1.0, chi_square_min / max(record.effective_samples, 1.0)))


@dataclass(frozen=True)
class LocalParabola:
    """χ² ≈ a (u − v)² + c fitted (least squares) to the runs nearest a profile's lowest one, in the unit range."""

    vertex: float  # v
    vertex_error: float  # the standard error of v (delta method)
    curvature: float  # a
    scatter: float  # RMS of the runs' χ² about the parabola (the chaotic impacts' run-to-run spread), χ²
    dof: int  # runs − 3
    span: tuple[float, float]  # of the runs it was fitted to

    @property
    def convex(self) -> bool:
        """A minimum among its runs: a > 0 and v within their span."""
        return self.curvature > 0.0 and self.span[0] <= self.vertex <= self.span[1]

    def quantile(self, level: float = INTERVAL_LEVEL) -> float:
        """Student's t at the two-sided `level`, for its dof (its scatter is estimated from dof residuals)."""
        return float(student.ppf(0.5 + 0.5 * level, max(self.dof, 1)))

    def indistinct(self, level: float = INTERVAL_LEVEL) -> float:
        """Δχ² the runs' scatter leaves undecided at `level`: t·scatter."""
        return self.quantile(level) * self.scatter

    def half_width(self, threshold: float, level: float = INTERVAL_LEVEL) -> float:
        """A convex parabola's interval half-width about v: its rise to `threshold` plus the scatter's t·s (values the
        runs do not tell apart), with t·σ_v for the vertex's own uncertainty."""
        t = self.quantile(level)
        return float(np.sqrt((t * self.vertex_error) ** 2 + (threshold + t * self.scatter) / self.curvature))


def local_parabola(units: np.ndarray, chi: np.ndarray) -> LocalParabola | None:
    """The parabola through the PROFILE_POINTS runs nearest the lowest one; None when fewer than 5 runs (its scatter
    needs 2 residual degrees of freedom) or fewer than 3 distinct values among them (a screened candidate's runs)."""
    near = np.argsort(np.abs(units - units[np.argmin(chi)]))[:PROFILE_POINTS]
    if len(near) < 5 or len(np.unique(units[near])) < 3:
        return None
    centre = float(units[np.argmin(chi)])
    coefficients, covariance = np.polyfit(units[near] - centre, chi[near], 2, cov="unscaled")
    a, b, _ = coefficients
    dof = len(near) - 3
    scatter = float(np.sqrt(np.sum((chi[near] - np.polyval(coefficients, units[near] - centre)) ** 2) / dof))
    if a == 0.0:
        return LocalParabola(centre, np.inf, 0.0, scatter, dof, (float(units[near].min()), float(units[near].max())))
    gradient = np.array([b / (2.0 * a * a), -1.0 / (2.0 * a), 0.0])
    error = float(scatter * np.sqrt(max(gradient @ covariance @ gradient, 0.0)))
    return LocalParabola(centre - b / (2.0 * a), error, float(a), scatter, dof,
                         (float(units[near].min()), float(units[near].max())))


def interval(scored: Scored, record: Record) -> tuple[float, float]:
    """The profile interval at INTERVAL_LEVEL (docs/diagnose.md §4 step 4): the evaluated values whose χ² is within
    Δ = scored.allowance (profile_threshold) plus the runs' scatter t·s (LocalParabola.indistinct) of the best, widened
    halfway to the next evaluated values outside, joined with a convex local parabola's vertex ± its half-width
    (LocalParabola.half_width: the scatter and the vertex's uncertainty, which the evaluated grid alone does not show)."""
    finished = sorted((p for p in scored.points if p.fit is not None), key=lambda p: p.value)
    units = scored.candidate.to_unit([p.value for p in finished])
    chi = np.array([p.chi_square for p in finished])
    parabola = local_parabola(units, chi) if np.all(np.isfinite(chi)) else None
    spread = parabola.indistinct() if parabola is not None else 0.0
    low_u, high_u = grid_interval(units, chi, scored.allowance + spread)
    if parabola is not None and parabola.convex:
        half = parabola.half_width(scored.allowance)
        low_u, high_u = min(low_u, parabola.vertex - half), max(high_u, parabola.vertex + half)
    low_u, high_u = np.clip([low_u, high_u], 0.0, 1.0)
    return float(scored.candidate.from_unit(low_u)), float(scored.candidate.from_unit(high_u))


def grid_interval(units: np.ndarray, chi: np.ndarray, allowance: float) -> tuple[float, float]:
    """The span (unit range, runs sorted by value) of the runs within `allowance` of the lowest χ², widened halfway to
    the next runs outside (to the bounds where there is none)."""
    inside = np.nonzero(chi <= chi.min() + allowance)[0]
    lo, hi = inside.min(), inside.max()
    low_u = 0.5 * (units[lo] + units[lo - 1]) if lo > 0 else 0.0
    high_u = 0.5 * (units[hi] + units[hi + 1]) if hi + 1 < len(units) else 1.0
    return float(low_u), float(high_u)


def smoothed_interval(scored: Scored, profile: tuple[float, float] | None = None) -> tuple[float, float]:
    """A rough candidate's interval at INTERVAL_LEVEL: the smoothed profile's vertex ± the normal quantile times its
    uncertainty (of the band chosen, or of `profile`: one band's (vertex, error)), within the bounds."""
    vertex, error = profile or scored.smoothed
    half = float(norm.ppf(0.5 + 0.5 * INTERVAL_LEVEL)) * error
    low, high = np.clip([vertex - half, vertex + half], 0.0, 1.0)
    return float(scored.candidate.from_unit(low)), float(scored.candidate.from_unit(high))


def mark_ties(ranked: list[Scored], all_sensors_scale: dict[str, float]) -> None:
    """On the winner: the candidates whose BIC is within TIE, and the sensor that would tell them apart."""
    if not ranked or ranked[0].best is None:
        return
    winner = ranked[0]
    ties = [s for s in ranked[1:] if s.fitted and s.best is not None and s.bic - winner.bic <= TIE]
    winner.ambiguous_with = [s.candidate.label for s in ties]
    if ties:
        winner.telling_sensor = telling_sensor(winner.estimate.prediction, [s.estimate.prediction for s in ties],
                                               all_sensors_scale)


def halves_improved(record: Record, baseline: Point, effect: Point) -> tuple[float, float]:
    """Δχ² of the effect over the model on each half of the record (both negative: the improvement
    is not carried by one part of the record alone — the split-record check of docs/diagnose.md)."""
    def halves(point: Point):
        return chi_square_halves(record, aligned_residuals(record, point.prediction, point.fit.offset))

    (base_first, base_second), (first, second) = halves(baseline), halves(effect)
    return first - base_first, second - base_second


def bic_margin(effective_samples: float) -> float:
    """Δχ² a one-parameter effect must beat the model by to lower the BIC by SIGNIFICANCE: ln n_eff + SIGNIFICANCE."""
    return float(np.log(max(effective_samples, 2.0)) + SIGNIFICANCE)


def significant_on_both_halves(scored: Scored, record: Record) -> bool:
    """The effect lowers χ² on each half of the record by the BIC margin of that half (n_eff / 2)."""
    return scored.halves is not None and max(scored.halves) < -bic_margin(record.effective_samples / 2.0)


def robust_to_perturbations(scored: Scored, record: Record) -> bool:
    """In each of PERTURBATIONS re-rolled impact sequences the effect still beats the model by the BIC margin: its
    evidence is not one lucky realisation of a chaotic sequence."""
    return len(scored.perturbed) >= PERTURBATIONS and max(scored.perturbed) < -bic_margin(record.effective_samples)


def keeps_its_gain(scored: Scored, baseline_chi_square: float) -> bool:
    """The median of the effect's re-rolled runs (scored.perturbed: Δχ² over the model) keeps at least RETAINED of the
    improvement of its estimate: when it does not, the estimate's improvement is one lucky realisation of a chaotic
    impact sequence (the ensemble's 1 nm twins, started alike, often replay the same one). No re-rolled runs: kept."""
    if not scored.perturbed:
        return True
    return median_change(scored) <= RETAINED * (scored.estimate.chi_square - baseline_chi_square)


def median_change(scored: Scored) -> float:
    """The median Δχ² over the model of the effect's re-rolled runs (scored.perturbed)."""
    return float(np.median(scored.perturbed))


def no_change(candidate: Candidate) -> float:
    """The value of an effect the model lacks (a worn arc, a clearance or friction of an ideal joint) that amounts to
    none of it: the lower bound (2 µm of wear: none to speak of)."""
    return candidate.low


def reaches_no_change(scored: Scored) -> bool:
    """An effect the model lacks whose interval reaches its lower bound (no_change): its runs' own scatter
    (LocalParabola.indistinct, the chaotic run-to-run spread of neighbouring values) is as large as its improvement
    over the model, so its low χ² is one lucky run (a needle), not a basin. A present value (candidate.current) inside
    the interval is not judged so: the benchmark's contact stiffness at the slider pin, rightly found, holds the
    model's own value in its interval (docs/diagnose.md §4 step 3)."""
    if scored.interval is None or scored.candidate.current is not None:
        return False
    return scored.interval[0] <= no_change(scored.candidate) * (1.0 + 1e-9)


def unbounded(scored: Scored) -> bool:
    """The candidate's interval spans its whole range: the record fixes no value of it, so its low χ² is one lucky run
    however it compares with the model's (a present value included)."""
    if scored.interval is None:
        return False
    low, high = scored.interval
    return low <= scored.candidate.low * (1.0 + 1e-9) and high >= scored.candidate.high * (1.0 - 1e-9)


def telling_sensor(first: Prediction, others: list[Prediction], scale: dict[str, float]) -> str | None:
    """The model sensor on which the tied models differ most (RMS difference over the sensor's range)."""
    best_name, best_score = None, 0.0
    for name, values in first.sensors.items():
        if not scale.get(name):
            continue
        for other in others:
            if name not in other.sensors:
                continue
            difference = np.interp(first.time, other.time, other.sensors[name]) - values
            score = float(np.sqrt(np.mean(difference ** 2)) / scale[name])
            if score > best_score:
                best_name, best_score = name, score
    return best_name


# --- joint refit of the effects found -------------------------------------------------------------


@dataclass
class JointFit:
    """All effects found refitted together; each point's value is the tuple of their values."""

    candidates: list[Candidate]
    start: tuple[float, ...]  # the values found one after another (greedy)
    points: list[Point] = field(default_factory=list)
    step: float = REFIT_STEP  # the last stencil step, in unit coordinates

    @property
    def best(self) -> Point:
        return min((p for p in self.points if p.fit is not None), key=lambda p: p.chi_square)

    @property
    def start_point(self) -> Point:
        return next(p for p in self.points if p.value == self.start)

    def units(self, values) -> np.ndarray:
        return np.array([float(c.to_unit(v)) for c, v in zip(self.candidates, values)])

    def values(self, units) -> tuple[float, ...]:
        return tuple(float(c.from_unit(u)) for c, u in zip(self.candidates, units))

    def intervals(self, allowance: float) -> list[tuple[float, float]]:
        """Per effect: the span of the evaluated points whose χ² is within `allowance` of the best, widened
        by half the last step on each side (in unit coordinates, kept within the bounds)."""
        best = self.best.chi_square
        inside = np.array([self.units(p.value) for p in self.points if p.fit is not None and p.chi_square <= best + allowance])
        low = np.clip(inside.min(axis=0) - 0.5 * self.step, 0.0, 1.0)
        high = np.clip(inside.max(axis=0) + 0.5 * self.step, 0.0, 1.0)
        return list(zip(self.values(low), self.values(high)))


def refit_jointly(evaluator: Tracked, record: Record, sensors: list[str], document: dict,
                  candidates: list[Candidate], start, rounds: int = REFIT_ROUNDS) -> JointFit:
    """Refit the effects' values together, starting from the greedy ones: each round runs a stencil of
    axial and pairwise-diagonal neighbours of the best point (one parallel batch), then the minimum of a
    quadratic surface fitted to the points near it (if convex), and halves the step."""
    joint = JointFit(list(candidates), tuple(float(v) for v in start))
    _run_joint(evaluator, record, sensors, document, joint, [joint.units(joint.start)])
    refine_jointly(evaluator, record, sensors, document, joint, REFIT_STEP, rounds)
    return joint


def refine_jointly(evaluator, record, sensors, document, joint: JointFit, step: float, rounds: int) -> None:
    """`rounds` stencil rounds about the joint fit's best point, the first of `step` (unit coordinates), each followed
    by a run at the minimum of the quadratic surface through the points near it (if convex), the step halved each
    round."""
    for _ in range(rounds):
        centre = joint.units(joint.best.value)
        _run_joint(evaluator, record, sensors, document, joint, stencil(centre, step))
        vertex = quadratic_minimum(joint, centre, step)
        if vertex is not None:
            _run_joint(evaluator, record, sensors, document, joint, [vertex])
        joint.step = step
        step /= 2.0


def _run_joint(evaluator, record, sensors, document, joint: JointFit, units: list) -> None:
    known = {p.value for p in joint.points}
    new = [v for v in dict.fromkeys(joint.values(u) for u in units) if v not in known]
    joint.points += evaluator.evaluate([with_effects(document, joint.candidates, v) for v in new],
                                       lambda i, prediction: score_point(record, sensors, new[i], prediction),
                                       [setting(joint.candidates, v) for v in new])


def stencil(centre: np.ndarray, step: float) -> list[np.ndarray]:
    """±step along each axis and (±step, ±step) in each pair of axes around `centre`, kept in [0, 1]."""
    axes = np.eye(len(centre))
    moves = [sign * axes[i] for i in range(len(centre)) for sign in (-1.0, 1.0)]
    moves += [a * axes[i] + b * axes[j] for i in range(len(centre)) for j in range(i + 1, len(centre))
              for a in (-1.0, 1.0) for b in (-1.0, 1.0)]
    return [np.clip(centre + step * move, 0.0, 1.0) for move in moves]


def quadratic_minimum(joint: JointFit, centre: np.ndarray, step: float) -> np.ndarray | None:
    """Minimum of a quadratic surface fitted (least squares) to χ² over the points within REFIT_REACH steps
    of `centre`, kept within that reach and the bounds; None when too few points or the surface is not convex."""
    finished = [p for p in joint.points if p.fit is not None]
    x = np.array([(joint.units(p.value) - centre) / step for p in finished])
    near = np.max(np.abs(x), axis=1) <= REFIT_REACH * (1.0 + 1e-9)
    n = len(centre)
    pairs = [(i, j) for i in range(n) for j in range(i, n)]
    if near.sum() < 2 + n + len(pairs):
        return None
    x = x[near]
    design = np.column_stack([np.ones(len(x)), x, *[x[:, i] * x[:, j] for i, j in pairs]])
    coefficients = np.linalg.lstsq(design, np.array([p.chi_square for p, keep in zip(finished, near) if keep]),
                                   rcond=None)[0]
    gradient = coefficients[1:n + 1]
    hessian = np.zeros((n, n))
    for (i, j), c in zip(pairs, coefficients[n + 1:]):
        hessian[i, j] += c
        hessian[j, i] += c
    if np.any(np.linalg.eigvalsh(hessian) <= 0.0):
        return None
    offset = np.clip(np.linalg.solve(hessian, -gradient), -REFIT_REACH, REFIT_REACH)
    return np.clip(centre + step * offset, 0.0, 1.0)


# --- pairwise search: two effects that neither improves the record alone -------------------------------------------


PAIRS = 3  # pairs of fitted candidates fitted together when no single one is significant
PAIR_GRID = (0.125, 0.375, 0.625, 0.875)  # the coarse grid of a pair, per axis, in unit coordinates
PAIR_ROUNDS = 4  # refinement rounds after the grid, the first stencil step half the grid's spacing


@dataclass
class PairFit:
    """Two candidates fitted together (`joint`: their coarse grid and its refinement), and the pair's evidence."""

    scored: tuple[Scored, Scored]  # their single-effect fits (screening, scan, zooms)
    joint: JointFit
    bic: float = np.inf  # χ²_min + (k₁ + k₂) ln n_eff
    delta_bic: float = np.inf  # BIC − the model's χ²

    @property
    def candidates(self) -> list[Candidate]:
        return self.joint.candidates


def candidate_pairs(fitted: list[Scored], baseline: float, count: int = PAIRS) -> list[tuple[Scored, Scored]]:
    """The `count` pairs of fitted candidates whose single improvements over the model (χ² − their lowest χ², negative
    when a candidate alone only makes the fit worse) add up most; never two values of one quantity (two worn arcs of
    one joint)."""
    def improvement(s: Scored) -> float:
        return baseline - s.best.chi_square

    usable = [s for s in fitted if s.best is not None]
    pairs = [(a, b) for i, a in enumerate(usable) for b in usable[i + 1:] if a.candidate.quantity != b.candidate.quantity]
    return sorted(pairs, key=lambda pair: -(improvement(pair[0]) + improvement(pair[1])))[:count]


def fit_pair(evaluator, record: Record, sensors: list[str], document: dict, pair: tuple[Scored, Scored],
             baseline: Fit) -> PairFit | None:
    """The pair on a coarse grid (PAIR_GRID², one parallel batch), then refined about its best point as the joint refit
    does (refine_jointly: PAIR_ROUNDS rounds, the first step half the grid's spacing); None when no run finished. Its
    BIC counts both candidates' parameters."""
    joint = JointFit([s.candidate for s in pair], ())
    _run_joint(evaluator, record, sensors, document, joint, [np.array(u) for u in np.array(np.meshgrid(
        PAIR_GRID, PAIR_GRID)).reshape(2, -1).T])
    if not any(p.fit is not None for p in joint.points):
        return None
    joint.start = joint.best.value
    spacing = PAIR_GRID[1] - PAIR_GRID[0]
    refine_jointly(evaluator, record, sensors, document, joint, 0.5 * spacing, PAIR_ROUNDS)
    penalty = np.log(max(record.effective_samples, 2.0)) * sum(s.candidate.parameters for s in pair)
    bic = joint.best.chi_square + penalty
    return PairFit(pair, joint, bic, bic - baseline.chi_square)
