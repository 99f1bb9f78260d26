"""The data behind the unresolved-contact warning (docs/model.md §4): for the bundled models over a ladder of
tolerances, the largest ratio of position tolerance to an impact's Hertz penetration, and the error of the peak
contact force against the same model at rtol 1e-9.

    python docs/scripts/tolerance_check.py

Prints the Markdown table of docs/model.md §4 (about a minute).
"""

import tempfile
from pathlib import Path

import numpy as np

from clearsim.model.loader import load_mechanism
from clearsim.runner import prepare, run_to_file

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
CASES = [("slider-crank", "slider_crank_flores.yaml", ()),
         ("slider-crank, friction", "slider_crank_flores_friction.yaml", ()),
         ("UHV, A and J 0.01 mm (bundled)", "uhv_breaker.yaml", ()),
         ("UHV, A and J 0.1 mm", "uhv_breaker.yaml", ("joints.A.clearance=0.1mm", "joints.J.clearance=0.1mm"))]
LADDER = (1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7)
REFERENCE_RTOL = 1e-9


def run(config: Path, overrides, rtol: float, folder: Path):
    loaded = load_mechanism(config, [*overrides, f"solver.rtol={rtol}", f"solver.atol={rtol * 1e-3}"])
    report = run_to_file(prepare(loaded), loaded, folder / f"{config.stem}-{len(overrides)}-{rtol}.h5")
    return report


def main() -> None:
    print("| model | rtol (atol = rtol/1000 m) | largest tolerance / Hertz penetration | warned onsets "
          "| max contact force per joint (N) | its error vs rtol 1e-9 |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        for label, file, overrides in CASES:
            reference = run(CONFIGS / file, overrides, REFERENCE_RTOL, folder).statistics.peak_normal_force
            for rtol in LADDER:
                report = run(CONFIGS / file, overrides, rtol, folder)
                stats = report.statistics
                error = np.max(np.abs(stats.peak_normal_force / reference - 1.0))
                # the count of unresolved onsets leads its warning; other warnings (a whirl) say nothing of it
                warned = next((w.split(" ")[0] for w in report.warnings if "not resolved" in w), "0")
                forces = " / ".join(f"{force:.0f}" for force in stats.peak_normal_force)
                print(f"| {label} | {rtol:g}{' (default)' if rtol == 1e-7 else ''} | {stats.tolerance_over_penetration:.3g} "
                      f"| {warned} | {forces} | {error:.1e} |")


if __name__ == "__main__":
    main()
