"""The one report :func:`~.validate.validate` returns for every fitted
model, :class:`Validation`: the part every structure shares (free run,
one-step prediction, residual tests, spectra), the linear part (poles,
modes, realisation; :mod:`.linear`) for a linear model and the nonlinear
part (:class:`~.nonlinear.NonlinearChecks`) for a nonlinear one."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..models.modes import ModeTable
from ..models.polynomials import format_pole_radius
from ..models.shapes import ModeShapes
from ..models.shared import SharedModes
from ..spectra import PSD, Modes, Peaks
from .correlation import CorrelationTest
from .fit import _format_fit
from .higher_order import correlation_dict
from .nonlinear import NonlinearChecks
from .outputs import joint_dict, joint_summary
from .realization import Realization

__all__ = ["Validation"]

# Closer than this, a pole and a zero (or a pole and the origin) are taken
# as one: relative to the unit circle, far below any resonance's width.
_CANCELLATION = 1e-6

# What the summary says in place of the linear rows for a nonlinear model.
_NO_POLES = (
    "not applicable: a nonlinear model has no poles (no modes, pole radius "
    "or controllability / observability)"
)


@dataclass(frozen=True)
class Validation:
    """Everything :func:`validate` found out about a model on a record.

    One type for every structure and for one output or several (see
    ``outputs``). Time-domain figures come in pairs: the
    free-run simulation (the primary one, the paper's validation) and the
    one-step prediction (``*_one_step``). Errors are ``y - yhat``. The
    fields marked *linear* describe a linear model's poles; for a nonlinear
    model (NARX) they are None (``modes``, ``poles`` and ``zeros`` empty)
    and the summary says they do not apply. ``nonlinear`` holds what only a
    nonlinear model has, and is None for a linear one.

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
        stability penalty when a linear model is unstable.
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
        *Linear.* Lightly damped modes of the model, from its poles (empty
        for a nonlinear model).
    stable : bool or None
        *Linear.* All poles strictly inside the unit circle: spiralid's one
        stability verdict
        (:func:`~spiralid.sysid.models.polynomials.is_stable_polynomial`,
        the same as ``model.is_stable`` and the cost's penalty). None for a
        nonlinear model, whose free run (``diverged``) is the verdict.
    max_pole_radius : float or None
        *Linear.* Largest ``|p|``, on the verdict's side of the unit circle
        (:func:`~spiralid.sysid.models.polynomials.max_pole_radius`).
    realization : Realization or None
        *Linear.* Controllability / observability of the state-space
        realisation.
    poles, zeros : ndarray of complex
        *Linear.* Of the transfer function in ``z`` (empty for a nonlinear
        model).
    t, u, y, y_sim, y_pred : ndarray
        Time axis and signals, for plots; after a ``warmup`` the time axis
        continues from its end.
    output_name, output_unit : str
        The record's output name and unit, for figure labels.
    integrator : int
        *Linear.* The number of known integrators (poles at ``z = 1``) the
        model has by design, so ``stable`` is judged without them.
    initial : {"rest", "warmup"}
        Where the free run started: from rest, or from the state the model
        reached over ``warmup``.
    fit_percent_measured : float
        The free run's fit started instead from the record's first
        ``max_lag`` measured samples (its initial state; scored on the
        samples after them), NaN for a model that cannot start there.
    diverged : bool
        The free run grew without bound on this record: its fit is reported
        (far below zero, or ``-inf``) but means only that.
    output_error : bool
        The model was fitted to its simulation error (output error, the
        spiral searches): the noise is not modelled, so the whiteness test
        does not apply to it and its one-step prediction is not what it
        promises (the summary leaves both out and says why).
    mode_table : ModeTable, SharedModes or None
        *Linear.* The model's modes with 95 % intervals and flags
        (:attr:`~spiralid.sysid.IdentifiedModel.modes`), when the model has
        a covariance; for a model of several outputs, its shared modes with
        each one's share per output.
    reduction : str or None
        *Linear.* What the estimation's pole-zero cancellation removed
        (:attr:`~spiralid.sysid.IdentifiedModel.reduction`), or None.
    choice : str or None
        How the estimation chose among its distinct minima on the held-back
        end of its record (the ``note`` of
        :attr:`~spiralid.sysid.IdentifiedModel.selection`), then whether it
        kept or lifted the default stability margin where that held a pole
        (the ``note`` of :attr:`~spiralid.sysid.IdentifiedModel.margin`),
        or None when it did neither.
    nonlinear : NonlinearChecks or None
        A nonlinear model's own part: the Billings-Voon higher-order
        correlation tests and what the network added over its linear start
        (:class:`~spiralid.sysid.validation.nonlinear.NonlinearChecks`);
        None for a linear model.
    outputs : dict of str to Validation, or None
        For a model of several outputs, each output's validation by name;
        then ``fit_percent`` is their joint fit
        (:func:`~spiralid.sysid.validation.outputs.joint_fit`),
        ``mode_table`` the model's modes (for a shared denominator a
        :class:`~spiralid.sysid.models.shared.SharedModes`, with each
        mode's share per output), and the fields of one output's record
        (signals, tests, spectra) are None: they are in each output's.
        None for a model of one output.
    mode_shapes : ModeShapes or None
        For a model of several outputs with a shared denominator, its modes'
        shapes over the outputs, with intervals and their auto-MAC
        (:attr:`~spiralid.sysid.SharedDenominatorModel.shapes`); None
        otherwise.
    """

    label: str
    n_samples: int | None = None
    ts: float | None = None
    fit_percent: float | None = None
    fit_percent_one_step: float | None = None
    rmse: float | None = None
    rmse_one_step: float | None = None
    cost: float | None = None
    cost_predictor: str | None = None
    error_range: tuple[float, float] | None = None
    error_range_one_step: tuple[float, float] | None = None
    residuals: str | None = None
    whiteness: CorrelationTest | None = None
    independence: CorrelationTest | None = None
    psd_measured: PSD | None = None
    psd_model: PSD | None = None
    peaks_measured: Peaks | None = None
    peaks_model: Peaks | None = None
    modes: Modes | None = None
    stable: bool | None = None
    max_pole_radius: float | None = None
    realization: Realization | None = None
    poles: np.ndarray | None = None
    zeros: np.ndarray | None = None
    t: np.ndarray | None = None
    u: np.ndarray | None = None
    y: np.ndarray | None = None
    y_sim: np.ndarray | None = None
    y_pred: np.ndarray | None = None
    output_name: str = "output"
    output_unit: str = ""
    integrator: int = 0
    initial: str = "rest"
    fit_percent_measured: float = float("nan")
    diverged: bool = False
    output_error: bool = False
    mode_table: ModeTable | SharedModes | None = None
    reduction: str | None = None
    choice: str | None = None
    nonlinear: NonlinearChecks | None = None
    outputs: dict[str, Validation] | None = None
    mode_shapes: ModeShapes | None = None

    @property
    def is_linear(self) -> bool:
        """Whether the model was linear (the poles, modes and realisation
        tests apply) rather than nonlinear (``nonlinear`` holds its part)."""
        return self.nonlinear is None

    @property
    def error(self) -> np.ndarray:
        """Free-run simulation error ``y - y_sim``."""
        return self.y - self.y_sim

    @property
    def order_advice(self) -> str | None:
        """Why the model's order looks higher than the data support, with
        advice, or None: an exact or near pole-zero cancellation
        (``|p - z| < 1e-6``, or a realisation that is not minimal), or poles
        at the origin (the denominator's last coefficients vanish). None
        for a nonlinear model, which has no poles."""
        if self.realization is None:
            return None
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

    def summary(self, modes: bool = True) -> str:
        """A plain-text table of the results (a nonlinear model's
        Billings-Voon tests after it); for several outputs each output's
        fit, the joint fit and (unless `modes` is False) the model's
        modes."""
        if self.outputs is not None:
            return joint_summary(self, modes)

        def hz(x) -> str:
            return ", ".join(f"{v:.2f}" for v in x) or "none"

        unit = f", {self.output_unit}" if self.output_unit else ""
        # The modes' row (or why there are none) first, beside the spectra.
        structural = self._linear_rows() if self.is_linear else self._nonlinear_rows()
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
                else _verdict(self.whiteness),
            ),
            (
                f"independence from the input ({self.residuals} residual)",
                _verdict(self.independence),
            ),
            ("PSD peaks, measured (Hz)", hz(self.peaks_measured.frequency)),
            ("PSD peaks, model (Hz)", hz(self.peaks_model.frequency)),
            *structural[:1],
            ("PSD resolution (Hz)", f"{self.psd_measured.resolution:.3g}"),
            *structural[1:],
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
        if self.nonlinear is not None:
            lines += ["", self.nonlinear.billings_voon.summary()]
        return "\n".join(lines)

    def _linear_rows(self) -> list[tuple[str, str]]:
        """The rows of the poles: modes, stability, realisation."""
        rz = self.realization
        return [
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

    def _nonlinear_rows(self) -> list[tuple[str, str]]:
        """A nonlinear model's rows in place of the poles': why those do not
        apply, its stability by the free run, and its network's gain."""
        nl = self.nonlinear
        run = "diverged" if self.diverged else "stayed bounded"
        return [
            ("modes, poles, realisation", _NO_POLES),
            ("stable", f"judged by the free run: it {run} on this record"),
            ("network over its linear start", nl.network_line(self.fit_percent)),
            (
                f"Billings-Voon tests ({self.residuals} residual)",
                nl.verdicts()
                + (
                    "; ee and e(eu) assume a white residual, which an "
                    "output-error model does not promise"
                    if self.output_error
                    else ""
                ),
            ),
        ]

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
        """JSON-safe dictionary, of the same keys for every structure: the
        linear keys null and ``"nonlinear"`` an object for a nonlinear
        model, ``"nonlinear"`` null for a linear one; ``signals=True`` adds
        the time series. For several outputs: the label, the joint fit,
        each output's dictionary and the model's modes."""
        if self.outputs is not None:
            return joint_dict(self)

        def cplx(z):
            return [[float(v.real), float(v.imag)] for v in np.asarray(z)]

        linear = self.is_linear
        out = {
            "label": self.label,
            "is_linear": linear,
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
            "whiteness": correlation_dict(self.whiteness),
            "independence": correlation_dict(self.independence),
            "psd_resolution_hz": float(self.psd_measured.resolution),
            "psd_nperseg": int(self.psd_measured.nperseg),
            "peaks_measured_hz": [float(v) for v in self.peaks_measured.frequency],
            "peaks_model_hz": [float(v) for v in self.peaks_model.frequency],
            "modes": self.modes.to_dict() if linear else None,
            "stable": None if self.stable is None else bool(self.stable),
            "integrator": int(self.integrator),
            "max_pole_radius": None
            if self.max_pole_radius is None
            else float(self.max_pole_radius),
            "realization": None
            if self.realization is None
            else self.realization.to_dict(),
            "poles": cplx(self.poles) if linear else None,
            "zeros": cplx(self.zeros) if linear else None,
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
            "nonlinear": None
            if self.nonlinear is None
            else self.nonlinear.to_dict(self.fit_percent),
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
            ``"residuals"`` (correlations with bands) and ``"spectrum"``
            (PSDs with peaks, and a linear model's modes); then
            ``"pole_zero"`` (map with unit circle) for a linear model, or
            ``"billings_voon"`` (the five higher-order correlations) for a
            nonlinear one. For several outputs, each output's figures,
            keyed ``"<output>_<figure>"``.
        """
        from . import plots

        if self.outputs is not None:
            return {
                f"{output}_{kind}": fig
                for output, one in self.outputs.items()
                for kind, fig in one.plot().items()
            }
        name = self.label or "model"
        figures = {
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
                modes={name: self.modes} if self.is_linear else None,
            ),
        }
        if self.nonlinear is not None:
            figures["billings_voon"] = self.nonlinear.billings_voon.plot()
        else:
            figures["pole_zero"] = plots.plot_pole_zero(
                {name: (self.poles, self.zeros)}
            )
        return figures


def _verdict(test: CorrelationTest) -> str:
    """A test's verdict at each level, or why it does not apply."""
    if not test.applicable:
        return "not applicable: no degrees of freedom"
    parts = [
        f"{'pass' if test.passed[lv] else 'FAIL'} at {100 * lv:g} %"
        for lv in test.levels
    ]
    return f"{', '.join(parts)} (p = {test.p_value:.3g})"
