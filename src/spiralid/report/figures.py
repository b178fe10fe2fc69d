"""Figures of the paper reproduction (Figures 6 and 7 and what we add).

Each function takes a :class:`~spiralid.report.experiment.Reproduction` and
returns a matplotlib ``Figure``; the plotting itself is
:mod:`spiralid.sysid.validation.plots`.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from spiralid.report.experiment import Reproduction
from spiralid.study.spec import BASELINES
from spiralid.sysid import plots

__all__ = ["all_figures"]

# The paper's two algorithms; the figures of Table-2's models show these two
# with the output-error baseline beside them.
PAPER_PAIR = ("SDA", "Eb-SDA")


def _models(rep: Reproduction) -> dict:
    labels = [*PAPER_PAIR, BASELINES["oe"]]
    return {label: rep.best(label).model for label in labels}


def convergence(rep: Reproduction, labels=PAPER_PAIR) -> Figure:
    """Figure 6a: best cost against iteration and wall time, median and IQR."""
    hist = {label: [r.history for r in rep.runs[label]] for label in labels}
    times = {label: [r.times for r in rep.runs[label]] for label in labels}
    fig = plots.plot_convergence(
        hist, times=times, cost_label="best cost, eq. (2) (% of rms(y))"
    )
    fig.axes[0].set_title(
        f"Convergence over {len(rep.seeds)} seeds (median and interquartile band)"
    )
    return fig


def estimation_response(rep: Reproduction) -> Figure:
    """Figures 6b-c: estimation part, measured against the models, and errors."""
    est = rep.estimation
    outs = {k: m.simulate(est.u) for k, m in _models(rep).items()}
    return plots.plot_time_response(
        est.t,
        est.y,
        outs,
        title="Modelling (estimation part), free run",
        ylabel=est.output_name,
        unit=est.output_unit,
    )


def validation_response(rep: Reproduction) -> Figure:
    """Figures 7a-b: validation part, measured against the models, and errors.

    The models run over the whole record; the validation third is shown.
    """
    n = rep.estimation.n
    val = rep.validation
    outs = {k: m.simulate(rep.data.u)[n:] for k, m in _models(rep).items()}
    return plots.plot_time_response(
        val.t + n * val.ts,
        val.y,
        outs,
        title="Validation part, free run",
        ylabel=val.output_name,
        unit=val.output_unit,
    )


def spectrum(rep: Reproduction) -> Figure:
    """Figure 7c: PSD of measured and model outputs with resonances marked."""
    labels = [*PAPER_PAIR, BASELINES["oe"]]
    vals = {label: rep.validations[label][1] for label in labels}
    first = vals[labels[0]]
    return plots.plot_psd(
        first.psd_measured,
        {k: v.psd_model for k, v in vals.items()},
        peaks=first.peaks_measured,
        modes={k: v.modes for k, v in vals.items()},
    )


def pole_zero(rep: Reproduction) -> Figure:
    """Pole-zero map of the best SDA and Eb-SDA models with the unit circle."""
    return plots.plot_pole_zero({k: rep.best(k).model for k in PAPER_PAIR})


def distributions(rep: Reproduction) -> Figure:
    """Estimation cost and validation fit of every run, per configuration,
    with the least-squares and output-error baselines as horizontal lines."""
    labels = list(rep.runs)
    fig = Figure(figsize=(9, 6.5), layout="constrained")
    ax_cost, ax_fit = fig.subplots(2, 1, sharex=True)
    for ax, attr in ((ax_cost, "cost"), (ax_fit, "fit_val")):
        values = [[getattr(r, attr) for r in rep.runs[k]] for k in labels]
        ax.boxplot(values, tick_labels=labels, showfliers=False)
        for i, v in enumerate(values, start=1):
            jitter = np.linspace(-0.12, 0.12, len(v)) if len(v) > 1 else [0.0]
            ax.plot(i + np.asarray(jitter), v, "o", ms=3, alpha=0.6, color="C0")
        for j, (name, run) in enumerate(rep.baselines.items()):
            ax.axhline(getattr(run, attr), ls="--", lw=1, color=f"C{j + 1}", label=name)
        ax.legend(loc="best", fontsize="small")
    ax_cost.set_ylabel("estimation cost, eq. (2) (% of rms(y))")
    plots.set_log_scale(ax_cost)
    ax_fit.set_ylabel("validation fit (%)")
    ax_fit.tick_params(axis="x", rotation=20)
    fig.suptitle(f"Every run over {len(rep.seeds)} seeds")
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
