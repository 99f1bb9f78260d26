"""docs/validation.md §7: the paper's studies on the rigid breaker (configs/uhv_breaker.yaml) and the flexible one
(configs/uhv_breaker_flexible.yaml), side by side.

    python docs/scripts/flexible_studies.py [OUT] [--samples N]
        (result files under OUT, default /tmp/clearsim-flexible-studies; N = 20 paired samples per model)

1. Clearance: J only, and A and J, at 0.01, 0.03, 0.05 and 0.1 mm, one run each per model: peak |a| of the output
   over the whole stroke (the summary's) and over 0–10 ms, the start delay against the rigid ideal curve (the time
   to reach 1 % of the rigid ideal peak speed, minus the rigid ideal's), the largest contact force at A and J,
   J's whirl warning (window, orbits), steps and wall time.
2. Friction μ_d 0.10 → 0.16 (A and J at 0.1 mm) as a paired ensemble: the perturbations of friction_ensemble.py
   (clearance ±1 %, restitution 0.9 ± 0.005, journal start |e| ≤ 0.5 c; sample k has the same draws at both μ_d),
   per model; the effect is the median of the paired relative changes of the whole-stroke peak, with its 95 %
   confidence interval (the order-statistic interval of the median, binomial, distribution-free) and the Wilcoxon
   signed-rank p of "no change".

Runs: 2 × 9 + 2 × (1 + 2 N) (≈ 100 for N = 20), a few minutes on 2 cores with the kernels cached; complete result
files under OUT are reused. Tables are printed as Markdown.
"""

import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from friction_ensemble import command_line, draws, run_case  # noqa: E402
from paper_studies import ROOT, delay_ms, window_peak  # noqa: E402

import friction_ensemble  # noqa: E402
from clearsim.io.hdf5 import read_result  # noqa: E402
from clearsim.runner import summarize  # noqa: E402

MODELS = {"rigid": ROOT / "configs" / "uhv_breaker.yaml", "flexible": ROOT / "configs" / "uhv_breaker_flexible.yaml"}
CLEARANCES_MM = ("0.01", "0.03", "0.05", "0.1")
IDEAL = ("joints.A.clearance=0", "joints.J.clearance=0")
FRICTION = ("0.10", "0.16")
CONFIDENCE = 0.95


def clearance_cases():
    """(label, overrides) of the clearance study: J only, then A and J, at each clearance."""
    cases = [(f"J only, {c} mm", ("joints.A.clearance=0", f"joints.J.clearance={c}mm")) for c in CLEARANCES_MM]
    return cases + [(f"A and J, {c} mm", (f"joints.A.clearance={c}mm", f"joints.J.clearance={c}mm"))
                    for c in CLEARANCES_MM]


def run_model(model, folder, name, overrides):
    """The result file of one case of a model (friction_ensemble.run_case on that model's file)."""
    friction_ensemble.CONFIG = MODELS[model]
    return run_case(folder, f"{model}-{name}", overrides)


def whirl_text(warnings: str) -> str:
    """J's whirl warning as "55.4–81.5 ms, 54 orbits (2.1 kHz)", or "none"."""
    match = re.search(r"joint J: the journal whirls around its bearing from ([\d.]+) to ([\d.]+) ms, (\d+) orbits "
                      r"\(([^)]+)\)", warnings)
    return f"{match[1]}–{match[2]} ms, {match[3]} orbits ({match[4]})" if match else "none"


def case_figures(path, rigid_ideal):
    data, summary = read_result(path), summarize(path)
    attrs = data["attrs"]
    return {"peak": summary.peak_acceleration[1], "peak_10ms": window_peak(data),
            "delay": delay_ms(data, rigid_ideal, 0.01), "force_A": summary.peak_contact_force.get("A", np.nan) / 1e3,
            "force_J": summary.peak_contact_force.get("J", np.nan) / 1e3, "steps": int(attrs["steps"]),
            "wall": float(attrs["wall_time_s"]), "whirl": whirl_text(str(attrs.get("warnings", ""))),
            "complete": bool(attrs.get("complete"))}


def print_clearance_study(folder):
    rigid_ideal = read_result(run_model("rigid", folder, "ideal", IDEAL))
    print("| case | model | peak \\|a\\| whole stroke (m/s²) | first 10 ms (m/s²) | start delay (ms) | max F_n A (kN) "
          "| max F_n J (kN) | whirl warning at J | steps | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, overrides in [("ideal", IDEAL)] + clearance_cases():
        for model in MODELS:
            name = re.sub(r"[^0-9a-zA-Z.]+", "-", label)
            f = case_figures(run_model(model, folder, name, overrides), rigid_ideal)
            forces = " | ".join("—" if not np.isfinite(f[k]) else f"{f[k]:.2f}" for k in ("force_A", "force_J"))
            flag = "" if f["complete"] else " (incomplete)"
            print(f"| {label}{flag} | {model} | {f['peak']:.1f} | {f['peak_10ms']:.1f} | {f['delay']:.3f} | {forces} | "
                  f"{f['whirl']} | {f['steps']} | {f['wall']:.2f} |")


def median_interval(values, confidence=CONFIDENCE):
    """(low, high): the distribution-free confidence interval of the median, the order statistics k and n − k + 1
    with k the least for which P(Binomial(n, ½) ≤ k) ≥ (1 − confidence)/2 (n = 20, 95 %: the 6th and 15th, 95.9 %)."""
    from scipy.stats import binom

    ordered, n = np.sort(values), len(values)
    k = max(int(binom.ppf((1 - confidence) / 2, n, 0.5)), 1)
    return float(ordered[k - 1]), float(ordered[n - k])


def print_friction_study(folder, samples):
    from scipy.stats import wilcoxon

    print(f"\n| model | μ_d 0.10 → 0.16, peak \\|a\\| whole stroke: median paired change [{CONFIDENCE:.0%} CI] | "
          "lower in | Wilcoxon p | median peak at 0.10 / 0.16 (m/s²) | median max F_n J at 0.10 / 0.16 (kN) |")
    print("|---|---|---|---|---|---|")
    for model in MODELS:
        rigid_ideal = read_result(run_model("rigid", folder, "ideal", IDEAL))
        figures = {mu: [case_figures(run_model(model, folder, f"friction-{k:02d}-mu{mu}",
                                               (f"defaults.friction.mu_d={mu}", *draws(k))), rigid_ideal)
                        for k in range(1, samples + 1)] for mu in FRICTION}
        before, after = (np.array([f["peak"] for f in figures[mu]]) for mu in FRICTION)
        force_before, force_after = (np.median([f["force_J"] for f in figures[mu]]) for mu in FRICTION)
        change = (after / before - 1) * 100
        low, high = median_interval(change)
        print(f"| {model} | {np.median(change):+.1f} % [{low:+.1f}, {high:+.1f}] | {int(np.sum(change < 0))}/{samples} "
              f"| {wilcoxon(after, before).pvalue:.2g} | {np.median(before):.0f} / {np.median(after):.0f} | "
              f"{force_before:.1f} / {force_after:.1f} |")


def main():
    folder, samples = command_line(sys.argv[1:], "/tmp/clearsim-flexible-studies")
    print_clearance_study(folder)
    print_friction_study(folder, samples)


if __name__ == "__main__":
    main()
