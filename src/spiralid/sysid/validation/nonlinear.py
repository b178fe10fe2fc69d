"""What :func:`~spiralid.sysid.validate` adds for a nonlinear (NARX) model:
the Billings-Voon higher-order correlation tests and what the network added
over its linear start.

A nonlinear model's validation is the same
:class:`~spiralid.sysid.validation.result.Validation` as a linear one's
(free run, one-step prediction, residual tests, spectra); its
``nonlinear`` field holds a :class:`NonlinearChecks`, and its poles, modes
and realisation tests, which have no meaning for it, are left empty.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .fit import _bounded_run, fit_percent
from .higher_order import BillingsVoon, billings_voon

__all__ = ["NonlinearChecks", "nonlinear_checks"]

# Within this many points of fit the network is taken to have added
# nothing (the fits print with one or two decimals).
_SAME_FIT = 0.005


@dataclass(frozen=True)
class NonlinearChecks:
    """A nonlinear model's own part of its validation.

    Attributes
    ----------
    billings_voon : BillingsVoon
        The five Billings-Voon correlation tests of the residual the
        validation examined (its ``residuals``); a test with no degrees of
        freedom is reported as not applicable, never as passed.
    linear_fit_percent : float
        Free-run fit of the model's linear start on the same record (NaN
        without one: no bypass, or a polynomial NARX); what the network
        adds is the validation's ``fit_percent`` minus it.
    kept_linear : bool
        Training ended at the linear start (the network adds nothing).
    linear_model : str
        What the linear start is, e.g. ``"ARX(2, 2, 1) by ls"`` (empty when
        unknown).
    """

    billings_voon: BillingsVoon
    linear_fit_percent: float = math.nan
    kept_linear: bool = False
    linear_model: str = ""

    def network_gain(self, fit_percent: float) -> float:
        """Points of free-run fit the network adds over its linear start
        (0 when training kept the start; NaN without one).

        Parameters
        ----------
        fit_percent : float
            The model's own free-run fit on the record.
        """
        if not np.isfinite(self.linear_fit_percent):
            return math.nan
        if self.kept_linear:
            return 0.0
        return float(fit_percent - self.linear_fit_percent)

    def network_line(self, fit_percent: float) -> str:
        """What the network added over its linear start, in one line.

        Parameters
        ----------
        fit_percent : float
            The model's own free-run fit on the record.
        """
        gain = self.network_gain(fit_percent)
        if not np.isfinite(gain):
            return "no linear start (no bypass, or a polynomial NARX)"
        lin = f"{self.linear_fit_percent:.1f} %"
        if abs(gain) <= _SAME_FIT:
            return (
                f"the network added nothing: the model is its linear start (fit {lin})"
            )
        return f"{gain:+.1f} points of fit (linear start {lin})"

    def verdicts(self) -> str:
        """The five tests in one line, e.g. ``"4 of 5 pass at 95 %: ee+
        ue+ e(eu)- u2e+ u2e2+"`` (a test that does not apply: ``u2e
        n/a``)."""
        bv = self.billings_voon
        return (
            f"{bv.n_passed} of {len(bv.passed)} applicable pass at "
            f"{100 * bv.level:g} %: {bv.verdicts()}"
        )

    def to_dict(self, fit_percent: float) -> dict:
        """JSON-safe dictionary.

        Parameters
        ----------
        fit_percent : float
            The model's own free-run fit, for the network's gain.
        """
        gain = self.network_gain(fit_percent)
        finite = np.isfinite(self.linear_fit_percent)
        return {
            "billings_voon": self.billings_voon.to_dict(),
            "linear_fit_percent": float(self.linear_fit_percent) if finite else None,
            "network_gain_points": float(gain) if np.isfinite(gain) else None,
            "kept_linear": bool(self.kept_linear),
            "linear_model": self.linear_model,
        }


def nonlinear_checks(model, u, e, y, whole_u, start: int, lags: int, levels):
    """The nonlinear part of a validation.

    Parameters
    ----------
    model : NARXModel
        The model (its ``linear_start``, ``result`` and ``linear_model``
        are read when it has them).
    u : ndarray
        The scored record's input.
    e : ndarray
        The residual the tests examine.
    y : ndarray
        The scored record's output.
    whole_u : ndarray
        The input the free run was driven by (the warm-up's, then ``u``).
    start : int
        Index of the scored record's first sample in ``whole_u``.
    lags : int
        Largest correlation lag (checked by the caller).
    levels : sequence of float
        Confidence levels; the first is the verdicts'.

    Returns
    -------
    NonlinearChecks
    """
    linear_fit = math.nan
    lin_model = getattr(model, "linear_start", None)
    if lin_model is not None:
        with np.errstate(all="ignore"):  # a diverging start is clipped below
            y_lin = np.asarray(lin_model.simulate(whole_u), dtype=float)[start:]
        linear_fit = fit_percent(y, _bounded_run(y_lin, y)[0])
    result = getattr(model, "result", None) or {}
    return NonlinearChecks(
        billings_voon=billings_voon(u, e, lags, levels),
        linear_fit_percent=linear_fit,
        kept_linear=bool(result.get("kept_linear", False)),
        linear_model=str(getattr(model, "linear_model", "") or ""),
    )
