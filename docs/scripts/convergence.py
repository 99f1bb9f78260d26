"""Tolerance study of a clearance model: peak contact force, output-acceleration RMS, first impact.

    python docs/scripts/convergence.py [CONFIG]      (default: the Flores slider-crank)

Prints the Markdown table of docs/model.md §7.
"""

import sys
import tempfile
from pathlib import Path

import numpy as np

from clearsim.io.hdf5 import read_result
from clearsim.model.loader import load_mechanism
from clearsim.runner import prepare, run_to_file

CONFIG = Path(__file__).resolve().parents[2] / "clearsim" / "configs" / "slider_crank_flores.yaml"


def study(config: Path, tolerances=(1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)) -> None:
    print("| rtol | steps | peak F_n (N, samples) | peak F_n (N, located) | output-acceleration RMS (m/s²) "
          "| contact episodes | first onset (ms) |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for rtol in tolerances:
            loaded = load_mechanism(config, [f"solver.rtol={rtol}"])
            system = prepare(loaded)
            report = run_to_file(system, loaded, Path(folder) / f"{rtol}.h5")
            result = read_result(report.output)
            joint = system.clearance_joints[0]
            acceleration = result[f"sensors/{system.mechanism.output.acceleration}"]
            onsets = result[f"joints/{joint}/episodes/onset"]
            print(f"| {rtol:.0e} | {report.statistics.steps} | {np.max(result[f'joints/{joint}/normal_force']):.1f} "
                  f"| {report.statistics.peak_normal_force[0]:.1f} | {np.sqrt(np.mean(acceleration**2)):.1f} "
                  f"| {len(onsets)} | {onsets[0] * 1e3:.6f} |")


if __name__ == "__main__":
    study(Path(sys.argv[1]) if len(sys.argv) > 1 else CONFIG)
