"""A subspace estimate of the shared poles (PO-MOESP): a start and a
baseline for the shared-denominator fit of several outputs.

Subspace identification (Verhaegen 1994, "Identification of the
deterministic part of MIMO state space models given in innovations form
from input-output data", Automatica 30(1); Van Overschee and De Moor 1996)
finds a state-space model's ``A`` without any iteration: the future outputs
``Y_f`` are projected onto the past inputs and outputs ``W_p`` orthogonally
to the future inputs ``U_f`` (an LQ factorisation of the stacked block
Hankel matrices ``[U_f; W_p; Y_f]``), the dominant left singular vectors of
that projection span the extended observability matrix ``Gamma``, and
``A`` solves the shift equation ``Gamma_up A = Gamma_down`` in least
squares. Its characteristic polynomial is every output's denominator,
which is what :func:`~spiralid.sysid.estimation.shared.denominator.identify_shared`
needs: one ``A(q)`` for all sensors.

Choices where the method is silent: the horizon (block rows) is ``2 n``
rounded up to at least ``n + 1``, and the poles are reflected into the unit
circle (a subspace estimate of a lightly damped structure can land just
outside).
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import integer

from ...data import IOData

__all__ = ["subspace_denominator"]


def _hankel(x: np.ndarray, rows: int, cols: int) -> np.ndarray:
    """Block Hankel matrix of the (N, m) signal `x`: ``rows`` block rows of
    ``m`` each, ``cols`` columns."""
    m = x.shape[1]
    out = np.empty((rows * m, cols))
    for r in range(rows):
        out[r * m : (r + 1) * m] = x[r : r + cols].T
    return out


def _merged(poles: np.ndarray, n: int, copies: int) -> np.ndarray:
    """The `n` poles that `poles` holds `copies` times each (the state of
    several inputs over one denominator): neighbours by angle averaged in
    groups of `copies`; a ValueError when they do not group so."""
    upper = poles[poles.imag > 1e-9]
    real = np.sort(poles[np.abs(poles.imag) <= 1e-9].real)
    if upper.size % copies or real.size % copies:
        raise ValueError(
            f"the subspace poles do not come {copies} times each; got {poles}"
        )
    upper = upper[np.argsort(np.angle(upper))]
    pairs = upper.reshape(-1, copies).mean(axis=1)
    singles = real.reshape(-1, copies).mean(axis=1)
    out = np.r_[pairs, pairs.conj(), singles]
    if out.size != n:
        raise ValueError(f"`n` = {n} poles do not fit the subspace's {poles}")
    return out


def subspace_denominator(
    data: IOData, n: int, horizon: int | None = None
) -> np.ndarray:
    """The denominator ``a_1..a_n`` shared by every output of `data`, from a
    PO-MOESP subspace estimate of order `n`.

    Parameters
    ----------
    data : IOData
        One or several inputs and one or several outputs.
    n : int
        The model order (number of poles). With ``m`` inputs and ``p``
        outputs the state holds each pole ``min(m, p)`` times (one
        denominator, several independent numerator columns); the copies
        are merged (neighbours by angle averaged).
    horizon : int, optional
        Block rows of the past and future Hankel matrices; default
        ``max(2 n, n + 1)``.

    Returns
    -------
    ndarray, shape (n,)
        ``A(q) = 1 + a_1 q^-1 + ... + a_n q^-n``, every root inside the
        unit circle.

    Examples
    --------
    Two modes seen by two sensors, noise-free: the subspace poles are the
    true ones.

    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> a = np.poly([0.9 * np.exp(0.3j), 0.9 * np.exp(-0.3j),
    ...              0.8 * np.exp(1.1j), 0.8 * np.exp(-1.1j)]).real
    >>> u = np.random.default_rng(0).standard_normal(600)
    >>> y = np.column_stack([lfilter([0, 1.0, 0.5], a, u), lfilter([0, 0.3], a, u)])
    >>> got = subspace_denominator(IOData(u, y, ts=1.0), 4)
    >>> bool(np.allclose(got, a[1:], atol=1e-8))
    True
    """
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData; got {type(data).__name__}")
    n = integer(n, "n", 1)
    u = data.inputs
    y = data.outputs
    p, m = y.shape[1], u.shape[1]
    # Several inputs over one denominator: a state per pole and input (the
    # McMillan degree of B(q) / A(q) with r = min(m, p) independent
    # columns), each pole then seen r times.
    copies = min(m, p)
    states = n * copies
    i = (
        max(2 * states, states + 1)
        if horizon is None
        else integer(horizon, "horizon", states + 1)
    )
    channels = p + m
    cols = data.n - 2 * i + 1
    if cols < 2 * i * channels:
        raise ValueError(
            f"`n` = {n} needs a longer record: {2 * i * channels + 2 * i - 1} "
            f"samples for horizon {i}; got {data.n}"
        )
    uh, yh = _hankel(u, 2 * i, cols), _hankel(y, 2 * i, cols)
    up, uf = uh[: i * m], uh[i * m :]
    yp, yf = yh[: i * p], yh[i * p :]
    stacked = np.vstack([uf, up, yp, yf]) / np.sqrt(cols)
    # LQ of the stacked matrix through QR of its transpose.
    r = np.linalg.qr(stacked.T, mode="r").T
    nu, nw = uf.shape[0], up.shape[0] + yp.shape[0]
    # The future outputs' part along the past, orthogonal to the future inputs.
    l32 = r[nu + nw :, nu : nu + nw]
    left, sing, _ = np.linalg.svd(l32, full_matrices=False)
    gamma = left[:, :states] * np.sqrt(sing[:states])
    a_state = np.linalg.lstsq(gamma[:-p], gamma[p:], rcond=None)[0]
    poles = np.linalg.eigvals(a_state)
    if copies > 1:
        poles = _merged(poles, n, copies)
    outside = np.abs(poles) >= 1.0
    poles[outside] = 1.0 / np.conj(poles[outside])
    return np.poly(poles).real[1:]
