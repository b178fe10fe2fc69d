"""Model validation the way the paper and MATLAB's toolbox judge a model.

:func:`validate` applies the measured input of a validation record to an
identified model and reports, in one :class:`Validation`:

* time domain: fit % as MATLAB's ``compare`` defines it, RMSE, the paper's
  cost (eq. (2)-(3)) and the range of the error (the paper's Table-2), for
  the free-run simulation (the paper's validation, Figure-3) and, labelled
  separately, the one-step prediction;
* residual analysis: whiteness of the residual and its independence from the
  input, with 95 % and 99 % bands (:mod:`spiralid.sysid.validation.correlation`);
* frequency domain: Welch spectra of measured and modelled output and their
  resonance peaks, and the model's own modes from its poles
  (:mod:`spiralid.sysid.spectra`; the paper's Figure-7c);
* structure: stability from the poles, and controllability / observability of
  the model's state-space realisation (the paper's MATLAB ``ctrb``/``obsv``
  check after eq. (10)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from spiralid._checks import positive, refuse_options

from ..data import check_pair
from ..estimation.cost import auto_gain, cost_of_errors
from ..estimation.outputerror import error_functions
from ..models.modes import ModeTable
from ..models.polynomials import (
    format_pole_radius,
    is_stable_polynomial,
    max_pole_radius,
)
from ..spectra import PSD, Modes, Peaks, find_resonances, modes_from_poles, psd
from .correlation import (
    CorrelationTest,
    check_lags,
    independence_test,
    whiteness_test,
)

__all__ = [
    "Realization",
    "Validation",
    "fit_percent",
    "realization_tests",
    "rmse",
    "validate",
]

_RESIDUALS = ("one-step", "simulation")


# Closer than this, a pole and a zero (or a pole and the origin) are taken
# as one: relative to the unit circle, far below any resonance's width.
_CANCELLATION = 1e-6


# Below this fit % (an error a million percent of the output's spread) the
# digits only tell how long an unstable run grew: a table says it diverged.
_DIVERGED_FIT = -1e6


def _format_fit(fit: float, run: str = "free run", unit: str = "") -> str:
    """A fit % as a table prints it, followed by `unit`: two decimals, or
    for a `run` that ran away its order of magnitude and that it diverged."""
    if not fit < _DIVERGED_FIT:
        return f"{fit:.2f}{unit}"
    return f"{fit:.2g}{unit} (the {run} diverged)"


def fit_percent(y, yhat) -> float:
    """Normalised fit in percent, as MATLAB's ``compare`` reports it.

    ``fit = 100 (1 - ||y - yhat|| / ||y - mean(y)||)``: 100 for a perfect
    model, 0 for one no better than the output's mean, negative for worse.

    Parameters
    ----------
    y : array_like, shape (N,)
        Measured output.
    yhat : array_like, shape (N,)
        Model output (simulated or predicted).

    Returns
    -------
    float

    Examples
    --------
    ``||e|| = 1`` and ``||y - mean(y)|| = sqrt(2)``, so the fit is
    ``100 (1 - 1 / sqrt(2))``:

    >>> round(fit_percent([1.0, 2.0, 3.0], [1.0, 2.0, 4.0]), 6)
    29.289322
    """
    a, b = check_pair(y, yhat, "y", "yhat")
    scale = np.linalg.norm(a - a.mean())
    if scale == 0.0:
        raise ValueError(
            "`y` must not be constant: the fit is relative to its variation; "
            f"got every sample equal to {a[0]!r}"
        )
    return float(100.0 * (1.0 - np.linalg.norm(a - b) / scale))


def rmse(y, yhat) -> float:
    """Root-mean-square error ``sqrt(mean((y - yhat)^2))``.

    Examples
    --------
    >>> rmse([0.0, 0.0], [3.0, 4.0])  # sqrt((9 + 16) / 2)
    3.5355339059327378
    """
    a, b = check_pair(y, yhat, "y", "yhat")
    return float(np.sqrt(np.mean((a - b) ** 2)))


# -- state-space realisation ------------------------------------------------------


@dataclass(frozen=True)
class Realization:
    """Controllability and observability of a transfer function's realisation.

    The realisation is SciPy's ``tf2ss`` (controller canonical form), the same
    kind MATLAB's ``ss(tf)`` builds. That form is controllable by
    construction, so a pole-zero cancellation shows up as a loss of
    observability. Rank is counted from singular values above
    ``rtol * s_max`` (default ``rtol = n * eps``, MATLAB's and NumPy's
    ``rank``), which only flags a cancellation exact to rounding; a near
    cancellation is better read from ``min_pole_zero_distance`` and the
    singular-value ratios.

    Attributes
    ----------
    order : int
        State dimension n.
    ctrb_rank, obsv_rank : int
        Numerical ranks of ``[B, AB, .., A^(n-1) B]`` and ``[C; CA; ..]``.
    controllable, observable : bool
        Rank equals n.
    ctrb_sv_ratio, obsv_sv_ratio : float
        Smallest over largest singular value of those matrices (1 is ideal,
        0 is singular).
    min_pole_zero_distance : float
        Smallest ``|p - z|`` over poles and zeros in the z-plane (``inf`` if
        there are no zeros). Zero means a cancellation: the realisation is not
        minimal.
    """

    order: int
    ctrb_rank: int
    obsv_rank: int
    controllable: bool
    observable: bool
    ctrb_sv_ratio: float
    obsv_sv_ratio: float
    min_pole_zero_distance: float

    @property
    def minimal(self) -> bool:
        """Controllable and observable: no pole-zero cancellation."""
        return self.controllable and self.observable

    def to_dict(self) -> dict:
        """JSON-safe dictionary (an infinite distance becomes ``None``)."""
        d = self.min_pole_zero_distance
        return {
            "order": int(self.order),
            "ctrb_rank": int(self.ctrb_rank),
            "obsv_rank": int(self.obsv_rank),
            "controllable": bool(self.controllable),
            "observable": bool(self.observable),
            "minimal": bool(self.minimal),
            "ctrb_sv_ratio": float(self.ctrb_sv_ratio),
            "obsv_sv_ratio": float(self.obsv_sv_ratio),
            "min_pole_zero_distance": float(d) if np.isfinite(d) else None,
        }


def _rank(mat: np.ndarray, rtol: float | None) -> tuple[int, float]:
    s = np.linalg.svd(mat, compute_uv=False)
    if s.size == 0 or s[0] == 0.0:
        return 0, 0.0
    tol = (max(mat.shape) * np.finfo(float).eps if rtol is None else rtol) * s[0]
    return int(np.sum(s > tol)), float(s[-1] / s[0])


def realization_tests(num, den, *, rtol: float | None = None) -> Realization:
    """Controllability and observability of ``num(z) / den(z)``.

    Parameters
    ----------
    num, den : array_like
        Coefficients in descending powers of ``z`` (``scipy.signal.dlti``'s
        convention; an ARX's ``polynomials(theta)``, padded to equal length,
        serve as they are). ``den[0]`` must be non-zero.
    rtol : float, optional
        Relative singular-value tolerance for the rank; default ``n * eps``.

    Returns
    -------
    Realization

    Examples
    --------
    The denominator is ``(z - 0.5)(z - 0.7)``; a zero at 0.2 leaves the
    realisation minimal, a zero at 0.5 cancels a pole:

    >>> r = realization_tests([1.0, -0.2], [1.0, -1.2, 0.35])
    >>> r.controllable, r.observable
    (True, True)
    >>> r = realization_tests([1.0, -0.5], [1.0, -1.2, 0.35])
    >>> r.controllable, r.observable, r.min_pole_zero_distance < 1e-12
    (True, False, True)
    """
    num = np.atleast_1d(np.asarray(num, dtype=float))
    den = np.atleast_1d(np.asarray(den, dtype=float))
    if num.ndim != 1 or den.ndim != 1:
        raise ValueError(
            f"`num` and `den` must be 1-D coefficient arrays; "
            f"got shapes {num.shape} and {den.shape}"
        )
    if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den))):
        raise ValueError(f"`num` and `den` must be finite; got {num!r} and {den!r}")
    if den.size == 0 or den[0] == 0.0:
        raise ValueError(f"`den` must have a non-zero leading coefficient; got {den!r}")
    if num.size > den.size:
        raise ValueError(
            f"`num` must not be longer than `den` (an improper transfer function "
            f"has no state-space realisation); got {num.size} and {den.size}"
        )
    if rtol is not None and not (np.isfinite(rtol) and 0.0 < rtol < 1.0):
        raise ValueError(f"`rtol` must be in (0, 1); got {rtol!r}")
    # Leading zeros of the numerator (input delay nk > 0) are exact; strip them
    # so that tf2ss does not warn about badly conditioned coefficients.
    num_trim = np.trim_zeros(num, "f")
    a, b, c, _ = signal.tf2ss(num_trim if num_trim.size else [0.0], den)
    n = a.shape[0]
    poles = np.roots(den)
    zeros = np.roots(num) if np.any(num != 0.0) else np.array([])
    dist = (
        float(np.min(np.abs(poles[:, None] - zeros[None, :])))
        if poles.size and zeros.size
        else float("inf")
    )
    if n == 0:
        return Realization(0, 0, 0, True, True, 1.0, 1.0, dist)
    ctrb = np.empty((n, n))
    obsv = np.empty((n, n))
    col, row = b[:, 0], c[0]
    for k in range(n):
        ctrb[:, k] = col
        obsv[k] = row
        col, row = a @ col, row @ a
    rc, sc = _rank(ctrb, rtol)
    ro, so = _rank(obsv, rtol)
    return Realization(n, rc, ro, rc == n, ro == n, sc, so, dist)


# -- validation -------------------------------------------------------------------


@dataclass(frozen=True)
class Validation:
    """Everything :func:`validate` found out about a model on a record.

    Time-domain figures come in pairs: the free-run simulation (the primary
    one, the paper's validation) and the one-step prediction (``*_one_step``).
    Errors are ``y - yhat``.

    Attributes
    ----------
    label : str
        Name of the model (for tables and legends).
    n_samples : int
        Length N of the record.
    ts : float
        Sample time in seconds.
    fit_percent, fit_percent_one_step : float
        MATLAB ``compare`` fit, ``100 (1 - ||e|| / ||y - mean(y)||)``.
    rmse, rmse_one_step : float
        Root-mean-square error.
    cost : float
        The paper's eq. (2)-(3) on this record for the error of the model's
        predictor, with the gain :func:`validate` was given (with
        ``gain="auto"`` it is ``100 rms(e) / rms(y)``, a percentage), plus the
        stability penalty when the model is unstable.
    cost_predictor : str
        Which error ``cost`` measures (``"simulation"`` or ``"one-step"``).
    error_range, error_range_one_step : tuple of float
        ``(min, max)`` of the error, as in the paper's Table-2.
    residuals : str
        Which error the correlation tests used (``"one-step"``, the model's
        innovations as MATLAB's ``resid`` takes them, or ``"simulation"``).
    whiteness, independence : CorrelationTest
        Residual autocorrelation (lags 1..L) and input-residual
        cross-correlation (lags -L..L).
    psd_measured, psd_model : PSD
        Welch spectra of the measured and the simulated output.
    peaks_measured, peaks_model : Peaks
        Their most prominent resonance peaks.
    modes : Modes
        Lightly damped modes of the model, from its poles.
    stable : bool
        All poles strictly inside the unit circle: spiralid's one stability
        verdict (:func:`~spiralid.sysid.models.polynomials.is_stable_polynomial`,
        the same as ``model.is_stable`` and the cost's penalty).
    max_pole_radius : float
        Largest ``|p|``, on the verdict's side of the unit circle
        (:func:`~spiralid.sysid.models.polynomials.max_pole_radius`).
    realization : Realization
        Controllability / observability of the state-space realisation.
    poles, zeros : ndarray of complex
        Of the transfer function in ``z``.
    t, u, y, y_sim, y_pred : ndarray
        Time axis and signals, for plots; after a ``warmup`` the time axis
        continues from its end.
    output_name, output_unit : str
        The record's output name and unit, for figure labels.
    integrator : int
        The number of known integrators (poles at ``z = 1``) the model has
        by design, so ``stable`` is judged without them.
    initial : {"rest", "warmup"}
        Where the free run started: from rest, or from the state the model
        reached over ``warmup``.
    fit_percent_measured : float
        The free run's fit started instead from the record's first
        ``max_lag`` measured samples (its initial state; scored on the
        samples after them), NaN for a model without an ARX structure.
    diverged : bool
        The free run grew without bound on this record: its fit is reported
        (far below zero, or ``-inf``) but means only that.
    output_error : bool
        The model was fitted to its simulation error (output error, the
        spiral searches): the noise is not modelled, so the whiteness test
        does not apply to it and its one-step prediction is not what it
        promises (the summary leaves both out and says why).
    mode_table : ModeTable or None
        The model's modes with 95 % intervals and flags
        (:attr:`~spiralid.sysid.IdentifiedModel.modes`), when the model has
        a covariance.
    reduction : str or None
        What the estimation's pole-zero cancellation removed
        (:attr:`~spiralid.sysid.IdentifiedModel.reduction`), or None.
    choice : str or None
        How the estimation chose among its distinct minima on the held-back
        end of its record (the ``note`` of
        :attr:`~spiralid.sysid.IdentifiedModel.selection`), or None.
    """

    label: str
    n_samples: int
    ts: float
    fit_percent: float
    fit_percent_one_step: float
    rmse: float
    rmse_one_step: float
    cost: float
    cost_predictor: str
    error_range: tuple[float, float]
    error_range_one_step: tuple[float, float]
    residuals: str
    whiteness: CorrelationTest
    independence: CorrelationTest
    psd_measured: PSD
    psd_model: PSD
    peaks_measured: Peaks
    peaks_model: Peaks
    modes: Modes
    stable: bool
    max_pole_radius: float
    realization: Realization
    poles: np.ndarray
    zeros: np.ndarray
    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    y_sim: np.ndarray
    y_pred: np.ndarray
    output_name: str = "output"
    output_unit: str = ""
    integrator: int = 0
    initial: str = "rest"
    fit_percent_measured: float = float("nan")
    diverged: bool = False
    output_error: bool = False
    mode_table: ModeTable | None = None
    reduction: str | None = None
    choice: str | None = None

    @property
    def error(self) -> np.ndarray:
        """Free-run simulation error ``y - y_sim``."""
        return self.y - self.y_sim

    @property
    def order_advice(self) -> str | None:
        """Why the model's order looks higher than the data support, with
        advice, or None: an exact or near pole-zero cancellation
        (``|p - z| < 1e-6``, or a realisation that is not minimal), or poles
        at the origin (the denominator's last coefficients vanish)."""
        reasons = []
        d = self.realization.min_pole_zero_distance
        if not self.realization.minimal or d < _CANCELLATION:
            reasons.append(f"a pole and a zero {d:.2g} apart cancel")
        if self.mode_table is not None and np.any(self.mode_table.spurious):
            table = self.mode_table
            spurious = table.frequency[table.spurious]
            reasons.append(
                f"{spurious.size} mode(s) at "
                + ", ".join(f"{f:.3g}" for f in spurious)
                + " Hz look spurious (a wide interval, a cancelling zero or "
                "under 1 % of the output); the data support about "
                f"{self.poles.size - 2 * spurious.size} poles"
            )
        at_origin = int(np.sum(np.abs(self.poles) < _CANCELLATION))
        if at_origin:
            reasons.append(
                f"{at_origin} pole(s) at the origin (vanishing denominator "
                "coefficients)"
            )
        # What the estimation already removed (`identify(cancel=True)`).
        done = [] if self.reduction is None else [self.reduction]
        if not reasons:
            return done[0] if done else None
        return "; ".join(
            [
                *done,
                f"{' and '.join(reasons)}: the order is higher than the data "
                "support; try a lower one",
            ]
        )

    def summary(self) -> str:
        """A plain-text table of the results."""

        def verdict(test: CorrelationTest) -> str:
            parts = [
                f"{'pass' if test.passed[lv] else 'FAIL'} at {100 * lv:g} %"
                for lv in test.levels
            ]
            return f"{', '.join(parts)} (p = {test.p_value:.3g})"

        def hz(x) -> str:
            return ", ".join(f"{v:.2f}" for v in x) or "none"

        rz = self.realization
        unit = f", {self.output_unit}" if self.output_unit else ""
        start = "from rest" if self.initial == "rest" else "after the warm-up"
        rows = [
            ("samples (N), ts", f"{self.n_samples}, {self.ts:g} s"),
            (f"fit % (simulation, {start})", _format_fit(self.fit_percent)),
            (
                "fit % (simulation, from measured samples)",
                _format_fit(self.fit_percent_measured),
            ),
            ("RMSE (simulation)", f"{self.rmse:.4g}"),
            *self._one_step_rows(unit),
            (f"paper cost, eq. (2) ({self.cost_predictor})", f"{self.cost:.4g}"),
            (
                f"error range (simulation{unit})",
                f"[{self.error_range[0]:.4f}, {self.error_range[1]:.4f}]",
            ),
            (
                f"whiteness ({self.residuals} residual)",
                "not applicable: an output-error model does not model the "
                "noise, so its residual need not be white"
                if self.output_error
                else verdict(self.whiteness),
            ),
            (
                f"independence from the input ({self.residuals} residual)",
                verdict(self.independence),
            ),
            ("PSD peaks, measured (Hz)", hz(self.peaks_measured.frequency)),
            ("PSD peaks, model (Hz)", hz(self.peaks_model.frequency)),
            (
                "model modes (Hz, damping)",
                ", ".join(
                    f"{f:.2f} ({z:.3f})"
                    for f, z in zip(
                        self.modes.frequency, self.modes.damping, strict=True
                    )
                )
                or "none",
            ),
            ("PSD resolution (Hz)", f"{self.psd_measured.resolution:.3g}"),
            (
                "stable (max |pole|)",
                f"{self.stable} ({format_pole_radius(self.max_pole_radius)})"
                + (
                    f"; and {self.integrator} known integrator(s) (pole at "
                    "z = 1): marginally stable by design"
                    if self.integrator
                    else ""
                ),
            ),
            (
                "controllable / observable",
                f"{rz.controllable} / {rz.observable} (order {rz.order})",
            ),
            ("min |pole - zero|", f"{rz.min_pole_zero_distance:.3g}"),
        ]
        advice = self.order_advice
        if advice is not None:
            rows.append(("order", advice))
        if self.choice is not None:
            rows.append(("estimate chosen by", self.choice))
        width = max(len(k) for k, _ in rows)
        title = f"Validation of {self.label}" if self.label else "Validation"
        lines = [title, "-" * max(len(title), width + 30)]
        lines += [f"{k:<{width}}  {v}" for k, v in rows]
        if self.mode_table is not None and len(self.mode_table):
            lines += ["", "Modes of the model (intervals from the estimate's "
                      "covariance)", str(self.mode_table)]  # fmt: skip
        return "\n".join(lines)

    def _one_step_rows(self, unit: str) -> list[tuple[str, str]]:
        """The one-step prediction's rows, or for an output-error model one
        row that says why they are left out."""
        if self.output_error:
            return [
                (
                    "one-step prediction",
                    "not shown: an output-error model is fitted to its free "
                    "run, not to predict one step ahead (see to_dict())",
                )
            ]
        return [
            (
                "fit % (one-step)",
                _format_fit(self.fit_percent_one_step, "one-step prediction"),
            ),
            ("RMSE (one-step)", f"{self.rmse_one_step:.4g}"),
            (
                f"error range (one-step{unit})",
                f"[{self.error_range_one_step[0]:.4f}, "
                f"{self.error_range_one_step[1]:.4f}]",
            ),
        ]

    def __str__(self) -> str:
        return self.summary()

    def to_dict(self, *, signals: bool = False) -> dict:
        """JSON-safe dictionary; ``signals=True`` adds the time series."""

        def cplx(z):
            return [[float(v.real), float(v.imag)] for v in np.asarray(z)]

        out = {
            "label": self.label,
            "n_samples": int(self.n_samples),
            "ts": float(self.ts),
            "fit_percent": float(self.fit_percent),
            "fit_percent_one_step": float(self.fit_percent_one_step),
            "order_advice": self.order_advice,
            "choice": self.choice,
            "rmse": float(self.rmse),
            "rmse_one_step": float(self.rmse_one_step),
            "cost": float(self.cost),
            "cost_predictor": self.cost_predictor,
            "error_range": [float(v) for v in self.error_range],
            "error_range_one_step": [float(v) for v in self.error_range_one_step],
            "residuals": self.residuals,
            "whiteness": self.whiteness.to_dict(),
            "independence": self.independence.to_dict(),
            "psd_resolution_hz": float(self.psd_measured.resolution),
            "psd_nperseg": int(self.psd_measured.nperseg),
            "peaks_measured_hz": [float(v) for v in self.peaks_measured.frequency],
            "peaks_model_hz": [float(v) for v in self.peaks_model.frequency],
            "modes": self.modes.to_dict(),
            "stable": bool(self.stable),
            "integrator": int(self.integrator),
            "max_pole_radius": float(self.max_pole_radius),
            "realization": self.realization.to_dict(),
            "poles": cplx(self.poles),
            "zeros": cplx(self.zeros),
            "initial": self.initial,
            # JSON has no infinity: a measured start that diverged is null.
            "fit_percent_measured": float(self.fit_percent_measured)
            if np.isfinite(self.fit_percent_measured)
            else None,
            "diverged": bool(self.diverged),
            "output_error": bool(self.output_error),
            "mode_table": None
            if self.mode_table is None
            else self.mode_table.to_dict(),
        }
        if signals:
            for name in ("t", "u", "y", "y_sim", "y_pred"):
                out[name] = [float(v) for v in getattr(self, name)]
        return out

    def plot(self) -> dict:
        """Figures of this validation.

        Returns
        -------
        dict of matplotlib.figure.Figure
            ``"time"`` (measured vs simulated output and error),
            ``"residuals"`` (correlations with bands), ``"spectrum"`` (PSDs
            with peaks and modes) and ``"pole_zero"`` (map with unit circle).
        """
        from . import plots

        name = self.label or "model"
        return {
            "time": plots.plot_time_response(
                self.t,
                self.y,
                {name: self.y_sim},
                title="Validation, free run",
                ylabel=self.output_name,
                unit=self.output_unit,
            ),
            "residuals": plots.plot_residual_tests(self.whiteness, self.independence),
            "spectrum": plots.plot_psd(
                self.psd_measured,
                {name: self.psd_model},
                peaks=self.peaks_measured,
                modes={name: self.modes},
            ),
            "pole_zero": plots.plot_pole_zero({name: (self.poles, self.zeros)}),
        }


def _attr(obj, name):
    val = getattr(obj, name)
    return val() if callable(val) else val


def _signals_of(data, name: str = "data"):
    for attr in ("u", "y", "ts"):
        if not hasattr(data, attr):
            raise ValueError(
                f"`{name}` must be an IOData (with .u, .y, .ts); "
                f"got {type(data).__name__}"
            )
    if np.ndim(data.y) == 2 and np.shape(data.y)[1] > 1:
        # Before .ravel() would interleave the outputs into one signal.
        data.require_single_output(f"validate (`{name}`)")
    u = np.asarray(data.u, dtype=float).ravel()
    y = np.asarray(data.y, dtype=float).ravel()
    if u.size != y.size:
        raise ValueError(
            f"`{name}` must have input and output of the same length; "
            f"got {u.size} and {y.size}"
        )
    return u, y, float(data.ts)


def validate(
    model,
    data,
    *,
    lags: int = 25,
    n_peaks: int = 3,
    levels=(0.95, 0.99),
    residuals: str = "auto",
    nperseg: int | None = None,
    max_damping: float = 0.3,
    gain="auto",
    warmup=None,
    label: str | None = None,
) -> Validation:
    """Validate an identified model on a record (the paper's validation phase).

    Parameters
    ----------
    model : IdentifiedModel or NARXModel
        From :func:`~spiralid.sysid.identify`. A NARX model gets a
        :class:`~spiralid.sysid.validation.nonlinear.NARXValidation` (fits
        and the Billings-Voon tests); an ARX model (anything with ``theta``,
        ``arx``, ``ts``, ``predictor``, ``gain``, ``simulate(u)``,
        ``predict(data)``, ``poles``, ``zeros``). For a NARX model
        `n_peaks`, `nperseg` and `max_damping` (spectra and modes) do not
        apply: one of them other than its default is refused in one line.
    data : IOData
        The validation record, usually the last third (the paper's split).
        The model is run from zero initial conditions over it.
    lags : int, default 25
        Correlation lags: autocorrelation at ``1..lags``, cross-correlation at
        ``-lags..lags``; ``1 <= lags < N``.
    n_peaks : int, default 3
        Resonance peaks to find in each spectrum (three modes in 0-100 Hz for
        the paper's arm).
    levels : sequence of float, default (0.95, 0.99)
        Confidence levels of the correlation bands and verdicts.
    residuals : {"auto", "one-step", "simulation"}, default "auto"
        Which error the correlation tests examine. ``"auto"`` takes the error
        the model was fitted to: the one-step prediction error for least
        squares and one-step searches (the ARX model's estimate of its
        innovations, which MATLAB's ``resid`` tests, and which it promises
        white and independent of the input), the simulation error for output
        error and the simulation searches. Such an output-error model
        promises only that its simulation error is independent of past
        inputs; it does not model the noise, so the whiteness test is then
        reported as not applicable (``Validation.output_error``).
    nperseg : int, optional
        Welch segment length; default :func:`~spiralid.sysid.spectra.default_nperseg`.
    max_damping : float, default 0.3
        Model modes with a damping ratio below this are listed.
    gain : "auto", "model" or float, default "auto"
        Gain ``w`` of the paper's cost on this record. ``"auto"`` recomputes
        it on ``data`` (``w = 100 sqrt(K) / rms(y)``), so the cost is
        ``100 rms(e) / rms(y)``, a percentage comparable between records.
        ``"model"`` reuses the model's own ``w`` (fixed on the estimation
        record, so on another record the cost is scaled by
        ``sqrt(K_est / K) rms(y_est) / rms(y)``); a number is used as given.
    warmup : IOData, optional
        The record that immediately precedes ``data`` (typically the
        estimation part). The model is run over it first and only the
        ``data`` part is scored, so the validation starts from the state the
        model has reached rather than from rest. Default: zero initial
        conditions, as the paper applies the input to the model.
    label : str, optional
        Name for tables and legends; default the model's ``method``.

    Returns
    -------
    Validation

    Raises
    ------
    ValueError
        ``lags`` outside ``[1, N - 1]``, unknown ``residuals``, mismatched
        signal lengths, or a sample time of the data that differs from the
        model's.

    Examples
    --------
    A noise-free ARX(2, 2, 1) record: least squares recovers the system, and
    the validation part is reproduced exactly.

    >>> import numpy as np
    >>> from scipy import signal
    >>> from spiralid.sysid import ARX, IOData, identify
    >>> u = np.random.default_rng(0).standard_normal(600)
    >>> y = signal.lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> est, val = IOData(u, y, ts=0.01).split(2 / 3)
    >>> fit = identify(est, ARX(2, 2, 1), method="ls")
    >>> rep = validate(fit, val, warmup=est, max_damping=1.0)
    >>> round(rep.fit_percent, 6), rep.stable, rep.realization.minimal
    (100.0, True, True)

    The pole pair of ``1 - 1.5 z^-1 + 0.7 z^-2`` is a mode at 7.84 Hz with
    damping 0.36 (listed because ``max_damping`` was raised from 0.3):

    >>> np.round(rep.modes.frequency, 2), np.round(rep.modes.damping, 2)
    (array([7.84]), array([0.36]))

    Notes
    -----
    The cost is eq. (2)-(3), ``w sqrt(sum e^2) / K`` plus the model's penalty
    when a pole has ``|z| >= 1``, with ``e`` the error of the model's own
    predictor (``model.predictor``) computed exactly as for the fit and error
    range (zero initial conditions, or after ``warmup``). It therefore equals
    ``100 rms(e) / rms(y)`` with ``gain="auto"``. For a simulation-predictor
    model estimated with ``initial="rest"`` (the default) and no ``warmup``
    this is exactly :class:`~spiralid.sysid.PaperCost` with
    ``initial="rest"`` on ``data``, the criterion the model was fitted with.
    The validation run always starts from rest (or after ``warmup``),
    whatever the model's ``initial``: a model estimated with
    ``initial="measured"`` (for records that start in motion) is scored on
    the same free run as its fit and error range, so its cost here can
    differ from ``PaperCost(..., initial="measured")`` on the same record,
    a lot for poles close to the unit circle, whose start-up transient
    hardly decays. Pass ``warmup`` to validate such a model from the state
    it has reached.
    """
    if isinstance(residuals, str) and residuals == "auto":
        residuals = _fitted_error(model)
    if getattr(model, "kind", None) == "narx":
        # Poles, modes and realisations mean nothing for a nonlinear model:
        # its own report (fits and the Billings-Voon tests), and the options
        # of spectra and modes are refused rather than ignored.
        from .nonlinear import validate_narx

        refuse_options(
            dict(n_peaks=n_peaks, nperseg=nperseg, max_damping=max_damping),
            ("lags", "levels", "residuals", "gain", "warmup", "label"),
            "validate for a NARX model",
            defaults=dict(n_peaks=3, nperseg=None, max_damping=0.3),
        )

        return validate_narx(
            model,
            data,
            lags=lags,
            levels=levels,
            residuals=residuals,
            gain=gain,
            warmup=warmup,
            label=label,
        )
    u, y, ts, lags, predictor = _valid_inputs(model, data, lags, residuals)
    n = y.size
    w = _gain(gain, model, y)
    penalty = float(getattr(model, "penalty", 1e6))
    poles = np.asarray(_attr(model, "poles"), dtype=complex)
    zeros = np.asarray(_attr(model, "zeros"), dtype=complex)
    # The one stability verdict (Schur-Cohn on the coefficients, see
    # spiralid.sysid.models.polynomials), not |np.roots| < 1, which misjudges
    # clustered poles near the circle.
    # Without the known integrators' poles (z = 1), which the model has by
    # design (`identify(integrator=...)`).
    denominator = np.asarray(
        getattr(model, "free_denominator", model.theta[: model.arx.na]), dtype=float
    )
    stable = bool(is_stable_polynomial(denominator))
    max_radius = float(max_pole_radius(denominator))
    y_sim, y_pred, start = _responses(model, data, warmup)
    y_sim, diverged = _bounded_run(
        y_sim, y, f" (max |pole| = {format_pole_radius(max_radius)})"
    )
    y, y_pred = check_pair(y, y_pred, "data.y", "model.predict(data)")
    e_sim, e_pred = y - y_sim, y - y_pred

    # Eq. (2)-(3) on the very errors the fit and error range are computed
    # from, so the columns of a Table-2 row agree with one another.
    e_cost = e_sim if predictor == "simulation" else e_pred
    cost = cost_of_errors(e_cost, w, stable, penalty)

    e_test = e_pred if residuals == "one-step" else e_sim
    fs = 1.0 / ts
    spec_y = psd(y, fs, nperseg=nperseg)
    spec_m = psd(y_sim, fs, nperseg=nperseg)
    # An IdentifiedModel's own polynomials: those of its effective order
    # when the estimation removed a pole-zero pair.
    num, den = getattr(model, "polynomials", None) or model.arx.polynomials(model.theta)
    label = label if label is not None else str(getattr(model, "method", "") or "")

    return Validation(
        label=label,
        n_samples=n,
        ts=ts,
        fit_percent=fit_percent(y, y_sim),
        fit_percent_one_step=fit_percent(y, y_pred),
        rmse=rmse(y, y_sim),
        rmse_one_step=rmse(y, y_pred),
        cost=float(cost),
        cost_predictor=predictor,
        error_range=(float(e_sim.min()), float(e_sim.max())),
        error_range_one_step=(float(e_pred.min()), float(e_pred.max())),
        residuals=residuals,
        whiteness=whiteness_test(e_test, lags, levels),
        independence=independence_test(u, e_test, lags, levels),
        psd_measured=spec_y,
        psd_model=spec_m,
        peaks_measured=find_resonances(spec_y, n_peaks),
        peaks_model=find_resonances(spec_m, n_peaks),
        modes=modes_from_poles(poles, ts, max_damping=max_damping),
        stable=bool(stable),
        max_pole_radius=max_radius,
        realization=realization_tests(num, den),
        poles=poles,
        zeros=zeros,
        t=(np.arange(n) + start) * ts,
        u=u,
        y=y,
        y_sim=y_sim,
        y_pred=y_pred,
        integrator=int(getattr(model, "integrator", 0)),
        output_name=str(getattr(data, "output_name", "output")),
        output_unit=str(getattr(data, "output_unit", "")),
        initial="rest" if warmup is None else "warmup",
        fit_percent_measured=_fit_from_measured(model, data),
        diverged=diverged,
        output_error=_fitted_error(model) == "simulation",
        mode_table=_mode_table(model),
        reduction=getattr(model, "reduction", None),
        choice=(getattr(model, "selection", None) or {}).get("note"),
    )


# A free run that leaves this many times the measured output's largest
# value has diverged (its fit would be below -1e6 %, where _format_fit says
# so); it is clipped there, so the error range, spectra and tests stay
# finite.
_RUNAWAY = 1e6


def _bounded_run(y_sim: np.ndarray, y: np.ndarray, why: str = ""):
    """The free run, clipped when it ran away, and whether it did (with one
    warning line: validation never raises on a model it accepted)."""
    import warnings

    if y_sim.size != y.size:
        raise ValueError(
            f"`model.simulate(data.u)` must have {y.size} samples; got {y_sim.size}"
        )
    limit = _RUNAWAY * max(float(np.max(np.abs(y), initial=0.0)), 1e-300)
    with np.errstate(invalid="ignore"):
        if np.all(np.isfinite(y_sim)) and np.max(np.abs(y_sim), initial=0.0) < limit:
            return y_sim, False
    warnings.warn(
        f"the model's free run diverges on this record{why}: its fit is "
        "reported but only says so",
        UserWarning,
        stacklevel=3,
    )
    clipped = np.clip(np.nan_to_num(y_sim, nan=0.0), -limit, limit)
    return clipped, True


def _fit_from_measured(model, data) -> float:
    """The free run's fit from the record's first measured samples (its
    initial state), on the samples after them."""
    arx = getattr(model, "arx", None)
    if arx is None or not hasattr(data, "u"):
        return float("nan")
    residual, _ = error_functions(arx, data, "simulation", "measured")
    with np.errstate(all="ignore"):
        e = residual(np.asarray(model.theta, dtype=float))
        y = np.asarray(data.y, dtype=float)[arx.max_lag :]
        fit = 100.0 * (1.0 - np.linalg.norm(e) / np.linalg.norm(y - y.mean()))
    return float(fit) if np.isfinite(fit) else -np.inf


def _mode_table(model) -> ModeTable | None:
    if getattr(model, "covariance", None) is None:
        return None
    return model.modes


def _fitted_error(model) -> str:
    """The error `model`'s estimate minimised: its method's (least squares:
    the one-step error), else the predictor its cost used."""
    from ..estimation.estimators import METHODS

    method = METHODS.get(str(getattr(model, "method", "")))
    predictor = getattr(model, "predictor", None) or "simulation"
    return (method.minimises if method is not None else None) or predictor


def _valid_inputs(model, data, lags, residuals):
    """`validate`'s argument checks: the signals, ``lags`` and the predictor,
    before any simulation or spectrum is computed."""
    if not all(hasattr(model, k) for k in ("simulate", "predict", "arx", "theta")):
        raise ValueError(
            "`model` must be an IdentifiedModel (from identify() or "
            f"IdentifiedModel.from_dict); got {type(model).__name__}"
        )
    u, y, ts = _signals_of(data)
    # Checked here too (the correlation tests would) so a bad `lags` fails
    # before the simulation and spectra are computed.
    lags = check_lags(lags, y.size)
    arx = model.arx
    if arx.max_lag >= y.size:
        # Before any signal of that length is built (a tampered file's nk
        # could ask for terabytes).
        raise ValueError(
            f"`model` reaches {arx.max_lag} samples into the past ({arx}), more "
            f"than `data`'s N = {y.size} samples hold"
        )
    if residuals not in _RESIDUALS:
        raise ValueError(
            f"`residuals` must be 'auto' or one of {_RESIDUALS}; got {residuals!r}"
        )
    model_ts = getattr(model, "ts", None)
    if model_ts is not None and not np.isclose(float(model_ts), ts, rtol=1e-9):
        raise ValueError(
            f"`data` sample time must match the model's ts = {float(model_ts)!r}; "
            f"got ts = {ts!r}"
        )
    predictor = getattr(model, "predictor", None) or "simulation"
    if predictor not in _RESIDUALS:
        raise ValueError(
            f"`model.predictor` must be one of {_RESIDUALS}; got {predictor!r}"
        )
    return u, y, ts, lags, predictor


def _gain(gain, model, y: np.ndarray) -> float:
    """The gain ``w`` of eq. (2) on the validation record (see `validate`)."""
    if isinstance(gain, str) and gain == "auto":
        return auto_gain(y)
    if isinstance(gain, str) and gain == "model":
        w = float(getattr(model, "gain", np.nan))
        if not (np.isfinite(w) and w > 0):
            raise ValueError(
                f"`gain` 'model' needs a model with a finite positive gain; got {w!r}"
            )
        return w
    try:
        return positive(gain, "gain")
    except ValueError:
        raise ValueError(
            f"`gain` must be 'auto', 'model' or a finite number > 0; got {gain!r}"
        ) from None


def _responses(model, data, warmup):
    """The model's free run and one-step prediction over ``data`` (after
    ``warmup`` when given), and the index of ``data``'s first sample in the
    run."""
    u, y, ts = _signals_of(data)
    if warmup is None:
        y_sim = np.asarray(model.simulate(u), dtype=float).ravel()
        y_pred = np.asarray(model.predict(data), dtype=float).ravel()
        start = 0
    else:
        wu, wy, wts = _signals_of(warmup, "warmup")
        if not np.isclose(wts, ts, rtol=1e-9):
            raise ValueError(
                f"`warmup` sample time must match `data`'s ts = {ts!r}; got {wts!r}"
            )
        whole = type(data)(np.r_[wu, u], np.r_[wy, y], ts=ts)
        start = wu.size
        y_sim = np.asarray(model.simulate(whole.u), dtype=float).ravel()[start:]
        y_pred = np.asarray(model.predict(whole), dtype=float).ravel()[start:]
    return y_sim, y_pred, start
