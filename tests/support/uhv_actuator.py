"""A force-driven variant of the UHV model (docs/validation.md §6, "Force-driven variant").

The bundled ``clearsim/configs/uhv_breaker.yaml`` prescribes the driving link's motion (paper eq. 16), so the
drive supplies whatever friction takes. The variant removes that driver and loads the driving link with one
``spring_damper`` along its guide, between a ground point 5 m to the left of A on the drive axis (y = −0.222 m)
and the driving link's point A. The guide keeps the line on the axis, so with x the stroke of the driving link
(positive to the left, the stroke direction) the actuator force in the stroke direction is

    F(x, ẋ) = F0 − k x − c ẋ          (preload F0, stiffness k, damping c)

an idealised hydraulic drive: a supply force F0 that accelerates the mechanism, falling linearly along the stroke
and reversing past x = F0/k into the braking of an end-of-stroke cushion, with an optional flow-limited damper c.
Its parameters are calibrated once, on the ideal mechanism (A and J without clearance), to the moving contact's
displacement under the bundled drive law: ``python3 docs/scripts/force_drive_ensemble.py --calibrate`` (least
squares over 0–85 ms; the fit puts c on its bound 0). CALIBRATED holds that fit, rounded to 4 digits.
crossing_time and mean_speed measure the stroke's motion for the script and tests/validation/test_force_drive.py.

The second force drive, EFFORT_HISTORY, applies a force history instead: the drive law's own effort on the ideal
mechanism, written by the script to a CSV file and applied open-loop (a `tabulated` force on the driving link at A
along its guide). It moves the ideal mechanism along the drive law by construction and does not respond to the
mechanism's state at all.

Everything here is `--set` overrides on the bundled file; clearsim itself is not changed.
"""

import numpy as np

ANCHOR_OFFSET_M = 5.0  # ground end of the actuator line, this far to the left of A on the drive axis
A_POINT = (0.095, -0.222)  # point A of configs/uhv_breaker.yaml, on the drive axis

# Least-squares fit on the ideal mechanism (docs/scripts/force_drive_ensemble.py --calibrate), rounded
CALIBRATED = {"preload_N": 20300.0, "stiffness_N_m": 182900.0, "damping_N_s_m": 0.0}


def actuator_overrides(preload_N, stiffness_N_m, damping_N_s_m=0.0):
    """The `--set` overrides that replace the bundled drive law by the actuator force F0 − k x − c ẋ."""
    anchor = f"[{A_POINT[0] - ANCHOR_OFFSET_M:.3f} m, {A_POINT[1]:.3f} m]"
    return ("drivers=[]",
            ("forces=[{type: spring_damper, name: actuator, bodies: [ground, driving_link], "
             f"at: [{anchor}, A], stiffness: {stiffness_N_m:.6g} N/m, damping: {damping_N_s_m:.6g} N*s/m, "
             f"preload: {preload_N:.6g} N}}]"))


STROKE = 0.300  # m: the moving contact's stroke under the drive law (docs/uhv-geometry.md)


def crossing_time(result, fraction):
    """First time (s) the moving contact reaches `fraction` of STROKE, interpolated between samples; nan if never."""
    x, t = result["sensors/contact_displacement"], result["time"]
    above = np.flatnonzero(x >= fraction * STROKE)
    if not above.size:
        return float("nan")
    i = int(above[0])
    return float(np.interp(fraction * STROKE, x[i - 1:i + 1], t[i - 1:i + 1]))


def mean_speed(result):
    """Mean speed of the moving contact between 10 % and 90 % of STROKE (m/s), a breaker's usual contact speed."""
    return 0.8 * STROKE / (crossing_time(result, 0.9) - crossing_time(result, 0.1))


FORCE_DRIVE = actuator_overrides(CALIBRATED["preload_N"], CALIBRATED["stiffness_N_m"], CALIBRATED["damping_N_s_m"])


def effort_history_overrides(csv_file):
    """The `--set` overrides that replace the bundled drive law by the force history in csv_file (absolute path;
    columns t in s and effort in N along +x, the drive law's effort on the ideal mechanism)."""
    return ("drivers=[]",
            ("forces=[{type: tabulated, name: actuator, body: driving_link, point: A, direction: [1, 0], "
             f"file: {csv_file}, time_column: t, value_column: effort}}]"))
