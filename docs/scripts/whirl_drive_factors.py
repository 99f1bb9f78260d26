"""Why J whirls under the prescribed stroke and not under the hydraulic cylinder (docs/validation.md §6,
"Force-driven breaker"): controlled runs that change one factor at a time, A and J at 0.01 mm.

Usage: python docs/scripts/whirl_drive_factors.py [OUT]   (default OUT /tmp/clearsim-whirl-factors; ≈ 2 min)

Factors: the drive (the prescribed stroke law of configs/uhv_breaker.yaml, the travel of the hydraulic file's ideal
run prescribed as a table, or the cylinder itself) and the moving contact's loads of configs/uhv_breaker_hydraulic.yaml
(puffer gas load, contact-finger friction; none, either or both). Every variant is written as a YAML file in OUT and
run with `clearsim run`. Printed per variant: J's orbits over 40-80 ms against rolling without slip (as
paper_studies.py), J's free flights over 20-75 ms (the first one's start), the largest force at A and the smallest at
J over the mid-stroke window (35-50 ms), the whirl warning of the run summary and the run's steps (100 ms each).
"""
import copy
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paper_studies import whirl  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
PRESCRIBED = ROOT / "configs" / "uhv_breaker.yaml"
HYDRAULIC = ROOT / "configs" / "uhv_breaker_hydraulic.yaml"
LOADS = ("puffer_gas", "contact_fingers")
CYLINDER = "operating_cylinder"
STROKE_LAW = {"law": "stroke", "stroke": "-0.23 m", "duration": "85 ms"}
TABLE_LAW = {"law": "table", "file": "cylinder_travel.csv"}
FREE_WINDOW = (0.020, 0.075)  # s
MID_STROKE = (0.035, 0.050)  # s: the load reversal at A
T_END = "100 ms"


def variant(drive, loads):
    """The hydraulic file with `drive` (stroke law, table or cylinder) and the moving contact's `loads` kept."""
    document = yaml.safe_load(HYDRAULIC.read_text())
    document["forces"] = [force for force in document["forces"]
                          if force["name"] in loads or (force["name"] == CYLINDER and drive == "cylinder")]
    if drive != "cylinder":
        law = STROKE_LAW if drive == "stroke law" else TABLE_LAW
        document["drivers"] = [{"name": "hydraulic_drive", "joint": "driving_guide", "motion": copy.deepcopy(law)}]
    document["solver"]["t_end"] = T_END
    if not document["forces"]:
        del document["forces"]
    return document


def run(document, path):
    path.with_suffix(".yaml").write_text(yaml.safe_dump(document, sort_keys=False))
    subprocess.run(["clearsim", "run", str(path.with_suffix(".yaml")), "-o", str(path)], check=True,
                   capture_output=True, text=True)


def whirl_warning_and_steps(path):
    with h5py.File(path, "r") as result:
        warned = any(line.startswith("joint J: the journal whirls") for line in str(result.attrs["warnings"]).split("\n"))
        return warned, int(result.attrs["steps"])


def cylinder_travel(out):
    """The driving link's travel in the hydraulic file's ideal run (A and J ideal), as a table for the drive."""
    ideal = out / "cylinder-ideal.h5"
    if not ideal.exists():
        subprocess.run(["clearsim", "run", str(HYDRAULIC), "-o", str(ideal), "--set", "joints.A.clearance=0",
                        "--set", "joints.J.clearance=0"], check=True, capture_output=True)
    with h5py.File(ideal, "r") as result:
        time = result["time"][:]
        x = result["bodies/driving_link/q"][:, 0]
    np.savetxt(out / TABLE_LAW["file"], np.c_[time, x - x[0]], delimiter=",", header="time,s", comments="")


def figures(path):
    from clearsim.io.hdf5 import read_result
    data = read_result(path)
    time = data["time"]
    turns, rolling, frequency, _, slip = whirl(data, window=(0.040, 0.080))
    free = (data["joints/J/mode"] == 0) & (time > FREE_WINDOW[0]) & (time < FREE_WINDOW[1])
    mid = (time > MID_STROKE[0]) & (time < MID_STROKE[1])
    first_free = f"{time[np.argmax(free)] * 1e3:.1f} ms" if free.any() else "none"
    return (f"orbits {turns:6.1f} (rolling {rolling:6.1f}, slip {slip:5.1f} %), J's first free flight {first_free}, "
            f"max F_n A {data['joints/A/normal_force'][mid].max() / 1e3:5.1f} kN, "
            f"min F_n J {data['joints/J/normal_force'][mid].min():6.0f} N")


def main(out):
    out.mkdir(parents=True, exist_ok=True)
    cylinder_travel(out)
    cases = [(drive, loads) for drive in ("stroke law", "cylinder travel as a table", "cylinder")
             for loads in ((), ("contact_fingers",), ("puffer_gas",), LOADS)]
    for drive, loads in cases:
        path = out / f"{drive.replace(' ', '-')}-{'-'.join(loads) or 'no-loads'}.h5"
        if not path.exists():
            run(variant(drive, loads), path)
        warned, steps = whirl_warning_and_steps(path)
        print(f"{drive:27s} loads {'+'.join(loads) or 'none':27s} whirl warning {str(warned):5s} {figures(path)}, "
              f"steps {steps}")


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/clearsim-whirl-factors"))
