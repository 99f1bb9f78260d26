"""Figures, colours and line styles shared by every plot.

Figures for files are made without pyplot (a `Figure` on an Agg canvas), so writing them never
needs a display and leaves no global state; `interactive=True` (the CLI's `--show`) makes them
with pyplot so that they can be shown. Plotting functions called with `ax=None` make a pyplot
figure, as one expects in a notebook.
"""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib import rcParams
from matplotlib.lines import Line2D

MODE_NAMES = ("free flight", "impact", "contact")
MODE_COLOURS = ("tab:blue", "tab:red", "tab:green")
RUN_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
               "tab:pink", "tab:olive", "tab:cyan")
IDEAL_STYLE = {"color": "black", "linestyle": "--", "linewidth": 1.2, "zorder": 3}  # drawn over the others
DPI = 100
TITLE_CHARACTERS_PER_INCH = 11.5  # at the 10 pt title size
LEGEND_LABEL_CHARACTERS = 30  # a legend beside the axes wraps longer labels onto more lines
LEGEND_WIDTH = 2.2  # inches a figure is widened by for legends beside its axes
FORMATS = ("png", "svg", "pdf")
NON_INTERACTIVE = {"agg", "pdf", "svg", "ps", "cairo", "template", "pgf"}

STYLE = {"font.size": 9, "axes.titlesize": 10, "axes.labelsize": 9, "legend.fontsize": 8,
         "axes.grid": True, "grid.alpha": 0.35, "lines.linewidth": 1.1, "figure.dpi": DPI,
         "axes.formatter.use_mathtext": True, "axes.formatter.limits": (-4, 5)}


def apply_style() -> None:
    rcParams.update(STYLE)


def new_figure(size: tuple[float, float], interactive: bool = False, layout: str | None = "constrained"):
    """A figure (constrained layout by default): pyplot's when interactive, else a pyplot-free Agg figure."""
    apply_style()
    if interactive:
        import matplotlib.pyplot as plt

        return plt.figure(figsize=size, layout=layout)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=size, layout=layout)
    FigureCanvasAgg(figure)
    return figure


def show_all() -> str | None:
    """Show the pyplot figures; a note instead when there is no interactive display."""
    import matplotlib.pyplot as plt

    if plt.get_backend().lower() in NON_INTERACTIVE:
        plt.close("all")
        return "--show: no interactive display here; the figures were written only"
    plt.show()
    return None


def axes_or_new(ax, size: tuple[float, float] = (7.0, 4.0)):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    apply_style()
    _, ax = plt.subplots(figsize=size, layout="constrained")
    return ax


def run_style(run) -> dict:
    """Line style of an overlaid run: the ideal run black dashed, the others by their place in the list."""
    if getattr(run, "label", "") == "ideal":
        return dict(IDEAL_STYLE)
    return {"color": RUN_COLOURS[run.index % len(RUN_COLOURS)]}


def overlay_zorders(peaks: list[float], base: float = 2.0) -> list[float]:
    """Drawing order of overlaid runs from the size of what each draws: the largest at the bottom, the smallest on
    top, so that a large case never hides the small ones (all below the ideal run's zorder 3)."""
    ranks = np.argsort(np.argsort(-np.nan_to_num(np.asarray(peaks, dtype=float), nan=-np.inf), kind="stable"))
    return [base + 0.9 * float(rank) / max(len(peaks), 1) for rank in ranks]


def overlay_styles(runs, peaks: list[float]) -> list[dict]:
    """`run_style` of each overlaid run, stacked by `overlay_zorders` (the ideal run keeps its place on top)."""
    styles = []
    for run, zorder in zip(runs, overlay_zorders(peaks)):
        style = run_style(run)
        style.setdefault("zorder", zorder)
        styles.append(style)
    return styles


def wrap_label(text: str, width: int = 24) -> str:
    return "\n".join(textwrap.wrap(text, width)) or text


def legend_beside(ax, **options):
    """The axes' legend outside it, on its right (constrained layout makes room): it never covers data."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    return ax.legend(handles, [wrap_label(label, LEGEND_LABEL_CHARACTERS) for label in labels], loc="upper left",
                     bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **options)


def figure_legend(figure, axes, **options):
    """One legend under the figure for panels that share their lines (each label once)."""
    entries = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    if not entries:
        return None
    return figure.legend(list(entries.values()), list(entries), loc="outside lower center",
                         ncol=min(len(entries), 4), **options)


def mode_handles() -> list[Line2D]:
    return [Line2D([], [], color=c, linewidth=2.5, label=n) for c, n in zip(MODE_COLOURS, MODE_NAMES)]


def set_title(figure, text: str) -> None:
    """The figure's title, each line wrapped to the figure's width (an incomplete-run note can be long)."""
    width = max(40, int(figure.get_figwidth() * TITLE_CHARACTERS_PER_INCH))
    lines = [wrapped for line in text.split("\n") for wrapped in textwrap.wrap(line, width) or [""]]
    figure.suptitle("\n".join(lines))


def title_of(run) -> str:
    """The run's mechanism name, with a warning when the run did not complete."""
    title = str(run.attrs.get("mechanism", run.path.stem))
    if not run.complete:
        title += f"  [incomplete: {run.attrs.get('status', 'unknown')}]"
    return title
