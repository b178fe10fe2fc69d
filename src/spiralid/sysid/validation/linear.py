"""The report :func:`~.validate.validate` returns for a linear model,
:class:`Validation` (a NARX model's is :class:`~.nonlinear.NARXValidation`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..models.modes import ModeTable
from ..models.polynomials import (
    format_pole_radius,
)
from ..spectra import PSD, Modes, Peaks
from .correlation import CorrelationTest
from .fit import _format_fit
from .realization import Realization

__all__ = ["Validation"]

# Closer than this, a pole and a zero (or a pole and the origin) are taken
# as one: relative to the unit circle, far below any resonance's width.
_CANCELLATION = 1e-6


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
