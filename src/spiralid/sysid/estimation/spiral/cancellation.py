"""Pole-zero cancellation after the search: the order the data support.

A pole and a zero that nearly coincide contribute next to nothing to the
transfer function except within a narrow band around them, and a record of
``N`` samples does not resolve such a band: spare poles of an over-sized
structure end up there, fitting drift or noise. After ``"spiral"`` and
``"oe"`` (``identify(cancel=True)``, their default), every pole ``p`` and
zero ``z`` of the estimate closer than

    |p - z| < 2 pi df ts = 2 pi / N,      df = 1 / (N ts),

are candidates for removal. Why that tolerance: ``df`` is the record's
frequency resolution, the spacing of its DFT bins; on the unit circle one
bin is an arc of ``2 pi df ts`` radians, and near the circle a pole's radial
distance ``1 - |p|`` is its resonance's half-width in the same units
(``zeta wn ts``). A pole and a zero closer than that shape the response
within one bin only, which the record cannot tell from its noise.

A candidate (a real pole with a real zero, or a complex pole pair with a
complex zero pair) is removed when dropping it raises the estimation cost
by no more than :data:`CANCEL_COST_SHARE` (1 %) of the cost before any
removal: both polynomials are deflated (the pole's and the zero's factors
divided out), the reduced model ``ARX(na - k, nb - k, nk)`` (``k`` = 1 or
2) is polished by output error (Levenberg-Marquardt with the same
stability margin) from the deflated model, and its cost is judged. Only
from there: fresh starts at the reduced order would find other minima,
which is choosing an order, not removing a pair. Candidates are tried
closest first, again after each removal; the share is of the original
cost, so removals cannot creep past it one by one.

The model keeps the structure it was asked for: the removed coefficients
are zeros at the end of ``a`` and ``b`` (the same transfer function), and
``IdentifiedModel.cancellations`` lists what was removed, so
``IdentifiedModel.effective_order`` and ``Validation.order_advice`` say it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...models.arx import ARX

__all__ = [
    "CANCEL_COST_SHARE",
    "Candidate",
    "deflate",
    "effective",
    "embed_covariance",
    "embed_factor",
    "near_cancellations",
    "pad",
    "reduce_order",
    "resolution",
]

# A removal may raise the estimation cost by at most this share of it.
CANCEL_COST_SHARE = 0.01

# A root with |imag| below this (relative to its size) is real.
_REAL = 1e-8


def resolution(n: int) -> float:
    """``2 pi / N``: one frequency bin of an ``N``-sample record as an arc of
    the unit circle (``2 pi df ts``, ``df = 1 / (N ts)``).

    Examples
    --------
    >>> round(resolution(1000), 6)
    0.006283
    """
    return 2.0 * np.pi / int(n)


@dataclass(frozen=True)
class Candidate:
    """A pole (or conjugate pair) and a zero (or pair) that nearly cancel."""

    pole: complex
    zero: complex
    distance: float

    @property
    def size(self) -> int:
        """1 for a real pair, 2 for a complex pair."""
        return 2 if abs(self.pole.imag) > 0.0 else 1

    def to_dict(self, tolerance: float, cost_increase: float) -> dict:
        """The JSON-safe record ``IdentifiedModel.cancellations`` holds."""
        return {
            "pole": [float(self.pole.real), float(self.pole.imag)],
            "zero": [float(self.zero.real), float(self.zero.imag)],
            "order": self.size,
            "distance": float(self.distance),
            "tolerance": float(tolerance),
            "cost_increase": float(cost_increase),
        }


def _is_real(r: np.ndarray) -> np.ndarray:
    return np.abs(r.imag) <= _REAL * np.maximum(1.0, np.abs(r))


def near_cancellations(theta, arx: ARX, tolerance: float) -> list[Candidate]:
    """Poles and zeros of ``B / A`` closer than `tolerance`, closest first,
    each root used once; real with real, complex pairs with complex pairs
    (one entry per pair, its upper half-plane member).

    Examples
    --------
    >>> import numpy as np
    >>> a = np.poly([0.999, 0.5])[1:]
    >>> b = np.poly([0.9985])                  # b0 + b1 q^-1, one zero
    >>> c = near_cancellations(np.r_[a, b], ARX(2, 2, 0), 0.01)
    >>> [(round(x.pole.real, 4), round(x.zero.real, 4)) for x in c]
    [(0.999, 0.9985)]
    """
    theta = np.asarray(theta, dtype=float)
    a, b = theta[: arx.na], theta[arx.na :]
    if arx.na == 0 or b.size < 2:
        return []
    poles = np.roots(np.r_[1.0, a])
    zeros = np.roots(b)
    out = []
    for want_real in (True, False):
        p = poles[_is_real(poles) == want_real]
        z = zeros[_is_real(zeros) == want_real]
        if not want_real:
            p, z = p[p.imag > 0], z[z.imag > 0]
        else:
            p, z = p.real.astype(complex), z.real.astype(complex)
        if not (p.size and z.size):
            continue
        dist = np.abs(p[:, None] - z[None, :])
        for i, j in zip(*np.nonzero(dist < tolerance), strict=True):
            out.append(Candidate(complex(p[i]), complex(z[j]), float(dist[i, j])))
    out.sort(key=lambda c: c.distance)
    used_p, used_z, kept = set(), set(), []
    for c in out:
        if c.pole in used_p or c.zero in used_z:
            continue
        used_p.add(c.pole)
        used_z.add(c.zero)
        kept.append(c)
    return kept


def _factor(root: complex) -> np.ndarray:
    """``(z - r)``, or ``(z - r)(z - conj r)`` for a complex ``r``."""
    if abs(root.imag) > 0.0:
        return np.array([1.0, -2.0 * root.real, abs(root) ** 2])
    return np.array([1.0, -root.real])


def deflate(theta, arx: ARX, candidate: Candidate) -> tuple[np.ndarray, ARX]:
    """``theta`` with the candidate's pole and zero factors divided out of
    ``A`` and ``B``, and its structure ``ARX(na - k, nb - k, nk)``.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.poly([0.999, 0.5])[1:]
    >>> b = 2.0 * np.poly([0.9985])
    >>> th, arx = deflate(np.r_[a, b], ARX(2, 2, 0), Candidate(0.999, 0.9985, 5e-4))
    >>> arx, np.round(th, 9).tolist()
    (ARX(na=1, nb=1, nk=0), [-0.5, 2.0])
    """
    theta = np.asarray(theta, dtype=float)
    k = candidate.size
    a = np.polydiv(np.r_[1.0, theta[: arx.na]], _factor(candidate.pole))[0]
    b = np.polydiv(theta[arx.na :], _factor(candidate.zero))[0]
    reduced = ARX(arx.na - k, arx.nb - k, arx.nk)
    return np.r_[a[1:] / a[0], b], reduced


def pad(theta_reduced, reduced: ARX, arx: ARX) -> np.ndarray:
    """A reduced model's theta in `arx`'s layout: zeros after its ``a`` and
    its ``b`` (the same transfer function)."""
    th = np.asarray(theta_reduced, dtype=float)
    out = np.zeros(arx.n_params)
    out[: reduced.na] = th[: reduced.na]
    out[arx.na : arx.na + reduced.nb] = th[reduced.na :]
    return out


def effective(theta, arx: ARX, order: tuple[int, int]) -> tuple[np.ndarray, ARX]:
    """The reduced model inside a padded ``theta``: its theta and structure
    ``ARX(order[0], order[1], nk)``."""
    na, nb = order
    th = np.asarray(theta, dtype=float)
    return np.r_[th[:na], th[arx.na : arx.na + nb]], ARX(na, nb, arx.nk)


def embed_covariance(cov, arx: ARX, order: tuple[int, int]) -> np.ndarray:
    """A reduced model's covariance in `arx`'s layout ``[a, b]``: the
    removed coefficients are fixed at zero, with zero variance."""
    na, nb = order
    idx = np.r_[np.arange(na), arx.na + np.arange(nb)]
    out = np.zeros((arx.n_params, arx.n_params))
    out[np.ix_(idx, idx)] = cov
    return out


def embed_factor(root, arx: ARX, order: tuple[int, int]) -> np.ndarray:
    """A reduced model's covariance factor ``R`` (``C = R^T R``) in `arx`'s
    layout: zero columns for the removed coefficients."""
    na, nb = order
    idx = np.r_[np.arange(na), arx.na + np.arange(nb)]
    out = np.zeros((root.shape[0], arx.n_params))
    out[:, idx] = root
    return out


def reduce_order(
    theta,
    arx: ARX,
    n_samples: int,
    cost: Callable[[np.ndarray], float],
    polish: Callable[[np.ndarray, ARX], np.ndarray],
    share: float = CANCEL_COST_SHARE,
) -> tuple[np.ndarray, list[dict]]:
    """Remove the near-cancelling pole-zero pairs the cost allows.

    Parameters
    ----------
    theta : array_like, shape (p,)
        The estimate, in `arx`'s layout.
    arx : ARX
    n_samples : int
        ``N`` of the estimation record (the tolerance :func:`resolution`).
    cost : callable
        The estimation cost of a theta in `arx`'s layout.
    polish : callable
        ``polish(start, reduced) -> theta`` at the reduced structure.
    share : float
        Largest allowed rise of the cost, as a share of ``cost(theta)``.

    Returns
    -------
    theta : ndarray, shape (p,)
        Padded with zeros where coefficients were removed (`theta` itself
        when nothing was).
    removed : list of dict
        One :meth:`Candidate.to_dict` per removal, in order.
    """
    theta = np.asarray(theta, dtype=float)
    tolerance = resolution(n_samples)
    base = float(cost(theta))
    if not np.isfinite(base):
        return theta, []
    current, structure, removed = theta, arx, []
    while True:
        for candidate in near_cancellations(current, structure, tolerance):
            start, reduced = deflate(current, structure, candidate)
            if not np.all(np.isfinite(start)):
                continue
            polished = np.asarray(polish(start, reduced), dtype=float)
            value = float(cost(pad(polished, reduced, arx)))
            if value <= base * (1.0 + share):
                rise = value / base - 1.0 if base > 0 else 0.0
                removed.append(candidate.to_dict(tolerance, rise))
                current, structure = polished, reduced
                break
        else:
            break
    if not removed:
        return theta, []
    return pad(current, structure, arx), removed
