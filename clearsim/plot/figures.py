"""`clearsim plot`: the figure set of one run, several runs overlaid, or a sweep folder.

Everything is read and every figure is built before anything is written, so a bad input
leaves no half-written set behind. File names are stable (docs/plotting.md):

    <stem>-output.png      output sensors (or the --sensor ones) against time
    <stem>-joint-<J>.png   clearance joint J: journal path, contact forces, penetration
    <stem>-spectrum.png    amplitude spectrum of the output acceleration (or the --sensor ones)
    <stem>-energy.png      energy balance and constraint violation
    <stem>-travel.png      travel curve in its tolerance envelope, with its figures (mechanisms with `travel:`)
    <stem>-measured.png    simulation over measurement, residual below (--measured)
    <stem>-merit.png       sweep folders with summary.csv: figures of merit against the swept quantity
    <stem>-animation.gif   the mechanism moving (--animate), one per run

<stem> is the file's name for one file, `compare` for several files, `sweep` for a folder.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from clearsim.plot import history, journal, measured as measured_plots, sweep, travel
from clearsim.plot.animate import animate_run, check_animation, parse_exaggerate
from clearsim.plot.data import PlotInputError, RunData, apply_window, load_run, parse_time_window, signals
from clearsim.life.store import is_life_file
from clearsim.plot.labels import run_labels
from clearsim.plot.life import life_figures
from clearsim.plot.style import DPI, FORMATS, show_all



@dataclass
class PlotRequest:
    inputs: list  # result files, or one sweep folder
    out: Path | None = None  # default: the folder of the (first) input
    fmt: str = "png"
    sensors: list = field(default_factory=list)
    time_window: str | None = None  # "a:b", ms unless a unit is written
    measured: Path | None = None
    animate: bool = False
    exaggerate: str | None = None  # journal-offset magnification in the animation: a factor or "auto"
    show: bool = False


@dataclass
class PlotReport:
    written: list
    notes: list


@dataclass
class _Inputs:
    """Runs plotted together: one figure set named `<stem>-*`."""
    files: list
    stem: str
    sweep: Path | None = None  # the sweep folder the runs are the cases of (its summary gives the merit figure)
    folder: Path | None = None  # the folder they were found in: a file that cannot be plotted is skipped with a note


def _folder_inputs(folder: Path, notes: list) -> list[_Inputs]:
    """The cases of the sweep that made the folder, overlaid; in any other folder each run on its own."""
    files = sweep.result_files(folder)
    cases = sweep.case_names(folder)
    if cases is None:
        notes.append(f"{folder} is not a sweep folder (no readable {sweep.CASES}): each run is plotted on its own; "
                     f"to overlay runs, name their files: clearsim plot a.h5 b.h5")
        return [_Inputs([file], file.stem, folder=folder) for file in files]
    foreign = [file for file in files if file.stem not in cases]
    for file in foreign:
        notes.append(f"left out {file.name}: not a case of the sweep in {folder} (its {sweep.CASES} does not name "
                     f"it); plot it on its own: clearsim plot {file}")
    if len(foreign) == len(files):
        raise PlotInputError(f"{folder}: none of its result files is a case of its sweep ({sweep.CASES}); plot them "
                             f"by name: clearsim plot {files[0]}")
    return [_Inputs([file for file in files if file not in foreign], "sweep", folder, folder)]


def _inputs(paths: list, notes: list) -> list[_Inputs]:
    paths = [Path(p) for p in paths]
    if not paths:
        raise PlotInputError("give at least one result file (.h5) or a sweep folder")
    folders = [p for p in paths if p.is_dir()]
    if folders and len(paths) > 1:
        raise PlotInputError(f"{folders[0]} is a folder: give either result files or one sweep folder")
    if folders:
        return _folder_inputs(folders[0], notes)
    return [_Inputs(paths, paths[0].stem if len(paths) == 1 else "compare")]


def _load(inputs: _Inputs, request: PlotRequest, notes: list) -> list[RunData]:
    """The runs; in a folder a file that cannot be plotted is skipped with a note (the others are plotted), while a
    file named on the command line must be plottable."""
    window = parse_time_window(request.time_window)
    runs = []
    for path in inputs.files:
        try:
            runs.append(load_run(path))
        except PlotInputError as exc:
            if inputs.folder is None:
                raise
            again = " (a re-run of the sweep runs that case again)" if inputs.sweep else ""
            notes.append(f"skipped {'case' if inputs.sweep else 'file'} {path.stem}: {exc}{again}")
    labels = run_labels(runs) if len(runs) > 1 else [""] * len(runs)
    for index, (run, label) in enumerate(zip(runs, labels)):
        apply_window(run, window)
        run.label, run.index = label, index
    return runs


def _spectrum_sensors(runs: list[RunData], chosen: list) -> list:
    if chosen:
        return list(chosen)
    acceleration = runs[0].output.get("acceleration")
    return [acceleration] if acceleration else []


def _clearance_joints(runs: list[RunData]) -> list:
    return list(dict.fromkeys(j for run in runs for j in run.clearance_joints))


def _signals_figure(runs: list[RunData], chosen: list, figures: dict, notes: list, show: bool) -> None:
    shown = signals(runs[0], chosen)
    for run in runs[1:]:
        signals(run, shown)  # every overlaid run must have them
    if shown:
        figures["output"] = history.signals_figure(runs, shown, show)
    else:
        notes.append(f"{runs[0].path}: no sensors, so no output figure")


def build_figures(runs: list[RunData], request: PlotRequest, folder: Path | None = None) -> tuple[dict, list]:
    """{figure kind: figure} and notes for the user; reads nothing from disk but the measurement."""
    show, notes, figures = request.show, [], {}
    chosen = list(request.sensors)
    _signals_figure(runs, chosen, figures, notes, show)
    for joint in _clearance_joints(runs):
        figures[f"joint-{joint}"] = journal.joint_figure(runs, joint, show)
    spectrum = _spectrum_sensors(runs, chosen)
    if spectrum:
        figures["spectrum"] = history.spectrum_figure(runs, spectrum, show)
    figures["energy"] = history.energy_figure(runs, show)
    if travel.travel_runs(runs):
        figures["travel"] = travel.travel_figure(runs, show)
    if request.measured is not None:
        record = measured_plots.read_measurement(request.measured, measured_plots.run_sensor_units(runs[0]),
                                                 str(runs[0].path))
        measurement = measured_plots.within(record, parse_time_window(request.time_window))
        names = measured_plots.matched_sensors(measurement, runs, chosen)
        figures["measured"] = measured_plots.measured_figure(runs, measurement, names, show)
    summary = sweep.summary_of(folder, notes) if folder is not None else None
    if summary is not None:
        figures["merit"] = sweep.merit_figure(summary, f"sweep folder {folder.name}", show)
    for run in runs:
        notes += run.notes
        if "complete" not in run.attrs:
            notes.append(f"{run.path} does not say whether its run completed (no 'complete' attribute): plotted up "
                         f"to {run.time[-1] * 1e3:.3f} ms")
        elif not run.complete:
            notes.append(f"{run.path} is incomplete ({run.attrs.get('status', 'unknown')}): plotted up to "
                         f"{run.time[-1] * 1e3:.3f} ms")
    return figures, notes


def _output_folder(request: PlotRequest, inputs: _Inputs) -> Path:
    if request.out is not None:
        return Path(request.out)
    return inputs.folder if inputs.folder is not None else inputs.files[0].parent


def _save(figures: dict, folder: Path, stem: str, fmt: str) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for kind, figure in figures.items():
        path = folder / f"{stem}-{kind}.{fmt}"
        figure.savefig(path, format=fmt, dpi=DPI)
        written.append(path)
    return written


def _plot_lives(lives: list[Path], request: PlotRequest) -> PlotReport:
    """The pages of life files (clearsim.plot.life), each in its own folder or --out."""
    if len(lives) != len(request.inputs):
        raise PlotInputError("a life file is plotted alone (its wear, clearance and drift pages): give life files "
                             "only, or result files only")
    written = []
    for path in lives:
        folder = Path(request.out) if request.out is not None else path.parent
        written += _save(life_figures(path, request.show), folder, path.stem, request.fmt)
    notes = [note] if request.show and (note := show_all()) else []
    return PlotReport(written, notes)


def plot_results(request: PlotRequest) -> PlotReport:
    """Read the inputs, build every figure, then write them (and the animations); paths and notes."""
    if request.fmt not in FORMATS:
        raise PlotInputError(f"--format {request.fmt!r}: expected one of {', '.join(FORMATS)}")
    if request.out is not None and Path(request.out).exists() and not Path(request.out).is_dir():
        raise PlotInputError(f"--out {request.out}: is a file, not a folder; give the folder for the figures")
    lives = [Path(path) for path in request.inputs if Path(path).is_file() and is_life_file(Path(path))]
    if lives:
        return _plot_lives(lives, request)
    skipped: list = []
    groups = _inputs(request.inputs, skipped)
    loaded = [(inputs, runs) for inputs in groups if (runs := _load(inputs, request, skipped))]
    if not loaded:
        what = "case" if groups[0].sweep else "result"
        raise PlotInputError(f"{groups[0].folder}: no {what} file can be plotted:\n  " + "\n  ".join(skipped))
    exaggerate = parse_exaggerate(request.exaggerate)
    for _, runs in loaded if request.animate else []:
        for run in runs:
            check_animation(run)
    built = [(inputs, runs, *build_figures(runs, request, inputs.sweep)) for inputs, runs in loaded]
    notes, written = list(skipped), []
    for inputs, runs, figures, figure_notes in built:
        notes += figure_notes
        folder = _output_folder(request, inputs)
        written += _save(figures, folder, inputs.stem, request.fmt)
        if request.animate:
            written += [animate_run(run, folder / f"{run.path.stem}-animation.gif", exaggerate) for run in runs]
    if request.show and (note := show_all()):
        notes.append(note)
    return PlotReport(written, notes)
