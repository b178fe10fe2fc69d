"""The convergence figure (the paper's Figure 6a): best cost against
iteration and wall time, one median and band per method, and the
logarithmic cost axis the report's figures share (:func:`set_log_scale`).
Drawn into a :class:`~matplotlib.figure.Figure` not registered with pyplot,
as the other figures of :mod:`spiralid.sysid.plots`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_convergence", "set_log_scale"]


def set_log_scale(ax) -> None:
    """A logarithmic y axis that keeps several labelled ticks.

    Over less than a decade or two, matplotlib's log axis labels one or two
    powers of ten at most; there the ticks are placed as on a linear axis
    and labelled in plain numbers.
    """
    from matplotlib.ticker import FuncFormatter, MaxNLocator, NullFormatter

    ax.set_yscale("log")
    lo, hi = ax.get_ylim()
    if lo > 0 and hi / lo < 30:
        ax.yaxis.set_major_locator(MaxNLocator(nbins=6))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())


def _step_on_grid(times: np.ndarray, values: np.ndarray, grid: np.ndarray):
    # Best-so-far is a step function: at time g it is the last value logged
    # at or before g (NaN before the first log).
    idx = np.searchsorted(times, grid, side="right") - 1
    out = np.full(grid.shape, np.nan)
    ok = idx >= 0
    out[ok] = values[idx[ok]]
    return out


def _runs(value, name: str) -> list[np.ndarray]:
    if hasattr(value, "history"):
        value = value.history
    if isinstance(value, np.ndarray) and value.ndim == 1:
        runs = [value]
    elif isinstance(value, np.ndarray) and value.ndim == 2:
        runs = list(value)
    elif (
        isinstance(value, Sequence)
        and value
        and np.ndim(value[0]) == 0
        and not hasattr(value[0], "history")
    ):
        runs = [np.asarray(value)]
    else:
        runs = [np.asarray(getattr(v, "history", v)) for v in value]
    out = []
    for r in runs:
        r = np.asarray(r, dtype=float).ravel()
        if r.size == 0:
            raise ValueError(
                f"`{name}` must hold non-empty histories; got an empty one"
            )
        out.append(r)
    return out


def plot_convergence(
    histories,
    *,
    times=None,
    log: bool = True,
    band: tuple[float, float] = (25.0, 75.0),
    cost_label: str = "best cost",
    figure=None,
) -> Figure:
    """Best cost against iteration (and wall time), one curve per method.

    The paper's Figure 6a. With several histories for a method (one per seed)
    the median is drawn with a shaded band between the ``band`` percentiles
    (the interquartile range by default); with one, the history itself.

    Parameters
    ----------
    histories : mapping of str to history or list of histories
        A history is the best cost after each iteration, index 0 the initial
        population (``OptimiserResult.history``); a result object with a
        ``history`` attribute is accepted in its place. Histories of one method
        may differ in length; the statistics at an iteration use the runs that
        reached it.
    times : mapping of str to (float or array or list of those), optional
        Wall time per method, keyed like ``histories``: for each run either
        the total search time in seconds (iterations then taken as evenly
        spaced in time) or the time of every history entry. Adds a second axes
        of best cost against time, where runs are compared on a common time
        grid as step functions.
    log : bool, default True
        Logarithmic cost axis.
    band : (float, float), default (25, 75)
        Percentiles of the shaded band.
    cost_label : str, default "best cost"
        Label of the cost axis; give the cost's unit, e.g. ``"best cost,
        eq. (2) (% of rms(y))"``.
    figure : Figure or SubFigure, optional
        Draw into this (empty) figure, e.g. one of ``Figure.subfigures``,
        instead of a new one.

    Returns
    -------
    Figure
        One axes (vs iteration) or two (vs iteration, vs time); `figure`
        when given.

    Examples
    --------
    >>> import numpy as np
    >>> h = [np.geomspace(10, 1, 51), np.geomspace(20, 2, 51)]
    >>> fig = plot_convergence({"Eb-SDA": h}, times={"Eb-SDA": [1.0, 1.2]})
    >>> len(fig.axes)
    2
    """
    runs = _histories(histories)
    lo_q, hi_q = band
    if not 0.0 <= lo_q < hi_q <= 100.0:
        raise ValueError(
            f"`band` must be percentiles 0 <= lo < hi <= 100; got {band!r}"
        )
    time_runs = {} if times is None else _time_runs(times, runs)

    fig = figure
    if fig is None:
        fig = Figure(figsize=(8, 6.5 if time_runs else 3.8), layout="constrained")
    axes = fig.subplots(2 if time_runs else 1, 1, squeeze=False)[:, 0]
    for label, hs in runs.items():
        stack, x = _padded(hs)
        _draw_runs(axes[0], x, stack, label, band)
    axes[0].set_xlabel("iteration")
    if time_runs:
        for label, hs in runs.items():
            grid, stack = _on_time_grid(time_runs[label], hs)
            _draw_runs(axes[1], grid, stack, label, band)
        axes[1].set_xlabel("wall time (s)")
    for ax in axes:
        ax.set_ylabel(cost_label)
        if log:
            set_log_scale(ax)
        ax.legend(loc="best", fontsize="small")
    axes[0].set_title("Convergence")
    return fig


def _histories(histories) -> dict[str, list[np.ndarray]]:
    """`histories` of :func:`plot_convergence` as each label's runs."""
    if not isinstance(histories, Mapping) or not histories:
        raise ValueError(
            "`histories` must be a non-empty mapping of label to history "
            f"(or list of histories); got {histories!r:.60}"
        )
    return {str(k): _runs(v, "histories") for k, v in histories.items()}


def _time_runs(times, runs: dict) -> dict[str, list[np.ndarray]]:
    """`times` of :func:`plot_convergence` as each run's time per entry."""
    if not isinstance(times, Mapping) or set(map(str, times)) != set(runs):
        raise ValueError(
            "`times` must be a mapping with the same labels as `histories` "
            f"({sorted(runs)}); got {times!r:.80}"
        )
    out = {}
    for k, v in times.items():
        k = str(k)
        per = _times_per_run(k, v, len(runs[k]))
        out[k] = [_entry_times(k, tv, h) for tv, h in zip(per, runs[k], strict=True)]
    return out


def _times_per_run(label: str, value, n_runs: int) -> list:
    """One label's `times` split into one item per run."""
    if n_runs == 1:
        # One run: its total, its per-entry times, or a one-item list.
        per = [value[0]] if np.ndim(value) == 1 and np.size(value) == 1 else [value]
    elif np.ndim(value) == 0:
        per = [value]  # rejected below: one entry for several runs
    else:
        per = list(value)
    if len(per) != n_runs:
        raise ValueError(
            f"`times` for {label!r} must give one entry per history "
            f"({n_runs}); got {len(per)}"
        )
    return per


def _entry_times(label: str, value, history: np.ndarray) -> np.ndarray:
    """The time of every entry of one run's history: given, or its total
    spread evenly over the entries."""
    if np.ndim(value) == 0:
        total = float(value)
        if not (np.isfinite(total) and total > 0):
            raise ValueError(
                f"`times` totals must be positive; got {value!r} for {label!r}"
            )
        return np.linspace(0.0, total, history.size)
    tv = np.asarray(value, dtype=float).ravel()
    if tv.size != history.size or np.any(np.diff(tv) < 0):
        raise ValueError(
            f"`times` for {label!r} must be non-decreasing and as long "
            f"as its history ({history.size}); got {tv.size} entries"
        )
    return tv


def _padded(hs: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Runs of different lengths as rows padded with NaN, and the
    iterations."""
    n = max(h.size for h in hs)
    stack = np.full((len(hs), n), np.nan)
    for i, h in enumerate(hs):
        stack[i, : h.size] = h
    return stack, np.arange(n)


def _on_time_grid(tr: list[np.ndarray], hs: list[np.ndarray]):
    """Several runs as step functions on a common time grid (one run: its
    own times)."""
    end = max(t[-1] for t in tr)
    grid = np.linspace(0.0, end, 400) if len(hs) > 1 else tr[0]
    stack = np.vstack([_step_on_grid(t, h, grid) for t, h in zip(tr, hs, strict=True)])
    return grid, stack


def _draw_runs(ax, x, stack: np.ndarray, label: str, band) -> None:
    """One run as a line; several as their median and a shaded band."""
    if stack.shape[0] == 1:
        ax.plot(x, stack[0], lw=1.2, label=label)
        return
    count = np.sum(np.isfinite(stack), axis=0)
    ok = count > 0
    x, stack = x[ok], stack[:, ok]
    med = np.nanmedian(stack, axis=0)
    lo = np.nanpercentile(stack, band[0], axis=0)
    hi = np.nanpercentile(stack, band[1], axis=0)
    (line,) = ax.plot(x, med, lw=1.2, label=f"{label} (median of {len(stack)})")
    ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.25, lw=0)
