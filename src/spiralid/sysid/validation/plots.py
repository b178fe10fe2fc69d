"""Figures for identification and validation (the paper's Figures 6 and 7).

Every function returns a new :class:`matplotlib.figure.Figure` and never
calls ``show()``; the figures are built with the object-oriented API
(:class:`~matplotlib.figure.Figure`, not ``pyplot``), so nothing is
registered with a GUI backend and nothing leaks between calls.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from spiralid._checks import positive

from ..spectra import PSD, Modes, Peaks
from .correlation import CorrelationTest
from .mode_plots import plot_stabilisation

__all__ = [
    "plot_convergence",
    "plot_pole_zero",
    "plot_psd",
    "plot_residual_tests",
    "plot_stabilisation",
    "plot_time_response",
    "plot_validations",
]


def _outputs(outputs, n: int, name: str = "outputs") -> dict[str, np.ndarray]:
    if not isinstance(outputs, Mapping):
        outputs = {"model": outputs}
    out = {}
    for label, yhat in outputs.items():
        arr = np.asarray(yhat, dtype=float).ravel()
        if arr.size != n:
            raise ValueError(
                f"`{name}` must hold signals as long as `y` ({n} samples); "
                f"got {arr.size} for {label!r}"
            )
        out[str(label)] = arr
    return out


def plot_time_response(
    t,
    y,
    outputs,
    *,
    error: bool = True,
    title: str | None = None,
    ylabel: str = "output",
    unit: str = "",
) -> Figure:
    """Measured output against one or several model outputs, and their errors.

    Parameters
    ----------
    t : array_like, shape (N,)
        Time in seconds.
    y : array_like, shape (N,)
        Measured output.
    outputs : array_like or mapping of str to array_like
        Model output(s), each of shape (N,); a mapping gives legend labels.
    error : bool, default True
        Add a second axes with the errors ``y - yhat`` (the paper's
        Figures 6c and 7b).
    title, ylabel : str, optional
        Labels.
    unit : str, optional
        Unit of `y` (e.g. ``"m/s^2"``), added to both y axes.

    Returns
    -------
    Figure
        One axes (response) or two (response, error), sharing the time axis.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(100) * 0.01
    >>> fig = plot_time_response(t, np.sin(t), {"A": np.sin(t) + 0.1})
    >>> len(fig.axes), len(fig.axes[0].lines)
    (2, 2)
    """
    t = np.asarray(t, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if t.size != y.size:
        raise ValueError(
            f"`t` and `y` must have the same length; got {t.size} and {y.size}"
        )
    outs = _outputs(outputs, y.size)
    fig = Figure(figsize=(8, 5.5 if error else 3.5), layout="constrained")
    axes = fig.subplots(2 if error else 1, 1, sharex=True, squeeze=False)[:, 0]
    ax = axes[0]
    ax.plot(t, y, color="k", lw=1.2, label="measured")
    for label, yhat in outs.items():
        ax.plot(t, yhat, lw=1.0, label=label)
    units = f" ({unit})" if unit else ""
    ax.set_ylabel(ylabel + units)
    ax.legend(loc="best", fontsize="small")
    if title:
        ax.set_title(title)
    if error:
        ax = axes[1]
        for label, yhat in outs.items():
            ax.plot(t, y - yhat, lw=0.9, label=label)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_ylabel(f"error, measured - model{units}")
        ax.legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("time (s)")
    return fig


def plot_residual_tests(*tests: CorrelationTest) -> Figure:
    """Residual correlations with their confidence bands, one axes per test.

    Each test (from :func:`~spiralid.sysid.validation.correlation.whiteness_test` or
    :func:`~spiralid.sysid.validation.correlation.independence_test`) is drawn as stems
    with dashed ``+-z/sqrt(N)`` bands for each of its levels, and its verdict
    in the title, as MATLAB's ``resid`` lays them out. When the test's
    ``band_scale`` differs from 1 (coloured input and residual), the
    colour-adjusted bands ``band_scale * z / sqrt(N)`` are drawn as well.

    Returns
    -------
    Figure
        ``len(tests)`` axes.

    Examples
    --------
    >>> import numpy as np
    >>> from spiralid.sysid import independence_test, whiteness_test
    >>> rng = np.random.default_rng(0)
    >>> u, e = rng.standard_normal(500), rng.standard_normal(500)
    >>> fig = plot_residual_tests(whiteness_test(e), independence_test(u, e))
    >>> len(fig.axes)
    2
    """
    if not tests:
        raise ValueError("`tests` must contain at least one CorrelationTest; got none")
    for i, tst in enumerate(tests):
        if not isinstance(tst, CorrelationTest):
            raise ValueError(
                f"`tests` must be CorrelationTest objects; got "
                f"{type(tst).__name__} at position {i}"
            )
    fig = Figure(figsize=(8, 2.8 * len(tests)), layout="constrained")
    axes = fig.subplots(len(tests), 1, squeeze=False)[:, 0]
    styles = ("--", ":", "-.")
    for ax, tst in zip(axes, tests, strict=True):
        ax.stem(tst.lags, tst.values, basefmt=" ")
        for j, lv in enumerate(tst.levels):
            b = tst.bands[lv]
            ls = styles[j % len(styles)]
            ax.axhline(b, color="r", ls=ls, lw=0.9, label=f"{100 * lv:g} % band")
            ax.axhline(-b, color="r", ls=ls, lw=0.9)
        if abs(tst.band_scale - 1.0) > 0.05:
            # Coloured input and residual widen the null spread of each lag;
            # show that band too, or a sine-sweep input looks like a failure.
            for j, lv in enumerate(tst.levels):
                b = tst.bands[lv] * tst.band_scale
                ls = styles[j % len(styles)]
                lab = f"{100 * lv:g} % band, colour-adjusted"
                ax.axhline(b, color="tab:green", ls=ls, lw=0.9, label=lab)
                ax.axhline(-b, color="tab:green", ls=ls, lw=0.9)
        verdict = ", ".join(
            f"{'pass' if tst.passed[lv] else 'fail'} {100 * lv:g} %"
            for lv in tst.levels
        )
        what = (
            "Residual autocorrelation"
            if tst.kind == "autocorrelation"
            else "Input-residual cross-correlation"
        )
        ax.set_title(f"{what}: {verdict} (p = {tst.p_value:.3g})", fontsize="medium")
        ax.set_xlabel("lag (samples)")
        ax.set_ylabel("normalised correlation")
        # Beside the axes: inside, the legend hides stems at some lags.
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return fig


def plot_psd(
    measured: PSD,
    models: Mapping[str, PSD] | PSD | None = None,
    *,
    peaks: Peaks | None = None,
    modes: Mapping[str, Modes] | None = None,
    fmax: float | None = None,
) -> Figure:
    """Power spectral densities of measured and model outputs (dB), with modes.

    The paper's Figure 7c. Measured peaks are marked with dots on the measured
    curve and labelled in Hz; each model's modes from its poles are marked as
    vertical dotted lines in that model's colour.

    Parameters
    ----------
    measured : PSD
        Spectrum of the measured output.
    models : PSD or mapping of str to PSD, optional
        Spectra of model outputs.
    peaks : Peaks, optional
        Peaks of the measured spectrum to mark.
    modes : mapping of str to Modes, optional
        Model resonances to mark, keyed like ``models``.
    fmax : float, optional
        Upper frequency limit of the plot (default ``fs/2``).

    Returns
    -------
    Figure
        One axes.

    Examples
    --------
    >>> import numpy as np
    >>> from spiralid.sysid.spectra import psd
    >>> x = np.random.default_rng(0).standard_normal(1024)
    >>> fig = plot_psd(psd(x, 100.0), {"model": psd(0.5 * x, 100.0)})
    >>> len(fig.axes), len(fig.axes[0].lines)
    (1, 2)
    """
    if not isinstance(measured, PSD):
        raise ValueError(f"`measured` must be a PSD; got {type(measured).__name__}")
    if models is None:
        models = {}
    elif isinstance(models, PSD):
        models = {"model": models}
    tiny = np.finfo(float).tiny
    fig = Figure(figsize=(8, 4), layout="constrained")
    ax = fig.subplots()
    ax.plot(
        measured.f,
        10 * np.log10(np.maximum(measured.p, tiny)),
        color="k",
        lw=1.2,
        label="measured",
    )
    colours = {}
    for label, spec in models.items():
        (line,) = ax.plot(
            spec.f, 10 * np.log10(np.maximum(spec.p, tiny)), lw=1.0, label=label
        )
        colours[label] = line.get_color()
    if peaks is not None and peaks.frequency.size:
        ax.plot(peaks.frequency, peaks.level_db, "o", color="k", ms=5, label="_peaks")
        for f, lv in zip(peaks.frequency, peaks.level_db, strict=True):
            ax.annotate(
                f"{f:.2f} Hz",
                (f, lv),
                textcoords="offset points",
                xytext=(4, 6),
                fontsize="small",
            )
    for label, md in (modes or {}).items():
        colour = colours.get(label, "tab:gray")
        for f in md.frequency:
            ax.axvline(f, color=colour, ls=":", lw=0.9)
    ax.set_xlim(0.0, measured.fs / 2.0 if fmax is None else float(fmax))
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("PSD (dB/Hz)")
    ax.set_title(f"Welch PSD (resolution {measured.resolution:.3g} Hz)")
    ax.legend(loc="best", fontsize="small")
    return fig


def plot_pole_zero(models, *, radius: float | None = None) -> Figure:
    """Pole-zero map in the z-plane with the unit circle, for several models.

    Parameters
    ----------
    models : mapping of str to (poles, zeros)
        Poles are drawn as crosses and zeros as circles, one colour per model.
        Objects with ``poles`` and ``zeros`` attributes (an
        ``IdentifiedModel``) are accepted in place of the pair.
    radius : float, optional
        Half-width of the square view around the origin. Default: enough to
        show every pole and zero, but at most 2; points beyond the view (an
        ARX numerator often has a far zero) are counted in the title.

    Returns
    -------
    Figure
        One axes with equal aspect.

    Examples
    --------
    >>> fig = plot_pole_zero({"A": ([0.5 + 0.5j, 0.5 - 0.5j], [0.0])})
    >>> len(fig.axes)
    1
    """
    if not isinstance(models, Mapping):
        raise ValueError(
            f"`models` must be a mapping of label to (poles, zeros); "
            f"got {type(models).__name__}"
        )
    fig = Figure(figsize=(5.5, 5.5), layout="constrained")
    ax = fig.subplots()
    w = np.linspace(0.0, 2 * np.pi, 361)
    ax.plot(np.cos(w), np.sin(w), color="k", lw=0.8, label="_unit circle")
    ax.axhline(0.0, color="0.7", lw=0.5)
    ax.axvline(0.0, color="0.7", lw=0.5)
    if radius is not None:
        radius = positive(radius, "radius")
    everything = []
    for label, pz in models.items():
        if hasattr(pz, "poles") and hasattr(pz, "zeros"):
            p, z = pz.poles, pz.zeros
        else:
            try:
                p, z = pz
            except (TypeError, ValueError):
                raise ValueError(
                    f"`models` values must be (poles, zeros) pairs; got {pz!r} "
                    f"for {label!r}"
                ) from None
        p = np.atleast_1d(np.asarray(p, dtype=complex))
        z = np.atleast_1d(np.asarray(z, dtype=complex))
        everything.append(np.abs(np.r_[p, z]))
        (line,) = ax.plot(p.real, p.imag, "x", ms=8, mew=1.5, label=f"{label} poles")
        ax.plot(
            z.real,
            z.imag,
            "o",
            ms=7,
            mfc="none",
            color=line.get_color(),
            label=f"{label} zeros",
        )
    mags = np.concatenate(everything) if everything else np.zeros(0)
    if radius is None:
        radius = float(np.clip(1.1 * mags.max(), 1.15, 2.0)) if mags.size else 1.15
    outside = int(np.sum(mags > radius))
    ax.set_xlim(-radius, radius)
    ax.set_ylim(-radius, radius)
    ax.set_aspect("equal")
    ax.set_xlabel("Re z")
    ax.set_ylabel("Im z")
    title = "Pole-zero map"
    if outside:
        title += f" ({outside} outside the view, largest |z| = {mags.max():.3g})"
    ax.set_title(title, fontsize="medium")
    ax.legend(loc="best", fontsize="small")
    return fig


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


def plot_validations(validations, *, fmax: float | None = None) -> dict[str, Figure]:
    """Several models validated on the same record, overlaid (paper Figure 7).

    Parameters
    ----------
    validations : sequence of Validation or mapping of str to Validation
        Results of :func:`~spiralid.sysid.validate` on one record; a mapping
        gives the legend labels, otherwise each validation's ``label`` is used.
    fmax : float, optional
        Upper frequency limit of the spectrum plot.

    Returns
    -------
    dict of Figure
        ``"time"`` (measured and simulated outputs, errors), ``"spectrum"``
        (Welch PSDs with measured peaks and each model's modes) and
        ``"pole_zero"``.
    """
    if isinstance(validations, Mapping):
        items = [(str(k), v) for k, v in validations.items()]
    else:
        items = [(v.label or f"model {i + 1}", v) for i, v in enumerate(validations)]
    if not items:
        raise ValueError("`validations` must hold at least one Validation; got none")
    ref = items[0][1]
    for label, v in items[1:]:
        if v.y.shape != ref.y.shape or v.ts != ref.ts or not np.array_equal(v.y, ref.y):
            raise ValueError(
                f"`validations` must all be on the same record; {label!r} differs "
                f"from {items[0][0]!r} (N = {v.y.size} vs {ref.y.size}, "
                f"ts = {v.ts} vs {ref.ts})"
            )
    return {
        "time": plot_time_response(
            ref.t, ref.y, {k: v.y_sim for k, v in items}, title="Free-run output"
        ),
        "spectrum": plot_psd(
            ref.psd_measured,
            {k: v.psd_model for k, v in items},
            peaks=ref.peaks_measured,
            modes={k: v.modes for k, v in items},
            fmax=fmax,
        ),
        "pole_zero": plot_pole_zero({k: (v.poles, v.zeros) for k, v in items}),
    }
