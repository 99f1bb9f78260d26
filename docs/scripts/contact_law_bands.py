"""docs/validation.md §6, "Under each contact law and lubricated": the breaker's headline figures under each elastic
law of docs/model-contact.md and with greased pins, and their bands.

    python docs/scripts/contact_law_bands.py [OUT] [--lengths 50,40] [--clearances 0.01,0.1] [--config FILE]
        (result files under OUT, default /tmp/clearsim-contact-law-bands; complete ones are reused: use another OUT
        for another FILE)

configs/uhv_breaker.yaml (or FILE, e.g. configs/uhv_breaker_hydraulic.yaml) with A and J at each clearance, run
- dry, under each elastic law: the file's point law (Meng 2015's K) and `point_hertz` with `stiffness: auto`,
  `pereira`, `johnson`, `esdu_78035` and `liu` (with the file's `law: lankarani_nikravesh` damping, `liu` is the
  Bai–Zhao hybrid) at each pin length L (ASSUMED: the model and the paper give none);
- dry, the file's point law, the journals started 1 µm below their bearings' centres (the lubricated runs' start);
- lubricated: `defaults.lubrication: {viscosity: VISCOSITY, length: L}` (short bearing, half-Sommerfeld, the
  default film → dry threshold `dry_below` 1.5 µm, the file's point law below it), the journals started 1 µm below
  their bearings' centres (as the dry control), with
  `solver.method: rosenbrock`: the squeeze film bounds dopri5's steps (at 0.01 mm 140× slower on the first ms,
  docs/performance.md "Stiff models"; at 0.1 mm, L = 50 mm, 3.95 s of integration against rosenbrock's 1.60 s);
  at rtol 1e-9 (LUBRICATED_SOLVER below).

Figures of each run (flexible_studies.case_figures, paper_studies.whirl): peak |a| of the output over the stroke and
over 0–10 ms, the start delay at 1 % of the ideal peak speed against the ideal run, the largest dry contact force
at A and J, the largest film force at A and J and the thinnest film (lubricated), J's orbits 40–80 ms, the energy
dissipated in the contacts and by friction, steps and wall time. Then the bands: per clearance, the range of each
figure over the dry laws, and the lubricated value. 27 runs, ≈ 100 s of integration with the kernels cached
(70 s of it the two greased runs at 0.01 mm).

The oil: ISO VG 68 (ISO 3448: 68 mm²/s at 40 °C, the grade spans 61.2–74.8 mm²/s), density ≈ 880 kg/m³:
μ = 68e-6 m²/s × 880 kg/m³ ≈ 0.060 Pa·s at 40 °C, ASSUMED as the service temperature of the mechanism housing.
"""

import argparse
import re
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from flexible_studies import IDEAL, case_figures  # noqa: E402
from friction_ensemble import run_case  # noqa: E402
from paper_studies import CONFIG, whirl  # noqa: E402

from clearsim.io.hdf5 import read_result  # noqa: E402

VISCOSITY = "0.06Pa*s"  # ISO VG 68 at 40 °C (see above)
OFF_CENTRE = ("joints.A.initial_eccentricity=[0 m, -1 um]", "joints.J.initial_eccentricity=[0 m, -1 um]")
CYLINDRICAL = ("pereira", "johnson", "esdu_78035", "liu")
FILE_LAW = "point_hertz, K of the file"
# the faster method with a film (see above; dry runs keep dopri5), at rtol 1e-9: at the default 1e-7 the peaks agree
# (3.5e-6) but samples differ by up to 9.4 m/s² (docs/model.md §4, "Limits"); min_step as the
# benchmark's lubricated cases (the film's start-up transient)
LUBRICATED_SOLVER = ("solver.method=rosenbrock", "solver.rtol=1e-9", "solver.atol=1e-12", "solver.min_step=1e-13 s")


def law_cases(clearance_mm: str, lengths: list[str]) -> list[tuple[str, str, tuple[str, ...]]]:
    """(label, kind, overrides) of every run at one clearance; kind is "dry", "control" or "lubricated"."""
    clearance = (f"joints.A.clearance={clearance_mm} mm", f"joints.J.clearance={clearance_mm} mm")
    cases = [(FILE_LAW, "dry", clearance),
             ("point_hertz, stiffness auto", "dry", clearance + ("defaults.contact.stiffness=auto",))]
    for length in lengths:
        pin = (f"defaults.contact.length={length}mm", "defaults.contact.stiffness=auto")
        cases += [(f"{law}, L = {length} mm", "dry", clearance + pin + (f"defaults.contact.elastic={law}",))
                  for law in CYLINDRICAL]
    cases.append((f"{FILE_LAW}, started 1 µm off-centre", "control", clearance + OFF_CENTRE))
    for length in lengths:
        oil = (f"defaults.lubrication.viscosity={VISCOSITY}", f"defaults.lubrication.length={length}mm")
        cases.append((f"lubricated, L = {length} mm", "lubricated",
                      clearance + OFF_CENTRE + oil + LUBRICATED_SOLVER))
    return cases


def file_name(clearance_mm: str, label: str) -> str:
    return f"c{clearance_mm}-" + re.sub(r"[^0-9a-zA-Z.]+", "-", label).strip("-")


def film_figures(data) -> dict:
    """Largest film force (kN) at A and J and the thinnest film (µm) over both, NaN for a dry run."""
    if "joints/J/film_force" not in data:
        return {"film_A": np.nan, "film_J": np.nan, "h_min": np.nan}
    largest = {j: float(np.max(np.hypot(*data[f"joints/{j}/film_force"].T))) / 1e3 for j in ("A", "J")}
    thinnest = min(float(np.min(data[f"joints/{j}/film_thickness"])) for j in ("A", "J")) * 1e6
    return {"film_A": largest["A"], "film_J": largest["J"], "h_min": thinnest}


def run_figures(path: Path, ideal) -> dict:
    """case_figures of the run, its film figures, J's orbits 40–80 ms (NaN without a clearance at J) and the
    energy dissipated (J)."""
    data = read_result(path)
    figures = case_figures(path, ideal) | film_figures(data)
    for joint in ("A", "J"):  # an ideal joint's force is its reaction
        if not np.isfinite(figures[f"force_{joint}"]) and f"joints/{joint}/reaction" in data:
            figures[f"force_{joint}"] = float(np.max(np.hypot(*data[f"joints/{joint}/reaction"].T))) / 1e3
    figures["orbits"] = np.nan  # no clearance at J (the ideal run)
    if "joints/J/eccentricity" in data:
        with warnings.catch_warnings():  # a journal never in dry contact has no slip or contact eccentricity to average
            warnings.simplefilter("ignore", RuntimeWarning)
            figures["orbits"] = abs(whirl(data)[0])
    figures["contact_J"] = float(data["energy/contact_dissipated"][-1])
    figures["friction_J"] = float(data["energy/friction_dissipated"][-1])
    return figures


COLUMNS = {  # figure → (header, format)
    "peak": ("peak \\|a\\| stroke (m/s²)", ".0f"), "peak_10ms": ("peak \\|a\\| 0–10 ms (m/s²)", ".0f"),
    "delay": ("start delay (ms)", ".3f"), "force_A": ("max F_n A (kN)", ".1f"), "force_J": ("max F_n J (kN)", ".1f"),
    "film_A": ("max film force A (kN)", ".1f"), "film_J": ("max film force J (kN)", ".1f"),
    "h_min": ("thinnest film (µm)", ".2f"), "orbits": ("J's orbits 40–80 ms", ".1f"),
    "contact_J": ("contact loss (J)", ".1f"), "friction_J": ("friction loss (J)", ".1f"),
    "steps": ("steps", "d"), "wall": ("wall (s)", ".2f"),
}
BANDED = ("peak", "peak_10ms", "delay", "force_A", "force_J", "orbits")


def cell(value, spec) -> str:
    return "—" if isinstance(value, float) and not np.isfinite(value) else format(value, spec)


def value_range(low, high, spec) -> str:
    """"low–high", or "low to high" where a dash would read as a minus sign."""
    return f"{cell(low, spec)}{' to ' if low < 0 else '–'}{cell(high, spec)}"


def band_cell(figures: dict, key: str) -> str:
    """One figure of a run; a joint force with the joint's largest film force beside the dry one where there is a film."""
    text = cell(figures[key], COLUMNS[key][1])
    film = figures.get(key.replace("force", "film"), np.nan) if key.startswith("force") else np.nan
    return text if not np.isfinite(film) else f"{text} (film {film:.1f})"


def print_runs(clearance_mm: str, rows: list[tuple[str, str, dict]]):
    print(f"\nA and J at {clearance_mm} mm\n")
    print("| case | " + " | ".join(header for header, _ in COLUMNS.values()) + " |")
    print("|---|" + "---|" * len(COLUMNS))
    for label, _, f in rows:
        flag = "" if f["complete"] else " (incomplete)"
        print(f"| {label}{flag} | " + " | ".join(cell(f[k], spec) for k, (_, spec) in COLUMNS.items()) + " |")


def print_bands(bands: dict[str, list[tuple[str, str, dict]]], ideal: dict):
    print("\n| A and J | " + " | ".join(COLUMNS[k][0] for k in BANDED) + " |")
    print("|---|" + "---|" * len(BANDED))
    print("| ideal (no clearance; F_n: the joint's reaction) | " + " | ".join(band_cell(ideal, k) for k in BANDED) + " |")
    for clearance_mm, rows in bands.items():
        dry = [f for _, kind, f in rows if kind == "dry"]
        ranges = [value_range(min(f[k] for f in dry), max(f[k] for f in dry), COLUMNS[k][1]) for k in BANDED]
        print(f"| {clearance_mm} mm, dry, every law | " + " | ".join(ranges) + " |")
        for label, kind, f in rows:
            if kind == "lubricated":
                print(f"| {clearance_mm} mm, {label} | " + " | ".join(band_cell(f, k) for k in BANDED) + " |")


def command_line(arguments):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", type=Path, default=Path("/tmp/clearsim-contact-law-bands"))
    parser.add_argument("--lengths", default="50,40", help="pin lengths L in mm (ASSUMED), comma-separated")
    parser.add_argument("--clearances", default="0.01,0.1", help="clearances at A and J in mm, comma-separated")
    parser.add_argument("--config", type=Path, default=CONFIG, help="the model (default the bundled breaker); the "
                        "start delay is measured against its own ideal run")
    options = parser.parse_args(arguments)
    options.out.mkdir(parents=True, exist_ok=True)
    return options


def main():
    options = command_line(sys.argv[1:])
    lengths, clearances = options.lengths.split(","), options.clearances.split(",")
    ideal_file = run_case(options.out, "ideal", IDEAL, options.config)
    ideal = read_result(ideal_file)
    bands = {}
    for clearance_mm in clearances:
        bands[clearance_mm] = [(label, kind, run_figures(run_case(options.out, file_name(clearance_mm, label),
                                                                  overrides, options.config), ideal))
                               for label, kind, overrides in law_cases(clearance_mm, lengths)]
        print_runs(clearance_mm, bands[clearance_mm])
    print_bands(bands, run_figures(ideal_file, ideal))
    print(f"\nlubricated: viscosity {VISCOSITY}, dry_below 1.5 µm (default), {', '.join(LUBRICATED_SOLVER)}")


if __name__ == "__main__":
    main()
