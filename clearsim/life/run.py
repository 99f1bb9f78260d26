"""`clearsim life`: simulate one operation, accumulate its wear, scale it over a block of operations, update the
bores, repeat to N (docs/life.md). The block control is clearsim/life/blocks.py, the file clearsim/life/store.py."""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import h5py
import numpy as np

from clearsim.errors import ClearsimError
from clearsim.io.files import keep_as_previous
from clearsim.life.blocks import Block, BlockControl, Operation, OperationFailed, live
from clearsim.life.store import ANGLES, LifeFile, is_life_file
from clearsim.model.loader import LoadedMechanism, dump_yaml, load_mechanism, load_mechanism_text
from clearsim.model.resolve import resolve_clearance
from clearsim.physics.wear import evaluate_profile, profile_block, summed_coefficients
from clearsim.runner import check_output_path, prepare, run_to_file, summarize

MAX_OPERATIONS = 10_000_000


class LifeError(ClearsimError):
    """A life that cannot start or go on (no wearing joint, N = 0, an operation that cannot be simulated)."""


class WornOperationFailed(LifeError, OperationFailed):
    """An operation that the solver could not finish with the bores worn to a state: its block is refused."""


@dataclass
class LifeRequest:
    config: Path
    operations: int
    output: Path = Path("results/life.h5")
    tolerance: float = 0.02
    overrides: list[str] = field(default_factory=list)


@dataclass
class LifeReport:
    output: Path
    complete: bool
    status: str
    last: Block | None
    blocks: int
    simulations: int
    resumed_from: int | None  # operations done when this call started (None: a new life)
    backup: Path | None


class Machine:
    """The mechanism of a life: its wearing joints (those with `wear: {archard: …}`), their clearances and the
    profiles the file starts from; runs one operation with the bores worn by a life state."""

    def __init__(self, loaded: LoadedMechanism):
        self.loaded = loaded
        mechanism = loaded.mechanism
        self.clearances, self.harmonics, self.initial = {}, {}, {}
        for joint in mechanism.joints:
            wear = getattr(joint, "wear", None)
            if wear is None or wear.archard is None:
                continue
            parameters = resolve_clearance(joint, mechanism.defaults)
            self.clearances[joint.name] = parameters.clearance
            self.harmonics[joint.name] = wear.archard.harmonics
            self.initial[joint.name] = wear.profile.coefficients() if wear.profile is not None else np.zeros(1)
        if not self.clearances:
            raise LifeError(f"{loaded.path}: no joint wears: a life needs at least one clearance joint with an "
                            "Archard law\n  hint: add e.g. `wear: {archard: {coefficient: 1e-6, hardness: 2 GPa}}` to "
                            "joint J (docs/yaml.md, joints → wear)")

    def initial_depth(self) -> dict[str, np.ndarray]:
        return {joint: evaluate_profile(coefficients, ANGLES) for joint, coefficients in self.initial.items()}

    def worn(self, state: dict[str, np.ndarray]) -> LoadedMechanism:
        """The mechanism with each wearing joint's profile = the file's + the life's."""
        document = copy.deepcopy(self.loaded.document)
        for item in document["joints"]:
            if item.get("name") in state:
                total = summed_coefficients(self.initial[item["name"]], state[item["name"]])
                item["wear"] = dict(item["wear"]) | {"profile": profile_block(total)}
        return load_mechanism_text(dump_yaml(document), name=str(self.loaded.path), base_dir=self.loaded.base_dir)

    def simulate(self, state: dict[str, np.ndarray], output: Path) -> Operation:
        """One operation with the bores worn to `state`: its wear per joint and its figures; LifeError when the run
        does not complete."""
        loaded = self.worn(state)
        report = run_to_file(prepare(loaded), loaded, output, contents="summary")
        if isinstance(report.error, KeyboardInterrupt):  # Ctrl-C or SIGTERM in the run stops the life, its rows kept:
            raise KeyboardInterrupt                      # not a failed operation, whose block would be refused
        if not report.complete:
            raise WornOperationFailed(f"{self.loaded.path}: the operation with the bores worn to "
                            f"{', '.join(f'{j} {max_depth(s) * 1e3:.4g} mm' for j, s in state.items())} did not "
                            f"complete: {report.status} (its file: {report.output})\n  hint: the wear may have "
                            "opened a clearance the solver settings cannot follow; see the run's message above, or "
                            "lower --operations")
        with h5py.File(report.output, "r") as result:
            wear = {joint: np.array(result[f"joints/{joint}/wear"].attrs["coefficients_m"]) for joint in self.clearances}
        return Operation(wear, operation_figures(report.output))


def max_depth(coefficients: np.ndarray) -> float:
    return float(evaluate_profile(coefficients, ANGLES).max())


def operation_figures(path: Path) -> dict[str, float]:
    """The figures of one operation kept per block: travel figures (SI), the output's peak acceleration, each
    clearance joint's largest contact force."""
    summary = summarize(path)
    figures = {f"peak_contact_force_{joint}_N": force for joint, force in summary.peak_contact_force.items()}
    if summary.peak_acceleration:
        figures["peak_acceleration_m_s2"] = summary.peak_acceleration[1]
    figures |= {name: value for name, value in summary.travel.items() if isinstance(value, (int, float))}
    return figures


def _check_operations(operations: int, config: Path) -> None:
    if not 1 <= operations <= MAX_OPERATIONS:
        raise LifeError(f"--operations {operations}: a life is at least 1 and at most {MAX_OPERATIONS:,} operations "
                        f"of {config}\n  hint: e.g. --operations 10000 (mechanical endurance class M2)")


def _resumable(output: Path, resolved_yaml: str, tolerance: float) -> bool:
    if not output.exists() or not is_life_file(output):
        return False
    with h5py.File(output, "r") as file:
        return file.attrs.get("config_yaml") == resolved_yaml and float(file.attrs.get("tolerance", -1)) == tolerance


def run_life(request: LifeRequest, progress: Callable[[int, int, int], None] = lambda done, total, blocks: None) -> LifeReport:
    """The life of `request`, started or continued from its file; progress(operations done, target, blocks)."""
    config, output = Path(request.config), Path(request.output)
    check_output_path(output, config)
    _check_operations(request.operations, config)
    if not 0.0 < request.tolerance < 1.0:
        raise LifeError(f"--tolerance {request.tolerance}: the error allowed per block is a fraction of the clearance "
                        "between 0 and 1\n  hint: e.g. --tolerance 0.02 (2 % of the clearance)")
    machine = Machine(load_mechanism(config, request.overrides))
    output.parent.mkdir(parents=True, exist_ok=True)
    runs = output.with_name(f"{output.stem}-operations")
    runs.mkdir(exist_ok=True)
    resolved = machine.loaded.resolved_yaml
    backup, counter = None, {"simulations": 0, "blocks": 0}

    def simulate(state: dict[str, np.ndarray], keep_as: str | None = None) -> Operation:
        counter["simulations"] += 1
        path = runs / (keep_as or "predicted.h5")
        if keep_as is None:
            path.unlink(missing_ok=True)  # a refused block's failed prediction: kept only while it is the last word
        operation = machine.simulate(state, path)
        if keep_as is None:
            path.unlink(missing_ok=True)
        return operation

    if _resumable(output, resolved, request.tolerance):
        life = LifeFile.reopen(output)
        start, size = life.last_block()
        resumed_from = start.operations
    else:
        backup = keep_as_previous(output)
        life = LifeFile.create(output, {"config_yaml": resolved, "config_path": str(config), "tolerance": request.tolerance,
                                        "operations": request.operations}, machine.clearances, machine.harmonics)
        state = {joint: np.zeros(2 * machine.harmonics[joint] + 1) for joint in machine.clearances}
        start = Block(0, 0, state, simulate(state, "operations-0.h5"), 0.0, 0)
        life.append(start, 0, machine.initial_depth())
        size, resumed_from = None, None
    life.file.attrs["operations"] = max(request.operations, int(life.file.attrs["operations"]))

    def kept(block: Block, next_size: int) -> None:
        counter["blocks"] += 1
        life.append(block, next_size, machine.initial_depth())
        progress(block.operations, request.operations, counter["blocks"])

    last, status, complete = start, "complete", True
    progress(start.operations, request.operations, 0)
    try:
        last = live(simulate, start, request.operations, machine.clearances, BlockControl(tolerance=request.tolerance),
                    size, kept, simulate_end=lambda state, done: simulate(state, f"operations-{done}.h5"))
    except (LifeError, KeyboardInterrupt) as exc:
        status = "interrupted" if isinstance(exc, KeyboardInterrupt) else f"stopped: {exc}"
        complete = False
        life.finish(False, status)
        life.close()
        raise
    life.finish(complete, status)
    life.close()
    return LifeReport(output, complete, status, last, counter["blocks"], counter["simulations"], resumed_from, backup)
