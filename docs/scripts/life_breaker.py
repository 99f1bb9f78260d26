"""The worked life of docs/life.md: the hydraulic UHV breaker, Archard wear at A and J, 10 000 operations.

    python docs/scripts/life_breaker.py [greased|dry] [OUTPUT] [--tolerance T]
                                                    (default: greased → results/life-breaker-greased.h5, T = 0.02)

Runs `clearsim life` and `clearsim plot` on configs/uhv_breaker_hydraulic.yaml with the wear overrides of
docs/life.md "Worked example", then prints the blocks, the clearance growth and worn angle of each joint and the
drift of every recorded figure (first row → last row).
A life stopped with Ctrl-C keeps its rows, and the same command continues it. `… dry --tolerance 0.005` runs the
dry life with a quarter of the blocks' error allowance (about twice the blocks) to OUTPUT or
results/life-breaker-dry-0.005.h5.
"""

import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

CONFIG = Path(__file__).resolve().parents[2] / "configs" / "uhv_breaker_hydraulic.yaml"
OPERATIONS = 10_000
WEAR_COEFFICIENTS = {"greased": 1e-6, "dry": 4.3e-5}  # docs/life.md "Worked example": sources there
HARDNESS, PIN_LENGTH, HARMONICS = "6 GPa", "40 mm", 32


def overrides(lubrication: str) -> list[str]:
    archard = (f"{{archard: {{coefficient: {WEAR_COEFFICIENTS[lubrication]}, hardness: {HARDNESS}, "
               f"length: {PIN_LENGTH}, harmonics: {HARMONICS}}}}}")
    return [argument for joint in ("A", "J") for argument in ("--set", f"joints.{joint}.wear={archard}")]


def half_depth_arc(angles: np.ndarray, depth: np.ndarray) -> tuple[float, float]:
    """(first, last) angle (deg) of the arc round the deepest point where the depth is at least half of it, walking
    round the bore both ways from the deepest point (the arc may cross 0°)."""
    deepest, count = int(np.argmax(depth)), len(depth)
    half = depth[deepest] / 2
    before = next((i for i in range(1, count) if depth[(deepest - i) % count] < half), count)
    after = next((i for i in range(1, count) if depth[(deepest + i) % count] < half), count)
    return angles[(deepest - before + 1) % count], angles[(deepest + after - 1) % count]


def summary(path: Path) -> None:
    with h5py.File(path, "r") as life:
        print(f"blocks: {life['block_size'][1:].tolist()} (refused before each: {life['refused'][1:].tolist()})")
        angles = np.degrees(life["angle"][:])
        for joint, group in life["joints"].items():
            depth = group["depth"][-1]
            first, last = half_depth_arc(angles, depth)
            print(f"joint {joint}: largest clearance {group['clearance'][0] * 1e6:.4g} → {group['clearance'][-1] * 1e6:.4g} µm, "
                  f"deepest {depth.max() * 1e6:.4g} µm at {angles[np.argmax(depth)]:.1f}° "
                  f"(half depth from {first:.1f}° to {last:.1f}°, bearing frame)")
        for name, values in life["figures"].items():
            first, last = float(values[0]), float(values[-1])
            print(f"{name}: {first:.6g} → {last:.6g} ({last - first:+.3g})")


def main(lubrication: str = "greased", *arguments: str) -> None:
    tolerance = arguments[arguments.index("--tolerance") + 1] if "--tolerance" in arguments else None
    output = next((a for a in arguments if a not in ("--tolerance", tolerance)), None)
    path = Path(output or f"results/life-breaker-{lubrication}{'-' + tolerance if tolerance else ''}.h5")
    subprocess.run(["clearsim", "life", str(CONFIG), "-n", str(OPERATIONS), "-o", str(path), *overrides(lubrication),
                    *(["--tolerance", tolerance] if tolerance else [])], check=True)
    subprocess.run(["clearsim", "plot", str(path)], check=True)
    summary(path)


if __name__ == "__main__":
    main(*sys.argv[1:])
