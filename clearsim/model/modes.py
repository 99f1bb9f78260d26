"""Which modes of the flexible links lie near the contact frequencies (docs/model.md §9, "Modes near the
contacts", and §10).

Axial mode of a flexible link: f = √(k / m_eff) / 2π, k its `<body>_compliance` stiffness and 1/m_eff the mobility
of its slide `<body>_stretch`: the stretch acceleration s̈ = gᵀ A g per unit pair of opposite forces along the link
(g: the stretch's row, ṡ = gᵀ q̇; A: the constrained response M q̈ + Φ_qᵀ λ = Q, Φ_q q̈ = γ) in the model at t = 0,
with every clearance joint closed (an ideal pin) and every other flexible link's slide held. With the link's spring
the only stiffness this is the exact linear mode at t = 0; for the free link m_eff = m/4, for a link fixed at one end
carrying a mass M at the other m_eff = M + m/2.

Bending mode of a beam link (and, in a model with beam links, the axial mode of an axial link): the model at t = 0
with every clearance joint closed, linearised (M_r = Tᵀ M T, K_r = Tᵀ ∇²V T, T an orthonormal basis of the null
space of Φ_q, V the compiled potential energy; the constraint forces' geometric stiffness left out); a mode belongs
to the flexible link whose springs (bending springs, or axial spring) store the largest share of its strain
energy; the link's lowest such mode is reported, and its MODES_REPORTED lowest up to √2 × the highest contact
frequency.

Contact frequency of a clearance joint: 1/(2 t_c), t_c the Hertz contact duration of its contact episodes at their
own impact speed and effective mass (their 5th–95th percentile range), or of an impact at 1 m/s with the reduced
mass of its two bodies when it made no contact. Whirl frequency: the mean orbit rate of each of its whirls.

A mode is *near* a frequency range [f₁, f₂] when it lies within a factor NEAR_FACTOR of it: f₁/√2 ≤ f ≤ √2 f₂.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from clearsim.whirl import hertz_text

NEAR_FACTOR = math.sqrt(2.0)  # half an octave: a mode √2 above a forcing frequency transmits it with gain 1/(r² − 1)
# ≤ 1 (the classical isolation limit), √2 below with gain 1/(1 − r²) ≤ 2; within the band it amplifies it
MODES_REPORTED = 3  # per link: its lowest modes up to the contacts' band (the linearised model gives them at no cost)
CONTACT_PERCENTILES = (5.0, 95.0)  # the range of the contacts' frequencies: most contacts, not a stray one


@dataclass(frozen=True)
class JointFrequencies:
    joint: str
    contacts: tuple[float, float]  # Hz: lowest, highest 1/(2 t_c)
    whirls: tuple[float, ...]  # Hz: the mean orbit rate of each whirl


def near(mode: float, lowest: float, highest: float, factor: float = NEAR_FACTOR) -> bool:
    """Whether a mode (Hz) lies within `factor` of the range [lowest, highest] (Hz)."""
    return lowest / factor <= mode <= highest * factor


def _closed_clearances(mechanism):
    """The mechanism with every clearance joint an ideal pin."""
    joints = [joint.model_copy(update={"clearance": None, "journal_radius": None})
              if getattr(joint, "clearance", None) or getattr(joint, "journal_radius", None) else joint
              for joint in mechanism.joints]
    return mechanism.model_copy(update={"joints": joints})


def _stretch_row(body_names: list[str], q: np.ndarray, spring) -> np.ndarray:
    """g with ṡ = gᵀ q̇: the rate at which the spring's two ends (global points at t = 0) part along their line."""
    near_point, far_point = (np.asarray(point, dtype=float) for point in spring.at)
    axis = (far_point - near_point) / np.linalg.norm(far_point - near_point)
    row = np.zeros(q.size)
    for body, point, sign in ((spring.bodies[0], near_point, -1.0), (spring.bodies[1], far_point, 1.0)):
        index = body_names.index(body)
        arm = point - q[3 * index:3 * index + 2]
        row[3 * index:3 * index + 3] += sign * np.array([axis[0], axis[1], arm[0] * axis[1] - arm[1] * axis[0]])
    return row


def stretch_mobilities(system, springs: list) -> np.ndarray:
    """C (L × L, 1/kg): stretch acceleration of each slide per unit pair of opposite forces along each link, in the
    constrained system at its initial configuration, at rest."""
    from clearsim.assembly.arrays import for_kernels
    from clearsim.assembly.dynamics import accelerations

    arrays = for_kernels(system.arrays)
    modes = np.zeros(len(system.clearance_joints), np.int64)
    rest = np.zeros(system.q0.size)
    rows = np.array([_stretch_row(system.body_names, system.q0, spring) for spring in springs]).reshape(-1, rest.size)
    baseline = accelerations(arrays, 0.0, system.q0, rest, rest.copy(), modes)[0]
    responses = [accelerations(arrays, 0.0, system.q0, rest, row.copy(), modes)[0] - baseline for row in rows]
    return rows @ np.array(responses).reshape(-1, rest.size).T


def held_mobility(mobilities: np.ndarray, link: int) -> float:
    """The link's own mobility with every other slide held: C_ii − C_io C_oo⁺ C_oi."""
    others = [k for k in range(len(mobilities)) if k != link]
    coupling = mobilities[link, others]
    return float(mobilities[link, link] - coupling @ np.linalg.pinv(mobilities[np.ix_(others, others)]) @ coupling)


def axial_mode_frequencies(mechanism, links: list[str], base_dir) -> dict[str, float]:
    """Each flexible link's axial mode (Hz), as the module's docstring defines it; NaN for a link whose slide cannot
    move with its clearance joints closed."""
    from clearsim.assembly.system import assemble

    system = assemble(_closed_clearances(mechanism), base_dir)
    springs = [next(force for force in system.mechanism.forces if force.name == f"{link}_compliance") for link in links]
    mobilities = stretch_mobilities(system, springs)
    frequencies = {}
    for k, (link, spring) in enumerate(zip(links, springs)):
        mobility = held_mobility(mobilities, k)
        frequencies[link] = math.sqrt(spring.stiffness * mobility) / (2 * math.pi) if mobility > 0 else math.nan
    return frequencies


def axial_link_modes(mechanism, links: list[str], base_dir) -> dict[str, list[float]]:
    """axial_mode_frequencies as a list of modes per link: the link's spring, one mode (its slide's)."""
    return {link: [mode] for link, mode in axial_mode_frequencies(mechanism, links, base_dir).items()}


def linear_modes(system) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies in Hz, mode shapes as columns of q) of the assembled system linearised at q0, at rest (module
    docstring); the Hessian of V by central differences, exact for the springs' quadratic energy."""
    import scipy.linalg

    from clearsim.assembly.arrays import for_kernels, mass_diagonal
    from clearsim.assembly.constraints import dense_jacobian
    from clearsim.assembly.forces import potential_energy

    arrays = for_kernels(system.arrays)
    basis = scipy.linalg.null_space(dense_jacobian(arrays, system.q0))
    if not basis.shape[1]:
        return np.zeros(0), np.zeros((system.q0.size, 0))
    step = HESSIAN_STEP * np.eye(basis.shape[1])

    def energy(x):
        return potential_energy(arrays, system.q0 + basis @ x)

    stiffness = np.array([[(energy(a + b) - energy(a - b) - energy(b - a) + energy(-a - b)) / (4 * HESSIAN_STEP ** 2)
                           for b in step] for a in step])
    mass = basis.T @ np.diag(mass_diagonal(system.arrays)) @ basis
    eigenvalues, shapes = scipy.linalg.eigh(stiffness, mass)
    return np.sqrt(np.abs(eigenvalues)) / (2 * math.pi), basis @ shapes


HESSIAN_STEP = 1e-5  # of the null-space coordinates (m, rad): small against the links, large against round-off


def strain_energies(system, link: str, shapes: np.ndarray) -> np.ndarray:
    """Per mode shape (column), the energy in the link's springs: ½ Σ k_θ (δθ_j − δθ_i)² of its bending springs
    `<link>_bend<k>`, ½ k (gᵀ δq)² of its axial spring `<link>_compliance`."""
    energy = np.zeros(shapes.shape[1])
    for force in system.mechanism.forces:
        if force.name.startswith(f"{link}_bend") and force.name[len(link) + 5:].isdigit():
            first, second = (3 * system.body_names.index(body) + 2 for body in force.bodies)
            energy += 0.5 * force.stiffness * (shapes[second] - shapes[first]) ** 2
        elif force.name == f"{link}_compliance":
            energy += 0.5 * force.stiffness * (_stretch_row(system.body_names, system.q0, force) @ shapes) ** 2
    return energy


def linearised_link_modes(mechanism, links: list[str], base_dir) -> dict[str, list[float]]:
    """Each flexible link's modes of the linearised model (Hz, ascending): the modes whose strain energy its springs
    hold the largest share of, among `links` (module docstring); a link that holds the largest share of none, the
    coupled mode in which its share is largest (also its owner's)."""
    from clearsim.assembly.system import assemble

    system = assemble(_closed_clearances(mechanism), base_dir)
    frequencies, shapes = linear_modes(system)
    total = 0.5 * (2 * math.pi * frequencies) ** 2  # the strain energy of each mass-normalised shape, ½ ω²
    shares = np.array([strain_energies(system, link, shapes) / np.maximum(total, np.finfo(float).tiny)
                       for link in links]).reshape(len(links), -1)
    owner = np.argmax(shares, axis=0)
    return {link: sorted(float(f) for f in frequencies[owner == k]) or _coupled_mode(frequencies, shares[k])
            for k, link in enumerate(links)}


def _coupled_mode(frequencies: np.ndarray, shares: np.ndarray) -> list[float]:
    """[the mode in which a link's springs hold their largest share of the strain energy], or [] without modes."""
    return [float(frequencies[np.argmax(shares)])] if shares.size and shares.max() > 0.0 else []


def linearised_mode_frequencies(mechanism, links: list[str], base_dir) -> dict[str, float]:
    """Each flexible link's lowest mode of the linearised model (Hz); NaN when no mode is its."""
    return {link: modes[0] if modes else math.nan
            for link, modes in linearised_link_modes(mechanism, links, base_dir).items()}


def contact_frequencies(system, episodes) -> list[tuple[float, float]]:
    """Per clearance joint, the range of 1/(2 t_c) over its contact episodes (CONTACT_PERCENTILES), or at the
    reference impact when it had none (Hz)."""
    from clearsim.solver.outputs import contact_durations, hertz_durations

    durations = hertz_durations(system, episodes.joint, episodes.impact_speed, episodes.effective_mass)
    reference = contact_durations(system)
    ranges = []
    for k in range(len(system.clearance_joints)):
        frequencies = 1.0 / (2.0 * durations[episodes.joint == k])
        if not len(frequencies):
            frequencies = np.array([1.0 / (2.0 * reference[k])])
        lowest, highest = np.percentile(frequencies, CONTACT_PERCENTILES)
        ranges.append((float(lowest), float(highest)))
    return ranges


def reported_modes(modes: list[float], joints: list[JointFrequencies]) -> list[float]:
    """A link's modes the summary lists: its lowest MODES_REPORTED at or below √2 × the highest contact frequency
    of any clearance joint (the top of the band where a mode is near a contact); the lowest alone when no joint
    gives a contact frequency."""
    if not joints:
        return list(modes[:1])
    ceiling = NEAR_FACTOR * max(j.contacts[1] for j in joints)
    return [mode for mode in modes if mode <= ceiling][:MODES_REPORTED]


def mode_report(modes: dict[str, list[float]], joints: list[JointFrequencies], kind: str = "axial") -> list[dict]:
    """The `flexible_modes` attribute (as a list): per link its lowest `kind` ("axial" or "bending") mode and what
    it is near, and under `modes` each reported mode (reported_modes) and what it is near; `modes` maps each link to
    its modes (Hz, ascending; [NaN] when the model could not give them)."""
    def nearby(mode: float) -> dict:
        return {"near_contacts": [j.joint for j in joints if near(mode, *j.contacts)],
                "near_whirls": [j.joint for j in joints if any(near(mode, w, w) for w in j.whirls)]}

    def entry(link: str, frequencies: list[float]) -> dict:
        lowest = frequencies[0] if frequencies else math.nan
        return {"link": link, f"{kind}_mode_hz": lowest, **nearby(lowest),
                "modes": [{"hz": mode, **nearby(mode)} for mode in reported_modes(frequencies, joints)],
                "contacts_hz": {j.joint: list(j.contacts) for j in joints},
                "whirls_hz": {j.joint: list(j.whirls) for j in joints if j.whirls}}

    return [entry(link, frequencies) for link, frequencies in modes.items()]


def flexible_modes_attribute(system, links: list[str], base_dir, episodes, whirls: dict,
                             beams: list[str] = ()) -> str:
    """The result file's `flexible_modes` (JSON, mode_report) of a run's system, its episode log and its joints'
    whirls (clearsim.whirl.joint_whirls): the axial links' axial modes, then the beam links' bending modes; a
    mode is NaN when the model with closed clearance joints does not assemble."""
    joints = [JointFrequencies(joint, contacts, tuple(whirl.frequency for whirl in whirls.get(joint, ())))
              for joint, contacts in zip(system.clearance_joints, contact_frequencies(system, episodes))]
    if beams:  # the mobility of a slide with the other slides held would leave the beams' hinges free pins
        modes = _modes_or_nan(linearised_link_modes, system.mechanism, [*links, *beams], base_dir)
        axial, bending = {link: modes[link] for link in links}, {link: modes[link] for link in beams}
    else:
        axial, bending = _modes_or_nan(axial_link_modes, system.mechanism, list(links), base_dir), {}
    report = mode_report(axial, joints, "axial") + mode_report(bending, joints, "bending")
    return json.dumps(report)


def _modes_or_nan(frequencies, mechanism, links: list[str], base_dir) -> dict:
    from clearsim.assembly.build import BuildError
    from clearsim.errors import ClearsimError

    try:
        return frequencies(mechanism, links, base_dir)
    except (BuildError, ClearsimError, ValueError, np.linalg.LinAlgError):
        return dict.fromkeys(links, [math.nan])


def frequency_text(frequency: float) -> str:
    """As a whirl warning gives a frequency ("412 Hz", "2.1 kHz"); "none" for a mode the model could not give."""
    return hertz_text(frequency) if math.isfinite(frequency) else "none"


def range_text(lowest: float, highest: float) -> str:
    if frequency_text(lowest) == frequency_text(highest):
        return frequency_text(lowest)
    if lowest >= 1e3 and highest >= 1e3:
        return f"{lowest / 1e3:.2g}–{highest / 1e3:.2g} kHz"
    return f"{frequency_text(lowest)} – {frequency_text(highest)}"


def _nearby_text(entry: dict) -> str:
    nearby = [f"joint {j}'s contacts" for j in entry["near_contacts"]]
    nearby += [f"joint {j}'s whirl" for j in entry["near_whirls"]]
    return " and ".join(nearby)


def mode_lines(attribute: str) -> list[str]:
    """One line per flexible link from the `flexible_modes` attribute, e.g. "flexible link pole: axial mode 412 Hz,
    near nothing (within √2); joint J: contacts 6–8 kHz, whirl 2.1 kHz" ("bending mode" for a beam link), with its
    higher reported modes after the lowest: "higher modes 2.1 kHz (near joint J's contacts), 3.2 kHz"."""
    lines = []
    for entry in json.loads(attribute) if attribute else []:
        joints = []
        for joint, contacts in entry["contacts_hz"].items():
            whirls = entry["whirls_hz"].get(joint, [])
            joints.append(f"joint {joint}: contacts {range_text(*contacts)}"
                          + "".join(f", whirl {frequency_text(w)}" for w in whirls))
        kind = "axial" if "axial_mode_hz" in entry else "bending"
        head = (f"flexible link {entry['link']}: {kind} mode {frequency_text(entry[f'{kind}_mode_hz'])}, near "
                f"{_nearby_text(entry) or 'no contact or whirl frequency'} (within ×√2)")
        higher = [frequency_text(mode["hz"]) + (f" (near {_nearby_text(mode)})" if _nearby_text(mode) else "")
                  for mode in entry.get("modes", [])[1:]]  # the reported modes begin with the lowest
        lines.append("; ".join([head] + ([f"higher modes {', '.join(higher)}"] if higher else []) + joints))
    return lines
