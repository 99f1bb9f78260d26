"""Figures from result files: `clearsim plot` and `clearsim draw` (docs/plotting.md).

    report = plot_results(PlotRequest([Path("results/run.h5")]))   # the figure set, paths in report.written
    run = load_run("results/run.h5")
    ax = plot_journal_path(run, "J")                               # any single plot, on a new or given axes

Plotting only reads result files (clearsim.io.hdf5) and the mechanism stored in them.
"""

from clearsim.plot.animate import animate_run
from clearsim.plot.data import PlotInputError, RunData, load_run
from clearsim.plot.draw import draw_config, draw_figure
from clearsim.plot.figures import FORMATS, PlotReport, PlotRequest, build_figures, plot_results
from clearsim.plot.history import plot_balance_error, plot_energies, plot_signal, plot_spectrum, plot_violation
from clearsim.plot.journal import plot_contact_forces, plot_friction_force, plot_journal_path, plot_penetration
from clearsim.plot.measured import plot_measured, read_measurement
from clearsim.plot.sweep import plot_merit, read_summary

__all__ = [
    "FORMATS", "PlotInputError", "PlotReport", "PlotRequest", "RunData", "animate_run", "build_figures",
    "draw_config", "draw_figure", "load_run", "plot_balance_error", "plot_contact_forces", "plot_energies",
    "plot_friction_force", "plot_journal_path", "plot_measured", "plot_merit", "plot_penetration", "plot_results",
    "plot_signal", "plot_spectrum", "plot_violation", "read_measurement", "read_summary",
]
