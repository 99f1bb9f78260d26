"""Hostile or broken input: each case ends in one located message and exit code 2, never a traceback, a hang, work
without bound or a file lost. Each case reproduces a reported failure (noted in its docstring)."""

import os
import threading
from contextlib import contextmanager
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner
from yaml.scanner import ScannerError

from clearsim.cli import app
from clearsim.diagnose import MeasuredDataError, read_measured
from clearsim import errors
from clearsim.errors import InputError
from clearsim.model import loader
from tests.unit.test_loader import SLIDER_CRANK, edited, line_of, load_error

CONFIGS = Path(__file__).resolve().parents[2] / "clearsim" / "configs"
FLORES = CONFIGS / "slider_crank_flores.yaml"
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def assert_located_exit_2(result, *fragments):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and result.exception is None or isinstance(result.exception, SystemExit)
    for fragment in fragments:
        assert fragment in result.output, result.output


# --- nesting, whatever libyaml PyYAML brings --------------------------------------------------------


class NestingLimitedLoader(yaml.SafeLoader):
    """The pure-Python loader with libyaml 0.2.6's rule (PyYAML 6.0.4): a ScannerError "exceeded maximum nesting
    depth" at the 1000th level, met while scanning ahead, before the parser hands out the first events."""

    def fetch_flow_collection_start(self, token_class):
        if self.flow_level >= 999:
            raise ScannerError("while increasing flow level", None, "exceeded maximum nesting depth", self.get_mark())
        super().fetch_flow_collection_start(token_class)


FAST_LOADERS = {"installed": loader.FAST_LOADER, "libyaml 0.2.5 (no limit)": yaml.SafeLoader,
                "libyaml 0.2.6 (1000 levels)": NestingLimitedLoader}
DEEP = {"1200 [": "a: " + "[" * 1200 + "]" * 1200, "10^4 [": "a: " + "[" * 10**4 + "]" * 10**4,
        "2·10^5 [": "a: " + "[" * 200_000 + "]" * 200_000}


def assert_too_deep(text: str) -> None:
    with pytest.raises(InputError) as info:
        loader.load_mechanism_text(text, "deep.yaml")
    assert str(info.value).startswith("deep.yaml:1:53\n  invalid YAML: nested more than 50 levels deep")


@pytest.mark.parametrize("fast", list(FAST_LOADERS))
@pytest.mark.parametrize("text", list(DEEP))
def test_deep_nesting_is_located_whatever_the_fast_parser_refuses(monkeypatch, fast, text):
    """PyYAML 6.0.4's libyaml refused 1200 '[' itself and the pure-Python fallback recursed into a RecursionError
    (exit 1)."""
    monkeypatch.setattr(loader, "FAST_LOADER", FAST_LOADERS[fast])
    assert_too_deep(DEEP[text])


def test_nesting_before_a_syntax_error_is_located_not_recursed_into():
    """600 '[' (too few to be checked before libyaml composes) then a syntax error: the pure-Python parser, asked
    again for its message, recursed into a RecursionError with every PyYAML version."""
    assert_too_deep("a: " + "[" * 600 + "]" * 599 + "\n b: c: d\n")


# --- values the YAML constructors cannot read ---------------------------------------------------------

UNREADABLE = {'!!float "abc"': "the tag !!float cannot read 'abc'", '!!int "12x"': "the tag !!int cannot read '12x'",
              "!!bool maybe": "the tag !!bool cannot read 'maybe'", '!!int ""': "the tag !!int cannot read ''",
              "1" * 5000: "a value of 5000 characters, more than any setting takes (256)"}


@pytest.mark.parametrize("value", list(UNREADABLE), ids=["float abc", "int 12x", "bool maybe", "int empty", "5000 digits"])
def test_a_value_its_tag_or_python_cannot_read_is_located(value):
    """ValueError/KeyError/IndexError tracebacks (exit 1); 5000 digits: Python's 4300-digit limit on int()."""
    text = edited("mass: 0.30 kg", f"mass: {value}")
    message = load_error(text)
    assert message.startswith(f"sc.yaml:{line_of(text, 'mass: ' + value[:10])}:11\n"), message
    assert UNREADABLE[value] in message


@pytest.mark.parametrize("command", ["validate", "run", "draw"])
def test_an_unreadable_tag_exits_2_from_every_command_that_reads_the_file(tmp_path, command):
    config = tmp_path / "sc.yaml"
    config.write_text(FLORES.read_text().replace("mass: 0.30 kg", 'mass: !!float "abc"'))
    output = {"validate": [], "run": ["-o", tmp_path / "r.h5"], "draw": ["-o", tmp_path / "d.png"]}[command]
    assert_located_exit_2(invoke(command, config, *output), "sc.yaml:17:", "the tag !!float cannot read 'abc'")


@pytest.mark.parametrize("override, fragment", [
    ("bodies.crank.mass=" + "1" * 5000, "a value of 5000 characters, more than any setting takes (256)"),
    ("bodies.crank.mass=!!int 12x", "cannot read the value '!!int 12x'"),
    ("gravity=&a [*a, 1]", "an alias (*name) in the value"),
    ("joints.A.clearance=", "no value after '='"),
    ("joints.A.clearance=  ", "no value after '='"),
])
def test_a_set_value_that_cannot_be_read_is_reported_at_the_set(override, fragment):
    """5000 digits: a ValueError traceback; an alias to itself: a RecursionError; an empty value: the joint's
    clearance silently unset, exit 0."""
    message = load_error(SLIDER_CRANK, override)
    assert message.startswith("in --set " + override[:40]), message
    assert fragment in message and len(message.splitlines()[0]) <= errors.MAX_LINE


def test_an_empty_set_value_exits_2_and_leaves_the_earlier_result_in_place(tmp_path):
    """`--set joints.slider_pin.clearance=` ran as if unset (exit 0) and moved run.h5 to run.previous.h5."""
    earlier = tmp_path / "run.h5"
    earlier.write_bytes(b"the earlier result")
    result = invoke("run", FLORES, "-o", earlier, "--set", "joints.slider_pin.clearance=", "--set", "solver.t_end=1ms")
    assert_located_exit_2(result, "in --set joints.slider_pin.clearance=", "no value after '='",
                          "--set joints.slider_pin.clearance=<value>")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"] and earlier.read_bytes() == b"the earlier result"


# --- bounded work and bounded messages --------------------------------------------------------------


@pytest.fixture
def unit_parser_lengths(monkeypatch):
    """The lengths of the texts the unit parser is given (its time grows with the square of the length)."""
    from clearsim import units

    lengths = []
    parse = units.parse_quantity

    def recording(text, *args, **kwargs):
        lengths.append(len(text))
        if len(text) > 1000:  # minutes of work ahead: stop here
            raise RuntimeError(f"the unit parser was given {len(text)} characters")
        return parse(text, *args, **kwargs)

    monkeypatch.setattr(units, "parse_quantity", recording)
    return lengths


@pytest.mark.parametrize("value", ["1" * 100_000 + " kg", "'" + "x" * 100_000 + "'"], ids=["digits", "text"])
def test_a_huge_value_is_refused_before_it_is_parsed(unit_parser_lengths, value):
    """A 100 000-digit mass made `validate` run for minutes in the unit parser."""
    text = edited("mass: 0.30 kg", f"mass: {value}")
    message = load_error(text)
    assert message.startswith(f"sc.yaml:{line_of(text, 'mass: ' + value[:5])}:11\n")
    assert "more than any setting takes (256)" in message and len(message) < 1000
    assert max(unit_parser_lengths, default=0) <= loader.MAX_VALUE_CHARACTERS


def test_a_long_string_aliased_thousands_of_times_is_refused_at_its_anchor(unit_parser_lengths):
    """A small file with one 10 kB string aliased 1000 times: 760 s of `validate` and a 20 MB message."""
    aliases = "".join(f"  - {{name: extra{k}, mass: *big, inertia: *big, position: [0 m, 0 m]}}\n" for k in range(20_000))
    text = edited("mass: 0.30 kg", "mass: &big '" + "1" * 10_000 + " kg'").replace("joints:\n", aliases + "joints:\n", 1)
    message = load_error(text)
    assert message.startswith(f"sc.yaml:{line_of(text, '&big')}:11\n") and len(message) < 1000
    assert unit_parser_lengths == []


def test_aliased_values_are_bounded_in_total_characters(unit_parser_lengths):
    """Values each short enough, aliased until they add up to more than MAX_TOTAL_CHARACTERS: refused at once."""
    value = "1 " + "g*" * 120 + "g"
    count = loader.MAX_TOTAL_CHARACTERS // len(value) + 1
    aliases = "".join(f"  - {{name: extra{k}, mass: *m, inertia: 1 kg*m^2, position: [0 m, 0 m]}}\n" for k in range(count))
    text = edited("mass: 0.30 kg", f"mass: &m '{value}'").replace("joints:\n", aliases + "joints:\n", 1)
    message = load_error(text)
    assert f"add up to more than {loader.MAX_TOTAL_CHARACTERS} characters" in message
    assert unit_parser_lengths == []


def test_thousands_of_problems_make_a_short_message():
    """Every problem of a file was printed, each quoting its whole value: megabytes on the terminal."""
    aliases = "".join(f"  - {{name: extra{k}, mass: *m, inertia: 1 kg*m^2, position: [0 m, 0 m]}}\n" for k in range(200))
    text = edited("mass: 0.30 kg", "mass: &m '1 " + "x" * 200 + "'").replace("joints:\n", aliases + "joints:\n", 1)
    message = load_error(text)
    assert sum(line.startswith("sc.yaml:") for line in message.splitlines()) == 20
    assert message.endswith("... and 181 more problems: fix the first 20 and check again")
    assert max(len(line) for line in message.splitlines()) <= errors.MAX_LINE and len(message) < 20_000


def test_every_error_message_is_bounded_in_lines_and_line_length():
    message = errors.bounded("\n".join(["x" * 5000] * 300))
    lines = message.splitlines()
    assert len(lines) == 101 and lines[-1] == "... (200 more lines)"
    assert lines[0] == "x" * (errors.MAX_LINE - 3) + "..."


# --- files that are not files -----------------------------------------------------------------------


@contextmanager
def named_pipe(path: Path):
    """A named pipe at `path`; whoever opens it to read gets the end of the file at once instead of waiting for ever
    for a writer (so that reading it fails a test rather than hanging it)."""
    os.mkfifo(path)
    done = threading.Event()

    def release_readers():
        while not done.wait(0.05):
            try:
                os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))  # succeeds only while a reader waits
            except OSError:
                pass

    writer = threading.Thread(target=release_readers, daemon=True)
    writer.start()
    try:
        yield path
    finally:
        done.set()
        writer.join()


@pytest.mark.parametrize("command", ["validate", "run", "draw"])
def test_a_named_pipe_is_refused_not_waited_on(tmp_path, command):
    """A FIFO as the mechanism file blocked `clearsim validate` for ever."""
    output = {"validate": [], "run": ["-o", tmp_path / "r.h5"], "draw": ["-o", tmp_path / "d.png"]}[command]
    with named_pipe(tmp_path / "sc.yaml") as fifo:
        result = invoke(command, fifo, *output)
    assert_located_exit_2(result, f"{fifo}\n  cannot read the file: it is a named pipe (FIFO), not a regular file")


def test_a_force_table_that_is_a_named_pipe_is_refused_at_its_file_key(tmp_path):
    """A FIFO named by a tabulated force's `file:` blocked `clearsim validate` for ever."""
    config = tmp_path / "sc.yaml"
    text = FLORES.read_text() + ("forces:\n  - {type: tabulated, name: push, body: slider, direction: [1, 0], "
                                 "file: push.csv, time_unit: ms, value_unit: N}\n")
    config.write_text(text)
    with named_pipe(tmp_path / "push.csv"):
        result = invoke("validate", config)
    assert_located_exit_2(result, f"sc.yaml:{line_of(text, 'file: push.csv')}:", "forces[0] 'push' → file",
                          "push.csv' is not a regular file (a folder, a named pipe or a device)")


def test_a_regular_file_beyond_32_mb_is_still_refused_by_its_size(tmp_path):
    big = tmp_path / "big.yaml"
    with big.open("wb") as handle:
        handle.truncate(loader.MAX_FILE_BYTES + 1)  # sparse: nothing written to the disk
    with pytest.raises(InputError, match="cannot read the file: it is larger than 32 MB"):
        loader.load_mechanism(big)


# --- synthesize and diagnose ------------------------------------------------------------------------


def test_synthesize_never_writes_over_the_mechanism_file_even_with_force(tmp_path, monkeypatch):
    """`synthesize -o sc.yaml --force` replaced the mechanism file by the CSV record."""
    config = tmp_path / "sc.yaml"
    config.write_text(FLORES.read_text())
    monkeypatch.chdir(tmp_path)
    result = invoke("synthesize", "sc.yaml", "-o", "sc.yaml", "--force", "--set", "solver.t_end=1ms")
    assert_located_exit_2(result, "-o sc.yaml: that is the mechanism file being read", "hint:")
    assert config.read_text() == FLORES.read_text()


UNITS = {"slider_displacement": "m", "slider_velocity": "m/s"}


@pytest.mark.parametrize("unit, value", [("m", "1e308"), ("km", "1e306"), ("m", "-1e200")])
def test_a_measured_sample_beyond_any_measurement_is_located(tmp_path, unit, value):
    """One 1e308 sample crashed `diagnose` in the noise estimate (lstsq: array must not contain infs); 1e306 km
    became inf in SI after the finiteness check."""
    rows = [f"{0.1 * k:g},{value if k == 7 else 0.01 * k:},{0.5 + 0.01 * k:g}" for k in range(30)]
    path = tmp_path / "bench.csv"
    path.write_text(f"time [ms],slider_displacement [{unit}],slider_velocity\n" + "\n".join(rows) + "\n")
    with pytest.raises(MeasuredDataError) as info:
        read_measured(path, UNITS)
    assert str(info.value).startswith(f"{path}:9: column 'slider_displacement': {float(value):g} is beyond any "
                                      "measured value")


def test_a_measured_record_that_is_a_named_pipe_is_refused(tmp_path):
    """A FIFO given as --measured blocked `diagnose` for ever."""
    with named_pipe(tmp_path / "bench.csv") as fifo, pytest.raises(MeasuredDataError, match="not a regular file"):
        read_measured(fifo, UNITS)


# --- t_end ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["validate", "run"])
def test_an_endless_t_end_is_refused_at_its_line_with_a_plausible_one(tmp_path, command):
    """`t_end: 1e308 s` passed `validate`; `run` said "about inf MB" with no line."""
    config = tmp_path / "sc.yaml"
    text = FLORES.read_text().replace("t_end: 24 ms", "t_end: 1e308 s")
    config.write_text(text)
    output = ["-o", tmp_path / "r.h5"] if command == "run" else []
    assert_located_exit_2(invoke(command, config, *output), f"sc.yaml:{line_of(text, 't_end: 1e308 s')}:17  solver → t_end",
                          "more than a result file can hold", "e.g. t_end: 100 ms")
    assert not (tmp_path / "r.h5").exists()
