"""Model runs for the diagnosis, in parallel through the sweep executor, each run once.

A model variant is a YAML document (dict). Its text is hashed into the file name under
`<report>/runs/`, and the sweep worker reuses a complete file written from the same text, so a
repeated evaluation (a scan point met again, a diagnosis run again) costs nothing.
"""

from __future__ import annotations

import copy
import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import h5py
import numpy as np

from clearsim.errors import ClearsimError
from clearsim.model.loader import dump_yaml
from clearsim.solver.outputs import IMPACT
from clearsim.sweep.worker import COMPLETE, CaseTask, run_case
from clearsim.units import si_text


@dataclass
class Prediction:
    """What a run predicts: all its sensors over its time grid; `error` when it failed; `impacts`, its clearance
    joints' contact episodes of kind impact (dry strikes of a journal on its bearing's wall, each as short as a Hertz
    contact: the events a chaotic impact sequence is made of; a film that carries the load, or a journal riding the wall
    in continuous contact, has none)."""

    time: np.ndarray
    sensors: dict[str, np.ndarray]
    error: str = ""
    impacts: int = 0

    @property
    def ok(self) -> bool:
        return not self.error


def document_text(document: dict) -> str:
    return dump_yaml(document)


def read_prediction(path: Path) -> Prediction:
    """A complete run's file: its sensors and its impacts (the `kind` column of each clearance joint's episode table,
    written in every file whatever its `contents`: a byte per contact episode)."""
    with h5py.File(path, "r") as handle:
        sensors = handle.get("sensors")
        values = {name: np.asarray(sensors[name][()], float) for name in sensors} if sensors is not None else {}
        return Prediction(np.asarray(handle["time"][()], float), values, impacts=_impacts(handle))


def _impacts(handle: h5py.File) -> int:
    joints = handle.get("joints")
    kinds = [joints[name]["episodes"]["kind"][()] for name in joints if "episodes" in joints[name]] if joints else []
    return int(sum(np.count_nonzero(k == IMPACT) for k in kinds))


class Evaluator:
    """Runs documents on an executor (a LocalPool kept open, or a Dask cluster); counts what it ran."""

    def __init__(self, folder: Path, config_name: str, base_dir: Path, executor, output_rate: float):
        self.folder = Path(folder)
        self.config_name = config_name
        self.base_dir = Path(base_dir)
        self.executor = executor
        self.output_rate = output_rate  # the record's: every run is sampled as the record is
        self.simulations = 0  # runs computed (not reused)
        self._memory: dict[str, Prediction] = {}

    def _prepared(self, document: dict) -> str:
        """The document's text with its output rate set to the record's (with its unit: a file may declare none): the
        steps do not depend on it, and samples beyond the record's rate cost the run (a UHV run at 100 kHz: 27 % more
        CPU than at 15 kHz, the same 6442 steps) and add nothing the comparison keeps (docs/diagnose.md §4)."""
        document.setdefault("solver", {})["output_rate"] = si_text(self.output_rate, "frequency")
        return document_text(document)

    def evaluate(self, documents: list[dict], then: Callable[[int, Prediction], Any] | None = None) -> list:
        """Predictions for the documents, in order; the new ones run in parallel.

        then(i, prediction): what to return for document i instead of its prediction, computed as soon as that
        prediction is there (a run reused at once, a new one when it ends): the parent's work on the finished runs
        (reading their sensors, scoring them) overlaps the runs still going instead of following the batch.
        """
        then = then or (lambda _, prediction: prediction)
        texts = [self._prepared(copy.deepcopy(d)) for d in documents]
        digests = [hashlib.sha256(text.encode()).hexdigest()[:16] for text in texts]
        positions: dict[str, list[int]] = {}
        for i, digest in enumerate(digests):
            positions.setdefault(digest, []).append(i)
        results: list = [None] * len(documents)

        def finish(digest: str) -> None:
            for i in positions[digest]:
                results[i] = then(i, self._memory[digest])

        todo = {}
        for digest, text in zip(digests, texts):
            if digest in self._memory:
                continue
            todo.setdefault(digest, CaseTask(digest, text, self.config_name, str(self.base_dir), (),
                                             str(self.folder / f"{digest}.h5"), contents="sensors"))
        for digest in positions:
            if digest not in todo:
                finish(digest)

        def collect(outcome) -> None:
            self.simulations += int(outcome.ran)
            if outcome.unwritten:  # a full disk: a fault of the machine, not a model that fails
                raise ClearsimError(outcome.error)
            if outcome.state == COMPLETE:
                self._memory[outcome.name] = read_prediction(Path(todo[outcome.name].output))
            else:
                self._memory[outcome.name] = Prediction(np.empty(0), {}, outcome.error or outcome.state)
            finish(outcome.name)

        if todo:
            self.folder.mkdir(parents=True, exist_ok=True)
            if self.executor.run(run_case, list(todo.values()), collect):
                raise KeyboardInterrupt
        return results

