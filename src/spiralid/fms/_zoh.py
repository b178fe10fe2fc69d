"""Exact zero-order-hold discretisation and a vectorised discrete simulation."""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

__all__ = ["discretise_zoh", "simulate_discrete"]


def discretise_zoh(
    A: np.ndarray, B: np.ndarray, ts: float
) -> tuple[np.ndarray, np.ndarray]:
    """``Ad = e^{A ts}``, ``Bd = int_0^ts e^{A s} ds B`` from one exponential.

    The exponential of the augmented matrix ``[[A, B], [0, 0]] ts`` holds both
    (Van Loan), which is exact for any ``A``, singular or defective ones
    included (the rigid mode's double zero eigenvalue).
    """
    n = A.shape[0]
    aug = np.zeros((n + 1, n + 1))
    aug[:n, :n] = A * ts
    aug[:n, n] = B * ts
    e = expm(aug)
    return e[:n, :n], e[:n, n]


def simulate_discrete(
    Ad: np.ndarray,
    Bd: np.ndarray,
    C: np.ndarray,
    D: np.ndarray,
    u: np.ndarray,
    x0: np.ndarray,
    return_state: bool = False,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Run ``x[k+1] = Ad x[k] + Bd u[k]``, ``y[k] = C x[k] + D u[k]``.

    Lifted (block) evaluation: the state is propagated in a Python loop only
    once per block of ``m`` samples; inside a block the outputs are
    ``C Ad^j x_b`` plus a lower-triangular Toeplitz product of the Markov
    parameters with the block's inputs, i.e. matrix products.  Same
    arithmetic as the recursion up to rounding, roughly ``m`` times fewer
    interpreted steps.

    Returns
    -------
    y : ndarray, shape (N, p)
    x : ndarray, shape (N, n) or None
        The state at each sample instant (before ``u[k]`` acts).
    """
    n = Ad.shape[0]
    p = C.shape[0]
    N = u.size
    m = int(min(max(16, round(math.sqrt(N))), 256, N))
    nb = -(-N // m)
    U = np.zeros(nb * m)
    U[:N] = u
    U = U.reshape(nb, m)

    powers = np.empty((m + 1, n, n))
    powers[0] = np.eye(n)
    for j in range(m):
        powers[j + 1] = Ad @ powers[j]
    # pb[j] = Ad^j Bd; markov[j] = C Ad^(j-1) Bd (j >= 1), markov[0] = D.
    pb = powers[:m] @ Bd
    markov = np.empty((m, p))
    markov[0] = D
    markov[1:] = pb[: m - 1] @ C.T
    # Block-start states.
    gamma = pb[::-1].T  # column i: Ad^(m-1-i) Bd
    drive = U @ gamma.T
    xs = np.empty((nb, n))
    x = np.asarray(x0, dtype=float).copy()
    am = powers[m]
    for b in range(nb):
        xs[b] = x
        x = am @ x + drive[b]
    obs = np.swapaxes(powers[:m], 1, 2) @ C.T  # (m, n, p): (C Ad^j)^T
    # Matrix products (BLAS) rather than einsum for the two big contractions.
    y = (xs @ obs.transpose(1, 0, 2).reshape(n, m * p)).reshape(nb, m, p)
    # Toeplitz part: y[b, j] += sum_{i <= j} markov[j - i] u[b, i].
    idx = np.arange(m)
    lag = idx[:, None] - idx[None, :]
    toep = np.where((lag >= 0)[..., None], markov[np.clip(lag, 0, None)], 0.0)
    y += (U @ toep.transpose(1, 0, 2).reshape(m, m * p)).reshape(nb, m, p)
    y = y.reshape(nb * m, p)[:N]
    if not return_state:
        return y, None
    xt = (xs @ powers[:m].transpose(2, 0, 1).reshape(n, m * n)).reshape(nb, m, n)
    # x[b, j] += sum_{i < j} Ad^(j-1-i) Bd u[b, i].
    sb = np.where((lag >= 1)[..., None], pb[np.clip(lag - 1, 0, None)], 0.0)
    xt += (U @ sb.transpose(1, 0, 2).reshape(m, m * n)).reshape(nb, m, n)
    return y, xt.reshape(nb * m, n)[:N]
