"""docs/validation.md §7: the paper's studies on two (or more) models side by side, by default the rigid breaker
(configs/uhv_breaker.yaml) and the flexible one (configs/uhv_breaker_flexible.yaml); with
`--models prescribed=configs/uhv_breaker.yaml,hydraulic=configs/uhv_breaker_hydraulic.yaml --skip-friction` the
clearance study of docs/validation.md §6, "Force-driven breaker".

    python docs/scripts/flexible_studies.py [OUT] [--samples N] [--models NAME=FILE,NAME=FILE…] [--skip-friction]
        (result files under OUT, default /tmp/clearsim-flexible-studies; N = 20 paired samples per model)

1. Clearance: J only, and A and J, at 0.01, 0.03, 0.05 and 0.1 mm, one run each per model (each model's own
   t_end): peak |a| of the output over the whole run (the summary's) and over 0–10 ms, the start delay against an
   ideal curve (the time to reach 1 % of that ideal's peak speed, minus the ideal's own), the largest contact force
   at A and J, J's whirl warning (window, orbits), steps and wall time; for a model with a `travel:` block, its
   travel figures (the result's `travel_figures`): the time from the command to contact touch and the contact-zone
   speed. The ideal curve of a model moved by a prescribed stroke is the ideal run (clearances 0) of the first such
   model (by default the rigid one for both); a force-driven model (no `drivers:`) is measured against its own
   ideal run, since its drive's motion is an outcome, not an input.
2. Friction μ_d 0.10 → 0.16 (A and J at 0.1 mm) as a paired ensemble: the perturbations of friction_ensemble.py
   (clearance ±1 %, restitution 0.9 ± 0.005, journal start |e| ≤ 0.5 c; sample k has the same draws at both μ_d),
   per model; the effect is the median of the paired relative changes of the whole-stroke peak, with its 95 %
   confidence interval (the order-statistic interval of the median, binomial, distribution-free) and the Wilcoxon
   signed-rank p of "no change". Left out with --skip-friction.

Runs: 2 × 9 + 2 × (1 + 2 N) (≈ 100 for N = 20), a few minutes on 2 cores with the kernels cached; complete result
files under OUT are reused (named <model>-<case>.h5: use another OUT for other files under the same names). Tables
are printed as Markdown.
"""

import argparse
import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from friction_ensemble import draws, run_case  # noqa: E402
from paper_studies import ROOT, delay_ms, window_peak  # noqa: E402

from clearsim.io.hdf5 import read_result  # noqa: E402
from clearsim.model.loader import load_mechanism  # noqa: E402
from clearsim.runner import summarize  # noqa: E402

MODELS = {"rigid": ROOT / "configs" / "uhv_breaker.yaml", "flexible": ROOT / "configs" / "uhv_breaker_flexible.yaml"}
CLEARANCES_MM = ("0.01", "0.03", "0.05", "0.1")
IDEAL = ("joints.A.clearance=0", "joints.J.clearance=0")
FRICTION = ("0.10", "0.16")
CONFIDENCE = 0.95


def parse_models(text: str) -> dict[str, Path]:
    """{name: config file} from "name=file,name=file" (a relative file from the current folder, else the repository)."""
    models = {}
    for item in text.split(","):
        name, _, file = item.partition("=")
        if not name or not file:
            raise argparse.ArgumentTypeError(f"{item!r}: expected NAME=FILE")
        path = Path(file)
        models[name] = path if path.is_absolute() or path.exists() else ROOT / path
    return models


def command_line(arguments):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", nargs="?", type=Path, default=Path("/tmp/clearsim-flexible-studies"),
                        help="folder of the result files (complete ones are reused)")
    parser.add_argument("--samples", type=int, default=20, help="paired samples per model of the friction study")
    parser.add_argument("--models", type=parse_models, default=MODELS,
                        help="the models compared, NAME=FILE,NAME=FILE (default rigid and flexible breaker)")
    parser.add_argument("--skip-friction", action="store_true", help="the clearance study only")
    options = parser.parse_args(arguments)
    options.out.mkdir(parents=True, exist_ok=True)
    return options


def clearance_cases():
    """(label, overrides) of the clearance study: J only, then A and J, at each clearance."""
    cases = [(f"J only, {c} mm", ("joints.A.clearance=0", f"joints.J.clearance={c}mm")) for c in CLEARANCES_MM]
    return cases + [(f"A and J, {c} mm", (f"joints.A.clearance={c}mm", f"joints.J.clearance={c}mm"))
                    for c in CLEARANCES_MM]


def run_model(models, model, folder, name, overrides):
    """The result file of one case of a model (friction_ensemble.run_case on that model's file)."""
    return run_case(folder, f"{model}-{name}", overrides, models[model])


def delay_references(models) -> dict[str, str]:
    """{model: the model whose ideal run its start delay is measured against}: the first model moved by a prescribed
    stroke for every such model, a force-driven model's own."""
    prescribed = [m for m, config in models.items() if load_mechanism(config, []).mechanism.drivers]
    return {m: prescribed[0] if m in prescribed else m for m in models}


def ideal_runs(models, folder):
    """{model: the ideal run (clearances 0) its start delay is measured against}."""
    return {model: read_result(run_model(models, reference, folder, "ideal", IDEAL))
            for model, reference in delay_references(models).items()}


def whirl_text(warnings: str) -> str:
    """J's whirl warning as "55.4–81.5 ms, 54 orbits (2.1 kHz)", or "none"."""
    match = re.search(r"joint J: the journal whirls around its bearing from ([\d.]+) to ([\d.]+) ms, (\d+) orbits "
                      r"\(([^)]+)\)", warnings)
    return f"{match[1]}–{match[2]} ms, {match[3]} orbits ({match[4]})" if match else "none"


def case_figures(path, ideal):
    data, summary = read_result(path), summarize(path)
    attrs = data["attrs"]
    return {"peak": summary.peak_acceleration[1], "peak_10ms": window_peak(data),
            "delay": delay_ms(data, ideal, 0.01), "force_A": summary.peak_contact_force.get("A", np.nan) / 1e3,
            "force_J": summary.peak_contact_force.get("J", np.nan) / 1e3, "steps": int(attrs["steps"]),
            "wall": float(attrs["wall_time_s"]), "whirl": whirl_text(str(attrs.get("warnings", ""))),
            "complete": bool(attrs.get("complete")), "travel": summary.travel}


# travel figure shown → (`travel_figures` key, scale from SI, format)
TRAVEL_COLUMNS = {"command → touch (ms)": ("operating_time_s", 1e3, ".3f"),
                  "contact-zone speed (m/s)": ("zone_speed_m_per_s", 1.0, ".4f")}


def travel_cells(travel: dict) -> str:
    """The travel figures of a run as table cells ("—" without a `travel:` block or where the travel never got)."""
    cells = []
    for key, scale, spec in TRAVEL_COLUMNS.values():
        value = travel.get(key)
        cells.append("—" if value is None else f"{value * scale:{spec}}")
    return " | ".join(cells)


def print_clearance_study(models, folder):
    ideals = ideal_runs(models, folder)
    with_travel = any(load_mechanism(config, []).mechanism.travel is not None for config in models.values())
    travel_header = "".join(f" {label} |" for label in TRAVEL_COLUMNS) if with_travel else ""
    print("| case | model | peak \\|a\\| whole stroke (m/s²) | first 10 ms (m/s²) | start delay (ms) | max F_n A (kN) "
          f"| max F_n J (kN) | whirl warning at J |{travel_header} steps | wall (s) |")
    print("|---|---|---|---|---|---|---|---|" + "---|" * (len(TRAVEL_COLUMNS) * with_travel + 2))
    for label, overrides in [("ideal", IDEAL)] + clearance_cases():
        for model in models:
            name = re.sub(r"[^0-9a-zA-Z.]+", "-", label)
            f = case_figures(run_model(models, model, folder, name, overrides), ideals[model])
            forces = " | ".join("—" if not np.isfinite(f[k]) else f"{f[k]:.2f}" for k in ("force_A", "force_J"))
            flag = "" if f["complete"] else " (incomplete)"
            travel = f" {travel_cells(f['travel'])} |" if with_travel else ""
            print(f"| {label}{flag} | {model} | {f['peak']:.1f} | {f['peak_10ms']:.1f} | {f['delay']:.3f} | {forces} | "
                  f"{f['whirl']} |{travel} {f['steps']} | {f['wall']:.2f} |")


def median_interval(values, confidence=CONFIDENCE):
    """(low, high): the distribution-free confidence interval of the median, the order statistics k and n − k + 1
    with k the least for which P(Binomial(n, ½) ≤ k) ≥ (1 − confidence)/2 (n = 20, 95 %: the 6th and 15th, 95.9 %)."""
    from scipy.stats import binom

    ordered, n = np.sort(values), len(values)
    k = max(int(binom.ppf((1 - confidence) / 2, n, 0.5)), 1)
    return float(ordered[k - 1]), float(ordered[n - k])


def print_friction_study(models, folder, samples):
    from scipy.stats import wilcoxon

    print(f"\n| model | μ_d 0.10 → 0.16, peak \\|a\\| whole stroke: median paired change [{CONFIDENCE:.0%} CI] | "
          "lower in | Wilcoxon p | median peak at 0.10 / 0.16 (m/s²) | median max F_n J at 0.10 / 0.16 (kN) |")
    print("|---|---|---|---|---|---|")
    ideals = ideal_runs(models, folder)
    for model in models:
        figures = {mu: [case_figures(run_model(models, model, folder, f"friction-{k:02d}-mu{mu}",
                                               (f"defaults.friction.mu_d={mu}", *draws(k))), ideals[model])
                        for k in range(1, samples + 1)] for mu in FRICTION}
        before, after = (np.array([f["peak"] for f in figures[mu]]) for mu in FRICTION)
        force_before, force_after = (np.median([f["force_J"] for f in figures[mu]]) for mu in FRICTION)
        change = (after / before - 1) * 100
        low, high = median_interval(change)
        print(f"| {model} | {np.median(change):+.1f} % [{low:+.1f}, {high:+.1f}] | {int(np.sum(change < 0))}/{samples} "
              f"| {wilcoxon(after, before).pvalue:.2g} | {np.median(before):.0f} / {np.median(after):.0f} | "
              f"{force_before:.1f} / {force_after:.1f} |")


def main():
    options = command_line(sys.argv[1:])
    print_clearance_study(options.models, options.out)
    if not options.skip_friction:
        print_friction_study(options.models, options.out, options.samples)


if __name__ == "__main__":
    main()
