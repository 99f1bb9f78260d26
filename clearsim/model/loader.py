"""YAML file → validated Mechanism, with every problem of the file reported at once, located.

    loaded = load_mechanism("configs/uhv_breaker.yaml", ["joints.J.clearance=0.1mm"])
    loaded.mechanism            # schema.Mechanism, SI floats
    loaded.resolved_yaml        # the YAML after overrides (written into result files)

Stages: YAML syntax (with duplicate keys as errors) → `--set` overrides →
schema validation → cross-references (clearsim.model.references). Problems of
the first stage stop the load; the later ones are gathered into one InputError.
"""

from __future__ import annotations

import os
import pickle
import stat
from dataclasses import dataclass, field, replace
from functools import cached_property, lru_cache
from pathlib import Path
from typing import Any, Sequence

import yaml
from pydantic import ValidationError
from yaml.constructor import SafeConstructor
from yaml.events import MappingEndEvent, MappingStartEvent, SequenceEndEvent, SequenceStartEvent
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode
from yaml.reader import ReaderError

from clearsim.errors import InputError, Problem
from clearsim.model.flexible import expanded_document, flexible_problems, rows_along_the_chain
from clearsim.model.messages import show, validation_problems
from clearsim.model.overrides import apply_overrides
from clearsim.model.paths import locate_error
from clearsim.model.references import KINDS, check_references
from clearsim.model.schema import Mechanism, validate_mechanism
from clearsim.model.yaml_reading import MAX_VALUE_CHARACTERS, CheckedLoader, FastCheckedLoader

MERGE_TAG = "tag:yaml.org,2002:merge"
FAST_LOADER = FastCheckedLoader  # libyaml when PyYAML has it: ~9× faster
FAST_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # the same text as SafeDumper (checked), 4× faster


@dataclass
class SourceMap:
    """Where each YAML path is written: path → (line, column), 1-based; plus list items' names.

    A mapping entry is located at its value when the value is a scalar or a flow
    collection (`bodies: [a, b]`), at its key when the value is a block below it.
    """

    positions: dict[tuple, tuple[int, int]] = field(default_factory=dict)
    names: dict[tuple, str] = field(default_factory=dict)
    overrides: dict[tuple, str] = field(default_factory=dict)  # path set by --set → its text

    @classmethod
    def from_text(cls, text: str) -> "SourceMap":
        return cls.from_node(yaml.compose(text, Loader=FAST_LOADER))

    @classmethod
    def from_node(cls, root: Node | None) -> "SourceMap":
        source = cls()
        if root is not None:
            source.positions[()] = _position(root)
            source._walk(root, (), set())
        return source

    def locate(self, path: tuple) -> tuple[tuple[int, int] | None, tuple]:
        """(position, path found) of `path` or of its nearest ancestor written in the file."""
        for depth in range(len(path), -1, -1):
            position = self.positions.get(tuple(path[:depth]))
            if position is not None:
                return position, tuple(path[:depth])
        return None, ()

    def override_for(self, path: tuple) -> str | None:
        """The `--set` text that wrote `path` or one of its ancestors."""
        for depth in range(len(path), 0, -1):
            text = self.overrides.get(tuple(path[:depth]))
            if text is not None:
                return text
        return None

    def _walk(self, node: Node, path: tuple, active: set) -> None:
        if id(node) in active:  # a recursive alias
            return
        active = active | {id(node)}
        if isinstance(node, SequenceNode):
            for index, item in enumerate(node.value):
                self._add(path + (index,), item)
                self._walk(item, path + (index,), active)
        elif isinstance(node, MappingNode):
            merged = [value for key, value in node.value if key.tag == MERGE_TAG]
            for key, value in node.value:
                if key.tag != MERGE_TAG:
                    child = path + (scalar_key(key),)
                    self.positions.setdefault(child, _position(key if _is_block(value) else value))
                    self._walk(value, child, active)
            for value in merged:  # keys written explicitly win over merged ones
                for mapping in value.value if isinstance(value, SequenceNode) else [value]:
                    self._walk(mapping, path, active)

    def _add(self, path: tuple, item: Node) -> None:
        self.positions.setdefault(path, _position(item))
        if isinstance(item, MappingNode):
            for key, value in item.value:
                if isinstance(key, ScalarNode) and key.value == "name" and isinstance(value, ScalarNode):
                    self.names.setdefault(path, value.value)


def _position(node) -> tuple[int, int]:
    """(line, column), 1-based, where a node or an event starts."""
    return node.start_mark.line + 1, node.start_mark.column + 1


def _is_block(node: Node) -> bool:
    return isinstance(node, (MappingNode, SequenceNode)) and not node.flow_style


def scalar_key(node: Node) -> Any:
    """A mapping key as the YAML loader constructs it (`1:` is the integer 1)."""
    if not isinstance(node, ScalarNode):
        return str(node.value)
    try:
        key = SafeConstructor().construct_object(node)
        hash(key)
        return key
    except Exception:
        return node.value


# --- YAML syntax ----------------------------------------------------------------------------------

_SYNTAX_HINTS = {
    "'\\t'": "indent with spaces: YAML does not allow tabs",
    "mapping values are not allowed": "a value that contains ': ' must be quoted, or a key is indented wrongly",
    "expected <block end>": "check the indentation of this line against the lines above",
    "could not find expected ':'": "a key needs ': ' after it (or a text value needs quotes)",
    "expected ',' or ']'": "a [list] is not closed, or an item needs quotes",
    "expected ',' or '}'": "a {mapping} is not closed, or an item needs quotes",
    "could not determine a constructor": "a mechanism file is plain YAML: remove the tag (!!...)",
    "expected a single document": "a mechanism file holds one YAML document: remove the extra '---'",
    "unacceptable character": "remove this character: a YAML file holds printable text only (a stray control "
                              "character, or a binary file)",
    "cannot read": "a mechanism file is plain YAML: remove the tag (!!...) and write the value itself, e.g. 0.3 kg",
}
MAX_NESTING = 50  # levels of mappings and lists; a mechanism file needs 5 (bodies → item → points → name → [x, y])
MAX_VALUES = 100_000  # values once aliases are expanded; a large mechanism file has a few thousand
# checking a value with a unit costs time growing with the square of its length (0.04 s at 1000 characters): one
# value (MAX_VALUE_CHARACTERS) and all of them together, aliases expanded, are bounded
MAX_TOTAL_CHARACTERS = 2**17  # the bundled files hold 2 000–6 000 characters of values
# every mapping or list opens with one of these of its own ('- ', 'key:', '? key', '[', '{'), so a text with fewer
# of them nests less deep than their count; libyaml composes 1000 levels safely (it crashes ~20 000 down)
COLLECTION_INDICATORS = "-:?[{"
COMPOSABLE_DEPTH = 1000


def _syntax_problem(exc: yaml.YAMLError, source: str) -> Problem:
    if isinstance(exc, ReaderError):  # a character YAML does not allow: located by its index in the text
        text = f"unacceptable character #x{exc.character:04x}: {exc.reason}"
        return Problem((), f"invalid YAML: {text}", _SYNTAX_HINTS["unacceptable character"],
                       position=text_position(source, exc.position))
    mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
    text = " ".join(str(part) for part in (getattr(exc, "context", None), getattr(exc, "problem", None)) if part)
    text = text or str(exc)
    hint = next((h for key, h in _SYNTAX_HINTS.items() if key in text), "check the YAML syntax at this line")
    position = (mark.line + 1, mark.column + 1) if mark is not None else None
    return Problem((), f"invalid YAML: {text}", hint, position=position)


def text_position(text: str, index: int) -> tuple[int, int]:
    """(line, column), 1-based, of a character index."""
    line_start = text.rfind("\n", 0, index) + 1
    return text.count("\n", 0, index) + 1, index - line_start + 1


def _too_deep(position: tuple[int, int]) -> Problem:
    return Problem((), f"invalid YAML: nested more than {MAX_NESTING} levels deep",
                   "a mechanism file nests a few levels (bodies → item → points): look for brackets opened and "
                   "never closed, or aliases (*name) inside the blocks they repeat", position=position)


def nesting_problem(text: str, loader_class=FAST_LOADER) -> Problem | None:
    """Nesting deeper than MAX_NESTING, found in the parser's events before a recursive composer meets it.

    (libyaml's composer overflows the C stack, a crash, some 20 000 levels down; the pure-Python one overflows
    Python's stack some 500 levels down.) The parser's YAMLError is raised: a syntax error before any deep nesting,
    or, from libyaml 0.2.6 on, nesting beyond libyaml's own limit of 1000 levels.
    """
    depth = 0
    for event in yaml.parse(text, Loader=loader_class):
        if isinstance(event, (MappingStartEvent, SequenceStartEvent)):
            depth += 1
            if depth > MAX_NESTING:
                return _too_deep(_position(event))
        elif isinstance(event, (MappingEndEvent, SequenceEndEvent)):
            depth -= 1
    return None


def _may_nest_too_deep(text: str) -> bool:
    """A text with fewer than COMPOSABLE_DEPTH collection indicators cannot nest deep enough to harm libyaml's
    composer, and is not parsed twice: its nesting beyond MAX_NESTING is found on the composed nodes (alias_problem),
    at the same place."""
    return sum(text.count(indicator) for indicator in COLLECTION_INDICATORS) >= COMPOSABLE_DEPTH


def _refuse_deep_nesting(text: str, loader_class, file: str | Path) -> None:
    too_deep = nesting_problem(text, loader_class)
    if too_deep is not None:
        raise InputError([too_deep], file)


def _too_long(node: ScalarNode) -> Problem:
    return Problem((), f"invalid YAML: a value of {len(node.value)} characters, more than any setting takes "
                   f"({MAX_VALUE_CHARACTERS}): {show(node.value)}", "names, numbers, units and file paths are short: "
                   "look for a missing quote or line break, or a wrong file pasted in", position=_position(node))


def alias_problem(root: Node | None) -> Problem | None:
    """Aliases that make the document contain itself, or expand it beyond MAX_VALUES values, MAX_NESTING levels or
    MAX_TOTAL_CHARACTERS characters of values; a value longer than MAX_VALUE_CHARACTERS.

    Walked without recursion: each of these would otherwise recurse without end or take hours.
    """
    on_path: set[int] = set()
    stack: list[tuple[Node, bool]] = [(root, False)] if root is not None else []
    values = characters = 0
    while stack:
        node, leaving = stack.pop()
        if leaving:
            on_path.discard(id(node))
            continue
        if id(node) in on_path:
            return Problem((), "invalid YAML: an alias (*name) refers to the block it is in, so the block would "
                           "contain itself", "write the repeated values out, or anchor (&name) a block that does "
                           "not hold the alias", position=_position(node))
        values += 1
        if values > MAX_VALUES:
            return Problem((), f"invalid YAML: the aliases (*name) expand the file to more than {MAX_VALUES} values",
                           "aliases repeat a block: use them for a few shared blocks, not nested in one another",
                           position=_position(node))
        if isinstance(node, ScalarNode):
            if len(node.value) > MAX_VALUE_CHARACTERS:
                return _too_long(node)
            characters += len(node.value)
            if characters > MAX_TOTAL_CHARACTERS:
                return Problem((), f"invalid YAML: the values of the file, aliases (*name) repeated, add up to more "
                               f"than {MAX_TOTAL_CHARACTERS} characters", "a mechanism file holds a few thousand "
                               "characters of values: use aliases for a few shared blocks, and check that this is "
                               "the right file", position=_position(node))
        if isinstance(node, (SequenceNode, MappingNode)) and len(on_path) >= MAX_NESTING:
            return _too_deep(_position(node))  # an empty list or mapping counts as a level, as in nesting_problem
        children = _children(node)
        if children:
            on_path.add(id(node))
            stack.append((node, True))
            stack.extend((child, False) for child in reversed(children))
    return None


def _children(node: Node) -> list[Node]:
    if isinstance(node, SequenceNode):
        return list(node.value)
    if isinstance(node, MappingNode):
        return [part for pair in node.value for part in pair]
    return []


def duplicate_keys(node: Node | None, path: tuple = ()) -> list[Problem]:
    """Keys written twice in one mapping (YAML itself would silently keep the last)."""
    problems: list[Problem] = []
    if isinstance(node, SequenceNode):
        for index, item in enumerate(node.value):
            problems += duplicate_keys(item, path + (index,))
    elif isinstance(node, MappingNode):
        first_line: dict = {}
        for key, value in node.value:
            if key.tag == MERGE_TAG:
                continue
            name = scalar_key(key)
            if name in first_line:
                message = f"duplicate key '{name}' (first written at line {first_line[name]})"
                problems.append(Problem(path + (name,), message, "remove one of the two", position=_position(key)))
            else:
                first_line[name] = _position(key)[0]
            problems += duplicate_keys(value, path + (name,))
    return problems


def parse_yaml(text: str, file: str | Path) -> tuple[dict, SourceMap]:
    """(document, source map); InputError for syntax errors, duplicate keys, a non-mapping top level."""
    try:
        if _may_nest_too_deep(text):
            _refuse_deep_nesting(text, FAST_LOADER, file)
        root, document = _compose(text, FAST_LOADER, file)
    except yaml.YAMLError:
        # a syntax error, or nesting beyond libyaml's own limit: the pure-Python parser again, for its messages (the
        # hints above know its wording), with no nesting limit of its own; its events first, its composer recurses
        try:
            _refuse_deep_nesting(text, CheckedLoader, file)
            root, document = _compose(text, CheckedLoader, file)
        except yaml.YAMLError as exc:
            raise InputError([_syntax_problem(exc, text)], file) from None
    source = SourceMap.from_node(root)
    _check_top_level(document, root, file, source)
    return document, source


@lru_cache(maxsize=4)
def _parsed_once(text: str, file: str) -> tuple[bytes, dict, dict]:
    """parse_yaml of a text, kept: (the document pickled, the source map's positions and names)."""
    document, source = parse_yaml(text, file)
    return pickle.dumps(document, pickle.HIGHEST_PROTOCOL), source.positions, source.names


def parse_yaml_again(text: str, file: str | Path) -> tuple[dict, SourceMap]:
    """parse_yaml of a text parsed before (a sweep loads one text with each case's overrides): a fresh copy of its
    document (0.04 ms, where parsing takes 3.4 ms for the UHV model) and a source map of its own."""
    pickled, positions, names = _parsed_once(text, str(file))
    return pickle.loads(pickled), SourceMap(positions, names)


def _compose(text: str, loader_class, file: str | Path) -> tuple[Node | None, Any]:
    """(root node, document) of one YAML document; InputError for duplicate keys, YAMLError for the rest."""
    loader = loader_class(text)
    try:
        root = loader.get_single_node()
        expanded = alias_problem(root)
        if expanded is not None:
            raise InputError([expanded], file)
        problems = duplicate_keys(root)
        if problems:
            raise InputError(problems, file, SourceMap.from_node(root))
        return root, loader.construct_document(root) if root is not None else None
    finally:
        loader.dispose()


def _check_top_level(document: Any, root: Node | None, file, source: SourceMap) -> None:
    if document is None:
        raise InputError([Problem((), "the file is empty", "a mechanism file needs at least `bodies:` and `solver:`",
                                  position=(1, 1))], file, source)
    if not isinstance(document, dict):
        found = "a list" if isinstance(document, list) else f"the value {document!r}"
        problem = Problem((), f"the top level must be a mapping (key: value), found {found}",
                          "start with keys such as `bodies:`, `joints:` and `solver:`", position=_position(root))
        raise InputError([problem], file, source)


# --- schema and names -----------------------------------------------------------------------------

_NEEDED_FOR_NAMES = {("bodies",), ("points",), ("defaults",)}  # invalid: too little left to check names against
_STAND_INS = {"solver": {"t_end": 1.0}}  # required sections that no name check reads


def _invalid_items(exc: ValidationError) -> set[tuple]:
    """The list items (("joints", 3)) and sections (("solver",)) that failed validation."""
    invalid = set()
    for error in exc.errors():
        path = locate_error(tuple(error["loc"]), Mechanism).path
        is_item = len(path) > 1 and path[0] in KINDS and isinstance(path[1], int)
        invalid.add(path[:2] if is_item else path[:1])
    return invalid


def _name(item: Any) -> str | None:
    name = item.get("name") if isinstance(item, dict) else None
    return name if isinstance(name, str) else None


def _references_of_valid_part(document: dict, exc: ValidationError) -> list[Problem]:
    """Name checks on the valid items of a file that failed validation, so that one run reports all.

    Invalid items are left out; references to their names are not reported again.
    """
    invalid = _invalid_items(exc)
    if invalid & _NEEDED_FOR_NAMES:
        return []
    partial = {key: value for key, value in document.items() if (key,) not in invalid}
    partial.update({key: value for key, value in _STAND_INS.items() if (key,) in invalid})
    known, kept = {}, {}
    for key in KINDS:
        items = partial.get(key)
        if isinstance(items, list):
            kept[key] = [index for index in range(len(items)) if (key, index) not in invalid]
            partial[key] = [items[index] for index in kept[key]]
            known[key] = {_name(item) for index, item in enumerate(items) if (key, index) in invalid}
    try:
        problems = check_references(Mechanism.model_validate(partial), known)
    except ValidationError:
        return []
    return [_in_file_order(problem, kept) for problem in problems]


def _in_file_order(problem: Problem, kept: dict[str, list[int]]) -> Problem:
    """A problem of the valid part located at its item's index in the file (the part leaves invalid items out)."""
    path = problem.path
    if len(path) > 1 and path[0] in kept and isinstance(path[1], int):
        return replace(problem, path=(path[0], kept[path[0]][path[1]]) + tuple(path[2:]))
    return problem


# --- loading --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LoadedMechanism:
    mechanism: Mechanism
    path: Path
    source: SourceMap
    document: dict  # the YAML document after overrides, as parsed (not to be changed)
    base_dir: Path  # relative file names (CSV tables) are read from here

    @cached_property
    def resolved_yaml(self) -> str:
        """The YAML text after overrides: enough to reproduce the run. Written when first asked for (a result
        file's `config_yaml`): 1.4 ms that a run kept in memory does not need."""
        return dump_yaml(self.document)


def dump_yaml(document: dict) -> str:
    """A mechanism document as YAML text, keys in their order (the `config_yaml` of result files)."""
    return yaml.dump(document, Dumper=FAST_DUMPER, sort_keys=False, allow_unicode=True)


def load_mechanism(path: str | Path, overrides: Sequence[str] = ()) -> LoadedMechanism:
    """Read, override, validate and cross-check a mechanism file; InputError lists every problem."""
    path = Path(path)
    return load_mechanism_text(read_mechanism_file(path), name=str(path), overrides=overrides, base_dir=path.parent)


MAX_FILE_BYTES = 32 * 2**20  # a mechanism file is a few kB; /dev/zero or a wrong file would be read until memory ends


def read_mechanism_file(path: Path) -> str:
    """The text of a mechanism file; InputError when it cannot be read, is not a regular file (a FIFO, a device), is
    not UTF-8 text or is far too large."""
    try:
        # opened without waiting: a named pipe (FIFO) with no writer would block here for ever
        with os.fdopen(os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)), "rb") as handle:
            kind = _not_regular(os.fstat(handle.fileno()).st_mode)
            if kind is not None:
                raise InputError([Problem((), f"cannot read the file: it is {kind}, not a regular file",
                                          "give the path of the YAML file itself (save what a pipe or a device "
                                          "would deliver into a file first)")], path)
            data = handle.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise InputError([Problem((), f"cannot read the file: {exc.strerror or exc}", "check the path")], path) from None
    if len(data) > MAX_FILE_BYTES:
        raise InputError([Problem((), f"cannot read the file: it is larger than {MAX_FILE_BYTES // 2**20} MB, far more "
                                      "than any mechanism file", "check that this is the right file")], path)
    try:
        return data.decode("utf-8").replace("\r\n", "\n").replace("\r", "\n")
    except UnicodeDecodeError:
        raise InputError([_not_utf8(data)], path) from None


def _not_regular(mode: int) -> str | None:
    """What a file that is not a regular one is ("a named pipe (FIFO)"), or None for a regular file."""
    if stat.S_ISREG(mode):
        return None
    kinds = {stat.S_ISFIFO: "a named pipe (FIFO)", stat.S_ISCHR: "a device", stat.S_ISBLK: "a device",
             stat.S_ISSOCK: "a socket", stat.S_ISDIR: "a folder"}
    return next((kind for test, kind in kinds.items() if test(mode)), "a special file")


def _not_utf8(data: bytes) -> Problem:
    """The first byte that is not UTF-8, located by line and column."""
    try:
        data.decode("utf-8")
        start = len(data)
    except UnicodeDecodeError as exc:
        start = exc.start
    line_start = data.rfind(b"\n", 0, start) + 1
    position = (data.count(b"\n", 0, start) + 1, len(data[line_start:start].decode("utf-8", "replace")) + 1)
    byte = f" 0x{data[start]:02x}" if start < len(data) else ""
    return Problem((), f"cannot read the file: it is not UTF-8 text (byte{byte})",
                   "a mechanism file is YAML text: save it as UTF-8 (not Latin-1 or UTF-16), "
                   "or check that this is the right file", position=position)


def boolean_problems(value: Any, path: tuple = ()) -> list[Problem]:
    """true/false anywhere in a mechanism file, where no setting takes one (pydantic would read true as 1)."""
    if isinstance(value, bool):
        return [Problem(path, f"expected a number, a value with a unit or a name, got {str(value).lower()}",
                        "YAML reads true, false, yes, no, on and off unquoted as true/false: write the number, "
                        "or quote a name that is one of these words")]
    if isinstance(value, dict):
        return [problem for key, item in value.items() for problem in boolean_problems(item, path + (key,))]
    if isinstance(value, list):
        return [problem for index, item in enumerate(value) for problem in boolean_problems(item, path + (index,))]
    return []


MAX_OUTPUT_SAMPLES = 1e9  # of each history: 8 GB a value written per sample; a long run writes a few million
HIGHEST_OUTPUT_RATE = 1e5  # Hz


def duration_problems(mechanism: Mechanism) -> list[Problem]:
    """A t_end (× output_rate) no run could finish or write: refused here, where its line is known, before the run
    asks the disk for "about inf MB"."""
    solver = mechanism.solver
    rate = solver.output_rate or HIGHEST_OUTPUT_RATE  # none written: chosen by the run, at most that
    samples = solver.t_end * rate
    if samples <= MAX_OUTPUT_SAMPLES:
        return []
    return [Problem(("solver", "t_end"), f"t_end = {solver.t_end:.3g} s at output_rate {rate:.3g} Hz is "
                    f"{samples:.3g} samples of each history, more than a result file can hold "
                    f"({MAX_OUTPUT_SAMPLES:.0e})", "t_end is the simulated time: a stroke or a few cycles of a "
                    "mechanism last milliseconds to seconds (the bundled models: 24 ms and 85 ms), e.g. t_end: 100 ms; "
                    "or lower solver.output_rate")]


def load_mechanism_text(text: str, name: str = "<string>", overrides: Sequence[str] = (),
                        base_dir: Path | None = None) -> LoadedMechanism:
    """As load_mechanism, from YAML text (`name` is used in messages)."""
    document, source = parse_yaml_again(text, name)
    source.overrides, problems = apply_overrides(document, list(overrides), Mechanism)
    booleans = boolean_problems(document)
    if booleans:  # alone: validation would also reject each (as 1, or as not a name) in its own words
        raise InputError(problems + booleans, name, source)
    mechanism = None
    try:
        mechanism = validate_mechanism(document)
        problems += check_references(mechanism) + duration_problems(mechanism)
        if not problems and any(body.flexible is not None for body in mechanism.bodies):
            problems += flexible_problems(mechanism)
            mechanism = mechanism if problems else rows_along_the_chain(validate_mechanism(
                expanded_document(document, mechanism, base_dir or Path.cwd())))
    except ValidationError as exc:
        problems += validation_problems(exc, document, Mechanism) + _references_of_valid_part(document, exc)
    if problems:
        raise InputError(problems, name, source)
    return LoadedMechanism(mechanism, Path(name), source, document, base_dir or Path.cwd())


def load_stored_mechanism(config_yaml: str, name: str) -> LoadedMechanism:
    """The mechanism a result file stores (its `config_yaml`). A stored text without a `units:` block was written
    when bare numbers meant SI (and one written now has none on a dimensional key), so it is read as `units: SI`."""
    try:
        document = yaml.load(config_yaml, Loader=FAST_LOADER)
    except (yaml.YAMLError, RecursionError):
        document = None  # the load below says what is wrong with it
    declared = isinstance(document, dict) and "units" in document
    return load_mechanism_text(config_yaml, name=name, overrides=() if declared else ("units=SI",))
