"""The diagnosis studies of docs/diagnose.md: an effect hidden in synthetic bench data, found again.

    python3 docs/scripts/diagnose_studies.py [--out results/diagnose-studies] [--only NAME] [--all] [--fresh]

Each study synthesizes a record (`clearsim synthesize`) from a model with the effect set by --set,
runs `clearsim diagnose` on the model without it, and prints the verdict, the fitted value beside
the truth, the gap before/after, the number of simulations and the wall time. Run files are kept
(a second call costs no simulation); delete the folder to time a study again.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import yaml

from clearsim.diagnose.candidates import candidates_for
from clearsim.diagnose.evaluate import document_text
from clearsim.model.loader import load_mechanism

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
CLEARSIM = [sys.executable, "-m", "clearsim.cli"]  # the clearsim this interpreter imports, on PATH or not
UHV, SLIDER_CRANK = CONFIGS / "uhv_breaker.yaml", CONFIGS / "slider_crank_flores.yaml"
FRICTION_CRANK = CONFIGS / "slider_crank_flores_friction.yaml"
UHV_BENCH = ["--sensors", "sealing_rod_displacement,turn_arm_angular_velocity", "--rate", "15kHz",
             "--lowpass", "2kHz", "--trigger-offset", "0.7ms"]
CRANK_BENCH = ["--sensors", "slider_displacement,slider_velocity", "--rate", "50kHz", "--lowpass", "10kHz",
               "--trigger-offset", "0.1ms"]
UHV_CONTACT = ["--sensors", "contact_displacement,contact_velocity", *UHV_BENCH[2:]]  # the moving contact's sensors
FRICTION_J = ["--candidates", "friction,clearance,restitution"]
FRICTIONLESS_UHV = ["defaults.friction={law: none}", "joints.A.clearance=0", "joints.J.clearance=0"]
AMBROSIO_UHV = ["defaults.friction={law: ambrosio, mu_d: 0.16, v_0: 1e-3 m/s, v_1: 1e-2 m/s}", "joints.A.clearance=0.1mm",
                "joints.J.clearance=0.1mm", "solver.rtol=1e-6", "solver.output_rate=30kHz"]


@dataclass
class Study:
    name: str
    config: Path
    model: list[str]  # --set of the model given to diagnose
    hidden: list[str]  # --set of the effect, added for the record only
    truth: str
    bench: list[str]
    noise: str
    options: list[str]
    seed: int = 3
    hidden_candidate: tuple[str, str, float] | None = None  # (kind, target, value): an effect --set cannot write


STUDIES = [
    Study("uhv-bundled-clearance-B", UHV, [], ["joints.B.clearance=0.08mm"], "clearance B 0.08 mm", UHV_BENCH, "1%", []),
    Study("uhv-bundled-no-effect", UHV, [], [], "none", UHV_BENCH, "1%", [], seed=11),
    Study("uhv-clearance-B", UHV, FRICTIONLESS_UHV, ["joints.B.clearance=0.08mm"], "clearance B 0.08 mm", UHV_BENCH,
          "0.05%", ["--candidates", "clearance,drive"]),
    Study("uhv-drive-lag", UHV, FRICTIONLESS_UHV, ["drivers.hydraulic_drive.lag=2ms"], "drive lag 2 ms", UHV_BENCH,
          "0.05%", ["--candidates", "clearance,drive"], seed=4),
    Study("uhv-two-effects", UHV, FRICTIONLESS_UHV, ["joints.B.clearance=0.08mm", "drivers.hydraulic_drive.lag=2ms"],
          "clearance B 0.08 mm + drive lag 2 ms", UHV_BENCH, "0.05%", ["--candidates", "clearance,drive", "--max-effects", "2"],
          seed=5),
    Study("uhv-no-effect", UHV, FRICTIONLESS_UHV, [], "none", UHV_BENCH, "0.05%", ["--candidates", "clearance,drive"], seed=6),
    Study("uhv-friction-J", UHV, AMBROSIO_UHV, ["joints.J.friction.mu_d=0.3"], "friction J μ_d 0.3",
          UHV_CONTACT, "0.05%", FRICTION_J, seed=5),
    Study("uhv-friction-J-200Hz", UHV, AMBROSIO_UHV, ["joints.J.friction.mu_d=0.3"], "friction J μ_d 0.3, `--lowpass 200Hz`",
          UHV_CONTACT, "0.05%", [*FRICTION_J, "--lowpass", "200Hz"], seed=5),
    Study("crank-clearance", SLIDER_CRANK, ["joints.slider_pin.clearance=0"], ["joints.slider_pin.clearance=0.2mm"],
          "clearance slider_pin 0.2 mm", CRANK_BENCH, "0.5%", ["--candidates", "clearance,drive,mass"]),
    Study("crank-friction", FRICTION_CRANK, [], ["joints.slider_pin.friction.mu_d=0.1"], "friction slider_pin μ_d 0.1",
          CRANK_BENCH, "0.1%", ["--candidates", "friction,restitution,clearance"], seed=5),
    Study("crank-compliance", SLIDER_CRANK, ["joints.slider_pin.clearance=0"], [], "rod axial stiffness 15 MN/m",
          CRANK_BENCH, "0.5%", ["--candidates", "compliance,clearance"], hidden_candidate=("compliance", "rod", 15e6)),
    Study("uhv-pole-compliance", UHV, FRICTIONLESS_UHV, [], "insulating pole axial stiffness 30 MN/m (contact sensors)",
          ["--sensors", "contact_displacement,contact_velocity", *UHV_BENCH[2:]], "0.05%", ["--candidates", "compliance,clearance,drive"], seed=7,
          hidden_candidate=("compliance", "insulating_pole", 30e6)),
]


SLOW = {"uhv-bundled-clearance-B", "uhv-bundled-no-effect"}


def sets(values: list[str]) -> list[str]:
    return [part for value in values for part in ("--set", value)]


def run_study(study: Study, root: Path) -> dict:
    folder = root / study.name
    folder.mkdir(parents=True, exist_ok=True)
    record = folder / "bench.csv"
    if not record.exists():
        source = truth_model(study, folder)
        hidden = sets(study.model + study.hidden) if source == study.config else []
        subprocess.run([*CLEARSIM, "synthesize", str(source), *hidden, *study.bench,
                        "--noise", study.noise, "--seed", str(study.seed), "-o", str(record)], check=True,
                       capture_output=True)
    report = folder / "report"
    for old in report.glob("diagnosis*.json"):
        old.unlink()
    started = time.perf_counter()
    subprocess.run([*CLEARSIM, "diagnose", str(study.config), *sets(study.model), "--measured", str(record),
                    "-o", str(report), *study.options], check=True, capture_output=True)
    found = json.loads((report / "diagnosis.json").read_text())
    found["wall_s"] = time.perf_counter() - started
    return found


def truth_model(study: Study, folder: Path) -> Path:
    """The file the record is synthesized from: the study's config, or for a hidden candidate (an effect that
    --set cannot write, e.g. a compliance) that candidate written into the model, as `truth.yaml`."""
    if study.hidden_candidate is None:
        return study.config
    kind, target, value = study.hidden_candidate
    loaded = load_mechanism(study.config, study.model + study.hidden)
    document = yaml.safe_load(loaded.resolved_yaml)
    candidate = next(c for c in candidates_for(loaded.mechanism, document, [kind]) if c.target == target)
    path = folder / "truth.yaml"
    path.write_text(document_text(candidate.applied(document, value)), encoding="utf-8")
    return path


def describe(found: dict) -> str:
    if not found["effects"]:
        return "no missing effect found"
    parts = []
    for effect in found["effects"]:
        (name, value), = effect["parameters"].items()
        shown = (f"{value * 1e3:.4g} mm" if name == "clearance" else f"{value * 1e3:.3g} ms" if name == "lag"
                 else f"{value / 1e6:.3g} MN/m" if effect["kind"] == "compliance" else f"{value:.3g}")
        tie = f" (tie: {', '.join(effect['ambiguous_with'])})" if effect["ambiguous_with"] else ""
        parts.append(f"{effect['kind']} {effect['target']} {name} = {shown}{tie}")
    return "; ".join(parts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/diagnose-studies"))
    parser.add_argument("--only", help="run one study by name")
    parser.add_argument("--fresh", action="store_true", help="delete earlier run files first (to time the studies)")
    parser.add_argument("--all", action="store_true", help="also the bundled UHV model studies (~7 min)")
    args = parser.parse_args()
    if args.fresh and args.out.exists():
        shutil.rmtree(args.out)
    print("| study | hidden | found | gap before → after | simulations | wall |")
    print("|---|---|---|---|---|---|")
    for study in STUDIES:
        if (args.only and study.name != args.only) or (not args.all and not args.only and study.name in SLOW):
            continue
        found = run_study(study, args.out)
        change = found["gap_after"] / found["gap_before"] - 1.0
        print(f"| {study.name} | {study.truth} (noise {study.noise}) | {describe(found)} | "
              f"{found['gap_before']:.3g} → {found['gap_after']:.3g} ({change:+.0%}) | {found['simulations']} | "
              f"{found['wall_s']:.0f} s |", flush=True)


if __name__ == "__main__":
    main()
