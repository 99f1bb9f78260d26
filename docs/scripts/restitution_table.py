"""Print the numbers quoted in docs/model-contact.md.

Run from the repository root: python3 docs/scripts/restitution_table.py
Effective restitution comes from the 1-DOF reference impact in
tests/support/impact_reference.py (DOP853, rtol 1e-12, events at δ = 0); it is
independent of stiffness, mass and impact speed, so one case per c_e suffices.
"""

import sys
from pathlib import Path

from scipy.optimize import brentq

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the script lives outside the package

from clearsim.physics.contact import (  # noqa: E402
    CONTACT_LAWS,
    hertz_contact_time,
    hertz_max_penetration,
    hysteresis_factor,
    internal_contact_stiffness,
)
from tests.support.impact_reference import law_impact  # noqa: E402

NOMINAL = (0.1, 0.3, 0.5, 0.7, 0.9, 0.99)
STEEL_E, STEEL_NU = 207e9, 0.3


def restitution_table():
    names = list(CONTACT_LAWS)
    lines = ["| c_e (nominal) | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    for restitution in NOMINAL:
        cells = [f"{law_impact(CONTACT_LAWS[name], restitution).restitution:.4f}" for name in names]
        lines.append(f"| {restitution} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def hysteresis_table():
    names = list(CONTACT_LAWS)
    lines = ["| c_e | " + " | ".join(f"D {name}" for name in names) + " |", "|---" * (len(names) + 1) + "|"]
    for restitution in NOMINAL:
        cells = [f"{hysteresis_factor(CONTACT_LAWS[name], restitution):.4f}" for name in names]
        lines.append(f"| {restitution} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def paper_stiffness_clearance():
    paper_stiffness = 3.81e7 * 1000.0**1.5  # N/mm^1.5 → N/m^1.5

    def mismatch(clearance):
        journal_radius = 0.05 - clearance
        stiffness = internal_contact_stiffness(0.05, journal_radius, STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
        return stiffness - paper_stiffness

    return paper_stiffness, brentq(mismatch, 1e-9, 1e-3, xtol=1e-15)


def main():
    print("Effective restitution |δ̇ exit|/δ̇⁻ of a single impact:\n")
    print(restitution_table())
    print("\nHysteresis factor D(c_e):\n")
    print(hysteresis_table())
    ratio = hertz_contact_time(1.0, 1.0, 1.0) / hertz_max_penetration(1.0, 1.0, 1.0)
    in_mass_stiffness_form = hertz_contact_time(1.0, 1.0, 1.0)
    print(f"\nHertz contact time: t_c = {ratio:.5f} δ_max/v = {in_mass_stiffness_form:.5f} (m/K)^(2/5) v^(-1/5)")
    stiffness, clearance = paper_stiffness_clearance()
    print(f"Paper K = 3.81e7 N/mm^1.5 = {stiffness:.4e} N/m^1.5; steel (E = 207 GPa, ν = 0.3), "
          f"R_B = 50 mm: reproduced at c = R_B − R_J = {clearance * 1e3:.4f} mm")
    steel_10mm = internal_contact_stiffness(0.010, 0.0095, STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
    print(f"Steel R_B = 10 mm, R_J = 9.5 mm: K = {steel_10mm:.4e} N/m^1.5")


if __name__ == "__main__":
    main()
