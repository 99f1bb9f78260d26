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
import typer.core
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from clearsim import __version__
from clearsim.heartbeat import Heartbeat
from clearsim.process import exit_without_final_collection

BOOLEAN_WORDS = {"true", "false", "yes", "no", "on", "off", "1", "0", "y", "n"}


class _Flags:
    """Flags (`--show`, `--force`, `--help`) take no value. typer's rich help writes them as `--show <bool>`, and
    `--show true` then reads `true` as the next argument (a file name): help writes them bare, and a true/false
    word right after one is refused with exit code 2 (unless a file of that name exists)."""

    def get_params(self, ctx):
        params = super().get_params(ctx)
        for param in params:
            if getattr(param, "is_flag", False) and param.metavar is None:
                param.metavar = ""  # no value column in the help
        return params

    def parse_args(self, ctx, args):
        flags = {name: param for param in self.get_params(ctx) if getattr(param, "is_flag", False)
                 for name in (*param.opts, *param.secondary_opts)}
        for flag, value in zip(args, args[1:]):
            if flag in flags and value.lower() in BOOLEAN_WORDS and not Path(value).exists():
                off = flags[flag].secondary_opts
                raise typer.BadParameter(f"{flag} is a switch and takes no value ('{flag} {value}'): write {flag} "
                                         f"to turn it on, leave it out{f' (or {off[0]})' if off else ''} to leave it off",
                                         ctx=ctx, param=flags[flag])
        return super().parse_args(ctx, args)


class _Command(_Flags, typer.core.TyperCommand):
    pass


class _Group(_Flags, typer.core.TyperGroup):
    pass


class _Typer(typer.Typer):
    def command(self, *args, cls=_Command, **kwargs):
        return super().command(*args, cls=cls, **kwargs)


app = _Typer(cls=_Group, add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
             help="Planar mechanisms with clearance joints: simulate, sweep, plot, diagnose.")
console = Console(emoji=False)  # no emoji codes: "run.yaml:100:9" would print as "run.yaml💯9"
errors = Console(stderr=True, emoji=False)
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
    exit_without_final_collection()


def _terminate(signum, frame):
    raise KeyboardInterrupt


def file_problem(exc: OSError) -> str:
    """An OSError of the file system as one line: the file, the reason, what to do."""
    where = f"{exc.filename}: " if exc.filename else ""
    return (f"{where}{exc.strerror or exc}. hint: check that the path exists and can be written (or read), "
            "or choose another one; --debug shows where it happened")


def user_errors(command):
    """Run a command; ClearsimError or a file-system OSError → message + exit 2, Ctrl-C/SIGTERM → exit 130."""

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        from clearsim.errors import ClearsimError, bounded

        signal.signal(signal.SIGTERM, _terminate)
        try:
            return command(*args, **kwargs)
        except ClearsimError as exc:
            if _state["debug"]:
                raise
            errors.print(f"[bold red]error:[/] {escape(bounded(str(exc)))}", markup=True, highlight=False, soft_wrap=True)
            raise typer.Exit(INPUT_ERROR) from None
        except OSError as exc:  # an output folder that cannot be made, a file that cannot be written or read
            if _state["debug"]:
                raise
            errors.print(f"[bold red]error:[/] {escape(file_problem(exc))}", markup=True, highlight=False, soft_wrap=True)
            raise typer.Exit(INPUT_ERROR) from None
        except KeyboardInterrupt:
            errors.print("interrupted")
            raise typer.Exit(INTERRUPTED) from None

    return wrapper


ConfigArgument = typer.Argument(None, help="Mechanism YAML file (default: the bundled UHV breaker model).")
SetOption = typer.Option([], "--set", help="Override a value: --set joints.J.clearance=0.1mm (repeatable).")


def _line(text: str) -> None:
    errors.print(text, markup=False, highlight=False, soft_wrap=True)


def _warning(text: str) -> None:
    errors.print(f"[bold yellow]warning:[/] {escape(text)}", markup=True, highlight=False, soft_wrap=True)


def heartbeat(command: str, terminal: Console = errors) -> Heartbeat:
    """A progress line now and then on stderr, when `terminal` (where the progress bar goes) is not a terminal."""
    return Heartbeat(_line, f"clearsim {command}", enabled=not terminal.is_terminal)


def _progress_bar(t_end: float):
    progress = Progress(TextColumn("simulating"), BarColumn(), TextColumn("{task.fields[now]:>9.3f} ms"),
                        TextColumn("of {task.fields[end]:.3f} ms"), TimeElapsedColumn(), console=errors,
                        transient=True, disable=not errors.is_terminal)
    task = progress.add_task("run", total=t_end, now=0.0, end=t_end * 1e3)
    beat = heartbeat("run")

    def update(t: float) -> None:
        progress.update(task, completed=t, now=t * 1e3)
        beat.update(f"t = {t * 1e3:.4g} of {t_end * 1e3:.4g} ms simulated", t, t_end)

    return progress, beat, update


def _announce_compile() -> None:
    """Say why the first run of a version waits before its progress bar moves."""
    from clearsim.solver.precompile import cache_is_cold

    if cache_is_cold():
        errors.print("compiling the numerical kernels: the first run of this clearsim version on this machine "
                     "(12–26 s on two idle cores depending on the CPU, longer on one or on a busy machine; later runs load them)", soft_wrap=True)


def _summary_table(report, summary) -> Table:
    table = Table(show_header=False, box=None, pad_edge=False)
    stats = report.statistics
    if summary.peak_velocity:
        table.add_row(f"peak |{summary.peak_velocity[0]}|", f"{summary.peak_velocity[1]:.4g} m/s")
    if summary.peak_acceleration:
        table.add_row(f"peak |{summary.peak_acceleration[0]}|", f"{summary.peak_acceleration[1]:.5g} m/s²")
    for joint, force in summary.peak_contact_force.items():
        free, impact, contact = summary.contact_time_share[joint]
        table.add_row(f"joint {joint}: max contact force", f"{force:.5g} N")
        table.add_row(f"joint {joint}: free / impact / contact", f"{free:.0%} / {impact:.0%} / {contact:.0%} of the time")
        if summary.sticking_share.get(joint, 0.0) > 0.0:
            table.add_row(f"joint {joint}: sticking", f"{summary.sticking_share[joint]:.0%} of the contact time")
    for label, value in _travel_rows(summary.travel):
        table.add_row(label, value)
    table.add_row("steps (rejected)", f"{stats.steps} ({stats.rejected_steps})")
    table.add_row("contact events", f"{stats.contact_events}")
    table.add_row("wall time", f"{stats.wall_time:.3f} s (integration)")
    table.add_row("compiled loop", f"{stats.kernel_time:.1f} s (compiled: not in the kernel cache)"
                  if stats.kernels_compiled else f"{stats.kernel_time:.2f} s (from the cache)")
    return table


def _travel_rows(travel: dict) -> list[tuple[str, str]]:
    from clearsim.travel import figure_rows

    return [(f"{travel['sensor']}: {label}", value) for label, value in figure_rows(travel)]


def _print_plausibility_warnings(loaded) -> None:
    """Values of the file that are valid but look like a misread unit (clearsim.model.plausibility)."""
    from clearsim.model.plausibility import plausibility_warnings, warning_text
    from clearsim.model.schema import validate_mechanism

    # the mechanism as written: a flexible link's expansion would be judged by its parts, at shifted places
    for problem in plausibility_warnings(validate_mechanism(loaded.document)):
        errors.print(f"[bold yellow]warning:[/] {escape(warning_text([problem], loaded))}", markup=True,
                     highlight=False, soft_wrap=True)


@app.command()
@user_errors
def run(
    config: Optional[Path] = ConfigArgument,
    output: Path = typer.Option(Path("results/run.h5"), "-o", "--output", help="Result file (HDF5)."),
    overrides: List[str] = SetOption,
) -> None:
    """Simulate a mechanism and write its time histories to an HDF5 file."""
    from clearsim.io.hdf5 import ResultWriteError
    from clearsim.runner import (BUNDLED_CONFIG, check_output_path, prepare, read_where_it_is, run_to_file, summarize,
                                 written_line)
    from clearsim.model.loader import load_mechanism

    check_output_path(output, config or BUNDLED_CONFIG)
    loaded = load_mechanism(config or BUNDLED_CONFIG, overrides)
    _print_plausibility_warnings(loaded)
    _announce_compile()
    system = prepare(loaded)
    progress, beat, update = _progress_bar(system.mechanism.solver.t_end)
    warned = []  # the run's warnings printed as they came, not again under the summary
    with progress, beat:
        report = run_to_file(system, loaded, output, update, warn=lambda text: (warned.append(text), _warning(text)))
    if report.backup is not None:
        console.print(f"kept the earlier result as {report.backup}")
    if isinstance(report.error, ResultWriteError):
        raise report.error  # the file may not even be readable: nothing to summarise
    console.print(f"[bold]{system.mechanism.name}[/]: {report.status} → {report.output}")
    console.print(read_where_it_is(report, written_line), highlight=False, soft_wrap=True)
    summary = read_where_it_is(report, summarize)
    console.print(_summary_table(report, summary))
    for line in summary.flexible_modes:
        console.print(line, highlight=False, soft_wrap=True)
    for warning in summary.warnings:
        if warning not in warned:
            _warning(warning)
    if isinstance(report.error, KeyboardInterrupt):
        raise KeyboardInterrupt
    if report.error is not None:
        raise report.error


@app.command()
@user_errors
def sweep(
    config: Optional[Path] = ConfigArgument,
    clearance: Optional[str] = typer.Option(
        None, "--clearance", help="Clearances to sweep, mm unless a unit is written: 0.01,0.03,0.1 "
        "(every clearance joint of the file, or the --joints)."),
    joints: Optional[str] = typer.Option(
        None, "--joints", help="The revolute joints --clearance applies to: A,J (an ideal one becomes a clearance joint)."),
    overrides: List[str] = typer.Option(
        [], "--set", help="path=value for every case, or path=v1,v2,... to sweep (repeatable; lists form a grid)."),
    sample: Optional[int] = typer.Option(None, "--sample", help="Monte Carlo: N cases drawn from the file's tolerances."),
    seed: int = typer.Option(0, "--seed", help="Seed of the Monte Carlo draws."),
    workers: Optional[int] = typer.Option(None, "--workers", help="Local worker processes (default: all cores)."),
    scheduler: Optional[str] = typer.Option(
        None, "--scheduler", help="Run on an existing Dask cluster: tcp://host:8786 (the result files come back here)."),
    out: Optional[Path] = typer.Option(
        None, "-o", "--out", help="Sweep folder (default: results/sweep-<config>-<hash>/); re-running resumes."),
    no_ideal: bool = typer.Option(False, "--no-ideal", help="Leave out the ideal (no-clearance) reference case."),
    delay_fraction: float = typer.Option(
        0.5, "--delay-fraction", help="Start delay: when the output velocity reaches this fraction of the ideal peak."),
    retry_failed: bool = typer.Option(False, "--retry-failed", help="Run cases that failed before again."),
    keep: str = typer.Option(
        "all", "--keep", help="What each case's file holds: all; summary (the sensors, the clearance joints, the "
        "energies: what the summary and `clearsim plot` read; a UHV case ~3× smaller); or figures (what summary.csv "
        "reads alone, for Monte Carlo studies)."),
) -> None:
    """Run a parameter study: one run per case, in parallel, with a summary table and summary.csv."""
    from clearsim.runner import BUNDLED_CONFIG
    from clearsim.sweep import DaskCluster, LocalPool, SweepFailed, SweepInterrupted, SweepRequest, plan_sweep, run_sweep
    from clearsim.sweep import display

    request = SweepRequest(config, overrides, clearance, joints, sample, seed, not no_ideal, out, delay_fraction,
                           keep)
    executor = DaskCluster(scheduler, workers) if scheduler is not None else LocalPool(workers)  # options first
    plan = plan_sweep(request, BUNDLED_CONFIG)
    console.print(display.opening_line(plan, executor.describe()), soft_wrap=True)
    if scheduler is None:
        _announce_compile()
    progress, update = display.case_progress(errors, len(plan.cases))
    beat = heartbeat("sweep")
    count = display.case_heartbeat(beat, len(plan.cases))
    try:
        with progress, beat:
            result = run_sweep(plan, executor, lambda *finished: (update(*finished), count(*finished)), retry_failed)
    except SweepInterrupted as exc:
        console.print(display.summary_table(exc.result))
        console.print("\n".join(display.closing_lines(exc.result)), soft_wrap=True)
        raise
    console.print(display.summary_table(result))
    console.print("\n".join(display.closing_lines(result)), soft_wrap=True)
    if result.failed:
        raise SweepFailed(display.failure_message(result))


@app.command()
@user_errors
def validate(config: Optional[Path] = ConfigArgument, overrides: List[str] = SetOption) -> None:
    """Check a mechanism file (schema, names, units, assembly) without running it."""
    from clearsim.runner import BUNDLED_CONFIG, prepare
    from clearsim.model.flexible import flexible_link_names
    from clearsim.model.loader import load_mechanism

    loaded = load_mechanism(config or BUNDLED_CONFIG, overrides)
    _print_plausibility_warnings(loaded)
    system = prepare(loaded)
    mechanism = system.mechanism
    written = {key: loaded.document.get(key) or [] for key in ("bodies", "joints")}  # as in the file, not expanded
    flexible = flexible_link_names(loaded.document)
    added = len(mechanism.bodies) - len(written["bodies"])  # each new body adds one freedom: a half or a segment
    stretches = f", {added} from flexible links: {', '.join(flexible)}" if flexible else ""
    console.print(f"{loaded.path}: OK — {len(written['bodies'])} bodies, {len(written['joints'])} joints, "
                  f"{len(mechanism.drivers)} drivers, {system.degrees_of_freedom} degrees of freedom "
                  f"({2 * len(system.clearance_joints)} from clearance joints: "
                  f"{', '.join(system.clearance_joints) or 'none'}{stretches})")


@app.command()
def schema() -> None:
    """Print the JSON Schema of the mechanism file (for editors)."""
    from clearsim.model.schema import Mechanism

    sys.stdout.write(json.dumps(Mechanism.model_json_schema(), indent=2) + "\n")


@app.command()
@user_errors
def plot(
    inputs: List[Path] = typer.Argument(..., help="Result files (overlaid when several) or one sweep folder."),
    out: Optional[Path] = typer.Option(None, "-o", "--out", help="Folder for the figures (default: the input's folder)."),
    fmt: str = typer.Option("png", "--format", help="png, svg or pdf."),
    sensors: List[str] = typer.Option([], "--sensor", help="Sensor to plot instead of the output sensors (repeatable)."),
    time_window: Optional[str] = typer.Option(None, "--time-window", help="Zoom: start:end in ms, e.g. 10:20."),
    measured: Optional[Path] = typer.Option(None, "--measured", help="Measurement CSV to plot the simulation over."),
    animate: bool = typer.Option(False, "--animate", help="Also write the mechanism moving (GIF)."),
    exaggerate: Optional[str] = typer.Option(
        None, "--exaggerate", help="Animation: magnify journal offsets by this factor, or 'auto'."),
    show: bool = typer.Option(False, "--show", help="Also open the figures in a window (where a display exists)."),
) -> None:
    """Write the figure set of result files or a sweep folder (paths printed)."""
    from clearsim.plot import PlotRequest, plot_results

    report = plot_results(PlotRequest(inputs, out, fmt, sensors, time_window, measured, animate, exaggerate, show))
    for note in report.notes:
        errors.print(f"note: {escape(note)}", highlight=False, soft_wrap=True)
    for path in report.written:
        console.print(str(path), highlight=False, soft_wrap=True)


@app.command()
@user_errors
def draw(
    config: Optional[Path] = ConfigArgument,
    out: Optional[Path] = typer.Option(None, "-o", "--output", help="Figure file (default: results/<config>-drawing.png)."),
    overrides: List[str] = SetOption,
    fmt: Optional[str] = typer.Option(None, "--format", help="png, svg or pdf (default: from the -o suffix, else png)."),
    show: bool = typer.Option(False, "--show", help="Also open the figure in a window."),
) -> None:
    """Draw the mechanism as assembled at t = 0, with the names of its bodies and joints."""
    from clearsim.plot import draw_config
    from clearsim.runner import BUNDLED_CONFIG

    path, notes = draw_config(config or BUNDLED_CONFIG, overrides, out, fmt, show)
    for note in notes:
        errors.print(f"note: {escape(note)}", highlight=False, soft_wrap=True)
    console.print(str(path), highlight=False, soft_wrap=True)


@app.command()
@user_errors
def synthesize(
    config: Optional[Path] = ConfigArgument,
    overrides: List[str] = SetOption,
    sensors: Optional[str] = typer.Option(None, "--sensors", help="Sensors to record: a,b (default: the output displacement and velocity)."),
    rate: str = typer.Option("15kHz", "--rate", help="Sampling rate of the record."),
    noise: str = typer.Option("0", "--noise", help="Sensor noise (std): 1% of each signal's range, or absolute with a unit: 0.02mm."),
    lowpass: Optional[str] = typer.Option(None, "--lowpass", help="Cut-off of the bench's low-pass filter: 2kHz (default: none)."),
    trigger_offset: str = typer.Option("0ms", "--trigger-offset", help="Trigger offset τ: measured(t) = sensor(t − τ)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the noise."),
    output: Path = typer.Option(Path("bench.csv"), "-o", "--output", help="Measured-like CSV to write."),
    force: bool = typer.Option(False, "--force", help="Overwrite an existing output."),
) -> None:
    """Make measured-like data from a model: sensors sampled, shifted, noisy and filtered like a bench."""
    from clearsim.diagnose.synthesize import SynthesisRequest, synthesize as make_record
    from clearsim.runner import BUNDLED_CONFIG

    chosen = [name.strip() for name in (sensors or "").split(",") if name.strip()]
    if sensors is not None and not chosen:
        from clearsim.diagnose.synthesize import SynthesisError

        raise SynthesisError(f"--sensors {sensors!r}: names no sensor; give sensor names such as "
                             "--sensors sealing_rod_displacement,turn_arm_angular_velocity, or leave the option out")
    record = make_record(SynthesisRequest(config or BUNDLED_CONFIG, overrides, chosen, rate, noise, lowpass,
                                          trigger_offset, seed, output, force))
    console.print(f"{record.output}: {len(record.time)} samples of {', '.join(record.values)} "
                  f"over {record.time[-1] * 1e3:.3f} ms", highlight=False, soft_wrap=True)


def _life_progress(total: int):
    """(bar, heartbeat, update(done, total, blocks)): operations done of the life's target, blocks kept."""
    progress = Progress(TextColumn("wearing"), BarColumn(), MofNCompleteColumn(), TextColumn("operations"),
                        TextColumn("{task.fields[blocks]} blocks"), TimeElapsedColumn(), console=errors,
                        transient=True, disable=not errors.is_terminal)
    task = progress.add_task("life", total=total, blocks=0)
    beat = heartbeat("life")

    def update(done: int, target: int, blocks: int) -> None:
        progress.update(task, completed=done, total=target, blocks=blocks)
        beat.update(f"{done} of {target} operations, {blocks} blocks", done, target)

    return progress, beat, update


@app.command()
@user_errors
def life(
    config: Optional[Path] = ConfigArgument,
    operations: int = typer.Option(..., "--operations", "-n", help="Operations of the life, e.g. 10000."),
    output: Path = typer.Option(Path("results/life.h5"), "-o", "--output", help="Life file (HDF5)."),
    tolerance: float = typer.Option(0.02, "--tolerance", help="Error allowed per block, a fraction of each wearing joint's clearance."),
    overrides: List[str] = SetOption,
) -> None:
    """Wear over a service life: simulate an operation, accumulate its wear, scale it over a block, update the bores, repeat."""
    from clearsim.life.run import LifeRequest, run_life

    _announce_compile()
    progress, beat, update = _life_progress(operations)
    with progress, beat:
        report = run_life(LifeRequest(config or _bundled(), operations, output, tolerance, overrides), update)
    if report.backup is not None:
        console.print(f"kept the earlier life as {report.backup}")
    started = "continued from" if report.resumed_from is not None else "new machine,"
    console.print(f"[bold]life[/]: {report.status} → {report.output}: {report.last.operations} operations "
                  f"({started} {report.resumed_from or 0}), {report.blocks} blocks, {report.simulations} operations simulated")
    console.print(_life_table(report.output))


def _bundled() -> Path:
    from clearsim.runner import BUNDLED_CONFIG

    return BUNDLED_CONFIG


def _life_table(path: Path) -> Table:
    from clearsim.life.store import life_rows

    table = Table(show_header=False, box=None, pad_edge=False)
    for label, value in life_rows(path):
        table.add_row(label, value)
    return table


def _diagnosis_progress():
    """(live line, heartbeat, update(SearchProgress)): runs done of those planned so far, the best gap and its model,
    the time elapsed; on stdout with the diagnosis's own lines (in a terminal), else a heartbeat on stderr."""
    progress = Progress(TextColumn("{task.fields[stage]}"), BarColumn(), MofNCompleteColumn(), TextColumn("runs"),
                        TextColumn("{task.fields[best]}"), TimeElapsedColumn(), console=console, transient=True,
                        disable=not console.is_terminal)
    task = progress.add_task("diagnose", total=None, stage="starting", best="")
    beat = heartbeat("diagnose", console)

    def update(state) -> None:
        best = f"best gap {state.best_gap:.3g}: {state.best_label}" if state.best_label else ""
        progress.update(task, total=state.planned, completed=state.done, stage=state.stage, best=escape(best))
        beat.update(f"{state.stage}: {state.done} of {state.planned} runs" + (f", {best}" if best else ""))

    return progress, beat, update


@app.command()
@user_errors
def diagnose(
    config: Optional[Path] = ConfigArgument,
    measured: List[Path] = typer.Option(..., "--measured", help="Measured record: CSV (time + one column per sensor) or HDF5; again for repeats of the same test (the noise from their spread)."),
    overrides: List[str] = SetOption,
    mapping: List[str] = typer.Option([], "--map", help="Map a column to a sensor: --map Weg=sealing_rod_displacement (repeatable)."),
    candidates: Optional[str] = typer.Option(
        None, "--candidates", help="Kinds of effect to try, e.g. clearance,friction (default all): clearance, friction, "
        "stiffness, restitution, drive, damping, mass, compliance, beam_stiffness, contact_length, port_area, precharge, "
        "bulk_modulus, preload, dashpot, gas_load, guide_friction, wear, viscosity, load."),
    max_effects: int = typer.Option(1, "--max-effects", help="Add up to N effects, one per iteration (greedy)."),
    out: Optional[Path] = typer.Option(None, "-o", "--out", help="Report folder (default: results/diagnose-<config>-<record>/)."),
    lowpass: Optional[str] = typer.Option(None, "--lowpass", help="The bench's low-pass filter if known: 2kHz (default: estimated from the record)."),
    workers: Optional[int] = typer.Option(None, "--workers", help="Local worker processes (default: all cores)."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Run the simulations on a Dask cluster: tcp://host:8786."),
    fit_top: int = typer.Option(3, "--fit-top", help="Candidates fitted in full per iteration (the best of the screening)."),
    ensemble: Optional[int] = typer.Option(None, "--ensemble", help="Runs per candidate value with a rattling joint (perturbed by 1 nm): its cost is their median (default: 3 where the model's re-rolled twins stray by more than the noise, else 1)."),
) -> None:
    """Compare a model with measured data, name the missing effect, add it and show the gap shrink."""
    from clearsim.diagnose.report import verdict, write_report
    from clearsim.diagnose.workflow import DiagnoseRequest, diagnose as run_diagnosis
    from clearsim.runner import BUNDLED_CONFIG

    request = DiagnoseRequest(config or BUNDLED_CONFIG, measured[0], overrides, mapping, candidates, max_effects, out,
                              workers, scheduler, lowpass, fit_top, measured[1:], ensemble)
    progress, beat, update = _diagnosis_progress()
    with progress, beat:
        result = run_diagnosis(request, say=lambda text: console.print(text, highlight=False, soft_wrap=True),
                               progress=update)
    written = write_report(result)
    console.print(f"[bold]{escape(verdict(result))}[/]", soft_wrap=True)
    console.print(f"{result.simulations} simulations in {result.wall_time:.0f} s; report: {written[2]}",
                  highlight=False, soft_wrap=True)


if __name__ == "__main__":
    app()
