"""Figures of the paper reproduction (Figures 6 and 7 and what we add).

Each function takes a :class:`~spiralid.reproduction.Reproduction` and
returns a matplotlib ``Figure``; the plotting itself is
:mod:`spiralid.sysid.validation.plots`.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from spiralid.reproduction import Reproduction
from spiralid.study.spec import BASELINES
from spiralid.sysid import plots

__all__ = ["all_figures", "figure_labels", "recommended"]

# The paper's two algorithms; the figures of Table-2's models show these two
# with the recommended method and the output-error baseline beside them.
PAPER_PAIR = ("SDA", "Eb-SDA")
# Reference lines (baselines): thin, dashed, under the data, and one colour
# each in every figure (the methods take C0-C2: SDA, Eb-SDA, recommended).
_REFERENCE_STYLE = {"ls": "--", "lw": 0.9, "zorder": 0.8}
_REFERENCE_COLOUR = {BASELINES["oe"]: "C3", BASELINES["ls"]: "C4"}


def recommended(rep: Reproduction) -> list[str]:
    """The labels of the recommended method's configurations in `rep` (none
    under ``initial="measured"``, where reproduce leaves it out)."""
    spiral = [c.label for c in rep.configurations if c.method == "spiral"]
    return [label for label in spiral if label in rep.runs]


def figure_labels(rep: Reproduction, baselines: bool = True) -> list[str]:
    """The models a figure of Table-2's models shows, in drawing order: the
    paper's pair, the recommended method, then (`baselines`) output error."""
    labels = [*PAPER_PAIR, *recommended(rep)]
    return [*labels, BASELINES["oe"]] if baselines else labels


def _models(rep: Reproduction) -> dict:
    return {label: rep.best(label).model for label in figure_labels(rep)}


def _legend_outside(
    fig, loc: str = "outside upper center", ncols: int | None = None
) -> None:
    """One legend of `fig` (a Figure or SubFigure) outside its axes, in place
    of each axes' own: the labels of every axes, each once (the panels share
    their colours)."""
    handles = {}
    for ax in fig.axes:
        for h, label in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(label, h)
        if ax.get_legend() is not None:
            ax.get_legend().remove()
    if ncols is None:
        ncols = min(len(handles), 5) if "center" in loc else 1
    fig.legend(
        list(handles.values()), list(handles), loc=loc, ncols=ncols, fontsize="small"
    )


def _as_reference(fig: Figure, label: str = BASELINES["oe"]) -> None:
    """Draw baseline `label`'s curves as a reference: thin and dashed in its
    colour, so that a method's curve under it shows between the dashes (the
    recommended method often lies on output error's); its other marks in its
    former colour (the spectrum's mode lines) take the colour."""
    for ax in fig.axes:
        lines = ax.get_lines()
        mine = [line for line in lines if line.get_label() == label]
        was = {line.get_color() for line in mine}
        for line in lines:
            if line.get_color() in was:
                line.set_color(_REFERENCE_COLOUR[label])
        for line in mine:
            line.set_linestyle((0, (3, 3)))
            line.set_linewidth(0.8)


def _reference_lines(ax, rep: Reproduction, attr: str) -> None:
    """The baselines' values as horizontal lines under the data, each named at
    the axes' right edge (outside, where no data is)."""
    for name, run in rep.baselines.items():
        value, colour = getattr(run, attr), _REFERENCE_COLOUR.get(name, "0.4")
        ax.axhline(value, color=colour, label=name, **_REFERENCE_STYLE)
        ax.annotate(
            name,
            (1.0, value),
            xycoords=ax.get_yaxis_transform(),
            xytext=(3, 0),
            textcoords="offset points",
            va="center",
            fontsize="small",
            color=colour,
            annotation_clip=False,
        )


def convergence(rep: Reproduction) -> Figure:
    """Figure 6a: best cost against iteration and wall time, median and IQR.

    Left the paper's pair on its own scale, as the paper draws it; right the
    pair with the recommended method and the baselines' costs as references,
    on a log scale (the recommended method ends far below the pair).
    """
    fig = Figure(figsize=(11, 6.5), layout="constrained")
    left, right = fig.subfigures(1, 2, wspace=0.03)
    for sub, labels in ((left, PAPER_PAIR), (right, figure_labels(rep, False))):
        hist = {label: [r.history for r in rep.runs[label]] for label in labels}
        times = {label: [r.times for r in rep.runs[label]] for label in labels}
        plots.plot_convergence(
            hist,
            times=times,
            log=sub is right,
            cost_label="best cost, eq. (2) (% of rms(y))",
            figure=sub,
        )
        if sub is right:
            for ax in sub.axes:
                _reference_lines(ax, rep, "cost")
                plots.set_log_scale(ax)
    # One legend for the four panels, under them: the suptitle takes the top.
    _legend_outside(fig, "outside lower center")
    left.axes[0].set_title("The paper's pair")
    right.axes[0].set_title(
        "With the recommended method" if recommended(rep) else "With the baselines"
    )
    fig.suptitle(
        f"Convergence over {len(rep.seeds)} seeds (median and interquartile band)"
    )
    return fig


def estimation_response(rep: Reproduction) -> Figure:
    """Figures 6b-c: estimation part, measured against the models, and errors."""
    est = rep.estimation
    outs = {k: m.simulate(est.u) for k, m in _models(rep).items()}
    return _time_response(est, est.t, outs, "Modelling (estimation part), free run")


def validation_response(rep: Reproduction) -> Figure:
    """Figures 7a-b: validation part, measured against the models, and errors.

    The models run over the whole record; the validation third is shown.
    """
    n = rep.estimation.n
    val = rep.validation
    outs = {k: m.simulate(rep.data.u)[n:] for k, m in _models(rep).items()}
    return _time_response(val, val.t + n * val.ts, outs, "Validation part, free run")


def _time_response(part, t, outs: dict, title: str) -> Figure:
    """A record part's measured output against the models' `outs` at times
    `t`, with their errors; output error dashed, the legend under."""
    fig = plots.plot_time_response(
        t,
        part.y,
        outs,
        title=title,
        ylabel=part.output_name,
        unit=part.output_unit,
    )
    _as_reference(fig)
    _legend_outside(fig)
    return fig


def spectrum(rep: Reproduction) -> Figure:
    """Figure 7c: PSD of measured and model outputs with resonances marked."""
    labels = figure_labels(rep)
    vals = {label: rep.validations[label][1] for label in labels}
    first = vals[labels[0]]
    fig = plots.plot_psd(
        first.psd_measured,
        {k: v.psd_model for k, v in vals.items()},
        peaks=first.peaks_measured,
        modes={k: v.modes for k, v in vals.items()},
    )
    _as_reference(fig)
    _legend_outside(fig)
    return fig


def pole_zero(rep: Reproduction) -> Figure:
    """Pole-zero map of the best SDA, Eb-SDA and recommended models with the
    unit circle."""
    labels = figure_labels(rep, baselines=False)
    fig = plots.plot_pole_zero({k: rep.best(k).model for k in labels})
    # Taller, for the legend under the square axes.
    fig.set_size_inches(5.5, 6.5)
    _legend_outside(fig, "outside lower center", ncols=2)
    return fig


def distributions(rep: Reproduction) -> Figure:
    """Estimation cost and validation fit of every run, per configuration,
    with the least-squares and output-error baselines as reference lines
    under the boxes."""
    labels = list(rep.runs)
    fig = Figure(figsize=(9, 6.5), layout="constrained")
    ax_cost, ax_fit = fig.subplots(2, 1, sharex=True)
    for ax, attr in ((ax_cost, "cost"), (ax_fit, "fit_val")):
        values = [[getattr(r, attr) for r in rep.runs[k]] for k in labels]
        ax.boxplot(
            values,
            manage_ticks=False,  # set once below: the axes share x
            showfliers=False,
            zorder=2,
            medianprops={"color": "k", "lw": 1.5},
        )
        for i, v in enumerate(values, start=1):
            jitter = np.linspace(-0.12, 0.12, len(v)) if len(v) > 1 else [0.0]
            ax.plot(
                i + np.asarray(jitter),
                v,
                "o",
                ms=3,
                alpha=0.6,
                color="0.35",
                zorder=3,
                label="one run (seed)",
            )
        _reference_lines(ax, rep, attr)
    ax_cost.set_ylabel("estimation cost, eq. (2) (% of rms(y))")
    plots.set_log_scale(ax_cost)
    ax_fit.set_ylabel("validation fit (%)")
    ax_fit.set_xticks(np.arange(1, len(labels) + 1), labels)
    ax_fit.set_xlim(0.5, len(labels) + 0.5)
    ax_fit.tick_params(axis="x", rotation=20)
    # A title over the axes: the legend takes the figure's top.
    ax_cost.set_title(f"Every run over {len(rep.seeds)} seeds")
    _legend_outside(fig)
    return fig


def all_figures(rep: Reproduction) -> dict[str, Figure]:
    """Every figure of the report, keyed by a file-name stem.

    The figures of the SDA vs Eb-SDA pair need both in the experiment.
    """
    figures = {}
    if set(PAPER_PAIR) <= set(rep.runs):
        figures |= {
            "fig6a_convergence": convergence(rep),
            "fig6bc_estimation": estimation_response(rep),
            "fig7ab_validation": validation_response(rep),
            "fig7c_spectrum": spectrum(rep),
            "pole_zero": pole_zero(rep),
        }
    figures["distributions"] = distributions(rep)
    return figures
