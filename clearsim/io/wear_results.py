"""The Archard wear datasets of a result file (docs/model.md §8, /joints/<name>/wear/...).

Per sample: the deepest point of the accumulated profile (`max_depth`, m) and the worn volume (`volume`, m³). At the
end of the run: the profile on a fixed grid of angles in the bearing's frame (`depth`, m, over `angle`, rad) with its
Fourier coefficients and the law's numbers as attributes.
"""

from __future__ import annotations

import math

import numpy as np

from clearsim.assembly.arrays import CL_CLEARANCE, WEAR_SLOT, WEAR_SLOT_HARMONICS
from clearsim.assembly.dynamics import WORK_COUNT
from clearsim.model.resolve import resolve_clearance
from clearsim.physics.wear import evaluate_profile

PROFILE_ANGLES = 720  # the end profile's grid: every 0.5°
HISTORY_ANGLES = 360  # max_depth per sample: the profile's largest value on a 1° grid


def archard_joints(system) -> list[tuple[int, str, object]]:
    """(index, name, ClearanceParameters) of the clearance joints that accumulate Archard wear."""
    slots = system.arrays.wear_slots
    return [(k, name, resolve_clearance(system.mechanism.joint(name), system.mechanism.defaults))
            for k, name in enumerate(system.clearance_joints) if slots[k, WEAR_SLOT] >= 0]


def accumulated_coefficients(system, k: int, element_states: np.ndarray) -> np.ndarray:
    """The accumulated profile's coefficients [a_0, a_1, b_1, ...] (m) of joint k from the force elements' states
    z (…, nz) (stored over the clearance c)."""
    first, harmonics = system.arrays.wear_slots[k, WEAR_SLOT], system.arrays.wear_slots[k, WEAR_SLOT_HARMONICS]
    return element_states[..., first:first + 2 * harmonics + 1] * system.arrays.clearance_params[k, CL_CLEARANCE]


def profile_basis(harmonics: int, angles: np.ndarray) -> np.ndarray:
    """(2M + 1, angles) rows [1, cos θ, sin θ, cos 2θ, sin 2θ, …]: the depths of many profiles [a_0, a_1, b_1, …] at
    once are coefficients @ basis (one product for a chunk's samples instead of a series per sample)."""
    phases = np.arange(1, harmonics + 1)[:, None] * angles[None, :]
    basis = np.empty((2 * harmonics + 1, len(angles)))
    basis[0], basis[1::2], basis[2::2] = 1.0, np.cos(phases), np.sin(phases)
    return basis


def wear_histories(system, states: np.ndarray) -> dict:
    """{dataset: (values, unit)} of the chunk's samples (states: the solver's y per sample)."""
    out = {}
    grid = np.linspace(0.0, 2.0 * math.pi, HISTORY_ANGLES, endpoint=False)
    z = states[:, 2 * system.coordinate_count + WORK_COUNT:]
    for k, name, parameters in archard_joints(system):
        coefficients = accumulated_coefficients(system, k, z)
        depth = coefficients @ profile_basis((coefficients.shape[1] - 1) // 2, grid)
        out[f"joints/{name}/wear/max_depth"] = (depth.max(axis=1, initial=0.0), "m")
        out[f"joints/{name}/wear/volume"] = (2.0 * math.pi * parameters.bearing_radius * parameters.archard.length
                                             * coefficients[:, 0], "m^3")
    return out


def wear_profile_tables(system, final_state: np.ndarray, time: float) -> dict:
    """{group: (columns, attributes)}: each joint's accumulated profile at the end of the run (time, s)."""
    tables = {}
    angles = np.linspace(0.0, 2.0 * math.pi, PROFILE_ANGLES, endpoint=False)
    z = final_state[2 * system.coordinate_count + WORK_COUNT:]
    for k, name, parameters in archard_joints(system):
        archard = parameters.archard
        coefficients = accumulated_coefficients(system, k, z)
        tables[f"joints/{name}/wear"] = (
            {"depth": (evaluate_profile(coefficients, angles), "m"), "angle": (angles, "rad")},
            {"coefficients_m": coefficients, "time_s": time, "wear_coefficient": archard.coefficient,
             "hardness_Pa": archard.hardness, "length_m": archard.length, "width_m": archard.width,
             "band": "fixed width" if archard.line_stiffness == 0.0 else "load-following (Hertz line contact)",
             "harmonics": archard.harmonics, "law": "Archard: dV = k_w F_n |v_t| dt / H (docs/model-contact.md)",
             "angle_frame": "bearing body's frame, from its x axis"})
    return tables
