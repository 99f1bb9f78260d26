"""docs/validation.md §6, "Force-driven breaker": the friction question on the breaker driven by its hydraulic
operating mechanism (configs/uhv_breaker_hydraulic.yaml), side by side with the prescribed drive (the bundled
configs/uhv_breaker.yaml, paper eq. 16).

    python docs/scripts/hydraulic_friction_ensemble.py [OUT] [--samples N]
        (result files under OUT/<drive>, default /tmp/clearsim-hydraulic-friction; N = 20 pairs)

μ_d at A and J is raised 0.10 → 0.16 on the paired ensemble of friction_ensemble.py: sample k draws the clearances
at A and J (0.1 mm ± 1 %), the restitution (0.9 ± 0.005) and where each journal starts in its bearing (|e| ≤ 0.5 c),
and is run at both μ_d with the same draws. Both drives use the same draws; each case is `clearsim run <file>
--set …` (OUT/<drive>/cases.csv). The hydraulic runs stop at 100 ms (the stroke ends at 85 ms), the prescribed ones at
their 85 ms. 4 × N runs of ≈ 1 s; re-running reuses complete result files.

Per run, from the moving contact's travel with the hydraulic file's `travel:` block (clearsim.travel, the figures of
`clearsim run`): the closing time (command to contact touch, 250 mm) and the contact-zone speed (200 → 250 mm); and,
up to the touch, the energies that explain them: the work friction took (A and J), the work the drive gave the
mechanism (the cylinder's ∫F ds, or the prescribed driver's work) and the kinetic energy at the touch; and the
paper's figure, the peak |a| of the moving contact over the stroke (0–85 ms).
Printed: per drive, the mean paired change with its 95 % confidence interval (Student t over the N pairs), the
relative change, and how many pairs change the same way.
"""

import sys
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parent))

from friction_ensemble import command_line, draws, run_case  # noqa: E402
from paper_studies import CONFIG, ROOT  # noqa: E402

from clearsim.io.hdf5 import read_result  # noqa: E402
from clearsim.model.loader import load_mechanism  # noqa: E402
from clearsim.travel import travel_figures  # noqa: E402

HYDRAULIC = ROOT / "configs" / "uhv_breaker_hydraulic.yaml"
DRIVES = {"hydraulic": (HYDRAULIC, ("solver.t_end=100ms",)), "prescribed": (CONFIG, ())}
DRIVE_NAMES = {"hydraulic": "hydraulic cylinder", "prescribed": "prescribed stroke (eq. 16)"}
MU_D = ("0.10", "0.16")
LABELS = {"closing_ms": "closing time, command → touch at 250 mm (ms)",
          "zone_speed": "contact-zone speed, 200 → 250 mm (m/s)",
          "friction_J": "friction work at A and J up to the touch (J)",
          "drive_J": "work the drive gave the mechanism up to the touch (J)",
          "kinetic_J": "kinetic energy at the touch (J)",
          "peak": "peak \\|a\\| of the moving contact, 0–85 ms (m/s²)"}
FORMATS = {"closing_ms": ".3f", "zone_speed": ".4f", "friction_J": ".2f", "drive_J": ".1f", "kinetic_J": ".1f", "peak": ".0f"}
TRAVEL = load_mechanism(HYDRAULIC, []).mechanism.travel
STROKE_END_S = 0.085  # the peak acceleration over the stroke: the prescribed drive's last sample (its jump) left out


def drive_work(data):
    """The work the drive has done on the mechanism at every sample (J): the cylinder's ∫F ds, or the driver's."""
    if "drives/operating_cylinder/force" in data:
        force, stroke = data["drives/operating_cylinder/force"], data["drives/operating_cylinder/stroke"]
        return np.concatenate([[0.0], np.cumsum(0.5 * (force[1:] + force[:-1]) * np.diff(stroke))])
    return data["energy/driver_work"]


def merit(path):
    """The figures of one run (None if it did not complete)."""
    data = read_result(path)
    if not bool(data["attrs"].get("complete")):
        return None
    time = data["time"]
    figures = travel_figures(time, data[f"sensors/{TRAVEL.sensor}"], TRAVEL)
    touch = figures["operating_time_s"]

    def at_touch(values):
        return float(np.interp(touch, time, values))

    return {"closing_ms": touch * 1e3, "zone_speed": figures["zone_speed_m_per_s"],
            "friction_J": at_touch(data["energy/friction_dissipated"]), "drive_J": at_touch(drive_work(data)),
            "kinetic_J": at_touch(data["energy/kinetic"]),
            "peak": float(np.max(np.abs(data["sensors/contact_acceleration"][time < STROKE_END_S])))}


def run_drive(folder, samples, drive):
    """{μ_d: [figures of sample k]} of one drive."""
    config, base = DRIVES[drive]
    folder = folder / drive
    folder.mkdir(parents=True, exist_ok=True)
    figures = {mu: [] for mu in MU_D}
    with open(folder / "cases.csv", "w") as handle:
        handle.write("case,overrides\n")
        for k in range(1, samples + 1):
            for mu in MU_D:
                name, overrides = f"sample-{k:02d}-mu{mu}", (*base, f"defaults.friction.mu_d={mu}", *draws(k))
                handle.write(f"{name},\"{' '.join(overrides)}\"\n")
                figures[mu].append(merit(run_case(folder, name, overrides, config)))
    complete = [k for k in range(samples) if all(figures[mu][k] is not None for mu in MU_D)]
    if len(complete) < samples:
        print(f"{drive}: {samples - len(complete)} pairs did not complete: left out", file=sys.stderr)
    return {mu: [figures[mu][k] for k in complete] for mu in MU_D}


def paired_change(figures, key):
    """(mean of the two μ_d, mean change, 95 % CI half-width, pairs that rise, pairs) of one figure."""
    before = np.array([f[key] for f in figures[MU_D[0]]])
    after = np.array([f[key] for f in figures[MU_D[1]]])
    change = after - before
    half = stats.t.ppf(0.975, len(change) - 1) * np.std(change, ddof=1) / np.sqrt(len(change))
    return float(np.mean(before)), float(np.mean(change)), float(half), int(np.sum(change > 0)), len(change)


def print_table(results):
    print(f"| μ_d {MU_D[0]} → {MU_D[1]} at A and J (0.1 mm), paired | "
          + " | ".join(f"{DRIVE_NAMES[d]}: mean at {MU_D[0]}; change [95 % CI]; rises in" for d in results) + " |")
    print("|---|" + "---|" * len(results))
    for key, label in LABELS.items():
        cells = []
        for figures in results.values():
            level, change, half, rises, pairs = paired_change(figures, key)
            spec = FORMATS[key]
            relative = f" ({change / level * 100:+.2f} % ± {half / abs(level) * 100:.2f} %)" if level else ""
            cells.append(f"{level:{spec}}; {change:+{spec}} [{change - half:+{spec}}, {change + half:+{spec}}]"
                         f"{relative}; {rises}/{pairs}")
        print(f"| {label} | " + " | ".join(cells) + " |")


def main():
    folder, samples = command_line(sys.argv[1:], "/tmp/clearsim-hydraulic-friction")
    results = {drive: run_drive(folder, samples, drive) for drive in DRIVES}
    print(f"{samples} pairs; sample 1 at μ_d = {MU_D[0]}: `clearsim run configs/uhv_breaker_hydraulic.yaml "
          + " ".join(f'--set "{o}"' for o in (*DRIVES["hydraulic"][1], f"defaults.friction.mu_d={MU_D[0]}", *draws(1)))
          + "`\n")
    print_table(results)


if __name__ == "__main__":
    main()
