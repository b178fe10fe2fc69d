"""The figure of a Pareto identification: its front, the knee marked."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from spiralid.sysid.estimation.pareto.identify import OBJECTIVES, ParetoIdentification

__all__ = ["front_figure"]

# Fronts up to this size have every point numbered.
_LABELLED = 60


def front_figure(front: ParetoIdentification, chosen: int | None = None) -> Figure:
    """The front in its first two objectives, a third as the colour.

    Parameters
    ----------
    front : ParetoIdentification
        From :func:`~spiralid.sysid.identify_pareto`.
    chosen : int, optional
        A front point marked besides the knee (e.g. from ``front.choose``).

    Returns
    -------
    matplotlib.figure.Figure
        Points numbered as their ``point-<i>`` folders (fronts of up to 60
        points); the knee a star.
    """
    f = front.objectives
    names = front.names
    fig = Figure(figsize=(7.0, 5.0), layout="constrained")
    ax = fig.add_subplot()
    x, y = f[:, 0], f[:, 1]
    if f.shape[1] == 3:
        dots = ax.scatter(x, y, c=f[:, 2], cmap="viridis", s=36, zorder=2)
        fig.colorbar(dots, ax=ax, label=OBJECTIVES[names[2]])
    else:
        ax.plot(x, y, "o-", color="tab:blue", ms=6, lw=0.8, zorder=2)
    # Numbered as the point-<i> folders, while the numbers stay legible.
    for i, (a, b) in enumerate(zip(x, y, strict=True) if len(x) <= _LABELLED else ()):
        ax.annotate(
            str(i), (a, b), textcoords="offset points", xytext=(4, 4), fontsize=7
        )
    k = front.knee
    ax.plot(
        x[k], y[k], "*", color="tab:red", ms=16, zorder=3, label=f"knee (point {k})"
    )
    if chosen is not None and chosen != k:
        ax.plot(
            x[chosen],
            y[chosen],
            "s",
            mfc="none",
            mec="black",
            ms=12,
            zorder=3,
            label=f"chosen (point {chosen})",
        )
    ax.set_xlabel(OBJECTIVES[names[0]])
    ax.set_ylabel(OBJECTIVES[names[1]])
    if np.all(x > 0) and x.max() > 20 * x.min():
        ax.set_xscale("log")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right")
    structures = sorted({str(m.arx) for m in front.models})
    what = structures[0] if len(structures) == 1 else f"{len(structures)} orders"
    ax.set_title(f"Pareto front: {len(front)} stable models, {what}")
    return fig
