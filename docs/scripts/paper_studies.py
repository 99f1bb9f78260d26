"""Cases 6 and 5c of docs/validation.md: the seed paper's studies (Meng et al. 2015) on the reconstructed UHV
model, and the UHV tolerance / output-rate study (A and J at every clearance of case 6).

    python docs/scripts/paper_studies.py [OUT] [--figures] [--workers N] [--stick smooth|exact]
        (sweep folders under OUT, default /tmp/clearsim-paper[-STICK]; --stick smooth: the friction law as
        written, the stiction band through zero: the smooth-law numbers quoted in §6; ≈ 8 min with --workers 1)

Runs the `clearsim sweep`s of SWEEPS on configs/uhv_breaker.yaml and prints, from their summary.csv and
result files: the detailed table, the "paper vs clearsim" table, the start delay at several thresholds,
the UHV tolerance study, the friction study (per joint), the whirl of J, and where on the bearings the contact
episodes begin.
The runs take ≈ 30 s of integration in all (0.2–2 s each; with --stick smooth much longer, the stiction band
holds the steps near 1e-7 s), ≈ 1.5 min with --workers 1 including each sweep's start-up. Re-running resumes
(finished cases are reused, ≈ 20 s). Only --figures writes in the repo (docs/figures/validation-paper-*.png).
The friction ensemble of §6 is docs/scripts/friction_ensemble.py, which reuses the figures of merit below.
"""

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import yaml

from clearsim.io.hdf5 import read_result
from clearsim.sweep.figures import start_time
from clearsim.units import parse_quantity
from clearsim.whirl import orbit_angle, orbit_rate

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "configs" / "uhv_breaker.yaml"
FIGURES = ROOT / "docs" / "figures"

# J's journal resting at t = 0 on the bearing wall that faces I (where the upper linking board pushes it at the
# start), instead of centred: 0.999 c along I − J, the points of configs/uhv_breaker.yaml
_TOWARD_I = np.subtract((0.633, 2.335), (0.589, 2.667)) / np.hypot(0.633 - 0.589, 2.335 - 2.667) * 0.999e-5
RESTING_AT_J = f"joints.J.initial_eccentricity=[{_TOWARD_I[0]:.4e} m, {_TOWARD_I[1]:.4e} m]"

SWEEPS = {
    # clearance at J only (A made ideal), vs the ideal mechanism
    "j_only": ["--clearance", "0.01", "--joints", "J", "--set", "joints.A.clearance=0"],
    # the same with J's journal starting on the bearing wall instead of centred
    "j_only_resting": ["--clearance", "0.01", "--joints", "J", "--set", "joints.A.clearance=0", "--set", RESTING_AT_J],
    # clearance at A and J
    "a_and_j": ["--clearance", "0.01,0.03,0.05,0.1", "--joints", "A,J"],
    # dynamic friction coefficient at c = 0.1 mm (A and J; defaults.friction applies to both)
    "friction": ["--clearance", "0.1", "--joints", "A,J", "--set", "defaults.friction.mu_d=0.10,0.15,0.16"],
    # the same at rtol 1e-9: is the friction trend a tolerance artefact?
    "friction_rtol": ["--clearance", "0.1", "--joints", "A,J", "--set", "defaults.friction.mu_d=0.10,0.15,0.16",
                      "--set", "solver.rtol=1e-9"],
    # the whirl of J (A and J at 0.01 mm) under other friction laws: none, no stiction peak (mu_s = mu_d), Coulomb
    "frictionless": ["--clearance", "0.01", "--joints", "A,J", "--set", "defaults.friction={law: none}"],
    "no_stiction_peak": ["--clearance", "0.01", "--joints", "A,J", "--set", "defaults.friction.mu_s=0.16"],
    "coulomb": ["--clearance", "0.01", "--joints", "A,J", "--set", "defaults.friction={law: coulomb, mu_d: 0.16}"],
    # case 5 for the UHV model (the file's A and J at 0.01 mm): tolerance, then output rate
    "uhv_rtol": ["--set", "solver.rtol=1e-6,1e-7,1e-8,1e-9"],
    "uhv_rate": ["--set", "solver.output_rate=100kHz,1MHz"],
    "uhv_rate_c01": ["--clearance", "0.1", "--joints", "A,J", "--set", "solver.output_rate=100kHz,1MHz"],
    # case 5 for the other clearances of case 6: the a_and_j sweep again at rtol 1e-9
    "a_and_j_rtol": ["--clearance", "0.03,0.05,0.1", "--joints", "A,J", "--set", "solver.rtol=1e-9"],
}
SWEPT = {"friction": "defaults.friction.mu_d", "friction_rtol": "defaults.friction.mu_d",
         "uhv_rtol": "solver.rtol", "uhv_rate": "solver.output_rate", "uhv_rate_c01": "solver.output_rate"}
DEFAULT_RTOL, TIGHT_RTOL = "1e-7", "1e-9"

PAPER = {  # Meng et al. 2015, section 4 (quoted in docs/reference.md); missing: not given in the text
    "j_only": {"0.01": {"acceleration_ratio": 3.58}},
    "a_and_j": {"0.01": {"peak_acceleration_m_s2": 2325.6, "start_delay_ms": 1.6},
                "0.1": {"peak_acceleration_m_s2": 10345.5, "start_delay_ms": 4.2, "end_error_percent": 8.5}},
    "friction": {"0.10": {"peak_acceleration_m_s2": 2815.4}, "0.16": {"peak_acceleration_m_s2": 2326.6}},
}

PAPER_WINDOW = 0.010  # s: the paper's Figs. 8(c), 9 and 10 show the first 10 ms of the stroke
DELAY_FRACTIONS = (0.5, 0.1, 0.01)  # of the ideal peak velocity (the sweep's start delay uses 0.5)
WHIRL_WINDOW = (0.040, 0.080)  # s: from mid-stroke to just before the end, where J whirls
DENSE_ARC = 90.0  # degrees: width of the arc whose share of contact onsets is reported
STICK_SPEED = 1e-4  # m/s: v_s of the file's stiction_step law; |v_t| below it counts as sticking


# ---------------------------------------------------------------- running the sweeps and reading their files

def sweep_arguments(name, stick=None):
    """The sweep's options; with `stick`, every friction law that sticks uses that treatment (exact is the default)."""
    arguments = SWEEPS[name]
    if stick is None:
        return arguments
    arguments = [a.replace("{law: coulomb, mu_d: 0.16}", f"{{law: coulomb, mu_d: 0.16, stick: {stick}}}") for a in arguments]
    return ["--set", f"defaults.friction.stick={stick}", *arguments]


def run_sweep(name, out, workers, stick=None):
    folder = out / name
    command = ["clearsim", "sweep", str(CONFIG), *sweep_arguments(name, stick), "--out", str(folder), "--workers", str(workers)]
    print(f"$ {' '.join(command)}", file=sys.stderr)
    command[:1] = [sys.executable, "-m", "clearsim.cli"]  # the clearsim this script imports, not whichever is installed
    subprocess.run(command, check=False, stdout=subprocess.DEVNULL)  # a failed case shows in its row
    with open(folder / "summary.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        row["file"] = folder / f"{row['case']}.h5"
    return rows


def command_text(name, stick=None):
    return " ".join(["clearsim sweep configs/uhv_breaker.yaml",
                     *(f'"{a}"' if " " in a else a for a in sweep_arguments(name, stick))])


def ideal_row(rows):
    return next(row for row in rows if not row["reference"])


def case_rows(rows):
    return [row for row in rows if row["reference"]]


def row_where(rows, column, value):
    return next(row for row in case_rows(rows) if float(row[column].split()[0]) == float(value))


_LOADED = {}


def result(row):
    """The result file of a summary row, read once."""
    if row["file"] not in _LOADED:
        _LOADED[row["file"]] = read_result(row["file"])
    return _LOADED[row["file"]]


def clearance_m(row):
    return float(row["clearance"].split()[0]) * 1e-3 if row.get("clearance") else float("nan")


# ---------------------------------------------------------------- figures of merit read from the result files

def acceleration(data):
    return np.abs(data["sensors/contact_acceleration"])


def window_peak(data, t_end=PAPER_WINDOW):
    """Peak |a| of the moving contact over the first t_end seconds (the paper's figure window)."""
    return float(np.max(acceleration(data)[data["time"] <= t_end + 1e-12]))


def percentile_99(data):
    return float(np.percentile(acceleration(data), 99.0))


def delay_ms(case, ideal, fraction):
    """Time shift (ms) of the case's output velocity in reaching `fraction` of the ideal peak velocity."""
    threshold = fraction * float(np.max(ideal["sensors/contact_velocity"]))
    shift = (start_time(case["time"], case["sensors/contact_velocity"], threshold, 1.0)
             - start_time(ideal["time"], ideal["sensors/contact_velocity"], threshold, 1.0))
    return shift * 1e3


def lost_motion_bound_ms(ideal, clearance):
    """Largest start delay lost motion can explain: the time the ideal output needs to travel 2c at J plus
    2c at A carried to the output by the start-up lever ratio (every slack taken up against the motion)."""
    drive = np.abs(ideal["bodies/driving_link/q"][:, 0] - ideal["bodies/driving_link/q"][0, 0])
    output = ideal["sensors/contact_displacement"] - ideal["sensors/contact_displacement"][0]
    early = np.flatnonzero(drive > 0)[:20]
    ratio = float(np.median(output[early] / drive[early]))
    slack = 2 * clearance * (1.0 + ratio)
    return start_time(ideal["time"], output, slack, 1.0) * 1e3, ratio


def velocity_error_percent(case, ideal):
    """max |v − v_ideal| over the run, in % of the ideal peak velocity."""
    v_ideal = np.interp(case["time"], ideal["time"], ideal["sensors/contact_velocity"])
    return float(np.max(np.abs(case["sensors/contact_velocity"] - v_ideal)) / np.max(v_ideal) * 100.0)


def joint_bodies(data, joint):
    """(bearing body, journal body, bearing radius, clearance) of a clearance joint, from the run's YAML."""
    document = yaml.safe_load(data["attrs"]["config_yaml"])
    spec = next(j for j in document["joints"] if j["name"] == joint)
    return spec["bodies"][0], spec["bodies"][1], _metres(spec.get("bearing_radius", "50 mm")), _metres(spec["clearance"])


def _metres(text):
    """A length of the file in metres ("0.01 mm", "0.01mm", "10 um" or a number in metres), read as the model reads it."""
    return float(parse_quantity(text).to("m").magnitude) if isinstance(text, str) else float(text)


def friction_by_joint(data, joint):
    """(stick share of the contact samples, friction energy in J, contact share) of one clearance joint."""
    in_contact = data[f"joints/{joint}/mode"] != 0
    sliding = data[f"joints/{joint}/sliding_velocity"]
    power = np.abs(data[f"joints/{joint}/friction_force"] * sliding)
    energy = float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(data["time"])))
    stick = float(np.mean(np.abs(sliding[in_contact]) < STICK_SPEED)) if in_contact.any() else float("nan")
    return stick, energy


def whirl(data, joint="J", window=WHIRL_WINDOW):
    """Orbits of the journal centre in `window` against pure rolling: (turns, rolling turns, frequency Hz,
    mean |e|/c in contact, slip speed as % of the rolling surface speed)."""
    bearing, journal, radius, clearance = joint_bodies(data, joint)
    t = data["time"]
    inside = (t >= window[0]) & (t <= window[1])
    e = data[f"joints/{joint}/eccentricity"][inside]
    eccentricity = np.hypot(e[:, 0], e[:, 1])
    angle = orbit_angle(e)  # global, as the rolling rate: ė·t = ω_B R_B − ω_J R_J
    contact = data[f"joints/{joint}/mode"][inside] != 0
    surface_speed = (data[f"bodies/{bearing}/qd"][inside, 2] * radius
                     - data[f"bodies/{journal}/qd"][inside, 2] * (radius - clearance))  # ω_B R_B − ω_J R_J
    rolling_rate = np.where(contact, surface_speed / eccentricity, 0.0)  # ė·t = v_surface when v_t = 0
    turns = (angle[-1] - angle[0]) / (2 * np.pi)
    rolling_turns = float(np.sum(0.5 * (rolling_rate[1:] + rolling_rate[:-1]) * np.diff(t[inside]))) / (2 * np.pi)
    slip = np.abs(data[f"joints/{joint}/sliding_velocity"][inside][contact])
    slip_percent = float(np.mean(slip) / np.mean(np.abs(surface_speed[contact])) * 100.0)
    mean_e = float(np.mean(eccentricity[contact]) / clearance)
    return turns, rolling_turns, abs(turns) / (window[1] - window[0]), mean_e, slip_percent


def onset_angles(data, joint):
    """Where on the bearing each contact episode begins: the angle (deg) of the eccentricity at onset in the
    bearing body's frame (0° = its x axis; for J, the upper linking board's direction I → J, so 180° faces I)."""
    bearing = joint_bodies(data, joint)[0]
    e = data[f"joints/{joint}/eccentricity"]
    angle = orbit_angle(e, data[f"bodies/{bearing}/q"][:, 2])
    onsets = np.asarray(data[f"joints/{joint}/episodes/onset"])
    return np.degrees(np.interp(onsets, data["time"], angle)) % 360.0


def densest_arc(angles, width=DENSE_ARC):
    """(centre in deg, share of the angles within ±width/2 of it, share in that arc plus the opposite one)."""
    if not len(angles):
        return float("nan"), float("nan"), float("nan")
    centres = np.arange(360.0)
    distance = np.abs((angles[None, :] - centres[:, None] + 180.0) % 360.0 - 180.0)
    shares = np.mean(distance <= width / 2, axis=1)
    best = int(np.argmax(shares))
    opposite = (best + 180) % 360
    return float(centres[best]), float(shares[best]), float(shares[best] + shares[opposite])


# ---------------------------------------------------------------- printed tables

def fmt(value, spec):
    return "—" if value is None or value == "" or (isinstance(value, float) and np.isnan(value)) else format(float(value), spec)


def print_detailed_table(studies):
    print("| study | case | peak \\|a\\| paper (m/s²) | peak \\|a\\| clearsim (m/s²) | ratio to ideal paper | ratio clearsim "
          "| start delay paper (ms) | start delay clearsim (ms, f = 0.5) | end error paper (%) | end error clearsim (%) "
          "| J: free / impact / contact (% of samples) | max F_n A / J (kN) | status |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, rows in studies.items():
        for row in rows:
            print(detailed_row(name, row))


def detailed_row(name, row):
    swept = SWEPT.get(name)
    if not row["reference"]:
        label = f"ideal ({swept} = {row[swept]})" if row.get(swept) else "ideal"
        return (f"| {name} | {label} | — | {fmt(row['peak_acceleration_m_s2'], '.1f')} | 1 | 1 | 0 | 0 | 0 | 0 | — | — "
                f"| {row['status']} |")
    clearance = row.get("clearance") or "0.01 mm (A, J: the file's)"
    key = row[swept] if swept and swept.endswith("mu_d") else clearance.split(" ")[0]
    label = f"{swept} = {row[swept]}, c = {clearance}" if swept else f"c = {clearance}"
    quoted = next((v for k, v in PAPER.get(name, {}).items() if key and float(k) == float(key)), {})
    modes = "/".join(fmt(row.get(f"{mode}_percent[J]"), ".0f") for mode in ("free", "impact", "contact"))
    forces = "/".join(fmt(float(row[f"max_contact_force_N[{j}]"]) / 1e3, ".1f") if row.get(f"max_contact_force_N[{j}]")
                      else "—" for j in ("A", "J"))
    return (f"| {name} | {label} | {fmt(quoted.get('peak_acceleration_m_s2'), '.1f')} "
            f"| {fmt(row['peak_acceleration_m_s2'], '.1f')} | {fmt(quoted.get('acceleration_ratio'), '.2f')} "
            f"| {fmt(row['acceleration_ratio'], '.2f')} | {fmt(quoted.get('start_delay_ms'), '.1f')} "
            f"| {fmt(row['start_delay_ms'], '.3f')} | {fmt(quoted.get('end_error_percent'), '.1f')} "
            f"| {fmt(row['end_error_percent'], '.3f')} | {modes} | {forces} | {row['status']} |")


def print_paper_vs_clearsim(studies):
    """The compact table: the paper's numbers beside clearsim's, over the run and over 0–10 ms."""
    j_only, a_and_j, friction = studies["j_only"], studies["a_and_j"], studies["friction"]
    ideal = result(ideal_row(a_and_j))
    print("\n| quantity | case | paper | clearsim, whole stroke | clearsim, first 10 ms |")
    print("|---|---|---|---|---|")
    for label, rows in (("J only, 0.01 mm", j_only),
                        ("J only, 0.01 mm, journal resting on the wall", studies["j_only_resting"])):
        j = row_where(rows, "clearance", 0.01)
        print(f"| peak \\|a\\| / ideal | {label} | 3.58 | {float(j['acceleration_ratio']):.2f} "
              f"| {window_peak(result(j)) / window_peak(result(ideal_row(rows))):.2f} |")
    for row in case_rows(a_and_j):
        quoted = PAPER["a_and_j"].get(row["clearance"].split()[0], {})
        print(f"| peak \\|a\\| (m/s²) | A and J, {row['clearance']} | {fmt(quoted.get('peak_acceleration_m_s2'), '.1f')} "
              f"| {float(row['peak_acceleration_m_s2']):.1f} | {window_peak(result(row)):.1f} |")
    for row in case_rows(a_and_j):
        quoted = PAPER["a_and_j"].get(row["clearance"].split()[0], {})
        print(f"| start delay (ms), f = 0.5 / 0.01 | A and J, {row['clearance']} | {fmt(quoted.get('start_delay_ms'), '.1f')} "
              f"| {delay_ms(result(row), ideal, 0.5):.3f} / {delay_ms(result(row), ideal, 0.01):.3f} | — |")
    big = row_where(a_and_j, "clearance", 0.1)
    print(f"| kinematic error (%): end displacement / max velocity error | A and J, 0.1 mm | ≈ 8.5 "
          f"| {float(big['end_error_percent']):.3f} / {velocity_error_percent(result(big), ideal):.2f} | — |")
    for row in case_rows(friction):
        mu = row["defaults.friction.mu_d"]
        quoted = PAPER["friction"].get(mu, {})
        print(f"| peak \\|a\\| (m/s²) | μ_d = {mu}, A and J 0.1 mm | {fmt(quoted.get('peak_acceleration_m_s2'), '.1f')} "
              f"| {float(row['peak_acceleration_m_s2']):.1f} | {window_peak(result(row)):.1f} |")


def print_start_delays(a_and_j):
    ideal = result(ideal_row(a_and_j))
    print("\n| c at A and J | " + " | ".join(f"delay f = {f} (ms)" for f in DELAY_FRACTIONS)
          + " | lost-motion bound (ms) | max velocity error (% of peak) |")
    print("|---|" + "---|" * (len(DELAY_FRACTIONS) + 2))
    for row in case_rows(a_and_j):
        bound, ratio = lost_motion_bound_ms(ideal, clearance_m(row))
        delays = " | ".join(f"{delay_ms(result(row), ideal, f):.3f}" for f in DELAY_FRACTIONS)
        print(f"| {row['clearance']} | {delays} | {bound:.2f} | {velocity_error_percent(result(row), ideal):.2f} |")
    print(f"\n(start-up lever ratio output/drive: {ratio:.3f}; the bound is the time the ideal output needs to travel "
          f"2c (1 + ratio))")


def print_friction(studies):
    print("\n| rtol | μ_d | peak \\|a\\| (m/s²) | first 10 ms | 99th pct \\|a\\| | stick share A / J (% of contact) "
          "| friction energy A / J (J) | sum / written total (J) | status |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, rtol in (("friction", "1e-7"), ("friction_rtol", "1e-9")):
        for row in case_rows(studies[name]):
            if row["status"] != "complete":
                print(f"| {rtol} | {row['defaults.friction.mu_d']} | — | — | — | — | — | — | {row['status']} |")
                continue
            data = result(row)
            (stick_a, energy_a), (stick_j, energy_j) = friction_by_joint(data, "A"), friction_by_joint(data, "J")
            print(f"| {rtol} | {row['defaults.friction.mu_d']} | {float(row['peak_acceleration_m_s2']):.1f} "
                  f"| {window_peak(data):.1f} | {percentile_99(data):.1f} | {stick_a * 100:.0f} / {stick_j * 100:.0f} "
                  f"| {energy_a:.2f} / {energy_j:.2f} | {energy_a + energy_j:.2f} / "
                  f"{float(data['energy/friction_dissipated'][-1]):.2f} | {row['status']} |")


def tolerance_figures(row, ideal):
    """Figures of merit compared between tolerances: peak |a| over the stroke and over the first 10 ms,
    start delay at 50 % and 1 % of the ideal peak speed (ms), located peak F_n at A and J (N), 99th percentile
    of |a|, end error (%)."""
    data = result(row)
    return {"peak": float(row["peak_acceleration_m_s2"]), "peak_10ms": window_peak(data),
            "delay_50": delay_ms(data, result(ideal), 0.5), "delay_1": delay_ms(data, result(ideal), 0.01),
            "force_A": float(row["max_contact_force_N[A]"]), "force_J": float(row["max_contact_force_N[J]"]),
            "p99": percentile_99(data), "end_error": float(row["end_error_percent"]), "steps": int(row["steps"]),
            "times_ms": [float(data["time"][np.argmax(signal)]) * 1e3 for signal in  # of the sampled peaks
                         (acceleration(data), data["joints/A/normal_force"], data["joints/J/normal_force"])]}


def _relative(value, reference):
    change = (value / reference - 1) * 100
    return "0.00 %" if abs(change) < 0.005 else f"{change:+.2f} %"


def uhv_tolerance_pairs(studies):
    """(clearance label, rtol, figures, figures at rtol 1e-9) for A and J at every clearance of case 6 at the
    default rtol and at 1e-9, then the 0.01 mm case at every tolerance of uhv_rtol."""
    tight = {row["clearance"]: tolerance_figures(row, ideal_row(studies["a_and_j_rtol"]))
             for row in case_rows(studies["a_and_j_rtol"])}
    by_rtol = {}
    for row in case_rows(studies["uhv_rtol"]):
        ideal = next(r for r in studies["uhv_rtol"] if not r["reference"] and r["solver.rtol"] == row["solver.rtol"])
        by_rtol[row["solver.rtol"]] = tolerance_figures(row, ideal)
    tight["0.01 mm"] = by_rtol[TIGHT_RTOL]
    pairs = [("0.01 mm", DEFAULT_RTOL, by_rtol[DEFAULT_RTOL], tight["0.01 mm"])]
    pairs += [(row["clearance"], DEFAULT_RTOL, tolerance_figures(row, ideal_row(studies["a_and_j"])),
               tight[row["clearance"]]) for row in case_rows(studies["a_and_j"]) if row["clearance"] != "0.01 mm"]
    return pairs, by_rtol


def print_uhv_tolerance(studies):
    """Case 5c: the UHV model's tolerance study (A and J at 0.01 mm, rtol 1e-6 … 1e-9), the default rtol against
    1e-9 at every clearance of case 6, and the largest deviation of each figure at the default rtol."""
    pairs, by_rtol = uhv_tolerance_pairs(studies)
    reference = by_rtol[TIGHT_RTOL]
    print("\n| rtol | steps | peak \\|a\\| (m/s²) | rel. to 1e-9 | first 10 ms (m/s²) | rel. | start delay f = 0.5 / 0.01 (ms) "
          "| max F_n A (kN) | rel. | max F_n J (kN) | rel. |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for rtol, f in by_rtol.items():
        print(f"| {rtol}{' (default)' if rtol == DEFAULT_RTOL else ''} | {f['steps']} | {f['peak']:.1f} "
              f"| {_relative(f['peak'], reference['peak'])} | {f['peak_10ms']:.1f} "
              f"| {_relative(f['peak_10ms'], reference['peak_10ms'])} | {f['delay_50']:.3f} / {f['delay_1']:.3f} "
              f"| {f['force_A'] / 1e3:.2f} | {_relative(f['force_A'], reference['force_A'])} | {f['force_J'] / 1e3:.2f} "
              f"| {_relative(f['force_J'], reference['force_J'])} |")
    print(f"\n| c at A and J | peak \\|a\\| rtol {DEFAULT_RTOL} / {TIGHT_RTOL} (m/s²) | rel. | first 10 ms (m/s²) | rel. "
          "| start delay f = 0.01 (ms) | max F_n A (kN) | rel. | max F_n J (kN) | rel. | 99th pct \\|a\\| (m/s²) "
          "| end error (%) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    worst = {}
    for clearance, rtol, f, t in pairs:
        print(f"| {clearance} | {f['peak']:.1f} / {t['peak']:.1f} | {_relative(f['peak'], t['peak'])} "
              f"| {f['peak_10ms']:.1f} / {t['peak_10ms']:.1f} | {_relative(f['peak_10ms'], t['peak_10ms'])} "
              f"| {f['delay_1']:.3f} / {t['delay_1']:.3f} | {f['force_A'] / 1e3:.2f} / {t['force_A'] / 1e3:.2f} "
              f"| {_relative(f['force_A'], t['force_A'])} | {f['force_J'] / 1e3:.2f} / {t['force_J'] / 1e3:.2f} "
              f"| {_relative(f['force_J'], t['force_J'])} | {f['p99']:.0f} / {t['p99']:.0f} "
              f"| {f['end_error']:.3f} / {t['end_error']:.3f} |")
        for key in ("peak", "peak_10ms", "force_A", "force_J", "p99"):
            worst[key] = max(worst.get(key, 0.0), abs(f[key] / t[key] - 1) * 100)
        worst["delay_1"] = max(worst.get("delay_1", 0.0), abs(f["delay_1"] - t["delay_1"]) * 1e3)
    print("\n(time of the sampled peak |a| / F_n at A / F_n at J, ms, at rtol " + f"{DEFAULT_RTOL} and {TIGHT_RTOL}: "
          + "; ".join(f"{c}: " + ", ".join(f"{x:.2f}/{y:.2f}" for x, y in zip(f["times_ms"], t["times_ms"]))
                      for c, _, f, t in pairs) + ")")
    print(f"\n(largest deviation at rtol {DEFAULT_RTOL} from {TIGHT_RTOL} over the four clearances: peak |a| "
          f"{worst['peak']:.2f} %, first 10 ms {worst['peak_10ms']:.2f} %, max F_n at A {worst['force_A']:.2f} %, at J "
          f"{worst['force_J']:.2f} %, start delay f = 0.01 {worst['delay_1']:.1f} µs, 99th percentile {worst['p99']:.0f} %)")


def whirl_cases(studies):
    """(label, row) of every case whose journal-centre orbit at J is compared with rolling."""
    cases = [("J only, 0.01 mm", row_where(studies["j_only"], "clearance", 0.01))]
    cases += [(f"A and J, {row['clearance']}", row) for row in case_rows(studies["a_and_j"])]
    cases += [(f"A and J, 0.01 mm, rtol {row['solver.rtol']}", row) for row in case_rows(studies["uhv_rtol"])
              if row["solver.rtol"] == "1e-9"]
    for name, label in (("frictionless", "no friction"), ("no_stiction_peak", "μ_s = μ_d = 0.16"),
                        ("coulomb", "Coulomb μ = 0.16")):
        cases += [(f"A and J, 0.01 mm, {label}", row) for row in case_rows(studies.get(name, []))]
    return cases


def print_whirl(studies):
    print(f"\n| case | orbits of e at J, {WHIRL_WINDOW[0] * 1e3:.0f}–{WHIRL_WINDOW[1] * 1e3:.0f} ms | rolling would give "
          "| orbit frequency (Hz) | mean \\|e\\|/c in contact | slip (% of surface speed) | J: free / impact / contact (%) "
          "| peak \\|a\\| (m/s²) | status |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, row in whirl_cases(studies):
        if not row["file"].exists():
            continue
        data = result(row)
        turns, rolling, frequency, mean_e, slip = whirl(data)
        modes = "/".join(fmt(row.get(f"{m}_percent[J]"), ".0f") for m in ("free", "impact", "contact"))
        print(f"| {label} | {turns:.1f} | {rolling:.1f} | {frequency:.0f} | {mean_e:.2f} | {slip:.1f} | {modes} "
              f"| {fmt(row['peak_acceleration_m_s2'], '.1f')} | {status_text(row)} |")


def print_whirl_details(studies):
    """The whirl of J at 0.01 mm (A and J): when the board's rotation reverses and the orbit locks on, the orbit rate
    at 60 ms, and the contact force and penetration while it whirls."""
    data = result(row_where(studies["a_and_j"], "clearance", 0.01))
    bearing, _, _, clearance = joint_bodies(data, "J")
    t, omega = data["time"], data[f"bodies/{bearing}/qd"][:, 2]
    reversal = t[1:][(np.diff(np.sign(omega)) != 0) & (t[1:] > 0.005) & (t[1:] < 0.08)][0]
    rate = orbit_rate(t, orbit_angle(data["joints/J/eccentricity"]))  # 1 ms running mean, as in the whirl figure
    locked = t[(np.abs(rate) > 1000.0) & (t > reversal)][0]
    window = (t >= 0.055) & (t <= 0.065)
    print(f"\n(A and J, 0.01 mm: the {bearing.replace('_', ' ')} turns at up to {np.max(np.abs(omega)):.1f} rad/s and "
          f"reverses at {reversal * 1e3:.1f} ms; the orbit rate of e at J exceeds 1 kHz from {locked * 1e3:.1f} ms and is "
          f"{abs(rate[np.searchsorted(t, 0.060)]):.0f} Hz at 60 ms; at 55–65 ms the mean F_n at J is "
          f"{np.mean(data['joints/J/normal_force'][window]) / 1e3:.1f} kN and the mean penetration "
          f"{np.mean(data['joints/J/penetration'][window]) * 1e6:.1f} µm ({np.mean(data['joints/J/penetration'][window]) / clearance:.2f} c); "
          f"the largest penetration is {np.max(data['joints/J/penetration']) / clearance:.2f} c)")


def status_text(row):
    """`complete`, or `failed at t = …` (the run's samples up to then are still read)."""
    return row["status"] if row["status"] == "complete" else f"{row['status']} ({row.get('error', '').split(',')[0]})"


def print_onsets(a_and_j):
    print(f"\n| c at A and J | joint | contact episodes (impacts) | densest {DENSE_ARC:.0f}° arc: centre (deg) "
          f"| share of onsets | with the opposite arc |")
    print("|---|---|---|---|---|---|")
    for row in case_rows(a_and_j):
        data = result(row)
        for joint in ("A", "J"):
            centre, share, pair = densest_arc(onset_angles(data, joint))
            impacts = int(np.sum(data[f"joints/{joint}/episodes/kind"] == 1))
            print(f"| {row['clearance']} | {joint} | {len(data[f'joints/{joint}/episodes/onset'])} ({impacts}) "
                  f"| {centre:.0f} | {share * 100:.0f} % | {pair * 100:.0f} % |")


# ---------------------------------------------------------------- figures (--figures)

def new_figure(rows, columns, size, **options):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from clearsim.plot.style import apply_style

    apply_style()
    return plt.subplots(rows, columns, figsize=size, layout="constrained", **options)


def save(figure, name):
    target = FIGURES / f"validation-paper-{name}.png"
    figure.savefig(target, dpi=100)
    print(f"(wrote {target.relative_to(ROOT)})")


def response_figure(studies):
    """The paper's Figs. 8–9: output velocity and acceleration, ideal vs clearances, first 10 ms and the stroke."""
    figure, axes = new_figure(2, 2, (9.0, 6.0))
    curves = [("ideal", ideal_row(studies["a_and_j"]), {"color": "black", "linestyle": "--", "zorder": 5})]
    curves += [(f"J only, {row['clearance']}", row, {"color": "tab:gray"}) for row in case_rows(studies["j_only"])]
    curves += [(f"A and J, {row['clearance']}", row, {}) for row in case_rows(studies["a_and_j"])]
    for label, row, style in curves:
        data = result(row)
        t_ms = data["time"] * 1e3
        for column, sensor in enumerate(("contact_velocity", "contact_acceleration")):
            for line, limit in enumerate((PAPER_WINDOW * 1e3, None)):
                shown = t_ms <= limit if limit else slice(None)
                axes[line, column].plot(t_ms[shown], data[f"sensors/{sensor}"][shown], lw=0.8, label=label, **style)
    for line, span in enumerate(("first 10 ms (the paper's Fig. 9 window)", "whole stroke")):
        axes[line, 0].set_ylabel("velocity (m/s)")
        axes[line, 1].set_ylabel("acceleration (m/s²)")
        for ax in axes[line]:
            ax.set_xlabel("time (ms)")
            ax.set_title(span)
    axes[0, 0].legend(fontsize=7)
    save(figure, "response")


def peak_figure(studies):
    """Peak |a| against clearance at A and J, whole stroke and first 10 ms, with the paper's end points."""
    rows = case_rows(studies["a_and_j"])
    clearance = [clearance_m(row) * 1e3 for row in rows]
    figure, ax = new_figure(1, 1, (5.5, 3.6))
    ax.plot(clearance, [float(row["peak_acceleration_m_s2"]) for row in rows], "o-", label="clearsim, whole stroke")
    ax.plot(clearance, [window_peak(result(row)) for row in rows], "^-", label="clearsim, first 10 ms")
    ax.plot([0.01, 0.1], [2325.6, 10345.5], "s--", label="Meng et al. 2015 (text: end points only)")
    ideal = float(ideal_row(studies["a_and_j"])["peak_acceleration_m_s2"])
    ax.axhline(ideal, color="0.6", lw=0.8, label=f"ideal, clearsim ({ideal:.0f} m/s²)")
    ax.set_xlabel("radial clearance at A and J (mm)")
    ax.set_ylabel("peak |a|, moving contact (m/s²)")
    ax.set_ylim(0, None)
    ax.legend(fontsize=7)
    save(figure, "peak")


def friction_figure(studies):
    """The paper's Fig. 10: acceleration over 10 ms for μ_d 0.10/0.15/0.16, and the peak figures against μ_d."""
    figure, (traces, peaks) = new_figure(1, 2, (9.0, 3.6))
    for row in case_rows(studies["friction"]):
        data = result(row)
        shown = data["time"] <= PAPER_WINDOW
        traces.plot(data["time"][shown] * 1e3, data["sensors/contact_acceleration"][shown], lw=0.8,
                    label=f"μ_d = {row['defaults.friction.mu_d']}")
    traces.set_xlabel("time (ms)")
    traces.set_ylabel("acceleration (m/s²)")
    traces.set_title("A and J at 0.1 mm, first 10 ms")
    traces.legend(fontsize=7)
    for name, marker, tolerance in (("friction", "o", "rtol 1e-7"), ("friction_rtol", "x", "rtol 1e-9")):
        rows = [row for row in case_rows(studies[name]) if row["status"] == "complete"]
        mu = [float(row["defaults.friction.mu_d"]) for row in rows]
        peaks.plot(mu, [float(row["peak_acceleration_m_s2"]) for row in rows], marker + "-", color="tab:blue",
                   label=f"clearsim peak, whole stroke, {tolerance}")
        peaks.plot(mu, [window_peak(result(row)) for row in rows], marker + "-", color="tab:orange",
                   label=f"clearsim peak, first 10 ms, {tolerance}")
        peaks.plot(mu, [percentile_99(result(row)) for row in rows], marker + ":", color="tab:green",
                   label=f"clearsim 99th percentile, {tolerance}")
    peaks.plot([0.10, 0.16], [2815.4, 2326.6], "s--", color="tab:red", label="Meng et al. 2015 (text)")
    peaks.set_xlabel("dynamic friction coefficient μ_d at A and J")
    peaks.set_ylabel("|a| (m/s²)")
    peaks.set_ylim(0, None)
    peaks.legend(fontsize=6)
    save(figure, "friction")


def path_figure(studies):
    """The paper's Fig. 11: J's journal-centre path coloured by contact mode, in the clearance circle."""
    from clearsim.plot.data import load_run
    from clearsim.plot.journal import plot_journal_path
    from clearsim.plot.style import mode_handles

    rows = [("J only, 0.01 mm", row_where(studies["j_only"], "clearance", 0.01)),
            ("A and J, 0.01 mm", row_where(studies["a_and_j"], "clearance", 0.01)),
            ("A and J, 0.1 mm", row_where(studies["a_and_j"], "clearance", 0.1))]
    figure, axes = new_figure(1, 3, (11.0, 4.2))
    for ax, (label, row) in zip(axes, rows):
        plot_journal_path(load_run(row["file"]), "J", ax=ax)
        ax.set_title(f"joint J, {label}")
    figure.legend(handles=mode_handles(), loc="outside lower center", ncol=3, fontsize=8)
    save(figure, "path")


def onset_figure(studies):
    """Where on the bearing contact episodes begin: polar histograms of the onset angle, A and J."""
    rows = [row_where(studies["a_and_j"], "clearance", c) for c in (0.01, 0.1)]
    figure, axes = new_figure(2, 2, (7.5, 7.5), subplot_kw={"projection": "polar"})
    bins = np.radians(np.arange(0.0, 361.0, 10.0))
    for line, joint in enumerate(("A", "J")):
        for column, row in enumerate(rows):
            angles = onset_angles(result(row), joint)
            centre, share, _ = densest_arc(angles)
            ax = axes[line, column]
            counts, _, _ = ax.hist(np.radians(angles), bins=bins, color="tab:red", alpha=0.8)
            if not np.isnan(centre):
                ax.bar(np.radians(centre), max(counts), width=np.radians(DENSE_ARC), color="0.85", zorder=0)
            ax.tick_params(labelsize=7)
            ax.set_title(f"{joint}, c = {row['clearance']}: {len(angles)} onsets,\n{share * 100:.0f} % in the "
                         f"{DENSE_ARC:.0f}° arc centred at {centre:.0f}°", fontsize=8)
    figure.suptitle("angle of e = journal − bearing centre at contact onset, in the bearing's frame\n"
                    "(A: driving link, 0° = +x, 90° = up; J: upper linking board, 0° = direction I → J, 180° faces I)",
                    fontsize=9)
    save(figure, "onsets")


def whirl_figure(studies):
    """Orbit rate of e at J against pure rolling, A and J at 0.01 mm, with and without friction."""
    figure, ax = new_figure(1, 1, (7.0, 3.4))
    cases = [("stiction_step (file)", row_where(studies["a_and_j"], "clearance", 0.01))]
    cases += [("no friction", row) for row in case_rows(studies["frictionless"])]
    for label, row in cases:
        data = result(row)
        bearing, journal, radius, clearance = joint_bodies(data, "J")
        t = data["time"]
        smooth = orbit_rate(t, orbit_angle(data["joints/J/eccentricity"]))  # 1 ms running mean
        ax.plot(t * 1e3, smooth, lw=1.0, label=f"orbit rate, {label}")
    data = result(cases[0][1])
    bearing, journal, radius, clearance = joint_bodies(data, "J")
    e = data["joints/J/eccentricity"]
    surface = data[f"bodies/{bearing}/qd"][:, 2] * radius - data[f"bodies/{journal}/qd"][:, 2] * (radius - clearance)
    ax.plot(data["time"] * 1e3, surface / np.maximum(np.hypot(e[:, 0], e[:, 1]), clearance) / (2 * np.pi), "k--", lw=0.8,
            label="rolling without slip: (ω_B R_B − ω_J R_J) / (2π |e|)")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("orbit rate of e at J (Hz)")
    ax.legend(fontsize=7)
    save(figure, "whirl")


FIGURE_MAKERS = (response_figure, peak_figure, friction_figure, path_figure, onset_figure, whirl_figure)


def main():
    arguments = sys.argv[1:]
    workers = int(arguments[arguments.index("--workers") + 1]) if "--workers" in arguments else 2
    positional = [a for i, a in enumerate(arguments)
                  if not a.startswith("--") and (i == 0 or arguments[i - 1] not in ("--workers", "--stick"))]
    stick = arguments[arguments.index("--stick") + 1] if "--stick" in arguments else None
    out = Path(positional[0]) if positional else Path("/tmp/clearsim-paper" + (f"-{stick}" if stick else ""))
    out.mkdir(parents=True, exist_ok=True)
    studies = {name: run_sweep(name, out, workers, stick) for name in SWEEPS}
    print_detailed_table(studies)
    print("\nReproduce: `python docs/scripts/paper_studies.py" + (f" --stick {stick}" if stick else "") + "`, i.e. the sweeps\n")
    for name in SWEEPS:
        print(f"- `{command_text(name, stick)}`")
    print_paper_vs_clearsim(studies)
    print_start_delays(studies["a_and_j"])
    print_uhv_tolerance(studies)
    print_friction(studies)
    print_whirl(studies)
    print_whirl_details(studies)
    print_onsets(studies["a_and_j"])
    if "--figures" in arguments:
        print()
        for make in FIGURE_MAKERS:
            make(studies)


if __name__ == "__main__":
    main()
