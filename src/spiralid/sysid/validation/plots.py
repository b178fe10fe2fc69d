"""Figures for identification and validation (the paper's Figures 6 and 7).

Every function returns a new :class:`matplotlib.figure.Figure` and never
calls ``show()``; the figures are built with the object-oriented API
(:class:`~matplotlib.figure.Figure`, not ``pyplot``), so nothing is
registered with a GUI backend and nothing leaks between calls.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from spiralid._checks import positive

from ..spectra import PSD, Modes, Peaks
from .convergence_plots import plot_convergence

# The report's figures draw their cost axes with plots.set_log_scale.
from .convergence_plots import set_log_scale as set_log_scale
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
    in the title, as MATLAB's ``resid`` lays them out; a test with no
    degrees of freedom reads "n/a" in grey, never "pass". When the test's
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
        what = (
            "Residual autocorrelation"
            if tst.kind == "autocorrelation"
            else "Input-residual cross-correlation"
        )
        if tst.applicable:
            verdict = ", ".join(
                f"{'pass' if tst.passed[lv] else 'fail'} {100 * lv:g} %"
                for lv in tst.levels
            )
            title = f"{what}: {verdict} (p = {tst.p_value:.3g})"
            colour = "black"
        else:
            # Nothing was tested (a constant input): its p-value of 1 would
            # read as a clean pass.
            title = f"{what}: n/a (no degrees of freedom)"
            colour = "tab:gray"
        ax.set_title(title, fontsize="medium", color=colour)
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
        raise TypeError(
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
