"""Exact zero-order-hold discretisation (with an input delay, whole or
fractional) and a vectorised discrete simulation."""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

__all__ = [
    "delay_split",
    "delayed_inputs",
    "delayed_system",
    "discretise_delayed",
    "discretise_zoh",
    "simulate_discrete",
]


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


def delay_split(delay: float, ts: float) -> tuple[int, float]:
    """``delay = (k + f) ts`` with an integer ``k >= -1`` and ``0 <= f < 1``
    (a ValueError for an advance of a whole sample or more: the output
    would need later inputs)."""
    r = delay / ts
    if not math.isfinite(r) or r <= -1.0:
        raise ValueError(
            f"`input_delay` must be finite and above -ts = {-ts}; got {delay}"
        )
    k = math.floor(r)
    return k, r - k


def discretise_delayed(
    A: np.ndarray, B: np.ndarray, ts: float, delay: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The exact sampled model of ``x' = A x + B u(t - delay)``, `u` held
    between samples: ``x[n+1] = Ad x[n] + G0 u[n-k] + G1 u[n-k-1]`` with
    ``delay = (k + f) ts`` (:func:`delay_split`). Within a sample the
    delayed input is ``u[n-k-1]`` for ``f ts``, then ``u[n-k]`` (the
    modified z-transform's split): ``G0 = int_0^{(1-f) ts} e^{A s} ds B``,
    ``G1 = e^{A (1-f) ts} int_0^{f ts} e^{A s} ds B``. Returns
    ``(Ad, G0, G1)``."""
    _, f = delay_split(delay, ts)
    late, g0 = discretise_zoh(A, B, (1.0 - f) * ts)
    first, early = discretise_zoh(A, B, f * ts)
    # e^{A ts} as the product of the two parts' (they commute): two
    # exponentials per run, not three.
    return late @ first, g0, late @ early


def delayed_inputs(u: np.ndarray, delay: float, ts: float) -> np.ndarray:
    """The two input columns of :func:`discretise_delayed`'s recursion,
    ``u[n-k]`` and ``u[n-k-1]`` (zero before the record; ``u[n+1]`` past
    its end, which only the unused state after the last sample sees),
    shape (N, 2)."""
    k, _ = delay_split(delay, ts)
    u = np.asarray(u, dtype=float).ravel()
    n = u.size
    padded = np.zeros(n + abs(k) + 2)
    start = k + 1  # padded[j + start] holds u[j] for k >= -1
    padded[start : start + n] = u
    out = np.empty((n, 2))
    out[:, 0] = padded[1 : n + 1]
    out[:, 1] = padded[0:n]
    return out


def delayed_system(
    ad: np.ndarray,
    g0: np.ndarray,
    g1: np.ndarray,
    c: np.ndarray,
    d: np.ndarray,
    delay: float,
    ts: float,
) -> tuple[np.ndarray, ...]:
    """The proper one-input model ``(Ad, Bd, C, D)`` of the delayed
    recursion (for its transfer function, poles and zeros): the past
    inputs it needs as extra states after the plant's (``m_j = u[n-j]``);
    an advance (``k = -1``) with the state ``x - G0 u[n]`` instead. `c`
    is ``(p, n)``, `d` ``(p,)``."""
    k, f = delay_split(delay, ts)
    n, p = ad.shape[0], c.shape[0]
    if k < 0:
        return ad, (ad @ g0 + g1)[:, None], c, (c @ g0 + d)[:, None]
    memory = k + (1 if f > 0 else 0)
    size = n + memory
    a = np.zeros((size, size))
    b = np.zeros((size, 1))
    cc = np.zeros((p, size))
    dd = np.zeros((p, 1))
    a[:n, :n] = ad
    cc[:, :n] = c
    if memory:
        b[n, 0] = 1.0  # m_1[n+1] = u[n]
        for j in range(1, memory):
            a[n + j, n + j - 1] = 1.0
    # x[n+1] gets G0 u[n-k] and, for a fractional delay, G1 u[n-k-1].
    if k == 0:
        b[:n, 0] += g0
    else:
        a[:n, n + k - 1] += g0
    if f > 0:
        a[:n, n + k] += g1
        cc[:, n + k] += d
    elif k == 0:
        dd[:, 0] = d
    else:
        cc[:, n + k - 1] += d
    return a, b, cc, dd
