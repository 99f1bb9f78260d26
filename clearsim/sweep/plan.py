"""A sweep request (the CLI's options) → a checked plan: the cases, their folder, `cases.json`.

Every case is loaded (schema, units, names) before anything runs or is written, so a bad path
or value stops the sweep with one message and exit code 2, not as a failure in each case.
Cases that come out as the same mechanism (`--clearance 0` and the ideal case) are run once.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

from clearsim.errors import ClearsimError, InputError
from clearsim.model.loader import load_mechanism_text
from clearsim.model.resolve import is_clearance_joint
from clearsim.sweep import grid, montecarlo
from clearsim.sweep.grid import Case, SweepOptionError

RESULTS = Path("results")
CASES_FILE = "cases.json"
IDEAL_PIN_IGNORES = ("clearance", "bearing_radius", "journal_radius", "material", "contact", "friction",
                     "initial_eccentricity", "initial_velocity")


@dataclass
class SweepRequest:
    """What to sweep; the fields are the options of `clearsim sweep`."""

    config: Path | None = None
    overrides: list[str] = field(default_factory=list)  # --set, single or comma-separated values
    clearance: str | None = None  # "0.01,0.1" in mm unless a unit is written
    joints: str | None = None  # "A,J": the joints --clearance applies to
    sample: int | None = None  # Monte Carlo cases from the file's tolerances
    seed: int = 0
    ideal: bool = True
    out: Path | None = None
    delay_fraction: float = 0.5


@dataclass
class SweepPlan:
    config: Path
    config_text: str
    base_dir: Path
    folder: Path
    cases: list[Case]
    labels: list[str]  # the swept quantities, in column order
    delay_fraction: float
    sampled: bool = False

    def case(self, name: str) -> Case:
        return next(c for c in self.cases if c.name == name)


class SweepInputError(ClearsimError):
    """Problems found in the cases of a sweep, each reported once."""


def _read(config: Path) -> str:
    try:
        return config.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SweepOptionError(f"cannot read {config}: {getattr(exc, 'strerror', None) or exc}") from None


def _check_request(request: SweepRequest) -> None:
    if not 0.0 < request.delay_fraction < 1.0:
        raise SweepOptionError(f"--delay-fraction must be between 0 and 1, got {request.delay_fraction}")
    if request.joints is not None and request.clearance is None:
        raise SweepOptionError("--joints names the joints of --clearance: give --clearance too")
    if request.sample is not None and request.sample < 1:
        raise SweepOptionError(f"--sample must be at least 1, got {request.sample}")
    if request.seed < 0:
        raise SweepOptionError(f"--seed must be 0 or more, got {request.seed}")


def _grid(request: SweepRequest, mechanism, fixed, swept) -> tuple[list[Case], list[str]]:
    targets = grid.target_joints(mechanism, request.joints) if request.clearance is not None else []
    zeroed = grid.zeroed_joints(mechanism, targets, swept)
    axes = [grid.clearance_axis(request.clearance, targets)] if request.clearance is not None else []
    axes += grid.set_axes(swept, set(zeroed))
    if not axes:
        raise SweepOptionError("nothing to sweep\n  hint: give --clearance 0.01,0.1, "
                               "--set path=value1,value2 or --sample N")
    if request.clearance is not None:
        clash = [path for path, _ in swept if grid.joint_of(path) in targets and path.endswith(".clearance")]
        if clash:
            raise SweepOptionError(f"--set {clash[0]}: that clearance is already swept by --clearance")
    return grid.grid_cases(axes, fixed, zeroed, request.ideal), [axis.label for axis in axes]


def _monte_carlo(request: SweepRequest, loaded, fixed, swept) -> tuple[list[Case], list[str]]:
    mechanism = loaded.mechanism
    if request.clearance is not None or swept:
        raise SweepOptionError("--sample draws the values of the file's tolerances: "
                               "it does not combine with --clearance or --set lists")
    if not mechanism.tolerances:
        raise SweepOptionError(f"--sample: {loaded.path} declares no `tolerances:`\n"
                               "  hint: see docs/sweeps.md, e.g. tolerances: [{path: joints.J.clearance, "
                               "distribution: uniform, low: 0.01 mm, high: 0.05 mm}]")
    zeroed = list(dict.fromkeys(grid.clearance_joints(mechanism) + montecarlo.sampled_joints(mechanism.tolerances)))
    cases = montecarlo.sample_cases(mechanism.tolerances, request.sample, request.seed, fixed, zeroed, request.ideal)
    return cases, [t.path for t in mechanism.tolerances]


def _validate(cases: list[Case], text: str, name: str, base_dir: Path, tolerances=()) -> list[Case]:
    """Load every case; one error listing each distinct problem; identical mechanisms merged."""
    blocks, kept, seen = {}, [], {}
    for case in sorted(cases, key=lambda c: c.ideal):  # the values as written first, then the ideal cases' zeros
        try:
            loaded = load_mechanism_text(text, name, case.overrides, base_dir)
        except InputError as exc:
            if tolerances:
                exc = InputError(montecarlo.tolerance_problems(tolerances, exc), exc.file, exc.source)
            for block in _blocks(str(exc)):
                blocks.setdefault(_problem_key(block), block)
            continue
        key = _physics_key(loaded.mechanism)
        if key in seen:
            kept[seen[key]] = _merged(kept[seen[key]], case)
        else:
            seen[key] = len(kept)
            kept.append(case)
    if blocks:
        raise SweepInputError("\n".join(blocks.values()))
    return sorted(kept, key=lambda c: not c.ideal)


def _blocks(report: str) -> list[str]:
    """An InputError's text split into its problems (a block starts at an unindented line)."""
    blocks: list[str] = []
    for line in report.splitlines():
        if line.startswith(" ") and blocks:
            blocks[-1] += "\n" + line
        else:
            blocks.append(line)
    return blocks


def _problem_key(block: str) -> str:
    """One report per distinct problem: per tolerance, or per message (the same bad path in many cases)."""
    header, _, body = block.partition("\n")
    return header if "  tolerances[" in header else (body or block)


def _physics_key(mechanism) -> str:
    """The mechanism as simulated: an ideal pin's clearance keys (radii, contact, friction) do not count."""
    data = mechanism.model_dump(exclude={"tolerances"})
    for joint, spec in zip(data["joints"], mechanism.joints):
        if spec.type == "revolute" and not is_clearance_joint(spec):
            joint.update({key: None for key in IDEAL_PIN_IGNORES})
    return json.dumps(data, sort_keys=True, default=str)


def _merged(first: Case, duplicate: Case) -> Case:
    """The ideal case absorbs a swept case that is the same mechanism (keeping its swept values)."""
    if duplicate.ideal and not first.ideal:
        first, duplicate = duplicate, first
    return replace(first, values={**duplicate.values, **first.values}, name=first.name) if first.ideal else first


def plan_sweep(request: SweepRequest, default_config: Path) -> SweepPlan:
    """Check the request and every case; nothing is written."""
    _check_request(request)
    config = Path(request.config or default_config).resolve()
    text = _read(config)
    fixed, swept = grid.split_overrides(list(request.overrides))
    loaded = load_mechanism_text(text, str(request.config or config), fixed, config.parent)
    if request.sample is not None:
        cases, labels = _monte_carlo(request, loaded, fixed, swept)
    else:
        cases, labels = _grid(request, loaded.mechanism, fixed, swept)
    tolerances = loaded.mechanism.tolerances if request.sample is not None else ()
    cases = _validate(cases, text, str(request.config or config), config.parent, tolerances)
    folder = Path(request.out) if request.out else RESULTS / f"sweep-{config.stem}-{_digest(text, cases)}"
    return SweepPlan(config, text, config.parent, folder.resolve(), cases, labels,
                     request.delay_fraction, request.sample is not None)


def _digest(text: str, cases: list[Case]) -> str:
    listing = json.dumps([text, [[c.name, list(c.overrides)] for c in cases]], ensure_ascii=False)
    return hashlib.sha256(listing.encode()).hexdigest()[:8]


def write_cases(plan: SweepPlan) -> Path:
    """cases.json: the config, the swept quantities and every case with its overrides."""
    document = {"config": str(plan.config), "config_sha256": hashlib.sha256(plan.config_text.encode()).hexdigest(),
                "swept": plan.labels, "delay_fraction": plan.delay_fraction,
                "cases": [{key: value for key, value in asdict(case).items() if key != "group"} for case in plan.cases]}
    path = plan.folder / CASES_FILE
    path.write_text(json.dumps(document, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    return path
