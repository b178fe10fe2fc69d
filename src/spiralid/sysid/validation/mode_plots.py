"""Figures of modes: the stabilisation diagram.

Kept apart from the computation (:mod:`.stabilisation`) so that matplotlib
is loaded only when drawing; returns a ``Figure`` not registered with
pyplot, as the other figures of :mod:`spiralid.sysid.plots`.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..data import IOData
from ..spectra import psd
from .stabilisation import StabilisationDiagram

__all__ = ["plot_stabilisation"]

_MARKERS = {
    "stable": ("o", "stable (frequency and damping)"),
    "frequency": ("+", "stable in frequency"),
    "new": (".", "new"),
}


def plot_stabilisation(
    diagram: StabilisationDiagram, data: IOData | None = None
) -> Figure:
    """The stabilisation diagram: each order's modes at their frequencies,
    marked by how they compare with the order below; with `data`, its
    power spectral density behind them (each output's, normalised).

    Parameters
    ----------
    diagram : StabilisationDiagram
        From :func:`~spiralid.sysid.validation.stabilisation.stabilisation`.
    data : IOData, optional
        The record whose spectrum is drawn behind the modes.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(diagram, StabilisationDiagram):
        raise ValueError(
            f"`diagram` must be a StabilisationDiagram; got {type(diagram).__name__}"
        )
    fig = Figure(figsize=(8, 5))
    ax = fig.add_subplot()
    for status, (marker, label) in _MARKERS.items():
        rows = diagram.status == status
        if rows.any():
            ax.plot(
                diagram.frequency[rows],
                diagram.order[rows],
                marker,
                linestyle="none",
                label=label,
            )
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("model order na")
    ax.set_title("Stabilisation diagram")
    if data is not None:
        spec_ax = ax.twinx()
        for k, name in enumerate(data.output_names):
            spectrum = psd(data.outputs[:, k], 1.0 / data.ts)
            level = 10 * np.log10(np.maximum(spectrum.p, 1e-300))
            spec_ax.plot(spectrum.f, level - level.max(), lw=0.8, alpha=0.5,
                         label=f"PSD of {name}")  # fmt: skip
        spec_ax.set_ylabel("PSD (dB, each output's peak at 0)")
        # The twin is drawn over its host: put the spectra behind the mode
        # markers and their legend instead.
        ax.set_zorder(spec_ax.get_zorder() + 1)
        ax.patch.set_visible(False)
    ax.legend(loc="upper left", fontsize="small")
    ax.set_xlim(left=0.0)
    return fig
