"""A sweep request (the CLI's options) → a checked plan: the cases, their folder, `cases.json`.

Every case is loaded (schema, units, names) before anything runs or is written, so a bad path
or value stops the sweep with one message and exit code 2, not as a failure in each case.
A case that comes out as the ideal mechanism (`--clearance 0`) is run once, as the ideal case; two swept cases
that are one mechanism (`--clearance 0.1,100um`) are refused.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

from clearsim.errors import ClearsimError, InputError
from clearsim.model.loader import load_mechanism_text
from clearsim.model.resolve import is_clearance_joint
from clearsim.sweep import grid, montecarlo
from clearsim.sweep.grid import Case, SweepOptionError

KEEP = ("all", "summary", "figures")  # what `--keep` may ask each case's file to hold (runner.CONTENTS)

RESULTS = Path("results")
MAX_CASES = 100_000  # each case is loaded and checked before anything runs (~3 ms each): 5 minutes of planning
CASES_FILE = "cases.json"
IDEAL_PIN_IGNORES = ("clearance", "bearing_radius", "journal_radius", "material", "contact", "friction",
                     "initial_eccentricity", "initial_velocity", "wear")


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
    keep: str = "all"  # the histories each case's file holds: "all", "summary" or "figures" (KEEP)


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
    keep: str = "all"
    _by_name: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def case(self, name: str) -> Case:
        """The case of that name, by a lookup (the summary asks for each of up to MAX_CASES cases)."""
        if len(self._by_name) != len(self.cases):
            self._by_name = {c.name: c for c in self.cases}
        return self._by_name[name]


class SweepInputError(ClearsimError):
    """Problems found in the cases of a sweep, each reported once."""


def _read(config: Path, shown: Path) -> str:
    """The config's text, or the loader's located message (a folder, not UTF-8, far too large)."""
    from clearsim.model.loader import read_mechanism_file

    try:
        return read_mechanism_file(config)
    except InputError as exc:
        raise InputError(exc.problems, shown) from None


def _check_request(request: SweepRequest) -> None:
    if not 0.0 < request.delay_fraction < 1.0:
        raise SweepOptionError(f"--delay-fraction must be between 0 and 1, got {request.delay_fraction}")
    if request.joints is not None and request.clearance is None:
        raise SweepOptionError("--joints names the joints of --clearance: give --clearance too")
    if request.sample is not None and request.sample < 1:
        raise SweepOptionError(f"--sample must be at least 1, got {request.sample}")
    if request.sample is not None and request.sample > MAX_CASES:
        raise SweepOptionError(f"--sample {request.sample}: a sweep has at most {MAX_CASES} cases (each is checked "
                               "before anything runs, and has its own result file)\n  hint: draw fewer samples "
                               "(the percentiles settle within a few hundred)")
    if request.seed < 0:
        raise SweepOptionError(f"--seed must be 0 or more, got {request.seed}")
    if request.keep not in KEEP:
        raise SweepOptionError(f"--keep must be {', '.join(KEEP[:-1])} or {KEEP[-1]}, got '{request.keep}'\n  hint: "
                               "all (the default) keeps every history; summary leaves out the bodies' motion and the "
                               "ideal joints' reactions; figures keeps only what summary.csv reads: the sensors and "
                               "the clearance joints' normal force, mode and stick flag (docs/sweeps.md §2)")


def _grid(request: SweepRequest, mechanism, fixed, swept) -> tuple[list[Case], list[str]]:
    targets = grid.target_joints(mechanism, request.joints) if request.clearance is not None else []
    zeroed = grid.zeroed_joints(mechanism, targets, swept)
    axes = [grid.clearance_axis(request.clearance, targets)] if request.clearance is not None else []
    axes += grid.set_axes(swept, set(zeroed))
    if not axes:
        raise SweepOptionError("nothing to sweep\n  hint: give --clearance 0.01,0.1, "
                               "--set path=value1,value2 or --sample N")
    count = math.prod(len(axis.values) for axis in axes)
    if count > MAX_CASES:
        sizes = " × ".join(f"{len(axis.values)} ({axis.label})" for axis in axes)
        raise SweepOptionError(f"the grid has {count} cases ({sizes}); a sweep has at most {MAX_CASES}\n"
                               "  hint: give fewer values, or split the study into several sweeps")
    if request.clearance is not None:
        clash = [path for path, _ in swept if grid.joint_of(path) in targets and path.endswith(".clearance")]
        clash += [path for path in _fixed_paths(fixed) if path in {f"joints.{j}.clearance" for j in targets}]
        if clash:
            raise SweepOptionError(f"--set {clash[0]}: that clearance is already swept by --clearance\n"
                                   "  hint: leave out the --set, or the joint from --joints")
    _check_not_also_fixed(fixed, {path: "a --set list" for path, _ in swept})
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
    _check_not_also_fixed(fixed, {t.path: f"the file's tolerances[{k}]" for k, t in enumerate(mechanism.tolerances)})
    zeroed = list(dict.fromkeys(grid.clearance_joints(mechanism) + montecarlo.sampled_joints(mechanism.tolerances)))
    cases = montecarlo.sample_cases(mechanism.tolerances, request.sample, request.seed, fixed, zeroed, request.ideal)
    return cases, [t.path for t in mechanism.tolerances]


def _fixed_paths(fixed: list[str]) -> list[str]:
    return [text.partition("=")[0].strip() for text in fixed]


def _check_not_also_fixed(fixed: list[str], varied: dict[str, str]) -> None:
    """A --set of one value for a path that the sweep varies would be overridden in every case: refused, not ignored."""
    for text, path in zip(fixed, _fixed_paths(fixed)):
        if path in varied:
            hint = ("leave out the --set, or that tolerance" if "tolerances" in varied[path]
                    else "give the path once: either one value or a list")
            raise SweepOptionError(f"--set {text}: {path} is also varied by {varied[path]}, which would override "
                                   f"this value in every case\n  hint: {hint}")


def _validate(cases: list[Case], text: str, name: str, base_dir: Path, tolerances=(),
              renamed: dict[str, str] | None = None) -> list[Case]:
    """Load every case; one error listing each distinct problem; identical mechanisms merged."""
    blocks, kept, seen, same, renamed = {}, [], {}, [], renamed or {}
    for case in sorted(cases, key=lambda c: c.ideal):  # the values as written first, then the ideal cases' zeros
        try:
            loaded = load_mechanism_text(text, name, case.overrides, base_dir)
        except InputError as exc:
            if tolerances:
                exc = InputError(montecarlo.tolerance_problems(tolerances, exc), exc.file, exc.source)
            for block in _blocks(str(exc)):
                blocks.setdefault(_problem_key(block), _as_written(block, renamed))
            continue
        key = _physics_key(loaded.mechanism)
        if key in seen and not case.ideal and not kept[seen[key]].ideal and not tolerances:  # grid values
            same.append((key, kept[seen[key]], case))
        if key in seen:
            kept[seen[key]] = _merged(kept[seen[key]], case)
        else:
            seen[key] = len(kept)
            kept.append(case)
    if blocks:
        raise SweepInputError("\n".join(blocks.values()))
    same = [(first, second) for key, first, second in same if not kept[seen[key]].ideal]  # the ideal one: run once
    if same:
        raise SweepOptionError(_same_mechanism(*same[0], len(same)))
    return sorted(kept, key=lambda c: not c.ideal)


def _same_mechanism(first: Case, second: Case, count: int) -> str:
    """Two swept cases that are one mechanism: the same value written twice (0.01 and 10um), or a swept value that
    nothing reads (they would be one row of the summary under the first one's name)."""
    differ = [label for label in first.values if first.values[label] != second.values.get(label)]
    shown = "; ".join(f"{label} {first.values[label]!r} and {second.values[label]!r}" for label in differ)
    option = "--clearance" if differ == [grid.CLEARANCE] else f"--set {differ[0]}" if len(differ) == 1 else "the grid"
    shown = shown or f"the cases {first.name} and {second.name}"
    more = f" ({count} such pairs)" if count > 1 else ""
    return (f"{option}: {shown} give the same mechanism{more}: the same value written twice, or a value "
            "that nothing in the file reads\n  hint: give each value once; check that the path reaches a joint "
            "that uses it")


def _as_written(block: str, renamed: dict[str, str]) -> str:
    """A problem of a --clearance value named by that option, not by the --set it became:
    'in --set joints.J.clearance=0.01 m' → 'in --clearance 0.01 m (joints.J.clearance)'."""
    for override, shown in renamed.items():
        header = f"in --set {override}"
        if block.startswith(header) and block[len(header):len(header) + 2] in ("", "  ", "\n"):
            return f"in {shown}" + block[len(header):]
    return block


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
    return json.dumps(_rounded(data), sort_keys=True, default=str)


def _rounded(value):
    """Floats to 12 significant digits: 0.1 mm and 100 um are 1e-4 and 1.0000000000000002e-4 m after conversion."""
    if isinstance(value, float):
        return float(f"{value:.12g}")
    if isinstance(value, dict):
        return {key: _rounded(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_rounded(item) for item in value]
    return value


def _merged(first: Case, duplicate: Case) -> Case:
    """The ideal case absorbs a swept case that is the same mechanism (keeping its swept values)."""
    if duplicate.ideal and not first.ideal:
        first, duplicate = duplicate, first
    return replace(first, values={**duplicate.values, **first.values}, name=first.name) if first.ideal else first


def plan_sweep(request: SweepRequest, default_config: Path) -> SweepPlan:
    """Check the request and every case; nothing is written."""
    _check_request(request)
    config = Path(request.config or default_config).resolve()
    text = _read(config, Path(request.config or config))
    fixed, swept = grid.split_overrides(list(request.overrides))
    loaded = load_mechanism_text(text, str(request.config or config), fixed, config.parent)
    if request.sample is not None:
        cases, labels = _monte_carlo(request, loaded, fixed, swept)
    else:
        cases, labels = _grid(request, loaded.mechanism, fixed, swept)
    tolerances = loaded.mechanism.tolerances if request.sample is not None else ()
    renamed = {}  # a --clearance value's override → how the user wrote it, for messages
    if request.clearance is not None and request.sample is None:
        for target in grid.target_joints(loaded.mechanism, request.joints):
            for value in grid.clearance_axis(request.clearance, [target]).values:
                renamed[f"joints.{target}.clearance={value}"] = f"--clearance {value} (joints.{target}.clearance)"
    cases = _validate(cases, text, str(request.config or config), config.parent, tolerances, renamed)
    folder = Path(request.out) if request.out else RESULTS / f"sweep-{config.stem}-{_digest(text, cases)}"
    check_folder(folder.resolve(), config, text)
    return SweepPlan(config, text, config.parent, folder.resolve(), cases, labels,
                     request.delay_fraction, request.sample is not None, request.keep)


def check_folder(folder: Path, config: Path, config_text: str) -> None:
    """A sweep writes into a new folder or one of its own config's (its cases.json names the same file, or a file
    with the same text: the project was moved or copied), never among other files or into another config's sweep
    (whose results would be mixed with, or renamed by, these)."""
    if folder.exists() and (not folder.is_dir() or (any(folder.iterdir()) and not (folder / CASES_FILE).exists())):
        raise SweepOptionError(f"--out {folder}: not a sweep folder (it holds other files and no {CASES_FILE})\n"
                               "  hint: give a new folder, or leave out --out for one under results/")
    cases = folder / CASES_FILE
    if not cases.exists():
        return
    try:
        document = json.loads(cases.read_text(encoding="utf-8"))
        earlier = Path(document["config"])
        same_text = document.get("config_sha256") == hashlib.sha256(config_text.encode()).hexdigest()
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError) as exc:
        raise SweepOptionError(f"--out {folder}: its {CASES_FILE} cannot be read ({type(exc).__name__}: {exc}), so "
                               "whose sweep the folder holds is unknown\n  hint: give a new folder; or, if it holds "
                               f"a sweep of {config.name}, delete {cases} and run again (its results are kept)") from None
    if earlier != config and not same_text:
        raise SweepOptionError(f"--out {folder}: it holds the sweep of another config, {earlier} "
                               f"({cases}: \"config\"), not of {config}; the two would be mixed\n"
                               "  hint: give a new folder, or leave out --out for one under results/")


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
