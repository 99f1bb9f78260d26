"""The public pipeline: load → assemble → simulate → write, and the run summary.

    loaded = load_mechanism(path, overrides)      # validated spec
    system = prepare(loaded)                      # arrays + consistent initial state
    report = run_to_file(system, loaded, out)     # HDF5 file, written as the run goes
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from clearsim.assembly.arrays import (
    CL_CLEARANCE, CL_DRY_GAP, CL_FILM_LENGTH, CL_JOURNAL_RADIUS, CL_STIFFNESS, CL_VISCOSITY, LAW_FILM_MODEL,
)
from clearsim.assembly.build import BuildError
from clearsim.assembly.drivelines import STORED_ENERGY_NAMES
from clearsim.assembly.hydraulics import HY_GAS_VOLUME
from clearsim.assembly.system import System, assemble
from clearsim.errors import ClearsimError, InputError, SolverError, format_path
from clearsim.io.files import adopt_abandoned, locate, partial_name, publish, same_file
from clearsim.io.hdf5 import (
    CHUNK_ROWS, NotAResultFile, ResultWriteError, ResultWriter, as_read, check_free_space, group_attribute,
    interrupts_deferred, read_result, result_overview, write_failure,
)
from clearsim.io.wear_results import archard_joints, wear_profile_tables
from clearsim.model.loader import FAST_LOADER, LoadedMechanism, load_mechanism
from clearsim.model.flexible import flexible_link_names
from clearsim.model.modes import flexible_modes_attribute, mode_lines
from clearsim.physics.cylindrical import range_warnings
from clearsim.physics.lubrication import film_range_warnings
from clearsim.solver.outputs import (
    classify_episodes, chunk_outputs, driveline_dissipations, full_precision, output_rate, sample_modes, stored_outputs,
)
from clearsim.solver.samples import C_ECC_X, C_ECC_Y
from clearsim.solver.simulate import Chunk, Run, Statistics
from clearsim.solver import precompile
from clearsim.travel import travel_figures
from clearsim.whirl import joint_whirls, journal_paths, whirl_warnings

BUNDLED_CONFIG = Path(__file__).parent / "configs" / "uhv_breaker.yaml"
# which per-sample histories a result file holds (its `contents` attribute, absent for "all"), each a subset of the
# one before: every dataset of the result layout (README); "summary", all but the bodies' q, q̇, q̈ and the ideal joints' reactions
# — what a sweep's summary table and `clearsim plot`'s figures read (`clearsim sweep --keep summary`; a UHV case at
# 100 kHz 4.4 → 1.3 MB); "figures", the sensors and the clearance joints' normal force, mode and stick flag — what
# the sweep's figures of merit read (`summarize`; `--keep figures`, for Monte Carlo studies); or the sensors alone — a
# diagnosis reads nothing else of its model runs (0.31 MB). The contact modes' episode tables and the run's
# attributes are in every file.
CONTENTS = {"all": lambda name: True,
            "summary": lambda name: not name.startswith("bodies/") and not name.endswith("/reaction"),
            "figures": lambda name: summary_dataset(name),
            "sensors": lambda name: name.startswith("sensors/")}


def contents_serve(held: str, wanted: str) -> bool:
    """Whether a file holding `held` histories has every history `wanted` asks for (CONTENTS: each a subset of the
    one before; an unknown value serves nothing)."""
    order = list(CONTENTS)
    return held in order and wanted in order and order.index(held) <= order.index(wanted)


DEFAULT_OUTPUT = Path("results") / "run.h5"
RESULT_SUFFIXES = (".h5", ".hdf5", ".hdf")


class OutputPathError(ClearsimError):
    """An -o that cannot be a result file (a folder, the mechanism file itself, not an HDF5 name)."""


def check_output_path(output: Path, config: Path) -> None:
    """Refuse, before anything runs, an output that would move a folder or the config aside, or put HDF5 in a
    file named as something else (an existing file there is renamed to <stem>.previous<suffix>, not overwritten)."""
    output = Path(output)
    hint = "hint: give a result file such as -o results/run.h5"
    if output.is_dir():
        raise OutputPathError(f"-o {output}: is a folder, not a result file\n  hint: name the file in it, e.g. "
                              f"-o {output / 'run.h5'}")
    if same_file(output, Path(config)):
        raise OutputPathError(f"-o {output}: that is the mechanism file being run; the result would take its "
                              f"place\n  {hint}")
    if output.suffix.lower() not in RESULT_SUFFIXES:
        raise OutputPathError(f"-o {output}: a result file is HDF5 and is named *.h5 (got "
                              f"{output.suffix or 'no suffix'!r})\n  hint: e.g. -o {output.with_suffix('.h5')}")


def prepare(loaded: LoadedMechanism) -> System:
    """Assemble a loaded mechanism; assembly problems are reported at their place in the file."""
    precompile.start_if_cold()  # on an empty kernel cache, a second process compiles part of the loop meanwhile
    try:
        return assemble(loaded.mechanism, loaded.base_dir)
    except BuildError as exc:
        raise InputError(exc.problems, file=loaded.path, source=loaded.source) from None


@dataclass
class Kept:
    """What a written result file holds of the datasets run_to_file's `keep` names, kept in memory as it was written,
    so that a reader of the file need not open it again (a sweep's case record): `data` in read_result's layout (the
    root attributes, and each kept dataset as read back: float32 histories as float64) and each clearance joint's
    episode table's `peak_normal_force_N` (absent with the table)."""

    data: dict
    episode_peaks: dict[str, float]


@dataclass
class RunReport:
    destination: Path  # the -o of the run
    backup: Path | None
    complete: bool
    status: str
    statistics: object
    error: Exception | None = None
    warnings: list[str] = field(default_factory=list)  # also the result file's `warnings` attribute, a line each
    identity: os.stat_result | None = None  # of the file written, once it has its name
    kept: Kept | None = None  # run_to_file(keep=…): what the file holds of those datasets, from memory

    @property
    def output(self) -> Path:
        """Where this run's file is now: its -o, or the <stem>.previous… name a run that finished later with the same
        -o moved it to."""
        return locate(self.destination, self.identity) if self.identity is not None else self.destination


def _attributes(system: System, loaded: LoadedMechanism) -> dict:
    return {"config_path": str(loaded.path), "mechanism": system.mechanism.name,
            "degrees_of_freedom": system.degrees_of_freedom,
            "clearance_joints": ",".join(system.clearance_joints), "output_rate_hz": output_rate(system),
            "output_rate_source": "derived" if system.mechanism.solver.output_rate is None else "solver.output_rate"}


def _final_attributes(run: Run, warnings: list[str]) -> dict:
    stats = run.statistics()
    return {"wall_time_s": stats.wall_time, "kernel_time_s": stats.kernel_time,
            "kernels_compiled": stats.kernels_compiled, "steps": stats.steps, "rejected_steps": stats.rejected_steps,
            "rhs_evaluations": stats.rhs_evaluations, "contact_events": stats.contact_events,
            "max_step_violation": stats.max_violation, "simulated_time_s": run.time,
            "tolerance_over_penetration": stats.tolerance_over_penetration,
            "penetration_guard_rejections": stats.penetration_rejections,
            "peak_output_acceleration": stats.peak_output_acceleration, "warnings": "\n".join(warnings)}


def _mode_attributes(system: System, loaded: LoadedMechanism, run: Run, whirls: dict) -> dict:
    """`flexible_modes`: the flexible links' axial and bending modes and what they are near (clearsim.model.modes),
    when the file has flexible links."""
    links, beams = (flexible_link_names(loaded.document, model) for model in ("axial", "beam"))
    if not links and not beams:
        return {}
    return {"flexible_modes": flexible_modes_attribute(system, links, loaded.base_dir, run.episode_log(), whirls,
                                                       beams)}


def _travel_attributes(system: System, writer: ResultWriter) -> dict:
    """`travel_figures`: the figures of the file's `travel:` block (clearsim.travel) as JSON, SI, from the samples
    written (none when the file has no such block, or nothing could be written)."""
    spec = system.mechanism.travel
    if spec is None or writer.broken or "time" not in writer.file or f"sensors/{spec.sensor}" not in writer.file:
        return {}
    figures = travel_figures(writer.file["time"][()], writer.file[f"sensors/{spec.sensor}"][()], spec)
    return {"travel_figures": json.dumps({"sensor": spec.sensor} | figures)}


def _write_episodes(writer: ResultWriter, system: System, run: Run, sample_episodes: np.ndarray) -> np.ndarray:
    """Episode tables per clearance joint and the final contact modes of every sample (returned, (S, nc))."""
    log = run.episode_log()
    kinds = classify_episodes(system, log)
    modes = sample_modes(kinds, sample_episodes)
    stats = run.statistics()
    for k, name in enumerate(system.clearance_joints):
        mine = log.joint == k
        writer.replace(f"joints/{name}/mode", modes[:, k])
        writer.write_table(f"joints/{name}/episodes", {
            "onset": (log.onset[mine], "s"), "loss": (log.loss[mine], "s"),
            "impact_speed": (log.impact_speed[mine], "m/s"),
            "effective_mass": (log.effective_mass[mine], "kg"),
            "kind": (kinds[mine], "1 impact, 2 continuous contact")},
            {"peak_normal_force_N": float(stats.peak_normal_force[k])})
    return modes


def run_to_file(system: System, loaded: LoadedMechanism, output: Path,
                progress: Callable[[float], None] | None = None, contents: str = "all",
                warn: Callable[[str], None] | None = None, keep: Callable[[str], bool] | None = None,
                adopt: bool = True) -> RunReport:
    """Simulate and write as it goes; interruption or failure still leaves a flagged, readable file with the
    histories `contents` names (CONTENTS). warn(text): a warning of the run as soon as it is seen (Run).
    keep(name): the datasets of the file to hold in memory too (RunReport.kept, when the file was written whole).
    adopt: first give the files a killed run left being written as `output` that name (adopt_abandoned); a caller
    that has just done so passes False (each look lists the folder: 5 ms in a folder of 10 000 files).

    Chunks are gathered and written at most every FLUSH_SECONDS of wall time (each HDF5 append
    costs ~0.4 ms per dataset, which for short runs cost more than the integration); whatever was
    computed is written when the run ends, fails or is interrupted.
    """
    output = Path(output)
    needed = result_file_bytes(system, contents)
    check_free_space(output, needed)
    if adopt:
        adopt_abandoned(output)  # a killed run's file: under its name, so that this run keeps it as previous
    partial = partial_name(output)  # its own file until it is finished: runs with the same -o never meet
    run = None  # made inside the try: loading the compiled kernels can take seconds, and may be interrupted
    episodes, status, complete, error = [], "complete", True, None
    # a state that overflows (absurd masses, speeds, forces) is reported once, by the solver's failure message,
    # not also by numpy's warnings from every place its samples pass through
    attributes = _attributes(system, loaded) | ({} if contents == "all" else {"contents": contents})
    try:
        writer = ResultWriter(partial, loaded.resolved_yaml, attributes)
    except OSError as exc:
        partial.unlink(missing_ok=True)
        raise write_failure(output, exc, needed) from None
    with np.errstate(all="ignore"), writer:
        pending = _PendingChunks(writer, episodes, system, CONTENTS[contents], keep)
        try:
            run = Run(system, warn)
            for chunk in run.chunks(progress):
                pending.add(chunk, run)
        except SolverError as exc:
            exc.place = element_place(loaded, exc.element)
            status, complete, error = f"failed: {exc}", False, exc
        except KeyboardInterrupt as exc:
            at = run.time if run is not None else 0.0
            status, complete, error = f"interrupted at t = {at * 1e3:.3f} ms", False, exc
        except OSError as exc:  # the disk filled up or went away mid-run
            error = write_failure(output, exc, needed)
            status, complete = f"failed: {error}", False
        finally:
            with interrupts_deferred():  # the file is finished, flagged and named whole, even on a Ctrl-C
                try:
                    if not writer.broken:
                        pending.flush()
                        if episodes:
                            pending.final_modes(_write_episodes(writer, system, run, np.concatenate(episodes)))
                        if run is not None:
                            for group, table in wear_profile_tables(system, run.y, run.time).items():
                                writer.write_table(group, *table)  # the accumulated wear profiles, at the end
                except OSError as exc:
                    if not isinstance(error, ResultWriteError):  # the first write failure is the one to report
                        error = write_failure(output, exc, needed)
                        status, complete = f"failed: {error}", False
                # whatever failed above, the file is flagged as far as it can still be written
                whirls = pending.whirls()
                warnings = run.warnings() + whirl_warnings(whirls, bool(flexible_link_names(loaded.document))) \
                    + pending.law_range_warnings() \
                    if run is not None else []
                final = _final_attributes(run, warnings) | _mode_attributes(system, loaded, run, whirls) \
                    | _travel_attributes(system, writer) if run is not None else {}
                readable = writer.finish(complete, status, final)
                backup, identity, error = _give_its_name(writer, output, readable, error)
    written_whole = identity is not None and not writer.broken and not isinstance(error, ResultWriteError)
    kept = pending.kept_histories(run) if keep is not None and written_whole else None
    return RunReport(output, backup, complete, status, run.statistics() if run is not None else Statistics(), error,
                     warnings, identity, kept)


def _give_its_name(writer: ResultWriter, output: Path, readable: bool, error: Exception | None):
    """Publish the finished file as `output` (an earlier one kept as previous), or remove it when the disk stopped
    the run before its first sample (an earlier result then keeps its name) or left it unreadable; a write failure
    then says which. → (where the earlier file went, the file's identity, the error)."""
    failed_to_write = isinstance(error, ResultWriteError)
    kept = readable and (writer.rows > 0 or not failed_to_write)
    backup, identity = None, None
    if kept:
        identity = writer.path.stat()  # the file's own, kept by the rename (a run finishing next may take the name)
        backup = publish(writer.path, output)
    else:
        writer.path.unlink(missing_ok=True)
    if failed_to_write:
        error = ResultWriteError(output, error.reason, f"{error.hint}; " + (
            f"the {writer.rows} samples written before are in {output}, flagged complete = false" if kept
            else "no sample could be written, so no file was left" if readable
            else "the failed write left the file unreadable, so it was removed"))
    return backup, identity, error


def element_place(loaded: LoadedMechanism, element: str | None) -> str:
    """Where the joint, driver or force a solver failure names is in the mechanism file: "file:line:column  joints[k] 'J'";
    a failure that names neither is placed at the file's `solver:` settings, whose limits stopped the run."""
    name = (element or "").split(" (")[0]
    path = next((path for path, item in loaded.source.names.items()
                 if len(path) == 2 and path[0] in ("joints", "drivers", "forces") and item == name), ("solver",))
    position = loaded.source.locate(path)[0]
    at = f"{loaded.path}:{position[0]}:{position[1]}" if position else str(loaded.path)
    return f"{at}  {format_path(path, loaded.source.names)}"


BASE_ENERGIES = 8  # kinetic, potential, contact/friction/damping dissipated, driver and applied work, balance error
HYDRAULIC_ENERGIES = 4  # hydraulic_supply_work, hydraulic_tank_work, orifice_dissipated, oil_compression
CYLINDER_VALUES, ACCUMULATOR_VALUES = 4, 2  # /drives/<cylinder>/: pressures, stroke, force; gas volume, supply pressure
DRIVELINE_VALUES = 2  # /drives/<element>/: stroke (or sliding_velocity) and force


def result_values(system: System) -> dict[str, int]:
    """A dataset of each kind of the result layout → its values per sample over the model's elements (int8
    datasets counted as 4-byte ones)."""
    arrays = system.arrays
    bodies, clearances = len(system.body_names), len(system.clearance_joints)
    lubricated = int(np.count_nonzero(arrays.clearance_params[:, CL_VISCOSITY] > 0.0))
    stored = set(arrays.driveline_kinds[:, 0].tolist()) & STORED_ENERGY_NAMES.keys()
    accumulators = int(np.count_nonzero(arrays.hydraulic_params[:, HY_GAS_VOLUME] > 0.0))
    return {
        "time": 1,
        "bodies/b/q": 3 * bodies, "bodies/b/qd": 6 * bodies,
        "joints/j/reaction": 2 * (len(system.pin_joints) + len(system.prismatic_joints)),
        "joints/j/eccentricity": 5 * clearances, "joints/j/sliding_velocity": 4 * clearances,
        "joints/j/film_force": 2 * lubricated, "joints/j/film_thickness": 2 * lubricated,
        "drivers/d/effort": len(system.drivers),
        "sensors/s": len(system.sensors),
        "drives/d/force": (CYLINDER_VALUES * len(system.hydraulic_cylinders) + ACCUMULATOR_VALUES * accumulators
                           + DRIVELINE_VALUES * len(arrays.driveline_kinds)),
        "energy/e": (BASE_ENERGIES + len(driveline_dissipations(system)) + len(stored)
                     + HYDRAULIC_ENERGIES * bool(system.hydraulic_cylinders)),
        "constraints/violation": 1,
        "joints/j/wear": 2 * len(archard_joints(system)),
    }


def result_sample_bytes(system: System, contents: str = "all") -> int:
    """Bytes a sample of the datasets `contents` keeps takes uncompressed: 8 a value where the file keeps full
    precision, 4 elsewhere (result_values)."""
    return sum(count * (8 if full_precision(name) else 4) for name, count in result_values(system).items()
               if name == "time" or CONTENTS[contents](name))


def result_file_bytes(system: System, contents: str = "all") -> float:
    """An upper estimate of the result file's size: result_sample_bytes in whole chunks of CHUNK_ROWS samples (a short
    run's file holds one whole chunk of every dataset), 20 % over, and 1 MiB for the attributes and episode tables."""
    samples = math.ceil((system.mechanism.solver.t_end * output_rate(system) + 1) / CHUNK_ROWS) * CHUNK_ROWS
    return 1.2 * result_sample_bytes(system, contents) * samples + 2**20


FLUSH_SECONDS = 0.5


class _PendingChunks:
    """Chunks integrated but not yet written; their outputs are derived and written together, whole, with their
    episodes (once per flush, not per chunk: the per-call cost of deriving ~40 datasets was a fifth of a short
    run's wall time). The contact modes written here are provisional; the final ones replace them at the end."""

    def __init__(self, writer: ResultWriter, episodes: list, system: System, wanted: Callable[[str], bool],
                 keep: Callable[[str], bool] | None = None):
        self.writer, self.episodes, self.system, self.wanted = writer, episodes, system, wanted
        self.keep = keep or (lambda name: False)
        self.kept: dict[str, list[np.ndarray]] = {}  # dataset → the parts written, as read back (Kept)
        self.run: Run | None = None
        self.items: list = []
        self.initial_energy: float | None = None
        self.written_at = time.perf_counter()
        self.times: list[np.ndarray] = []  # of the samples written, and their clearance joints' journal_paths
        self.paths: list[np.ndarray] = []

    def add(self, chunk, run: Run) -> None:
        self.run = run  # its episode log classifies the modes at the flush
        if self.initial_energy is None:
            self.initial_energy = float(chunk.kinetic[0] + chunk.potential[0])
        self.items.append(chunk)
        if time.perf_counter() - self.written_at >= FLUSH_SECONDS:
            self.flush()

    def flush(self) -> None:
        if not self.items:
            return
        chunk = Chunk.joined(self.items)
        provisional = sample_modes(classify_episodes(self.system, self.run.episode_log()), chunk.episodes)
        outputs = stored_outputs({name: values for name, values in chunk_outputs(
            self.system, chunk, provisional, self.initial_energy).items() if self.wanted(name)})
        with interrupts_deferred():  # the samples and their episodes are written whole, or not at all
            self.writer.append(chunk.times, outputs)
            for name, values in (("time", chunk.times), *((name, values) for name, (values, _) in outputs.items())):
                if self.keep(name):
                    self.kept.setdefault(name, []).append(as_read(np.ascontiguousarray(values)))
            self.episodes.append(chunk.episodes)
            self.times.append(chunk.times)
            arrays = self.system.arrays
            self.paths.append(journal_paths(arrays.clearance_bodies, arrays.clearance_params[:, CL_CLEARANCE],
                                            chunk.states, chunk.contact[:, :, [C_ECC_X, C_ECC_Y]]))
        self.items.clear()
        self.written_at = time.perf_counter()

    def final_modes(self, modes: np.ndarray) -> None:
        """The final contact modes of every sample written (_write_episodes) in place of the provisional ones kept."""
        for k, name in enumerate(self.system.clearance_joints):
            if f"joints/{name}/mode" in self.kept:
                self.kept[f"joints/{name}/mode"] = [modes[:, k]]

    def kept_histories(self, run: Run | None) -> Kept:
        """The kept datasets whole, the file's root attributes, and the episode tables' peaks where the file has the
        tables (written with the first samples)."""
        data = {"attrs": dict(self.writer.attributes)}
        data |= {name: np.concatenate(parts) for name, parts in self.kept.items()}
        peaks = run.statistics().peak_normal_force if run is not None and self.episodes else []
        return Kept(data, {name: float(peak) for name, peak in zip(self.system.clearance_joints, peaks)})

    def law_range_warnings(self) -> list[str]:
        """Each clearance joint's elastic law used outside its range, at the deepest penetration sampled
        (cylindrical.range_warnings), and each oil film outside its L/D range (lubrication.film_range_warnings)."""
        arrays = self.system.arrays
        params = arrays.clearance_params
        clearance = params[:, CL_CLEARANCE]
        peaks = ((np.concatenate(self.paths)[:, :, 2].max(axis=0) - 1.0) * clearance if self.paths
                 else np.full(len(clearance), np.nan)) + params[:, CL_DRY_GAP]
        return [text for k, joint in enumerate(self.system.clearance_joints)
                for text in range_warnings(joint, arrays.clearance_laws[k, 3], clearance[k],
                                           params[k, CL_STIFFNESS], peaks[k])
                + film_range_warnings(joint, arrays.clearance_laws[k, LAW_FILM_MODEL], params[k, CL_VISCOSITY],
                                      params[k, CL_FILM_LENGTH], params[k, CL_JOURNAL_RADIUS])]

    def whirls(self) -> dict[str, list]:
        """The whirls of each clearance joint in the samples written (clearsim.whirl)."""
        if not self.times:
            return {}
        return joint_whirls(self.system.clearance_joints, np.concatenate(self.times), np.concatenate(self.paths))


def simulate_config(config: Path | str | None = None, overrides=(), output: Path | str = DEFAULT_OUTPUT,
                    progress: Callable[[float], None] | None = None) -> RunReport:
    """load → assemble → run → file, the whole of `clearsim run`."""
    loaded = load_mechanism(Path(config) if config else BUNDLED_CONFIG, overrides)
    return run_to_file(prepare(loaded), loaded, Path(output), progress)


@dataclass
class Summary:
    peak_velocity: tuple[str, float] | None
    peak_acceleration: tuple[str, float] | None
    peak_contact_force: dict[str, float]
    contact_time_share: dict[str, tuple[float, float, float]]
    sticking_share: dict[str, float]  # of the time in contact, per joint (files without /stick: absent)
    warnings: list[str] = field(default_factory=list)  # the file's `warnings` attribute, a line each
    flexible_modes: list[str] = field(default_factory=list)  # a line per flexible link (clearsim.model.modes)
    travel: dict = field(default_factory=dict)  # the `travel_figures` attribute: sensor and figures, SI (clearsim.travel)


SUMMARY_JOINT_DATASETS = ("/normal_force", "/mode", "/stick")
NO_SAMPLES = np.zeros(0)


def summary_dataset(name: str) -> bool:
    """The datasets `summarize` reads: the sensors and each clearance joint's force, mode and stick flag."""
    return name.startswith("sensors/") or name.endswith(SUMMARY_JOINT_DATASETS)


def summarize(path: Path, data: dict | None = None) -> Summary:
    """The figures `clearsim run` prints, read back from a result file (or from `data`, read_result of it with at
    least the datasets of `summary_dataset`)."""
    data = read_result(path, summary_dataset) if data is None else data
    peaks = {joint: group_attribute(path, f"joints/{joint}/episodes", "peak_normal_force_N", 0.0)
             for joint in _clearance_joints(data["attrs"])}
    return summary_of(data, _output_sensors(data["attrs"]["config_yaml"]), peaks)


def _clearance_joints(attributes: dict) -> list[str]:
    return [j for j in str(attributes.get("clearance_joints", "")).split(",") if j]


def summary_of(data: dict, output: dict, episode_peaks: dict[str, float]) -> Summary:
    """summarize's figures from `data` (read_result's layout, or run_to_file's Kept), the file's `output:` block
    (role → sensor name) and its episode tables' `peak_normal_force_N` (joint → N; absent: no table)."""
    peak = {}
    for role in ("velocity", "acceleration"):
        name = output.get(role)
        values = _finite(data.get(f"sensors/{name}", NO_SAMPLES)) if name else NO_SAMPLES
        peak[role] = (name, float(np.max(np.abs(values)))) if len(values) else None
    if peak["acceleration"] is not None:  # the larger of the sampled peak and the one at every step's end
        name, sampled = peak["acceleration"]
        tracked = float(data["attrs"].get("peak_output_acceleration", 0.0))
        peak["acceleration"] = (name, max(sampled, tracked if np.isfinite(tracked) else 0.0))
    joints = _clearance_joints(data["attrs"])
    forces = {j: _peak_contact_force(episode_peaks.get(j, 0.0), data.get(f"joints/{j}/normal_force", NO_SAMPLES))
              for j in joints}
    shares = {}
    for j in joints:
        mode = data.get(f"joints/{j}/mode", NO_SAMPLES)  # none in a run stopped before its first sample
        shares[j] = tuple(float(np.mean(mode == m)) if len(mode) else 0.0 for m in (0, 1, 2))
    sticking = {j: float(np.mean(data[f"joints/{j}/stick"][data[f"joints/{j}/mode"] > 0]))
                for j in joints if f"joints/{j}/stick" in data and np.any(data[f"joints/{j}/mode"] > 0)}
    warnings = [line for line in str(data["attrs"].get("warnings", "")).split("\n") if line]
    modes = mode_lines(str(data["attrs"].get("flexible_modes", "")))
    travel = json.loads(str(data["attrs"].get("travel_figures", "{}")))
    return Summary(peak["velocity"], peak["acceleration"], forces, shares, sticking, warnings, modes, travel)


def _finite(values: np.ndarray) -> np.ndarray:
    """The finite samples: a run that failed as its state overflowed ends with NaN or inf samples, and its peaks are
    those of the motion before (a NaN peak said nothing)."""
    values = np.asarray(values, dtype=float)
    return values[np.isfinite(values)]


def _peak_contact_force(located: float, sampled: np.ndarray) -> float:
    """The larger of the sampled peak and the peak located within every step (which samples can miss)."""
    tracked = float(located)
    return max(tracked if np.isfinite(tracked) else 0.0, float(np.max(_finite(sampled), initial=0.0)))


def _output_sensors(config_yaml: str) -> dict:
    import yaml

    document = yaml.load(config_yaml, Loader=FAST_LOADER) or {}
    return dict(document.get("output") or {})


def _frequency(hertz: float) -> str:
    for scale, unit in ((1e6, "MHz"), (1e3, "kHz")):
        if hertz >= scale:
            return f"{hertz / scale:.4g} {unit}"
    return f"{hertz:.4g} Hz"


def read_where_it_is(report, read: Callable[[Path], object]):
    """read(path) of a run's published file; when a later run with the same output name moves it aside between
    finding it and opening it (`report.output` locates it each time), read it once more where it is now."""
    path = report.output
    try:
        return read(path)
    except (OSError, NotAResultFile):
        moved = report.output
        if moved == path:
            raise
        return read(moved)


def written_line(path: Path) -> str:
    """What `clearsim run` says it wrote: "results/run.h5: 3.1 MB, 8 501 samples at 100 kHz, 9 bodies, 13 joints,
    5 sensors" (MB = 2^20 bytes; "(from the model's time scales)" after a derived rate)."""
    overview = result_overview(path)
    rate = "" if overview.rate_hz is None else f" at {_frequency(overview.rate_hz)}"
    if overview.rate_derived:
        rate += " (from the model's time scales)"
    members = "".join(f", {count} {group if count != 1 else group[:-1]}" for group, count in overview.members.items())
    samples = f"{overview.samples:,}".replace(",", " ")
    return f"{path}: {overview.size_bytes / 2**20:.1f} MB, {samples} samples{rate}{members}"
