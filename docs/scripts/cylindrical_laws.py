"""Draw docs/figures/contact-cylindrical-laws.png and print the table of docs/model-contact.md ("Elastic laws").

Run from the repository root: python3 docs/scripts/cylindrical_laws.py
The breaker's pins (clearsim/configs/uhv_breaker.yaml): R_B = 50 mm, c = 0.01 mm, steel E = 207 GPa, ν = 0.3;
the pin length L = 50 mm is an assumption (the model and the paper give none). Every law's F(δ) from
clearsim.physics.cylindrical, up to the breaker's load range of 100 kN.
"""

import math
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the script lives outside the package

from clearsim.physics.contact import internal_contact_stiffness  # noqa: E402
from clearsim.physics.cylindrical import (  # noqa: E402
    ELASTIC_LAWS, ESDU_78035, JOHNSON, effective_modulus, law_state, line_contact_constant,
    line_contact_edge, pereira_coefficients,
)

BEARING, CLEARANCE, LENGTH = 0.05, 1e-5, 0.05  # m
YOUNGS, POISSON = 207e9, 0.3
PAPER_STIFFNESS = 1.205e12  # N/m^1.5: the bundled model's `stiffness` (Meng 2015 Table 2, 3.81e7 N/mm^1.5)
LOADS = (1e3, 18e3, 50e3, 100e3)  # N: 18 kN is J's mean load in the bundled run
FIGURE = Path(__file__).resolve().parents[1] / "figures" / "contact-cylindrical-laws.png"


def coefficients():
    """name → (elastic law code, K, n) at the breaker's pin."""
    modulus = effective_modulus(YOUNGS, POISSON, YOUNGS, POISSON)
    line = math.pi * LENGTH * modulus
    auto = internal_contact_stiffness(BEARING, BEARING - CLEARANCE, YOUNGS, POISSON, YOUNGS, POISSON)
    return {
        "point_hertz (paper K)": (ELASTIC_LAWS["point_hertz"], PAPER_STIFFNESS, 1.5),
        "point_hertz (auto K)": (ELASTIC_LAWS["point_hertz"], auto, 1.5),
        "pereira": (ELASTIC_LAWS["pereira"], *pereira_coefficients(CLEARANCE, LENGTH, modulus)),
        "johnson": (ELASTIC_LAWS["johnson"], line, 1.0),
        "esdu_78035": (ELASTIC_LAWS["esdu_78035"], line, 1.0),
        "liu": (ELASTIC_LAWS["liu"], line, 1.0),
    }


def penetration_at(law, stiffness, exponent, load):
    """δ where F_el(δ) = load (the laws rise monotonically)."""
    upper = CLEARANCE
    while law_state(law, upper, stiffness, exponent, CLEARANCE)[0] < load:
        upper *= 2.0
    return brentq(lambda d: law_state(law, d, stiffness, exponent, CLEARANCE)[0] - load, 0.0, upper, xtol=1e-18,
                  rtol=1e-14)


def edge_penetration(law):
    return 8.0 * CLEARANCE * line_contact_edge(line_contact_constant(law))


def table():
    lines = ["| law | " + " | ".join(f"δ at {load / 1e3:g} kN (µm)" for load in LOADS)
             + " | dF/dδ at 18 kN (N/m) |", "|---" * (len(LOADS) + 2) + "|"]
    for name, (law, stiffness, exponent) in coefficients().items():
        depths = [penetration_at(law, stiffness, exponent, load) for load in LOADS]
        cells = [f"{d * 1e6:.3f}" + ("*" if law in (JOHNSON, ESDU_78035) and d > edge_penetration(law) else "")
                 for d in depths]
        tangent = law_state(law, depths[1], stiffness, exponent, CLEARANCE)[1]
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {tangent:.3g} |")
    return "\n".join(lines)


def draw():
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    figure, axes = pyplot.subplots(figsize=(8, 5))
    for name, (law, stiffness, exponent) in coefficients().items():
        deepest = penetration_at(law, stiffness, exponent, LOADS[-1])
        depths = np.linspace(0.0, deepest, 400)
        forces = np.array([law_state(law, d, stiffness, exponent, CLEARANCE)[0] for d in depths])
        if law in (JOHNSON, ESDU_78035):
            inside = depths <= edge_penetration(law)
            line, = axes.plot(depths[inside] * 1e6, forces[inside] / 1e3, label=name)
            if not inside.all():
                axes.plot(depths[~inside] * 1e6, forces[~inside] / 1e3, "--", color=line.get_color(),
                          label=f"{name}, straight past its edge")
        else:
            axes.plot(depths * 1e6, forces / 1e3, label=name)
    axes.set_xlabel("penetration δ (µm)")
    axes.set_ylabel("elastic force F_el (kN)")
    axes.set_ylim(0.0, LOADS[-1] / 1e3)
    axes.set_title("Pin in its bore: R = 50 mm, c = 0.01 mm, L = 50 mm (assumed), steel")
    axes.grid(alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(FIGURE, dpi=100)


if __name__ == "__main__":
    print(table())
    draw()
    print(f"figure: {FIGURE}")
