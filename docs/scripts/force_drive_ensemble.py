"""Case 6 of docs/validation.md, "Force-driven variant": the friction study (μ_d 0.10 → 0.15 → 0.16, A and J at
0.1 mm) with the drive law replaced by a force, over the same paired ensemble as friction_ensemble.py, for two
force drives (tests/support/uhv_actuator.py):

- `actuator`: an actuator force that depends on the stroke, F = F0 − k x − c ẋ (one spring_damper);
- `history`: the drive law's effort on the ideal mechanism as a force history, applied open-loop (a tabulated
  force; its CSV is written to OUT/drive-law-effort.csv from the ideal drive-law run).

    python docs/scripts/force_drive_ensemble.py [OUT] [--samples N] [--figures] [--calibrate]
        (result files under OUT/<drive>, default /tmp/clearsim-force-drive-ensemble; N = 20 samples per μ_d)

The actuator is one spring_damper along the driving link's guide: in the stroke direction F = F0 − k x − c ẋ. It
is calibrated once, on the ideal mechanism (A and J without clearance, so
friction does no work), to the moving contact's displacement under the bundled drive law (paper eq. 16);
--calibrate runs that least-squares fit (≈ 50 runs, ≈ 40 s) and checks that the rounded constants in
uhv_actuator.py are its result. Every run prints the calibration's residual. The μ_d study is then not tuned:
each case is `clearsim run configs/uhv_breaker.yaml --set "drivers=[]" --set "forces=[…]" --set …` with the
perturbations of friction_ensemble.py (draws; per drive 3 × N + 4 runs of ≈ 0.5 s, ≈ 2 min in all with the kernels
cached; re-running reuses complete result files). The reference of the figures of merit is each drive's ideal run.

Besides friction_ensemble.py's figures of merit, the motion of the output, which a prescribed drive fixes:
the time the moving contact takes to reach 90 % of the 0.300 m stroke, its mean speed between 10 % and 90 % of the
stroke (the usual definition of a breaker's contact speed), its peak speed and the peak kinetic energy of the
mechanism; and, at the sample of the peak acceleration, the two parts of J's force on the moving contact along
the stroke, the normal force's and the friction force's. --figures writes docs/figures/validation-force-drive-calibration.png and
docs/figures/validation-force-drive-ensemble.png.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # tests.support

from friction_ensemble import (FORMATS, IDEAL, LABELS, MU_D, PAIRED, command_line,  # noqa: E402
                               ensemble_figure, figures_of_merit, print_distributions, print_paired, run_case,
                               run_ensemble)
from paper_studies import FIGURES, ROOT, new_figure  # noqa: E402

from clearsim.io.hdf5 import read_result  # noqa: E402
from tests.support.uhv_actuator import (CALIBRATED, FORCE_DRIVE, actuator_overrides, crossing_time,  # noqa: E402
                                        effort_history_overrides, mean_speed)

FIT_STEP = 50  # fit the displacement every 50th sample (0.5 ms)
SCALES = (1e4, 1e5, 1e3)  # N, N/m, N·s/m: the fit's parameters in these units are of order 1
DIGITS = 4  # CALIBRATED is the fit rounded to this many significant digits
MOVING_CONTACT_KG = 5.420  # configs/uhv_breaker.yaml

MOTION_LABELS = {"t_90": "time to 90 % of the stroke (ms)", "mean_speed": "mean speed, 10–90 % of the stroke (m/s)",
                 "v_peak": "peak speed (m/s)", "kinetic_max": "peak kinetic energy (J)"}
PEAK_LABELS = {"peak_normal": "at the peak: J's normal force along the stroke (kN)",
               "peak_friction": "at the peak: J's friction force along the stroke (kN)"}
MOTION_FORMATS = {"t_90": ".2f", "mean_speed": ".3f", "v_peak": ".3f", "kinetic_max": ".0f", "peak_normal": ".1f",
                  "peak_friction": ".2f"}
LABELS_ALL = {**{key: label for key, label in LABELS.items() if key != "driver_extra"}, **MOTION_LABELS, **PEAK_LABELS}
FORMATS_ALL = {**FORMATS, **MOTION_FORMATS}
PAIRED_ALL = (*PAIRED, *MOTION_LABELS)  # PEAK_LABELS: signed, their change is printed in kN
DRIVE_NAMES = {"actuator": "actuator F0 − k x", "history": "force history (the law's effort, open-loop)"}


def motion(data):
    return {"t_90": crossing_time(data, 0.9) * 1e3, "mean_speed": mean_speed(data),
            "v_peak": float(np.max(data["sensors/contact_velocity"])), "kinetic_max": float(np.max(data["energy/kinetic"]))}


def peak_parts(data):
    """(normal, friction) part of J's force on the moving contact along the stroke (+y), kN, and the angle (deg)
    between J's contact normal and the stroke, at the sample of the peak |a|: the force on the journal is
    −F_n n + F_t t, t = (−n_y, n_x), n along the eccentricity."""
    i = int(np.argmax(np.abs(data["sensors/contact_acceleration"])))
    e = data["joints/J/eccentricity"][i]
    n = e / np.hypot(*e)
    return (-data["joints/J/normal_force"][i] * n[1] / 1e3, data["joints/J/friction_force"][i] * n[0] / 1e3,
            float(np.degrees(np.arccos(abs(n[1])))))


def merit(path, ideal):
    figures = figures_of_merit(path, ideal)
    if figures is None:
        return None
    data = read_result(path)
    normal, friction, angle = peak_parts(data)
    return {**figures, **motion(data), "peak_normal": normal, "peak_friction": friction, "peak_angle": angle}


def actuator_force(data, preload, stiffness, damping=0.0):
    """The actuator's force on the driving link in the stroke direction (N) over the run."""
    x = -(data["bodies/driving_link/q"][:, 0] - data["bodies/driving_link/q"][0, 0])
    return preload - stiffness * x + damping * data["bodies/driving_link/qd"][:, 0]


def residual(data, law):
    """Contact displacement of a force-driven ideal run minus the drive law's, sampled every FIT_STEP samples (m)."""
    return (data["sensors/contact_displacement"] - law["sensors/contact_displacement"])[::FIT_STEP]


def calibrate(folder, law):
    """Least squares of the contact displacement, 0–85 ms, over (F0, k, c) ≥ 0 on the ideal mechanism."""
    from scipy.optimize import least_squares

    effort = -law["drivers/hydraulic_drive/effort"]  # in the stroke direction
    drive = -(law["bodies/driving_link/q"][:, 0] - law["bodies/driving_link/q"][0, 0])
    start = (effort[0], (effort[0] - effort[-2]) / drive[-2], 500.0)  # the law's start force, its end-to-end slope
    runs = iter(range(10**6))

    def misfit(scaled):
        parameters = np.multiply(scaled, SCALES)
        path = run_case(folder, f"fit-{next(runs):03d}", (*actuator_overrides(*parameters), *IDEAL))
        data = read_result(path)
        path.unlink()
        return residual(data, law) * 1e3  # mm

    fit = least_squares(misfit, np.divide(start, SCALES), bounds=(0, np.inf), diff_step=1e-3)
    parameters = np.multiply(fit.x, SCALES)
    print(f"(calibration: least squares over (F0, k, c) ≥ 0 from F0 = {start[0]:.0f} N, k = {start[1]:.0f} N/m, "
          f"c = {start[2]:.0f} N·s/m, {fit.nfev} runs: F0 = {parameters[0]:.1f} N, k = {parameters[1]:.1f} N/m, "
          f"c = {parameters[2]:.3g} N·s/m, RMS residual {np.sqrt(np.mean(fit.fun**2)):.3f} mm)")
    rounded = [float(f"{value:.{DIGITS}g}") if value > 1e-3 else 0.0 for value in parameters]
    stored = [CALIBRATED["preload_N"], CALIBRATED["stiffness_N_m"], CALIBRATED["damping_N_s_m"]]
    if rounded != stored:
        sys.exit(f"tests/support/uhv_actuator.py CALIBRATED {stored} is not the fit rounded to {DIGITS} digits "
                 f"{rounded}: update it")
    print(f"(tests/support/uhv_actuator.py CALIBRATED = the fit rounded to {DIGITS} digits)")


def write_effort_history(law, target):
    """The drive law's effort on the ideal mechanism as a CSV force history (t = 85 ms left out: the law's end)."""
    np.savetxt(target, np.column_stack([law["time"][:-1], law["drivers/hydraulic_drive/effort"][:-1]]),
               delimiter=",", header="t,effort", comments="", fmt="%.9g")


def print_calibration(ideals, law):
    """How closely each force drive moves the ideal mechanism like the drive law."""
    ideal = ideals["actuator"]
    force = actuator_force(ideal, CALIBRATED["preload_N"], CALIBRATED["stiffness_N_m"], CALIBRATED["damping_N_s_m"])
    effort = -law["drivers/hydraulic_drive/effort"][:-1]  # t = 85 ms left out: the law's end
    reverse = np.flatnonzero(force < 0)[0]
    drive = -(ideal["bodies/driving_link/q"][:, 0] - ideal["bodies/driving_link/q"][0, 0])
    print(f"Actuator: F0 = {CALIBRATED['preload_N'] / 1e3:.2f} kN, k = {CALIBRATED['stiffness_N_m'] / 1e3:.1f} kN/m, "
          f"c = {CALIBRATED['damping_N_s_m']:.0f} N·s/m; the force reverses (cushion) at x = "
          f"{CALIBRATED['preload_N'] / CALIBRATED['stiffness_N_m'] * 1e3:.0f} mm of the driving link's "
          f"{drive[-1] * 1e3:.0f} mm ({ideal['time'][reverse] * 1e3:.1f} ms) and ends at {force[-1] / 1e3:+.1f} kN; "
          f"the drive law's effort runs {effort.max() / 1e3:+.1f} … {effort.min() / 1e3:+.1f} kN\n")
    runs = (*(ideals[drive] for drive in DRIVE_NAMES), law)

    def error_mm(data):
        return (data["sensors/contact_displacement"] - law["sensors/contact_displacement"]) * 1e3

    rows = [("contact displacement: RMS / max \\|x − x_law\\|, 0–85 ms (mm)",
             *(f"{np.sqrt(np.mean(error_mm(d)**2)):.2f} / {np.max(np.abs(error_mm(d))):.2f}" for d in runs[:-1]), "—"),
            ("contact displacement at 85 ms (mm)", *(f"{d['sensors/contact_displacement'][-1] * 1e3:.1f}" for d in runs)),
            ("contact velocity at 85 ms (m/s)", *(f"{d['sensors/contact_velocity'][-1]:.3f}" for d in runs))]
    rows += [(MOTION_LABELS[key], *(format(motion(d)[key], MOTION_FORMATS[key]) for d in runs)) for key in MOTION_LABELS]
    print("| ideal mechanism | " + " | ".join(DRIVE_NAMES.values()) + " | drive law (eq. 16) |\n|---|---|---|---|")
    for row in rows:
        print("| " + " | ".join(row) + " |")


def calibration_figure(ideals, law):
    figure, axes = new_figure(1, 3, (11.0, 3.4))
    ideal = ideals["actuator"]
    force = actuator_force(ideal, CALIBRATED["preload_N"], CALIBRATED["stiffness_N_m"], CALIBRATED["damping_N_s_m"])
    t_ideal, t_law = ideal["time"] * 1e3, law["time"][:-1] * 1e3
    for ax, (key, scale, title) in zip(axes[:2], (("sensors/contact_displacement", 1e3, "contact displacement (mm)"),
                                                 ("sensors/contact_velocity", 1.0, "contact velocity (m/s)"))):
        ax.plot(t_law, law[key][:-1] * scale, color="0.5", lw=2.5, label="drive law (eq. 16)")
        ax.plot(t_ideal, ideal[key] * scale, color="tab:blue", label=DRIVE_NAMES["actuator"])
        ax.plot(ideals["history"]["time"] * 1e3, ideals["history"][key] * scale, "--", color="tab:orange",
                label=DRIVE_NAMES["history"])
        ax.set_title(title, fontsize=9)
    axes[2].plot(t_law, -law["drivers/hydraulic_drive/effort"][:-1] / 1e3, color="0.5", lw=2.5, label="drive law's effort")
    axes[2].plot(t_ideal, force / 1e3, color="tab:blue", label="actuator force")
    axes[2].axhline(0, color="k", lw=0.5)
    axes[2].set_title("force on the driving link, stroke direction (kN)", fontsize=9)
    for ax in axes:
        ax.set_xlabel("t (ms)")
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=7)
    figure.suptitle("Ideal mechanism (A and J without clearance): the two force drives against the drive law",
                    fontsize=9)
    target = FIGURES / "validation-force-drive-calibration.png"
    figure.savefig(target, dpi=100)
    print(f"(wrote {target.relative_to(ROOT)})")


def print_peak_summary(figures):
    """When the peak happens, and how much of m·a J's normal and friction forces make there."""
    runs = [f for mu in MU_D for f in figures[mu]]
    times = np.array([f["t_peak_ms"] for f in runs])
    same = sum(abs(a["t_peak_ms"] - b["t_peak_ms"]) < 0.1 for a, b in zip(figures["0.10"], figures["0.16"]))
    share = np.array([(f["peak_normal"] + f["peak_friction"]) * 1e3 / (MOVING_CONTACT_KG * f["peak"]) for f in runs])
    print(f"\n(the peak is at t = {times.min():.2f} … {times.max():.2f} ms; the same impact at μ_d 0.10 and 0.16 (times "
          f"within 0.1 ms) in {same} of {len(figures['0.10'])} samples; J's normal + friction force along the stroke "
          f"there is {share.min() * 100:.0f} … {share.max() * 100:.0f} % of m·|a| of the moving contact; J's contact "
          f"normal is {min(f['peak_angle'] for f in runs):.0f} … {max(f['peak_angle'] for f in runs):.0f}° off the "
          f"stroke, median {np.median([f['peak_angle'] for f in runs]):.0f}°)")
    change = np.array([(b["peak"] / a["peak"] - 1) * 100 for a, b in zip(figures["0.10"], figures["0.16"])])
    print(f"(μ_d 0.10 → 0.16, peak |a| per sample: {change.min():+.1f} … {change.max():+.1f} %)")
    change = {key: np.array([b[key] - a[key] for a, b in zip(figures["0.10"], figures["0.16"])])
              for key in ("peak_normal", "peak_friction")}
    mass_times_peak = np.array([(b["peak"] - a["peak"]) * MOVING_CONTACT_KG / 1e3 for a, b in zip(figures["0.10"], figures["0.16"])])
    print(f"(μ_d 0.10 → 0.16, at the peak, medians of the paired changes: m·|a| {np.median(mass_times_peak):+.2f} kN, "
          f"of it J's normal force along the stroke {np.median(change['peak_normal']):+.2f} kN, J's friction force "
          f"along the stroke {np.median(change['peak_friction']):+.2f} kN "
          f"[IQR {np.percentile(change['peak_friction'], 25):+.2f}, {np.percentile(change['peak_friction'], 75):+.2f}])")


def main():
    arguments = sys.argv[1:]
    folder, samples = command_line(arguments, "/tmp/clearsim-force-drive-ensemble")
    law = read_result(run_case(folder, "ideal-drive-law", IDEAL))
    if "--calibrate" in arguments:
        calibrate(folder, law)
    history = folder / "drive-law-effort.csv"
    write_effort_history(law, history)
    bases = {"actuator": FORCE_DRIVE, "history": effort_history_overrides(history)}
    ideals, results = {}, {}
    for drive, base in bases.items():
        (folder / drive).mkdir(exist_ok=True)
        print(f"{DRIVE_NAMES[drive]}: ", end="")
        ideals[drive], *results[drive] = run_ensemble(folder / drive, samples, base=base, merit=merit)
    print_calibration(ideals, law)
    for drive, (nominal, figures) in results.items():
        print(f"\n### {DRIVE_NAMES[drive]}\n")
        print_distributions(figures, nominal, LABELS_ALL, FORMATS_ALL)
        print_paired(figures, PAIRED_ALL, LABELS_ALL)
        print_peak_summary(figures)
    if "--figures" in arguments:
        calibration_figure(ideals, law)
        nominal, figures = results["actuator"]
        ensemble_figure(figures, nominal, ("peak", "rms_dev", "friction_J", "t_90", "mean_speed", "kinetic_max"),
                        LABELS_ALL, "validation-force-drive-ensemble.png", "Force drive F0 − k x: ")


if __name__ == "__main__":
    main()
