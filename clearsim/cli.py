"""The `clearsim` command line: a thin shell over clearsim.runner.

Errors a user can fix (clearsim.errors.ClearsimError) become one message on stderr and exit
code 2; tracebacks only with --debug.
"""

from __future__ import annotations

import functools
import json
import signal
import sys
from pathlib import Path
from typing import List, Optional

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from clearsim import __version__

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Planar mechanisms with clearance joints: simulate, sweep, plot, diagnose.")
console = Console()
errors = Console(stderr=True)
_state = {"debug": False}

INPUT_ERROR = 2
INTERRUPTED = 130


def _version(value: bool) -> None:
    if value:
        console.print(f"clearsim {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True, help="Print the version."),
    debug: bool = typer.Option(False, "--debug", help="Show tracebacks for errors."),
) -> None:
    _state["debug"] = debug


def _terminate(signum, frame):
    raise KeyboardInterrupt


def user_errors(command):
    """Run a command; ClearsimError → message + exit 2, Ctrl-C/SIGTERM → exit 130."""

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        from clearsim.errors import ClearsimError

        signal.signal(signal.SIGTERM, _terminate)
        try:
            return command(*args, **kwargs)
        except ClearsimError as exc:
            if _state["debug"]:
                raise
            errors.print(f"[bold red]error:[/] {escape(str(exc))}", markup=True, highlight=False, soft_wrap=True)
            raise typer.Exit(INPUT_ERROR) from None
        except KeyboardInterrupt:
            errors.print("interrupted")
            raise typer.Exit(INTERRUPTED) from None

    return wrapper


ConfigArgument = typer.Argument(None, help="Mechanism YAML file (default: the bundled UHV breaker model).")
SetOption = typer.Option([], "--set", help="Override a value: --set joints.J.clearance=0.1mm (repeatable).")


def _progress_bar(t_end: float):
    progress = Progress(TextColumn("simulating"), BarColumn(), TextColumn("{task.fields[now]:>9.3f} ms"),
                        TextColumn("of {task.fields[end]:.3f} ms"), TimeElapsedColumn(), console=errors,
                        transient=True, disable=not errors.is_terminal)
    task = progress.add_task("run", total=t_end, now=0.0, end=t_end * 1e3)
    return progress, lambda t: progress.update(task, completed=t, now=t * 1e3)


def _summary_table(report, summary) -> Table:
    table = Table(show_header=False, box=None, pad_edge=False)
    stats = report.statistics
    if summary.peak_velocity:
        table.add_row(f"peak |{summary.peak_velocity[0]}|", f"{summary.peak_velocity[1]:.4g} m/s")
    if summary.peak_acceleration:
        table.add_row(f"peak |{summary.peak_acceleration[0]}|", f"{summary.peak_acceleration[1]:.5g} m/s²")
    for joint, force in summary.peak_contact_force.items():
        free, impact, contact = summary.contact_time_share[joint]
        table.add_row(f"max contact force, joint {joint}",
                      f"{force:.5g} N   (time free {free:.0%}, impact {impact:.0%}, contact {contact:.0%})")
    table.add_row("steps (rejected)", f"{stats.steps} ({stats.rejected_steps})")
    table.add_row("contact events", f"{stats.contact_events}")
    table.add_row("wall time", f"{stats.wall_time:.3f} s (integration)")
    return table


@app.command()
@user_errors
def run(
    config: Optional[Path] = ConfigArgument,
    output: Path = typer.Option(Path("results/run.h5"), "-o", "--output", help="Result file (HDF5)."),
    overrides: List[str] = SetOption,
) -> None:
    """Simulate a mechanism and write its time histories to an HDF5 file."""
    from clearsim.runner import BUNDLED_CONFIG, prepare, run_to_file, summarize
    from clearsim.model.loader import load_mechanism

    loaded = load_mechanism(config or BUNDLED_CONFIG, overrides)
    system = prepare(loaded)
    progress, update = _progress_bar(system.mechanism.solver.t_end)
    with progress:
        report = run_to_file(system, loaded, output, update)
    if report.backup is not None:
        console.print(f"kept the earlier result as {report.backup}")
    console.print(f"[bold]{system.mechanism.name}[/]: {report.status} → {report.output}")
    console.print(_summary_table(report, summarize(report.output)))
    if isinstance(report.error, KeyboardInterrupt):
        raise KeyboardInterrupt
    if report.error is not None:
        raise report.error


@app.command()
@user_errors
def validate(config: Optional[Path] = ConfigArgument, overrides: List[str] = SetOption) -> None:
    """Check a mechanism file (schema, names, units, assembly) without running it."""
    from clearsim.runner import BUNDLED_CONFIG, prepare
    from clearsim.model.loader import load_mechanism

    loaded = load_mechanism(config or BUNDLED_CONFIG, overrides)
    system = prepare(loaded)
    mechanism = system.mechanism
    console.print(f"{loaded.path}: OK — {len(mechanism.bodies)} bodies, {len(mechanism.joints)} joints, "
                  f"{len(mechanism.drivers)} drivers, {system.degrees_of_freedom} degrees of freedom "
                  f"({2 * len(system.clearance_joints)} from clearance joints: "
                  f"{', '.join(system.clearance_joints) or 'none'})")


@app.command()
def schema() -> None:
    """Print the JSON Schema of the mechanism file (for editors)."""
    from clearsim.model.schema import Mechanism

    sys.stdout.write(json.dumps(Mechanism.model_json_schema(), indent=2) + "\n")


if __name__ == "__main__":
    app()
