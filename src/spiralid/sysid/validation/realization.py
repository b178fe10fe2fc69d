"""Controllability and observability of a transfer function's state-space
realisation (the paper's MATLAB ``ctrb``/``obsv`` check after eq. (10))."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

__all__ = ["Realization", "realization_tests"]


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
