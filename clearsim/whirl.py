"""Whirl of a clearance joint: its journal orbiting round the bore, continuously, in one direction.

The orbit angle φ is the angle of the eccentricity e (journal centre − bearing centre) in the bearing body's frame,
unwrapped; the orbit rate is φ̇/2π (Hz). A journal pressed on the wall by a load that turns with the links is carried
round at about the links' relative rotation (one orbit per relative turn at most); a journal that rolls on the wall
orbits at (ω_B R_B − ω_J R_J)/|e|, R/c times faster (R/c = 5000 at 0.01 mm on a 50 mm pin), so a few degrees of
relative rotation become many orbits. A rigid chain lets this go on undamped (docs/model.md, "Whirl").

A *whirl* (whirl_windows) is a run of at least MIN_ORBITS consecutive full turns of φ in one direction, at a
sustained rate (SLOW_TURN), along the bearing wall (AT_WALL), with at least AMPLIFICATION times as many orbits as the
two bodies turn against each other meanwhile.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_ORBITS = 5  # full turns in one direction: a journal rattling between impacts crosses the bore at random, its
# orbit angle goes back and forth and does not make 5 turns in a row
AMPLIFICATION = 10.0  # orbits per turn of the bodies' relative rotation: a journal carried by its load makes ≈ 1
SLOW_TURN = 3.0  # a turn that takes longer than 3× the median turn of its run ends the whirl (or precedes it): the
# journal drifting round before the whirl locks on, or after it stops, is not orbiting at a sustained rate
AT_WALL = 0.5  # median |e|/c over the window at least: the journal runs along the wall (the UHV's J: 0.9–1.5), not
# round the bearing's centre, where the angle of a small e wanders at random
RATE_WINDOW = 1e-3  # s: the running mean of the orbit rate (orbit_rate), ≈ 2 orbits of the UHV's whirl of J
LOADS_HINT = ("the loads that keep the journal on its wall (e.g. a gas load) or a force drive; "
              "docs/model.md §5, \"Whirl\"")
HINT = f"model the links' compliance, {LOADS_HINT}"


@dataclass(frozen=True)
class Whirl:
    start: float  # s: where the first of its turns began
    end: float  # s: where the last one ended
    orbits: int  # full turns, signed: + counter-clockwise in the bearing's frame
    relative_turns: float  # turns of the journal body against the bearing body in the window (total variation)

    @property
    def frequency(self) -> float:
        """Mean orbit rate (Hz)."""
        return abs(self.orbits) / (self.end - self.start)


def orbit_angle(eccentricity: np.ndarray, bearing_angle: np.ndarray | float = 0.0) -> np.ndarray:
    """φ (rad): the unwrapped angle of the eccentricity (S, 2), global, in the frame of a bearing body at
    `bearing_angle` (rad, per sample; 0 for the ground)."""
    return np.unwrap(np.arctan2(eccentricity[:, 1], eccentricity[:, 0]) - bearing_angle)


def orbit_rate(time: np.ndarray, angle: np.ndarray, window: float = RATE_WINDOW) -> np.ndarray:
    """The orbit rate φ̇/2π (Hz) at every sample, as a running mean over `window` seconds."""
    rate = np.gradient(angle, time) / (2 * np.pi)
    samples = max(1, int(round(window / np.median(np.diff(time))))) if len(time) > 1 else 1
    return np.convolve(rate, np.ones(samples) / samples, mode="same")


@dataclass(frozen=True)
class Turns:
    """The full turns of φ in order: sample indices where each began and completed, and its direction ±1."""
    starts: np.ndarray
    ends: np.ndarray
    directions: np.ndarray


def full_turns(angle: np.ndarray) -> Turns:
    """A turn completes when φ is 2π past the level where the previous one completed (at first: φ at the first
    sample), in either direction; it began at the last sample before at which φ was at or behind that level."""
    angle = np.asarray(angle, dtype=float)
    ends, directions = [], []
    level = float(angle[0]) if len(angle) else 0.0
    i = _turn_away(angle, level, 0)
    while i < len(angle):
        value = float(angle[i])
        while abs(value - level) >= 2 * np.pi:
            direction = 1 if value > level else -1
            level += direction * 2 * np.pi
            ends.append(i)
            directions.append(direction)
        i = _turn_away(angle, level, i + 1)
    starts, previous = [], 0
    for end, direction in zip(ends, directions):
        # from the sample before the previous turn completed, φ was behind this turn's level (or the run began)
        searched = max(previous - 1, 0)
        behind = np.flatnonzero((angle[searched:end] - (angle[end] - direction * 2 * np.pi)) * direction <= 0.0)
        starts.append(searched + int(behind[-1]) if len(behind) else searched)
        previous = end
    return Turns(np.asarray(starts, dtype=int), np.asarray(ends, dtype=int), np.asarray(directions, dtype=int))


TURN_SEARCH = 256  # samples compared with the level at a time (a whirl's turn takes ~50 samples at 100 kHz)


def _turn_away(angle: np.ndarray, level: float, start: int) -> int:
    """The first sample from `start` at which φ is 2π or more from `level` (len(angle): none): the comparison
    full_turns makes at each sample, made TURN_SEARCH samples at a time (one at a time in Python took 1.3 ms a
    joint of a UHV run)."""
    for first in range(start, len(angle), TURN_SEARCH):
        away = np.flatnonzero(np.abs(angle[first:first + TURN_SEARCH] - level) >= 2 * np.pi)
        if len(away):
            return first + int(away[0])
    return len(angle)


def whirl_windows(time: np.ndarray, angle: np.ndarray, relative_angle: np.ndarray, eccentricity_ratio: np.ndarray,
                  min_orbits: int = MIN_ORBITS, amplification: float = AMPLIFICATION) -> list[Whirl]:
    """The whirls in a journal path: φ (orbit_angle), the relative rotation θ_journal − θ_bearing (rad) and |e|/c,
    per sample at `time` (s)."""
    turns = full_turns(angle)
    whirls = []
    for run in _sustained_runs(time, turns):
        first, last = turns.starts[run[0]], turns.ends[run[-1]]
        relative = float(np.sum(np.abs(np.diff(relative_angle[first:last + 1])))) / (2 * np.pi)
        at_wall = np.median(eccentricity_ratio[first:last + 1]) >= AT_WALL
        if len(run) >= min_orbits and len(run) >= amplification * relative and at_wall:
            whirls.append(Whirl(float(time[first]), float(time[last]), int(turns.directions[run[0]]) * len(run),
                                relative))
    return whirls


def _sustained_runs(time: np.ndarray, turns: Turns) -> list[np.ndarray]:
    """The turns (indices into `turns`) split into runs of consecutive turns in one direction, leaving out every turn
    that takes more than SLOW_TURN times the median turn of its direction's run."""
    runs = []
    for same_direction in np.split(np.arange(len(turns.ends)), np.flatnonzero(np.diff(turns.directions)) + 1):
        if not len(same_direction):
            continue
        durations = time[turns.ends[same_direction]] - time[turns.starts[same_direction]]
        sustained = durations <= SLOW_TURN * np.median(durations)
        breaks = np.flatnonzero(np.diff(sustained)) + 1
        runs += [run for run, first in zip(np.split(same_direction, breaks), np.r_[0, breaks]) if sustained[first]]
    return runs


def whirl_warning(joint: str, whirl: Whirl, compliant_links: bool = False) -> str:
    """The warning of one whirl; with `compliant_links` (the file has flexible links) it does not blame rigid links
    nor suggest the compliance the model already has."""
    cause, hint = ("with the links' compliance in the model, and it", LOADS_HINT) if compliant_links else \
        ("an effect of the rigid links that", HINT)
    return (f"joint {joint}: the journal whirls around its bearing from {whirl.start * 1e3:.1f} to "
            f"{whirl.end * 1e3:.1f} ms, {abs(whirl.orbits)} orbits ({hertz_text(whirl.frequency)}) while its two bodies turn "
            f"{whirl.relative_turns:.2g} turns against each other: it runs round the bore, {cause} "
            f"can set the run's peaks (hint: {hint})")


def hertz_text(frequency: float) -> str:
    return f"{frequency / 1e3:.2g} kHz" if frequency >= 1e3 else f"{frequency:.3g} Hz"


def journal_paths(clearance_bodies: np.ndarray, clearances: np.ndarray, states: np.ndarray,
                  eccentricity: np.ndarray) -> np.ndarray:
    """(S, joints, 3) per sample and clearance joint: the angle of e in the bearing body's frame, not unwrapped,
    θ_journal − θ_bearing (rad), and |e|/c, from the bodies (bearing, journal) of each joint (−1: the ground, θ = 0),
    its clearance c (m), the states (q first) and e (S, joints, 2, global)."""
    def body_angles(bodies: np.ndarray) -> np.ndarray:  # (S, joints)
        return np.column_stack([states[:, 3 * body + 2] if body >= 0 else np.zeros(len(states)) for body in bodies]
                               or [np.zeros((len(states), 0))])

    bearing, journal = body_angles(clearance_bodies[:, 0]), body_angles(clearance_bodies[:, 1])
    return np.stack([np.arctan2(eccentricity[..., 1], eccentricity[..., 0]) - bearing, journal - bearing,
                     np.hypot(eccentricity[..., 0], eccentricity[..., 1]) / clearances], axis=2)


def joint_whirls(joints: list[str], time: np.ndarray, paths: np.ndarray) -> dict[str, list[Whirl]]:
    """The whirls of each clearance joint, from its journal_paths."""
    return {joint: whirl_windows(time, np.unwrap(paths[:, k, 0]), paths[:, k, 1], paths[:, k, 2])
            for k, joint in enumerate(joints)}


def whirl_warnings(whirls: dict[str, list[Whirl]], compliant_links: bool = False) -> list[str]:
    """A warning per whirl of each clearance joint (joint_whirls)."""
    return [whirl_warning(joint, whirl, compliant_links) for joint, found in whirls.items() for whirl in found]
