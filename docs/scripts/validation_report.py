"""Print every number of docs/validation.md (cases 1–5) as Markdown tables.

Run from the repository root:

    python docs/scripts/validation_report.py [--figures]

--figures also writes docs/figures/validation-orbit.png (independent model vs clearsim, journal
path over the first crank revolution). Runtime ≈ 32 s on 2 cores (numba kernels cached); no UHV clearance
runs here (they are in docs/scripts/paper_studies.py, cases 5c and 6).

The references are the test-support codes, written separately from the assembler:
tests/support/uhv_loop_closure.py (position analysis of the UHV geometry by circle intersections),
tests/support/impact_reference.py (1-DOF impact, DOP853 rtol 1e-12) and
tests/support/slider_crank_minimal.py (minimal-coordinate Flores slider-crank with clearance).
The mechanism texts of the single-impact and energy cases are those of tests/validation/.
"""

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # tests.support and docs/scripts live outside the package
sys.path.insert(0, str(ROOT / "docs" / "scripts"))

from clearsim.io.hdf5 import read_result  # noqa: E402
from clearsim.model.loader import load_mechanism, load_mechanism_text  # noqa: E402
from clearsim.physics import contact  # noqa: E402
from clearsim.runner import prepare, run_to_file  # noqa: E402
from restitution_table import restitution_table  # noqa: E402
from tests.support import slider_crank_minimal as minimal  # noqa: E402
from tests.support.impact_reference import law_impact  # noqa: E402
from tests.support.uhv_loop_closure import solve_uhv_kinematics  # noqa: E402
from tests.validation.test_energy import CLEARANCE_PENDULUM, DOUBLE_PENDULUM  # noqa: E402
from tests.validation.test_ideal_kinematics import closed_form  # noqa: E402
from tests.validation.test_single_impact import LAWS, impact_yaml, measured_impact  # noqa: E402

CONFIGS = ROOT / "clearsim" / "configs"
SCRIPT = "python docs/scripts/validation_report.py"
WORK = Path(tempfile.mkdtemp(prefix="clearsim-validation-"))
_counter = iter(range(10**6))


def run(source, *overrides):
    """Run a bundled config (file name) or an inline YAML text; return (result dict, run report)."""
    if source.endswith(".yaml") and "\n" not in source:
        loaded = load_mechanism(CONFIGS / source, list(overrides))
    else:
        loaded = load_mechanism_text(source, overrides=list(overrides))
    output = WORK / f"run{next(_counter)}.h5"
    report = run_to_file(prepare(loaded), loaded, output)
    assert report.complete, report.status
    return read_result(output), report


def heading(text):
    print(f"\n### {text}\n")
    print(f"Reproduce: `{SCRIPT}`\n")


# ---- case 1: ideal kinematics ------------------------------------------------------------------

def case_ideal_kinematics():
    heading("Case 1a — ideal slider-crank vs closed form (clearance set to 0, 12 ms, 100 kHz)")
    result, _ = run("slider_crank_flores.yaml", "joints.slider_pin.clearance=0", "solver.t_end=12ms")
    x, v, a = closed_form(result["time"])
    rows = [("slider displacement (m)", result["sensors/slider_displacement"], x - x[0]),
            ("slider velocity (m/s)", result["sensors/slider_velocity"], v),
            ("slider acceleration (m/s²)", result["sensors/slider_acceleration"], a)]
    print("| quantity | range of the exact signal | max abs error | max error / range |")
    print("|---|---|---|---|")
    for name, simulated, exact in rows:
        error = np.max(np.abs(simulated - exact))
        print(f"| {name} | {np.ptp(exact):.4g} | {error:.3e} | {error / np.ptp(exact):.2e} |")
    print(f"\nmax constraint violation {np.max(result['constraints/violation']):.2e}; "
          f"{len(result['time'])} samples")

    heading("Case 1b — ideal UHV breaker vs the independent loop-closure solution (A, J ideal, 85 ms, 20 kHz)")
    result, _ = run("uhv_breaker.yaml", "joints.A.clearance=0", "joints.J.clearance=0", "solver.output_rate=20kHz")
    expected = solve_uhv_kinematics(result["time"])
    pairs = [("contact_displacement", "moving_contact_displacement", "m"),
             ("contact_velocity", "moving_contact_velocity", "m/s"),
             ("contact_acceleration", "moving_contact_acceleration", "m/s²"),
             ("sealing_rod_displacement", "sealing_rod_displacement", "m"),
             ("turn_arm_angular_velocity", "lower_turn_arm_angular_velocity", "rad/s")]
    print("| clearsim sensor | range of the reference | max abs error | max error / range |")
    print("|---|---|---|---|")
    for sensor, reference, unit in pairs:
        simulated, exact = result[f"sensors/{sensor}"][:-1], expected[reference][:-1]  # t = 85 ms: drive jump
        error = np.max(np.abs(simulated - exact))
        print(f"| {sensor} ({unit}) | {np.ptp(exact):.4g} | {error:.3e} | {error / np.ptp(exact):.2e} |")
    acceleration = result["sensors/contact_acceleration"]
    print(f"\nIdeal UHV: stroke {result['sensors/contact_displacement'][-1] * 1e3:.1f} mm, peak velocity "
          f"{np.max(result['sensors/contact_velocity']):.3f} m/s, peak |acceleration| "
          f"{np.max(np.abs(acceleration[:-1])):.1f} m/s² (before the drive stops at 85 ms), "
          f"max constraint violation {np.max(result['constraints/violation']):.2e}.")
    return result


# ---- case 2: single impact ---------------------------------------------------------------------

def case_single_impact():
    heading("Case 2a — single impact in the full solver vs the 1-DOF reference (K = 1e10 N/m^1.5, m = 1 kg, "
            "δ̇⁻ = 1 m/s)")
    print("| law | nominal c_e | clearsim restitution | reference restitution | rel. diff | clearsim contact time (µs) "
          "| reference (µs) | rel. diff |")
    print("|---|---|---|---|---|---|---|---|")
    for law in sorted(LAWS):
        for nominal in ((1.0,) if law == "hertz" else (0.5, 0.8, 0.9)):
            measured, duration, _ = measured_impact(run(impact_yaml(law, nominal))[0])
            reference = law_impact(LAWS[law], nominal, stiffness=1e10, mass=1.0, impact_speed=1.0)
            print(f"| {law} | {nominal} | {measured:.6f} | {reference.restitution:.6f} "
                  f"| {measured / reference.restitution - 1:.1e} | {duration * 1e6:.4f} "
                  f"| {reference.contact_time * 1e6:.4f} | {duration / reference.contact_time - 1:.1e} |")

    heading("Case 2b — effective vs nominal restitution of each law (1-DOF reference; same table as "
            "docs/model-contact.md, from docs/scripts/restitution_table.py)")
    print(restitution_table())

    heading("Case 2c — Hertz (c_e = 1) impact in the full solver vs the closed form")
    mass, stiffness, speed = 1.0, 1e10, 1.0
    result = run(impact_yaml("hertz", 1.0, stiffness, mass, speed))[0]
    _, duration, _ = measured_impact(result)
    rows = [("max penetration (µm)", np.max(result["joints/O/penetration"]) * 1e6,
             contact.hertz_max_penetration(mass, stiffness, speed) * 1e6),
            ("peak force (N)", np.max(result["joints/O/normal_force"]),
             contact.hertz_peak_force(mass, stiffness, speed)),
            ("contact duration (µs)", duration * 1e6, contact.hertz_contact_time(mass, stiffness, speed) * 1e6)]
    print("| quantity | clearsim | closed form | rel. diff |")
    print("|---|---|---|---|")
    for name, mine, exact in rows:
        print(f"| {name} | {mine:.6g} | {exact:.6g} | {mine / exact - 1:.1e} |")
    print("\nPeaks are read from output samples t_H/400 apart (at most ½(π/800)² ≈ 8e-6 below the true peak); "
          "the duration comes from the located contact events.")


# ---- case 3: energy ----------------------------------------------------------------------------

def case_energy():
    heading("Case 3 — energy of free (undriven) mechanisms")
    print("| case | impacts | max kinetic energy (J) | max drift of T + V (J) | drift / max T | written dissipation (J) "
          "| max balance error (J) | balance error / dissipation |")
    print("|---|---|---|---|---|---|---|---|")
    result = run(DOUBLE_PENDULUM)[0]
    energy = result["energy/kinetic"] + result["energy/potential"]
    scale = np.max(result["energy/kinetic"])
    drift = np.max(np.abs(energy - energy[0]))
    print(f"| ideal double pendulum, 5 s | 0 | {scale:.4g} | {drift:.2e} | {drift / scale:.1e} | — | — | — |")
    result = run(CLEARANCE_PENDULUM)[0]
    energy = result["energy/kinetic"] + result["energy/potential"]  # potential includes the contact potential
    scale = np.max(result["energy/kinetic"])
    drift = np.max(np.abs(energy - energy[0]))
    impacts = len(result["joints/O/episodes/onset"])
    print(f"| pendulum, pivot clearance 0.1 mm, Hertz c_e = 1, μ = 0, 0.4 s | {impacts} | {scale:.4g} | {drift:.2e} "
          f"| {drift / scale:.1e} | {result['energy/contact_dissipated'][-1]:.1e} | — | — |")
    for label, friction in (("LN c_e = 0.7, μ = 0", "{law: none}"),
                            ("LN c_e = 0.7, stiction step μ_s 0.2 / μ_d 0.15",
                             "{law: stiction_step, mu_s: 0.2, mu_d: 0.15, v_s: 1e-4 m/s, v_d: 1e-2 m/s}")):
        text = CLEARANCE_PENDULUM.replace("law: hertz, restitution: 1.0", "law: lankarani_nikravesh, restitution: 0.7")
        text = text.replace("  contact:", f"  friction: {friction}\n  contact:")
        result = run(text)[0]
        lost = result["energy/contact_dissipated"][-1] + result["energy/friction_dissipated"][-1]
        error = np.max(np.abs(result["energy/balance_error"]))
        print(f"| pendulum, 0.1 mm, {label}, 0.4 s | {len(result['joints/O/episodes/onset'])} "
              f"| {np.max(result['energy/kinetic']):.4g} | — | — | {lost:.4e} | {error:.1e} | {error / lost:.1e} |")
    print("\nbalance error = (T + V)(t) − (T + V)(0) + written dissipation(t) − work of drivers(t).")


# ---- case 4: independent formulation -----------------------------------------------------------

JOINT = "joints/slider_pin"
TOLERANCES = ("solver.rtol=1e-10", "solver.atol=1e-13")


def case_independent(figures):
    heading("Case 4 — clearsim vs the independent minimal-coordinate slider-crank (Flores, c = 0.5 mm, "
            "5000 rpm; clearsim rtol 1e-10, reference DOP853 rtol 1e-11)")
    print("| case | first onset, clearsim (ms) | \\|Δ onset\\| (s) | δ̇⁻ (m/s) | rel. Δ δ̇⁻ | peak F_n first impact (N) "
          "| rel. Δ peak | episodes in rev. 1 | max \\|Δ onset\\| rev. 1 (ns) | max \\|Δe\\|/c rev. 1 | max \\|Δe\\|/c 24 ms |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    orbits = {}
    for name, config, parameters in (("frictionless", "slider_crank_flores.yaml", minimal.FRICTIONLESS),
                                     ("Ambrósio friction μ_d = 0.01", "slider_crank_flores_friction.yaml",
                                      minimal.FRICTION)):
        reference = minimal.simulate(parameters)
        full = run(config, *TOLERANCES, "solver.output_rate=1MHz")[0]
        first = run(config, *TOLERANCES, "solver.t_end=0.4ms", "solver.output_rate=20MHz")[0]
        mine = reference.episodes[0]
        onsets, speeds = full[f"{JOINT}/episodes/onset"], full[f"{JOINT}/episodes/impact_speed"]
        window = (first["time"] >= mine.onset) & (first["time"] <= mine.loss)
        peak = np.max(first[f"{JOINT}/normal_force"][window])
        turn = [e for e in reference.episodes if e.onset < 0.012]
        onset_error = np.max(np.abs(onsets[:len(turn)] - [e.onset for e in turn]))
        times = full["time"]
        ref_path = reference.histories(times)["eccentricity"]
        deviation = np.linalg.norm(full[f"{JOINT}/eccentricity"] - ref_path, axis=1) / parameters.clearance
        first_turn = times <= 0.012
        print(f"| {name} | {onsets[0] * 1e3:.6f} | {abs(onsets[0] - mine.onset):.1e} | {speeds[0]:.4f} "
              f"| {abs(speeds[0] / mine.impact_speed - 1):.1e} | {peak:.0f} | {abs(peak / mine.peak_normal_force - 1):.1e} "
              f"| {len(turn)} | {onset_error * 1e9:.1f} | {np.max(deviation[first_turn]):.1e} "
              f"| {np.max(deviation):.1e} |")
        orbits[name] = (times[first_turn], full[f"{JOINT}/eccentricity"][first_turn], ref_path[first_turn],
                        parameters.clearance)
        if name == "frictionless":
            stats = (len(onsets), len(reference.episodes),
                     np.sqrt(np.mean(full[f"{JOINT}/normal_force"] ** 2)),
                     np.sqrt(np.mean(reference.histories(times)["normal_force"] ** 2)))
    print(f"\nFrictionless, whole 24 ms (chaotic after ~12 ms, compared statistically): episodes clearsim "
          f"{stats[0]} vs reference {stats[1]}; normal-force RMS (1 MHz samples) {stats[2]:.0f} N vs {stats[3]:.0f} N "
          f"({stats[2] / stats[3] - 1:+.1%}).")
    if figures:
        orbit_figure(orbits)


def orbit_figure(orbits):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(orbits), figsize=(8, 4), dpi=100)
    circle = np.linspace(0, 2 * np.pi, 400)
    for ax, (name, (_, path, ref_path, clearance)) in zip(axes, orbits.items()):
        ax.plot(np.cos(circle), np.sin(circle), color="0.7", lw=0.8)
        ax.plot(ref_path[:, 0] / clearance, ref_path[:, 1] / clearance, color="tab:blue", lw=2.5, label="independent model")
        ax.plot(path[:, 0] / clearance, path[:, 1] / clearance, color="tab:orange", lw=1.2, label="clearsim")
        ax.set_aspect("equal")
        ax.set_title(f"{name}\nfirst revolution (12 ms)", fontsize=9)
        ax.set_xlabel("e_x / c")
        ax.set_ylabel("e_y / c")
        ax.set_xlim(-1.15, 1.15)
        ax.set_ylim(-1.15, 1.15)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=2)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    target = ROOT / "docs" / "figures" / "validation-orbit.png"
    fig.savefig(target)
    print(f"\n(wrote {target.relative_to(ROOT)})")


# ---- case 5: convergence -----------------------------------------------------------------------

def case_convergence():
    heading("Case 5a — tolerance: Flores slider-crank, 24 ms, 100 kHz output (first impact compared exactly, "
            "the chaotic rest statistically)")
    print("| config | rtol | steps | peak F_n, located (N) | rel. to 1e-11 | peak \\|slider acc.\\| (m/s²) "
          "| slider-acc. RMS (m/s²) | rel. to 1e-11 | episodes | first onset (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for config in ("slider_crank_flores.yaml", "slider_crank_flores_friction.yaml"):
        rows = []
        for rtol in (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11):
            result, report = run(config, f"solver.rtol={rtol}")
            acceleration = result["sensors/slider_acceleration"]
            rows.append((rtol, report.statistics.steps, report.statistics.peak_normal_force[0],
                         np.max(np.abs(acceleration)), np.sqrt(np.mean(acceleration**2)),
                         len(result[f"{JOINT}/episodes/onset"]), result[f"{JOINT}/episodes/onset"][0]))
        best = rows[-1]
        for rtol, steps, force, peak_acc, rms, count, onset in rows:
            label = f"{rtol:.0e}" + (" (default)" if rtol == 1e-7 else "")
            print(f"| {config.removesuffix('.yaml')} | {label} | {steps} | {force:.1f} | {force / best[2] - 1:+.1e} "
                  f"| {peak_acc:.4g} | {rms:.1f} | {rms / best[4] - 1:+.1e} | {count} | {onset * 1e3:.7f} |")

    heading("Case 5b — output rate: the same run (default rtol) sampled at different rates; "
            "peaks read from samples vs located on the continuous extension")
    print("| output rate | steps | peak F_n, samples (N) | peak F_n, located (N) | samples / located − 1 "
          "| peak \\|slider acc.\\|, samples (m/s²) |")
    print("|---|---|---|---|---|---|")
    for rate in ("100kHz", "1MHz", "10MHz"):
        result, report = run("slider_crank_flores.yaml", f"solver.output_rate={rate}", "solver.t_end=2ms")
        sampled, located = np.max(result[f"{JOINT}/normal_force"]), report.statistics.peak_normal_force[0]
        print(f"| {rate} | {report.statistics.steps} | {sampled:.1f} | {located:.1f} | {sampled / located - 1:+.1e} "
              f"| {np.max(np.abs(result['sensors/slider_acceleration'])):.4g} |")
    print("\n(first 2 ms, which hold the largest impact; the integration does not depend on the output rate — "
          "samples come from the continuous extension of each step.)")


def main():
    figures = "--figures" in sys.argv
    started = time.perf_counter()
    for case in (case_ideal_kinematics, case_single_impact, case_energy,
                 lambda: case_independent(figures), case_convergence):
        t0 = time.perf_counter()
        case()
        print(f"\n<!-- {time.perf_counter() - t0:.1f} s -->", file=sys.stderr)
    print(f"\n_Total runtime {time.perf_counter() - started:.0f} s._")


if __name__ == "__main__":
    main()
