"""A stability margin tied to the data: no pole slower than the record.

``identify(max_time_constant=T)`` keeps every pole of the estimated
denominator inside the circle of radius

    r_max = exp(-ts / T),

the radius of a continuous pole whose time constant is ``T`` seconds
(``exp(s ts)`` with ``s = -1 / T``). A record of ``N`` samples cannot tell a
mode whose time constant is longer than the record itself from a drift, an
offset or a slow disturbance: on real records an unconstrained search puts
such a pole at ``|z| = 0.9997-0.999999``, nearly cancelled by a zero, and
fits the drift with it, not the plant; that model costs less on the
estimation record and validates far below output error.

Default (``max_time_constant="auto"``): ``T = N ts``, the estimation
record's length, for the methods the margin applies to -- the recommended
``"spiral"``, output error ``"oe"`` and the Levenberg-Marquardt polish of
``refine=True``. ``None`` switches it off (poles anywhere inside the unit
circle). The paper's searches (``"sda"``, ``"ebsda"``,
``"lasda"``..., and the ``"de"`` baseline over the same cost) keep eq. (3)'s
stability penalty exactly as printed and no margin; a value other than
``"auto"`` given to one of them without ``refine=True`` is refused, as it is
for ``"ls"`` (see :func:`~spiralid.sysid.estimation.core.identify.identify`).
Where the default margin holds a pole, the held-back end decides whether
the data need it lifted (:mod:`~spiralid.sysid.estimation.spiral.margin_choice`);
a time constant given explicitly is kept.

A plant that integrates is not approximated by a pole near ``z = 1``: say
so with ``integrator=True`` (or ``integrator=2`` for a double integrator,
such as the rig's hub angle driven by torque), which factors the poles at
``z = 1`` out before estimation; the margin is on the other poles.

Where the margin acts, so that no evaluation is spent outside it:

- the modal parametrisation (:class:`~spiralid.sysid.estimation.linear.modal.
  ModalParametrization` with ``max_radius``): every pole the box maps to is
  scaled by ``r_max`` (the continuous poles shifted left by ``1 / T``), so a
  mode's decay ``zeta wn`` is its coordinates' decay plus ``1 / T >= 1 / T``;
  the spiral search and its variable-projection polish
  (:func:`~spiralid.sysid.estimation.linear.varpro.gauss_newton_polish`) move in
  those coordinates;
- the reflection parametrisation
  (:class:`~spiralid.sysid.estimation.linear.parametrizations.Reflection`
  with ``max_radius``): the step-up
  polynomial's roots ``p`` map to ``r_max p`` (``a_k -> a_k r_max^k``);
- the Levenberg-Marquardt polish of ``"oe"`` and ``refine``
  (:func:`~spiralid.sysid.estimation.linear.outputerror.local_polish` with
  ``max_radius``): a trial step that leaves the disc has its outside poles
  reflected about the circle of radius ``r_max`` (``z -> r_max^2 /
  conj(z)``), as the unit circle reflects them without the margin, and the
  starts are projected likewise.

The functions here work in the scaled polynomial ``A(r_max z)``, whose
coefficients are ``a_k / r_max^k`` and whose poles are ``z / r_max``: a pole
inside radius ``r_max`` is a pole of the scaled polynomial inside the unit
circle, so every unit-circle tool (step-down, reflection coefficients
bounded by :data:`~spiralid.sysid.estimation.linear.parametrizations.KMAX`) applies
unchanged.
"""

from __future__ import annotations

import math

import numpy as np

from ...models.polynomials import step_down, step_up

__all__ = [
    "AUTO",
    "is_auto",
    "max_radius",
    "powers",
    "project_denominator",
    "scaled",
    "unscaled",
    "within",
]

# identify()'s default of `max_time_constant`: the record's length for the
# methods the margin applies to, off for the others.
AUTO = "auto"


def is_auto(max_time_constant) -> bool:
    """Whether `max_time_constant` is the default, :data:`AUTO` (a value
    that is no string, an array say, is not)."""
    return isinstance(max_time_constant, str) and max_time_constant == AUTO


def max_radius(ts: float, max_time_constant) -> float | None:
    """``r_max = exp(-ts / T)``, or None for ``T = None`` (no margin).

    Examples
    --------
    >>> round(max_radius(0.01, 10.0), 9)      # a 1000-sample record at 100 Hz
    0.9990005
    >>> max_radius(0.01, None) is None
    True
    """
    if max_time_constant is None:
        return None
    return math.exp(-float(ts) / float(max_time_constant))


def powers(na: int, radius: float) -> np.ndarray:
    """``r^1..r^na``: ``a_k r^k`` are the coefficients of ``A(z / r)``."""
    return float(radius) ** np.arange(1, na + 1)


def scaled(a, radius: float) -> np.ndarray:
    """The coefficients ``a_k / r^k`` of ``A(r z)``, whose poles are
    ``z / r`` (a row per polynomial for a 2-D `a`)."""
    a = np.asarray(a, dtype=float)
    return a / powers(a.shape[-1], radius)


def unscaled(a, radius: float) -> np.ndarray:
    """The inverse of :func:`scaled`: ``a_k r^k``, poles ``p -> r p``."""
    a = np.asarray(a, dtype=float)
    return a * powers(a.shape[-1], radius)


def within(a, radius: float | None, kmax: float) -> bool:
    """Every reflection coefficient of ``A(r z)`` at most `kmax` in size
    (every pole inside radius ``r``; the unit circle for ``r = None``)."""
    a = np.asarray(a, dtype=float)
    if a.size == 0:
        return True
    if radius is not None:
        a = scaled(a, radius)
    return bool(np.all(np.abs(step_down(a)) <= kmax))


def project_denominator(a, radius: float, kmax: float) -> np.ndarray:
    """``a`` with its poles outside radius ``r`` reflected about that circle.

    A pole ``z`` with ``|z| >= r`` goes to ``r^2 / conj(z)`` (one on the
    circle just inside), so that every reflection coefficient of ``A(r z)``
    is at most `kmax`; poles already inside are kept.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.poly([0.9999, 0.5])[1:]              # a pole near z = 1
    >>> r = 0.999
    >>> p = np.sort(np.roots(np.r_[1.0, project_denominator(a, r, 1 - 1e-6)]))
    >>> np.round(p, 6)                               # 0.999^2 / 0.9999
    array([0.5     , 0.998101])
    """
    a = np.asarray(a, dtype=float)
    if a.size == 0:
        return a.copy()
    w = scaled(a, radius)
    if not np.all(np.abs(np.nan_to_num(step_down(w), nan=2.0)) <= kmax):
        roots = np.roots(np.r_[1.0, w])
        out = np.abs(roots) >= 1.0
        roots[out] = 1.0 / np.conj(roots[out])
        big = np.abs(roots) >= kmax
        roots[big] = roots[big] * kmax / np.abs(roots[big])
        w = np.real(np.poly(roots))[1:]
    k = np.clip(np.nan_to_num(step_down(w), nan=0.0), -kmax, kmax)
    return unscaled(step_up(k), radius)
