"""What :func:`~spiralid.sysid.validate` adds for a linear (ARX) model: its
poles and zeros, the stability verdict and pole radius, the modes read from
the poles and the realisation tests (the paper's MATLAB ``ctrb``/``obsv``
check after eq. (10)). A nonlinear model has none of these: its
:class:`~spiralid.sysid.validation.result.Validation` leaves them empty
(:func:`absent`)."""

from __future__ import annotations

import numpy as np

from ..models.modes import ModeTable
from ..models.polynomials import (
    format_pole_radius,
    is_stable_polynomial,
    max_pole_radius,
)
from ..spectra import Modes, modes_from_poles
from .realization import realization_tests

__all__ = ["absent", "linear_checks", "runaway_note"]


def _attr(obj, name):
    val = getattr(obj, name)
    return val() if callable(val) else val


def linear_checks(model, ts: float, max_damping: float) -> dict:
    """The linear fields of a :class:`~.result.Validation`, by name.

    Parameters
    ----------
    model : FittedModelProtocol
        A linear model (``poles``, ``zeros``, ``polynomials``,
        ``free_denominator``: the protocol's linear members).
    ts : float
        Sample time (s), for the modes.
    max_damping : float
        Modes with a damping ratio below this are listed.

    Returns
    -------
    dict
        ``modes, stable, max_pole_radius, realization, poles, zeros,
        integrator, mode_table, reduction``.
    """
    poles = np.asarray(_attr(model, "poles"), dtype=complex)
    zeros = np.asarray(_attr(model, "zeros"), dtype=complex)
    # The one stability verdict (Schur-Cohn on the coefficients, see
    # spiralid.sysid.models.polynomials), not |np.roots| < 1, which misjudges
    # clustered poles near the circle.
    # Without the known integrators' poles (z = 1), which the model has by
    # design (`identify(integrator=...)`).
    denominator = np.asarray(model.free_denominator, dtype=float)
    # The model's own polynomials: an ARX fit's are those of its effective
    # order when the estimation removed a pole-zero pair.
    num, den = model.polynomials
    return dict(
        modes=modes_from_poles(poles, ts, max_damping=max_damping),
        stable=bool(is_stable_polynomial(denominator)),
        max_pole_radius=float(max_pole_radius(denominator)),
        realization=realization_tests(num, den),
        poles=poles,
        zeros=zeros,
        integrator=int(getattr(model, "integrator", 0)),
        mode_table=_mode_table(model),
        reduction=getattr(model, "reduction", None),
    )


def absent() -> dict:
    """The linear fields of a nonlinear model's validation: None, or empty
    where a collection is expected (no poles, no modes)."""
    empty = np.zeros(0, dtype=complex)
    return dict(
        modes=Modes(empty, np.zeros(0), np.zeros(0), np.zeros(0)),
        stable=None,
        max_pole_radius=None,
        realization=None,
        poles=empty,
        zeros=empty.copy(),
        integrator=0,
        mode_table=None,
        reduction=None,
    )


def runaway_note(checks: dict) -> str:
    """What the warning of a diverging free run adds: the largest pole
    radius of a linear model, nothing for a nonlinear one."""
    radius = checks["max_pole_radius"]
    if radius is None:
        return ""
    return f" (max |pole| = {format_pole_radius(radius)})"


def _mode_table(model) -> ModeTable | None:
    if getattr(model, "covariance", None) is None:
        return None
    return model.modes
