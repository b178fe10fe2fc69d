"""Validation of a NARX model: fit of the free run and the one-step
prediction, and the Billings-Voon correlation tests.

:func:`~spiralid.sysid.validate` hands a
:class:`~spiralid.sysid.models.narx.NARXModel` to :func:`validate_narx`; the
poles, modes and realisation tests of a linear model have no meaning for
it, so its :class:`NARXValidation` carries what does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .correlation import check_lags
from .fit import (
    _bounded_run,
    _format_fit,
    _gain,
    _signals_of,
    check_sample_time,
    fit_percent,
    responses,
    rmse,
)
from .higher_order import BillingsVoon, billings_voon

__all__ = ["NARXValidation", "validate_narx"]

_RESIDUALS = ("one-step", "simulation")


@dataclass(frozen=True)
class NARXValidation:
    """Outcome of validating a NARX model on a record.

    Attributes
    ----------
    label : str
        Name for tables.
    n_samples : int
        Scored samples.
    fit_percent, fit_percent_one_step : float
        Fit of the free run and of the one-step prediction (percent).
    rmse, rmse_one_step : float
        Their RMS errors.
    cost : float
        The paper's eq. (2) on the model's predictor's error.
    error_range : tuple of float
        Free-run error range.
    residuals : str
        Which error the correlation tests examined.
    correlation : BillingsVoon
        The five Billings-Voon tests.
    t, u, y, y_sim, y_pred : ndarray
        Time, signals and responses over the scored part (a diverged free
        run clipped).
    diverged : bool
        The free run grew without bound on this record: its fit is reported
        (far below zero) but means only that.
    linear_fit_percent : float
        Free-run fit of the model's linear start on the same record (nan
        without one): what the network adds is ``fit_percent`` minus it.
    kept_linear : bool
        Training ended at the linear start (the network adds nothing).
    output_label : str
        The output's name and unit for the figures, e.g. ``"hub_angle
        [rad]"``.
    """

    label: str
    n_samples: int
    fit_percent: float
    fit_percent_one_step: float
    rmse: float
    rmse_one_step: float
    cost: float
    error_range: tuple[float, float]
    residuals: str
    correlation: BillingsVoon
    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    y_sim: np.ndarray
    y_pred: np.ndarray
    diverged: bool = False
    linear_fit_percent: float = float("nan")
    kept_linear: bool = False
    output_label: str = "output"

    def network_line(self) -> str:
        """What the network added over its linear start, in one line."""
        if not np.isfinite(self.linear_fit_percent):
            return "  no linear start (no bypass, or a polynomial NARX)"
        lin = f"{self.linear_fit_percent:.1f} %"
        if self.kept_linear or np.isclose(
            self.fit_percent, self.linear_fit_percent, atol=0.005, rtol=0.0
        ):
            return (
                f"  the network added nothing: the model is its linear start "
                f"(fit {lin})"
            )
        gain = self.fit_percent - self.linear_fit_percent
        return (
            f"  network over its linear start: {gain:+.1f} points of fit "
            f"(linear start {lin})"
        )

    def summary(self) -> str:
        """Human-readable report."""
        free = _format_fit(self.fit_percent, unit=" %")
        one_step = _format_fit(self.fit_percent_one_step, "one-step prediction", " %")
        lines = [
            f"NARX validation ({self.label}), N = {self.n_samples}",
            f"  fit (free run)   {free:>10}",
            f"  fit (one step)   {one_step:>10}",
            self.network_line(),
            f"  cost (eq. 2)     {self.cost:8.4g}",
            "  error range      "
            f"[{self.error_range[0]:.4g}, {self.error_range[1]:.4g}]",
            f"  residuals tested: {self.residuals}",
            self.correlation.summary(),
        ]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.summary()

    def to_dict(self, *, signals: bool = False) -> dict:
        """JSON-safe dictionary (signals only when asked)."""
        out = {
            "model": "narx",
            "label": self.label,
            "n_samples": int(self.n_samples),
            "fit_percent": float(self.fit_percent),
            "fit_percent_one_step": float(self.fit_percent_one_step),
            "rmse": float(self.rmse),
            "rmse_one_step": float(self.rmse_one_step),
            "cost": float(self.cost),
            "error_range": [float(v) for v in self.error_range],
            "residuals": self.residuals,
            "billings_voon": self.correlation.to_dict(),
            "diverged": bool(self.diverged),
            "linear_fit_percent": float(self.linear_fit_percent),
            "kept_linear": bool(self.kept_linear),
        }
        if signals:
            for k in ("t", "u", "y", "y_sim", "y_pred"):
                out[k] = [float(v) for v in getattr(self, k)]
        return out

    def plot(self) -> dict:
        """``{"response": Figure, "billings_voon": Figure}``."""
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(8, 3.5))
        ax.plot(self.t, self.y, label="measured", lw=1)
        ax.plot(self.t, self.y_sim, label=f"free run ({self.fit_percent:.1f} %)", lw=1)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(self.output_label)
        ax.set_title(
            f"NARX free run against the record ({self.label}, N = {self.n_samples})",
            fontsize=10,
        )
        ax.legend(fontsize=8)
        fig.tight_layout()
        return {"response": fig, "billings_voon": self.correlation.plot()}


def validate_narx(
    model,
    data,
    *,
    lags: int = 25,
    levels=(0.95, 0.99),
    residuals: str = "auto",
    gain="auto",
    warmup=None,
    label: str | None = None,
) -> NARXValidation:
    """Validate a NARX model (see :func:`~spiralid.sysid.validate`, which
    calls this for a :class:`~spiralid.sysid.models.narx.NARXModel`; the
    parameters mean the same).

    Parameters
    ----------
    model : NARXModel
    data : IOData
    lags : int
    levels : sequence of float
    residuals : {"auto", "one-step", "simulation"}
    gain : "auto", "model" or float
    warmup : IOData, optional
    label : str, optional

    Returns
    -------
    NARXValidation
    """
    u, y, ts = _signals_of(data)
    lags = check_lags(lags, y.size)
    if residuals == "auto":
        residuals = model.predictor
    if residuals not in _RESIDUALS:
        raise ValueError(
            f"`residuals` must be 'auto' or one of {_RESIDUALS}; got {residuals!r}"
        )
    check_sample_time(model, ts)
    with np.errstate(all="ignore"):  # a diverging free run is reported below
        y_sim, y_pred, start = responses(model, data, warmup)
    whole = u if warmup is None else np.r_[_signals_of(warmup, "warmup")[0], u]
    y_sim, diverged = _bounded_run(y_sim, y)
    w = _gain(gain, model, y)
    e_sim, e_pred = y - y_sim, y - y_pred
    linear_fit = math.nan
    lin_model = getattr(model, "linear_start", None)
    if lin_model is not None:
        with np.errstate(all="ignore"):
            y_lin = np.asarray(lin_model.simulate(whole), dtype=float)[start:]
        linear_fit = fit_percent(y, _bounded_run(y_lin, y)[0])
    result = getattr(model, "result", None) or {}
    unit = getattr(model, "output_unit", "")
    name = getattr(model, "output_name", "y")
    e_cost = e_sim if model.predictor == "simulation" else e_pred
    e_test = e_pred if residuals == "one-step" else e_sim
    return NARXValidation(
        label=label if label is not None else str(model.method),
        n_samples=y.size,
        fit_percent=fit_percent(y, y_sim),
        fit_percent_one_step=fit_percent(y, y_pred),
        rmse=rmse(y, y_sim),
        rmse_one_step=rmse(y, y_pred),
        cost=float(w * np.sqrt(np.sum(e_cost**2)) / y.size),
        error_range=(float(e_sim.min()), float(e_sim.max())),
        residuals=residuals,
        correlation=billings_voon(u, e_test, lags, levels),
        t=(np.arange(y.size) + start) * ts,
        u=u,
        y=y,
        y_sim=y_sim,
        y_pred=y_pred,
        diverged=diverged,
        linear_fit_percent=linear_fit,
        kept_linear=bool(result.get("kept_linear", False)),
        output_label=f"{name} [{unit}]" if unit else name,
    )
