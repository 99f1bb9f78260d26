"""The diagnosis benchmark of docs/diagnose.md: hidden-effect records, diagnosed and scored.

    python3 docs/scripts/diagnose_benchmark.py [--out results/diagnose-benchmark] [--cases NAME,NAME] [--quick]
                                               [--workers 2] [--table]

Each case writes the model with one effect into `truth.yaml` (a candidate of the diagnosis at a value off its scan
points, a worn arc at an angle off the ones it tries, or an effect no candidate describes: a wrong link length or
pivot, a damper engaging later, a mass change when masses are not candidates; or nothing), synthesizes a bench record from it (`clearsim synthesize`), diagnoses the model without
it (`clearsim diagnose`, the CLI's code path) and scores the report:

- right effect: the first effect named is the hidden one (kind, target, parameter);
- covered: the hidden value lies inside the reported interval (stated level: search.INTERVAL_LEVEL);
- null (nothing hidden): no effect named; outside the candidate set: the record is called `unexplained`;
- identifiable: the model as given misses the record by a gap of 3 or more.

One JSON line per case is appended to `<out>/cases.jsonl`; a case already there is not run again (delete its line or
the folder to rerun it), so the benchmark can be run in parts and resumed. `--table` prints the summary table of the
cases done, in the form of docs/diagnose.md.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from diagnose_studies import CLEARSIM, CONFIGS, CRANK_BENCH, FRICTION_CRANK, FRICTIONLESS_UHV, SLIDER_CRANK, UHV, sets

from clearsim.diagnose.candidates import worn_arcs, candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.diagnose.search import SCAN_POINTS, SCREEN_POINTS
from clearsim.model.loader import load_mechanism

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
from tests.diagnose.drive_mechanisms import SPRING_DRIVE  # noqa: E402  (the spring-driven block: preload, dashpot)

HYDRAULIC, FLEXIBLE = CONFIGS / "uhv_breaker_hydraulic.yaml", CONFIGS / "uhv_breaker_flexible.yaml"
NOISE = ("0.1%", "0.5%", "2%")  # the three noise levels, of each signal's range
UHV_BENCH = ["--sensors", "sealing_rod_displacement,turn_arm_angular_velocity", "--rate", "15kHz", "--lowpass", "2kHz",
             "--trigger-offset", "0.7ms"]
UHV_CONTACT = ["--sensors", "contact_displacement,contact_velocity", *UHV_BENCH[2:]]
DRIVE_BENCH = ["--sensors", "contact_displacement,contact_velocity", "--rate", "10kHz"]
BLOCK_BENCH = ["--sensors", "travel,speed", "--rate", "10kHz"]
CRANK_RIGID = ["joints.slider_pin.clearance=0"]
CRANK_CYLINDRICAL_PIN = ["joints.slider_pin.contact={elastic: liu, length: 20 mm}"]
IDENTIFIABLE_GAP = 3.0


@dataclass
class Case:
    name: str
    config: Path | str  # a mechanism file, or its text (written into the case's folder as model.yaml)
    model: list[str]  # --set of the model as given to diagnose (and of the record's model)
    bench: list[str]
    noise: str
    candidates: str
    hidden: tuple[str, str, str, float] | None = None  # (kind, target, parameter, value): a candidate's effect
    outside: list[str] = field(default_factory=list)  # --set of an effect no candidate describes
    seed: int = 3
    angle: float | None = None  # deg: where a hidden worn arc lies in its bearing body's frame (a wear case)

    @property
    def kind(self) -> str:
        return "effect" if self.hidden else "outside" if self.outside else "null"

    @property
    def truth(self) -> str:
        if self.hidden:
            kind, target, parameter, value = self.hidden
            around = f" around {self.angle:g}°" if self.angle is not None else ""
            return f"{kind} {target} {parameter} {value:.4g}{around}"
        return f"outside: {' '.join(self.outside)}" if self.outside else "none"


UHV_KINDS = "clearance,drive,compliance,mass"
CRANK_KINDS = "clearance,drive,mass,compliance"
CYLINDER_KINDS = "port_area,precharge,bulk_modulus,gas_load,guide_friction"
BLOCK_KINDS = "preload,dashpot,gas_load,guide_friction"
low, mid, high = NOISE

CASES = [
    # slider-crank (Flores): every joint and body kind it has
    Case("crank-clearance-low", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, low, "clearance,drive,mass",
         ("clearance", "slider_pin", "clearance", 0.17e-3)),
    Case("crank-clearance-mid", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, mid, "clearance,drive,mass",
         ("clearance", "slider_pin", "clearance", 0.19e-3), seed=4),
    Case("crank-clearance-high", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, high, "clearance,drive,mass",
         ("clearance", "slider_pin", "clearance", 0.31e-3), seed=5),
    Case("crank-lag-mid", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, mid, CRANK_KINDS,
         ("drive", "crank_drive", "lag", 0.7e-3)),
    Case("crank-mass-low", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, low, CRANK_KINDS, ("mass", "slider", "mass factor", 1.3)),
    Case("crank-compliance-mid", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, mid, "compliance,clearance,mass",
         ("compliance", "rod", "stiffness", 9.5e6)),
    Case("crank-damping-low", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, low, "damping,drive,mass",
         ("damping", "slider", "damping", 3.3)),
    Case("crank-restitution-low", SLIDER_CRANK, [], CRANK_BENCH, low, "restitution,stiffness,friction",
         ("restitution", "slider_pin", "restitution", 0.55)),
    # the stiffness shows in these sensors only as which realisation of the slider pin's rattle a run replays: the model's
    # own 1 µm twins differ by more than its gap before (docs/diagnose.md, Benchmark), so one record does not identify it
    Case("crank-stiffness-low", SLIDER_CRANK, [], CRANK_BENCH, low, "stiffness,restitution",
         ("stiffness", "slider_pin", "stiffness", 2.0e10)),
    Case("crank-friction-low", FRICTION_CRANK, [], CRANK_BENCH, low, "friction,restitution,clearance",
         ("friction", "slider_pin", "mu_d", 0.11)),
    # a worn arc at the slider pin, where the rod pulls the slider back at outer dead centre (the bore's most loaded
    # side, 165–180°), 0.15 mm deep: 30 % of its 0.5 mm clearance
    Case("crank-wear-mid", SLIDER_CRANK, [], CRANK_BENCH, mid, "wear,clearance,restitution",
         ("wear", "slider_pin", "depth", 0.15e-3), seed=11, angle=170.0),
    # the slider pin as a 20 mm pin in a conformal (Liu) contact; the record's pin bears on 13 mm of it (misalignment)
    Case("crank-contact-length-low", SLIDER_CRANK, CRANK_CYLINDRICAL_PIN, CRANK_BENCH, low,
         "contact_length,restitution,clearance", ("contact_length", "slider_pin", "length", 13e-3), seed=12),
    Case("crank-null-low", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, low, "clearance,drive,mass", seed=6),
    Case("crank-null-high", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, high, CRANK_KINDS, seed=7),
    Case("crank-load-mid", SLIDER_CRANK, [], CRANK_BENCH, mid, "clearance,drive,mass,load", ("load", "slider", "force", 30.0)),
    Case("crank-rod-length-low", SLIDER_CRANK, CRANK_RIGID, CRANK_BENCH, low, "clearance,drive,mass",
         outside=["points.B=[0.173 m, 0 m]"]),
    # UHV breaker (prescribed drive), frictionless ideal joints: the cheap variant of the studies
    Case("uhv-clearance-low", UHV, FRICTIONLESS_UHV, UHV_BENCH, low, "clearance,drive",
         ("clearance", "B", "clearance", 0.071e-3)),
    Case("uhv-clearance-mid", UHV, FRICTIONLESS_UHV, UHV_BENCH, mid, "clearance,drive",
         ("clearance", "B", "clearance", 0.06e-3), seed=4),
    Case("uhv-lag-low", UHV, FRICTIONLESS_UHV, UHV_BENCH, low, "clearance,drive",
         ("drive", "hydraulic_drive", "lag", 1.7e-3)),
    Case("uhv-lag-high", UHV, FRICTIONLESS_UHV, UHV_BENCH, high, "clearance,drive",
         ("drive", "hydraulic_drive", "lag", 1.2e-3), seed=5),
    Case("uhv-stroke-mid", UHV, FRICTIONLESS_UHV, UHV_BENCH, mid, "clearance,drive",
         ("drive", "hydraulic_drive", "stroke factor", 0.973)),
    Case("uhv-pole-compliance-low", UHV, FRICTIONLESS_UHV, UHV_CONTACT, low, "compliance,clearance,drive",
         ("compliance", "insulating_pole", "stiffness", 27e6), seed=7),
    Case("uhv-null-low", UHV, FRICTIONLESS_UHV, UHV_BENCH, low, "clearance,drive", seed=6),
    Case("uhv-null-mid", UHV, FRICTIONLESS_UHV, UHV_CONTACT, mid, UHV_KINDS, seed=8),
    Case("uhv-pivot-outside-low", UHV, FRICTIONLESS_UHV, UHV_CONTACT, low, "clearance,drive,compliance",
         outside=["points.H=[0.359 m, 2.463 m]"]),
    # UHV breaker driven by its hydraulic cylinder: the drive's parameters
    Case("hydraulic-port-mid", HYDRAULIC, [], DRIVE_BENCH, mid, CYLINDER_KINDS,
         ("port_area", "operating_cylinder", "piston port area", 58e-6)),
    Case("hydraulic-precharge-mid", HYDRAULIC, [], DRIVE_BENCH, mid, CYLINDER_KINDS,
         ("precharge", "operating_cylinder", "accumulator precharge", 289e5), seed=4),
    Case("hydraulic-bulk-low", HYDRAULIC, [], DRIVE_BENCH, low, CYLINDER_KINDS,
         ("bulk_modulus", "operating_cylinder", "bulk modulus", 0.88e9)),
    Case("hydraulic-gas-high", HYDRAULIC, [], DRIVE_BENCH, high, CYLINDER_KINDS,
         ("gas_load", "puffer_gas", "puffer area", 63e-4), seed=5),
    Case("hydraulic-fingers-mid", HYDRAULIC, [], DRIVE_BENCH, mid, CYLINDER_KINDS,
         ("guide_friction", "contact_fingers", "normal force", 3300.0)),
    Case("hydraulic-mass-mid", HYDRAULIC, [], DRIVE_BENCH, mid, "port_area,precharge,mass,damping",
         ("mass", "insulating_pole", "mass factor", 1.23)),
    Case("hydraulic-damping-low", HYDRAULIC, [], DRIVE_BENCH, low, "port_area,precharge,mass,damping",
         ("damping", "moving_contact", "damping", 500.0)),
    Case("hydraulic-load-low", HYDRAULIC, [], DRIVE_BENCH, low, CYLINDER_KINDS + ",load",
         ("load", "moving_contact", "force", 1700.0)),
    Case("hydraulic-null-mid", HYDRAULIC, [], DRIVE_BENCH, mid, CYLINDER_KINDS, seed=9),
    Case("hydraulic-mass-outside-low", HYDRAULIC, [], DRIVE_BENCH, low, CYLINDER_KINDS,
         outside=["bodies.moving_contact.mass=13 kg"]),
    # the spring-driven block (tests/diagnose/drive_mechanisms.py): the spring drive's and the dashpot's parameters
    Case("block-preload-low", SPRING_DRIVE, [], BLOCK_BENCH, low, BLOCK_KINDS, ("preload", "opening_spring", "preload", 2630.0)),
    Case("block-dashpot-mid", SPRING_DRIVE, [], BLOCK_BENCH, mid, BLOCK_KINDS, ("dashpot", "end_damper", "damping", 1300.0)),
    Case("block-null-high", SPRING_DRIVE, [], BLOCK_BENCH, high, BLOCK_KINDS, seed=10),
    Case("block-damper-outside-low", SPRING_DRIVE, [], BLOCK_BENCH, low, BLOCK_KINDS + ",load",
         outside=["forces.end_damper.engaged=[70 mm, 200 mm]"]),
    # the flexible UHV breaker: a beam's bending stiffness
    Case("flexible-beam-low", FLEXIBLE, FRICTIONLESS_UHV, UHV_CONTACT, low, "beam_stiffness,drive",
         ("beam_stiffness", "lower_turn_arm", "E·I factor", 0.62)),
    # the slider-crank with its slider pin in an oil film (20 mPa·s, 9 mm short bearing): a thinner oil
    Case("crank-viscosity-mid", SLIDER_CRANK, ["joints.slider_pin.lubrication={viscosity: 20 mPa*s, length: 9 mm}",
                                               "solver.method=rosenbrock"], CRANK_BENCH, mid, "viscosity,clearance,mass",
         ("viscosity", "slider_pin", "viscosity", 0.012)),
]
QUICK = ["crank-clearance-low", "crank-null-low", "crank-load-mid", "block-preload-low"]


def model_file(case: Case, folder: Path) -> Path:
    """The mechanism file diagnosed: the case's config, or its text written as model.yaml."""
    if isinstance(case.config, Path):
        return case.config
    path = folder / "model.yaml"
    path.write_text(case.config, encoding="utf-8")
    return path


def truth_document(case: Case, config: Path) -> tuple[dict, dict]:
    """The record's model (the case's model with its hidden effect) and where the hidden value lies in the candidate's
    unit range (its distance to the nearest screening or scan value: it is off them)."""
    loaded = load_mechanism(config, case.model + case.outside)
    document = yaml.safe_load(loaded.resolved_yaml)
    placement = {}
    if case.hidden:
        value = case.hidden[3]
        candidate = hidden_candidate(case, loaded.mechanism, document, config.parent)
        document = candidate.applied(document, value)
        unit = float(candidate.to_unit(value))
        grid = np.concatenate([SCREEN_POINTS, candidate.to_unit(candidate.grid(SCAN_POINTS))])
        placement = {"unit": unit, "off_grid": float(np.min(np.abs(grid - unit)))}
    return document, placement


def hidden_candidate(case: Case, mechanism, document: dict, base_dir: Path):
    """The candidate whose effect the case hides: a worn arc at the case's angle (off the 30° positions the diagnosis
    screens), or the candidate of the hidden kind, target and parameter."""
    kind, target, parameter, _ = case.hidden
    if case.angle is not None:
        joint = next(j for j in mechanism.joints if j.name == target)
        return worn_arcs(mechanism, joint, [math.radians(case.angle)])[0]
    return next(c for c in candidates_for(mechanism, document, [kind], base_dir) if (c.target, c.parameter) == (target, parameter))


def run_case(case: Case, root: Path, workers: int) -> dict:
    folder = root / case.name
    folder.mkdir(parents=True, exist_ok=True)
    config = model_file(case, folder)
    document, placement = truth_document(case, config)
    truth = folder / "truth.yaml"
    truth.write_text(document_text(document), encoding="utf-8")
    record = folder / "bench.csv"
    subprocess.run([*CLEARSIM, "synthesize", str(truth), *case.bench, "--noise", case.noise, "--seed", str(case.seed),
                    "-o", str(record), "--force"], check=True, capture_output=True, cwd=config.parent)
    report = folder / "report"
    started = time.perf_counter()
    done = subprocess.run([*CLEARSIM, "diagnose", str(config), *sets(case.model), "--measured", str(record),
                           "-o", str(report), "--candidates", case.candidates, "--workers", str(workers)],
                          capture_output=True, text=True)
    wall = time.perf_counter() - started
    if done.returncode != 0:
        return {"case": case.name, "error": (done.stderr or done.stdout)[-2000:], "wall_s": wall}
    found = json.loads((report / "diagnosis.json").read_text())
    return score(case, found, wall) | placement


def score(case: Case, found: dict, wall: float) -> dict:
    effects = found["effects"]
    first = effects[0] if effects else None
    row = {"case": case.name, "kind": case.kind, "truth": case.truth, "noise": case.noise,
           "named": [f"{e['kind']} {e['target']} {next(iter(e['parameters']))}" for e in effects],
           "gap_before": found["gap_before"], "gap_after": found["gap_after"], "unexplained": found["unexplained"],
           "simulations": found["simulations"], "wall_s": wall}
    if case.hidden:
        kind, target, parameter, value = case.hidden
        right = first is not None and (first["kind"], first["target"]) == (kind, target) and parameter in first["parameters"]
        row.update(identifiable=found["gap_before"] >= IDENTIFIABLE_GAP, right=right, truth_value=value,
                   tied=bool(first) and not right and any(target in label for label in first["ambiguous_with"]))
        if right:
            low, high = first["interval"][parameter]
            row.update(value=first["parameters"][parameter], interval=[low, high], covered=bool(low <= value <= high))
    return row


def rescored(case: Case, root: Path, row: dict) -> dict:
    """The case scored again from its report (after a change of the scoring, or diagnosed again on its kept runs), with
    the wall time and simulations of its first diagnosis."""
    if "error" in row:
        return row
    found = json.loads((root / case.name / "report" / "diagnosis.json").read_text())
    _, placement = truth_document(case, model_file(case, root / case.name))
    return score(case, found, row["wall_s"]) | placement | {"simulations": row["simulations"]}


def done_cases(path: Path) -> dict[str, dict]:
    if not path.exists():
        return {}
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return {row["case"]: row for row in rows}


def share(hits: list[bool]) -> str:
    return f"{sum(hits)}/{len(hits)}" + (f" ({sum(hits) / len(hits):.0%})" if hits else "")


def summary(rows: list[dict]) -> list[str]:
    """The benchmark's scores: right effect on identifiable cases, coverage, nulls, outside-the-set cases, wall."""
    effects = [r for r in rows if r.get("kind") == "effect"]
    identifiable = [r for r in effects if r["identifiable"]]
    covered = [r["covered"] for r in effects if "covered" in r]
    nulls = [r for r in rows if r.get("kind") == "null"]
    outside = [r for r in rows if r.get("kind") == "outside"]
    walls = [r["wall_s"] for r in rows if "error" not in r]
    return [f"right effect named, identifiable cases (gap before ≥ {IDENTIFIABLE_GAP:g}): "
            f"{share([r['right'] for r in identifiable])}; all hidden-effect cases: {share([r['right'] for r in effects])}; "
            f"named a candidate tied with the truth: {sum(bool(r.get('tied')) for r in effects)}",
            f"true value inside the interval (right effect named): {share(covered)}",
            f"nulls with no effect named: {share([not r['named'] for r in nulls])}",
            f"outside the candidate set called unexplained: {share([r['unexplained'] for r in outside])}",
            f"failed: {sum('error' in r for r in rows)}; wall per case: median {np.median(walls):.0f} s, "
            f"max {max(walls):.0f} s" if walls else "no case done"]


def table(rows: list[dict]) -> list[str]:
    lines = ["| case | hidden | noise | named | value (interval) | gap before → after | unexplained | runs | wall |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['case']} | failed: {r['error'].strip().splitlines()[-1][:80]} | | | | | | | |")
            continue
        value = (f"{r['value']:.4g} ({r['interval'][0]:.4g}–{r['interval'][1]:.4g}) "
                 f"{'✓' if r['covered'] else '✗'}" if "value" in r else "")
        named = "; ".join(r["named"]) or "none"
        named += " (tie with the truth)" if r.get("tied") else ""
        lines.append(f"| {r['case']} | {r['truth']} | {r['noise']} | {named} | {value} | "
                     f"{r['gap_before']:.3g} → {r['gap_after']:.3g} | {'yes' if r['unexplained'] else 'no'} | "
                     f"{r['simulations']} | {r['wall_s']:.0f} s |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/diagnose-benchmark"))
    parser.add_argument("--cases", help="comma-separated case names (default: all)")
    parser.add_argument("--quick", action="store_true", help=f"the CI-sized subset: {', '.join(QUICK)}")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--table", action="store_true", help="print the table of the cases done, run nothing")
    parser.add_argument("--rescore", action="store_true", help="score the cases done again from their reports")
    args = parser.parse_args()
    names = QUICK if args.quick else args.cases.split(",") if args.cases else [c.name for c in CASES]
    unknown = sorted(set(names) - {c.name for c in CASES})
    if unknown:
        parser.error(f"unknown case(s) {', '.join(unknown)}; cases: {', '.join(c.name for c in CASES)}")
    args.out.mkdir(parents=True, exist_ok=True)
    results = args.out / "cases.jsonl"
    if not args.table:
        for case in (c for c in CASES if c.name in names):
            if case.name in done_cases(results):
                continue
            row = run_case(case, args.out, args.workers)
            with results.open("a", encoding="utf-8") as out:
                out.write(json.dumps(row) + "\n")
            print(json.dumps(row), flush=True)
    done = done_cases(results)
    rows = [done[c.name] for c in CASES if c.name in done and c.name in names]
    if args.rescore:
        rows = [rescored(c, args.out, done[c.name]) for c in CASES if c.name in done and c.name in names]
        results.write_text("".join(json.dumps(row) + "\n" for row in rows), encoding="utf-8")
    print("\n".join(table(rows) + [""] + summary(rows)))


if __name__ == "__main__":
    main()
