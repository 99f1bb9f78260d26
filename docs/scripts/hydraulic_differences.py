"""Where A's start impact goes, prescribed stroke against hydraulic cylinder (docs/validation.md §6, "Force-driven
breaker").

Usage: python docs/scripts/hydraulic_differences.py OUT
where OUT was written by
    python docs/scripts/flexible_studies.py OUT --skip-friction \
        --models prescribed=configs/uhv_breaker.yaml,hydraulic=configs/uhv_breaker_hydraulic.yaml

Window: from A's first contact (first sample with F_n A > 0) to J's first contact (first sample with F_n J > 0).
Printed per clearance and drive:
- the driving link's momentum budget along the drive axis x over the window: its momentum change m Δv, the impulse
  of A's contact force on it (normal and friction), the impulse of the drive's recorded force on it (the cylinder's;
  for the prescribed stroke none is recorded: what is left is the driver's reaction);
- J's first impact speed and the turn arm's angular velocity at J's first contact, A and J against J only, and the
  output's largest |a| over the first 10 ms, A and J against J only;
- under the cylinder, the start delay (forward crossing of 1 % of the ideal's peak speed, as flexible_studies.py),
  the delay predicted from the output's velocity deviation at the ideal's crossing, −(v − v_threshold)/a_ideal, and
  the range of v − v_ideal within ±1 ms of the crossing;
- under the cylinder, over the contact-zone window (the output from 200 to 250 mm): the output's, the driving
  link's and the turn arm's mean speeds and the chambers' mean pressures, ideal against A and J at 0.1 mm;
- under the cylinder, where that difference comes from (zone_transient): when the cylinder's net force on the link
  first changes sign (the load reversal at A) and A's free flights after it, the output's speed against the ideal's
  at the same travel along the stroke, the zone's mean speed for windows shifted by ±10 mm, and the kinetic-energy
  change, the cylinder's work and the friction work over the zone.
"""
import sys
from pathlib import Path

import h5py
import numpy as np

from clearsim.sweep.figures import start_time

DRIVING_LINK_MASS = 3.670  # kg, both files
CLEARANCES = ("0.01", "0.03", "0.05", "0.1")
MODELS = ("prescribed", "hydraulic")
FIRST_MILLISECONDS = 0.010  # s
DELAY_FRACTION = 0.01  # of the ideal's peak speed
DEVIATION_WINDOW = 0.001  # s either side of the crossing
SPEED_ZONE = (0.200, 0.250)  # m of output travel, the hydraulic file's travel: speed_zone
AFTER_START = 0.020  # s: past the start's pull-back, where the cylinder's force also changes sign


def first_contact_index(normal_force):
    return int(np.argmax(normal_force > 0))


def contact_force_on_bearing_x(result):
    """x-component of A's contact force on its bearing (the driving link): normal along the eccentricity
    (journal centre − bearing centre), friction along its right-hand perpendicular (checked: m a_x = this − cylinder force, sample by sample)."""
    eccentricity = result["joints/A/eccentricity"][:]
    length = np.hypot(eccentricity[:, 0], eccentricity[:, 1])
    safe_length = np.where(length > 0, length, 1.0)
    normal_x = eccentricity[:, 0] / safe_length
    tangent_x = eccentricity[:, 1] / safe_length
    return result["joints/A/normal_force"][:] * normal_x + result["joints/A/friction_force"][:] * tangent_x


def momentum_budget(path):
    with h5py.File(path, "r") as result:
        time = result["time"][:]
        start = first_contact_index(result["joints/A/normal_force"][:])
        stop = first_contact_index(result["joints/J/normal_force"][:])
        window = slice(start - 1, stop + 1)
        velocity = result["bodies/driving_link/qd"][:, 0]
        contact_impulse = np.trapezoid(contact_force_on_bearing_x(result)[window], time[window])
        drive_impulse = 0.0
        if "drives/operating_cylinder/force" in result:  # recorded as the force on ground: the link feels −force
            drive_impulse = -np.trapezoid(result["drives/operating_cylinder/force"][window], time[window])
        return {
            "window (ms)": f"{time[start - 1] * 1e3:.2f}-{time[stop] * 1e3:.2f}",
            "v before (m/s)": velocity[start - 1],
            "v after (m/s)": velocity[stop],
            "m dv (N s)": DRIVING_LINK_MASS * (velocity[stop] - velocity[start - 1]),
            "A impulse (N s)": contact_impulse,
            "cylinder impulse (N s)": drive_impulse,
        }


def j_closing(path):
    with h5py.File(path, "r") as result:
        time = result["time"][:]
        closing = first_contact_index(result["joints/J/normal_force"][:])
        return {
            "J impact speed (m/s)": result["joints/J/episodes/impact_speed"][0],
            "turn arm omega (rad/s)": result["sensors/turn_arm_angular_velocity"][closing],
            "output peak 0-10 ms (m/s^2)": np.abs(result["sensors/contact_acceleration"][time <= FIRST_MILLISECONDS]).max(),
        }


def start_delay_phase(path, ideal_path):
    with h5py.File(ideal_path, "r") as ideal:
        ideal_time = ideal["time"][:]
        ideal_velocity = ideal["sensors/contact_velocity"][:]
    threshold = DELAY_FRACTION * ideal_velocity.max()
    ideal_crossing = start_time(ideal_time, ideal_velocity, threshold, 1.0)
    ideal_acceleration = np.interp(ideal_crossing, ideal_time, np.gradient(ideal_velocity, ideal_time))
    with h5py.File(path, "r") as result:
        time = result["time"][:]
        velocity = result["sensors/contact_velocity"][:]
    crossing = start_time(time, velocity, threshold, 1.0)
    near = np.abs(time - crossing) < DEVIATION_WINDOW
    deviation = velocity[near] - np.interp(time[near], ideal_time, ideal_velocity)
    return {
        "crossing (ms)": crossing * 1e3,
        "delay (ms)": (crossing - ideal_crossing) * 1e3,
        "a_ideal (m/s^2)": ideal_acceleration,
        "predicted (ms)": -(np.interp(ideal_crossing, time, velocity) - threshold) / ideal_acceleration * 1e3,
        "v - v_ideal min (m/s)": deviation.min(),
        "v - v_ideal max (m/s)": deviation.max(),
    }


def crossing_time(time, travel, level):
    k = int(np.argmax(travel >= level))
    return time[k - 1] + (level - travel[k - 1]) / (travel[k] - travel[k - 1]) * (time[k] - time[k - 1])


def zone_means(path):
    with h5py.File(path, "r") as result:
        time = result["time"][:]
        travel = result["sensors/contact_displacement"][:] - result["sensors/contact_displacement"][0]
        enter, leave = (crossing_time(time, travel, level) for level in SPEED_ZONE)
        zone = (time >= enter) & (time <= leave)
        link_position = result["bodies/driving_link/q"][:, 0]
        cylinder = result["drives/operating_cylinder"]
        return {
            "zone (ms)": f"{enter * 1e3:.3f}-{leave * 1e3:.3f}",
            "output (m/s)": (SPEED_ZONE[1] - SPEED_ZONE[0]) / (leave - enter),
            "driving link (m/s)": abs(np.interp(leave, time, link_position) - np.interp(enter, time, link_position))
            / (leave - enter),
            "turn arm (rad/s)": result["sensors/turn_arm_angular_velocity"][zone].mean(),
            "supply (bar)": cylinder["supply_pressure"][zone].mean() / 1e5,
            "piston chamber (bar)": cylinder["piston_pressure"][zone].mean() / 1e5,
            "rod chamber (bar)": cylinder["rod_pressure"][zone].mean() / 1e5,
        }


def _zone_energies(time, travel, result):
    """Kinetic-energy change, cylinder work and joint-friction work over the contact zone (J)."""
    enter, leave = (int(np.argmax(travel >= level)) for level in SPEED_ZONE)
    cylinder = result["drives/operating_cylinder"]
    window = slice(enter, leave + 1)
    kinetic = result["energy/kinetic"][:]
    friction = result["energy/friction_dissipated"][:]
    return {"kinetic change (J)": kinetic[leave] - kinetic[enter],
            "cylinder work (J)": float(np.trapezoid(cylinder["force"][window], cylinder["stroke"][window])),
            "friction work (J)": friction[leave] - friction[enter]}


def load_reversal(time, travel, force):
    """Index of the first sign change of the cylinder's net force after the start, before the contact's 299 mm."""
    after_start = time > AFTER_START
    pushing = np.sign(force[int(np.argmax(after_start))])
    return int(np.argmax((time < crossing_time(time, travel, 0.299)) & after_start & (np.sign(force) != pushing)))


def zone_transient(path, ideal_path):
    """The load reversal at A and the output's speed along the stroke against the ideal's (at equal travel)."""
    with h5py.File(ideal_path, "r") as ideal:
        ideal_time = ideal["time"][:]
        ideal_travel = ideal["sensors/contact_displacement"][:]
        ideal_speed = ideal["sensors/contact_velocity"][:]
        ideal_energies = _zone_energies(ideal_time, ideal_travel, ideal)
        ideal_reversal = ideal_time[load_reversal(ideal_time, ideal_travel, ideal["drives/operating_cylinder/force"][:])]
    with h5py.File(path, "r") as result:
        time = result["time"][:]
        travel = result["sensors/contact_displacement"][:]
        speed = result["sensors/contact_velocity"][:]
        force = result["drives/operating_cylinder/force"][:]
        free_at_a = result["joints/A/mode"][:] == 0
        energies = _zone_energies(time, travel, result)
    stroke = time < crossing_time(time, travel, 0.299)
    reversal = load_reversal(time, travel, force)
    flights = np.flatnonzero(free_at_a & (time > time[reversal]) & (travel < SPEED_ZONE[1]))
    row = {"ideal's reversal (ms)": ideal_reversal * 1e3, "reversal at A (ms)": time[reversal] * 1e3, "output there (mm)": travel[reversal] * 1e3,
           "A's free flights (ms)": f"{time[flights[0]] * 1e3:.2f}-{time[flights[-1]] * 1e3:.2f}" if flights.size else "none",
           "output there (mm) ": f"{travel[flights[0]] * 1e3:.0f}-{travel[flights[-1]] * 1e3:.0f}" if flights.size else "-"}
    ideal_stroke = ideal_time < crossing_time(ideal_time, ideal_travel, 0.299)
    for level in np.arange(0.170, 0.271, 0.010):
        ratio = (np.interp(level, travel[stroke], speed[stroke])
                 / np.interp(level, ideal_travel[ideal_stroke], ideal_speed[ideal_stroke]) - 1.0)
        row[f"speed at {level * 1e3:.0f} mm (%)"] = ratio * 100.0
    for shift in (-0.010, 0.0, 0.010):
        low, high = SPEED_ZONE[0] + shift, SPEED_ZONE[1] + shift
        duration = crossing_time(time, travel, high) - crossing_time(time, travel, low)
        ideal_duration = (crossing_time(ideal_time, ideal_travel, high)
                          - crossing_time(ideal_time, ideal_travel, low))
        row[f"zone {low * 1e3:.0f}-{high * 1e3:.0f} mm speed (%)"] = (ideal_duration / duration - 1.0) * 100.0
    row.update({f"{key}, difference": energies[key] - ideal_energies[key] for key in energies})
    return row


def formatted(row):
    return ", ".join(f"{key} {value:+.3f}" if isinstance(value, float) else f"{key} {value}" for key, value in row.items())


def main(out_directory):
    out = Path(out_directory)
    print("Driving link's momentum along x, A's first contact -> J's first contact (A and J cases):")
    for clearance in CLEARANCES:
        for model in MODELS:
            print(f"  {clearance} mm {model}: {formatted(momentum_budget(out / f'{model}-A-and-J-{clearance}-mm.h5'))}")
    print("J's first closing, A and J / J only:")
    for clearance in CLEARANCES:
        for model in MODELS:
            both = j_closing(out / f"{model}-A-and-J-{clearance}-mm.h5")
            j_only = j_closing(out / f"{model}-J-only-{clearance}-mm.h5")
            ratios = {key: float(both[key] / j_only[key]) for key in both}
            print(f"  {clearance} mm {model}: A and J {formatted(both)}; ratio to J only {formatted(ratios)}")
    print("Start delay under the cylinder:")
    for case in ("J-only", "A-and-J"):
        for clearance in CLEARANCES:
            row = start_delay_phase(out / f"hydraulic-{case}-{clearance}-mm.h5", out / "hydraulic-ideal.h5")
            print(f"  {case} {clearance} mm: {formatted(row)}")
    print("Contact zone under the cylinder:")
    for case in ("hydraulic-ideal", "hydraulic-A-and-J-0.1-mm"):
        print(f"  {case}: {formatted(zone_means(out / f'{case}.h5'))}")
    print("Where the zone's difference comes from, A and J at 0.1 mm against the ideal:")
    print(f"  {formatted(zone_transient(out / 'hydraulic-A-and-J-0.1-mm.h5', out / 'hydraulic-ideal.h5'))}")


if __name__ == "__main__":
    main(sys.argv[1])
