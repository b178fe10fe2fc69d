"""Monic polynomials and reflection coefficients (Levinson step-up / step-down).

A denominator ``A(z) = 1 + a_1 z^-1 + ... + a_n z^-n`` has all its roots
strictly inside the unit circle exactly when its reflection (Schur)
coefficients ``k_1..k_n`` all satisfy ``|k_j| < 1``. The step-up recursion
maps any ``k`` in ``(-1, 1)^n`` to a stable polynomial (and reaches every
stable one); the step-down recursion maps back, and doubles as the
Schur-Cohn (Jury) stability test: ``O(n^2)`` per polynomial, vectorised
over a population, and much cheaper than ``numpy.roots``.

This is how the initial points are put "in the feasible region" (DESIGN.md
item 12) and how ``parametrization="reflection"`` keeps every candidate
stable (item 13).

Convention: with ``a^{(j)}`` the coefficients of the degree-``j`` polynomial,

    a^{(j)}_i = a^{(j-1)}_i + k_j a^{(j-1)}_{j-i},  i = 1..j-1,   a^{(j)}_j = k_j.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = [
    "fold_reflection",
    "is_stable_polynomial",
    "random_stable_polynomial",
    "step_down",
    "step_up",
]


def _as_batch(a, name: str) -> tuple[np.ndarray, bool]:
    arr = np.asarray(a, dtype=float)
    if arr.ndim not in (1, 2):
        raise ValueError(
            f"`{name}` must be a 1-D array (n,) or a 2-D population (m, n); "
            f"got shape {arr.shape}"
        )
    single = arr.ndim == 1
    return np.atleast_2d(arr), single


def step_up(k) -> np.ndarray:
    """Map reflection coefficients to monic polynomial coefficients.

    Parameters
    ----------
    k : array_like, shape (n,) or (m, n)
        Reflection coefficients ``k_1..k_n``; ``|k_j| < 1`` for all ``j``
        gives a polynomial with every root strictly inside the unit circle.

    Returns
    -------
    a : ndarray, same shape as `k`
        ``a_1..a_n`` of ``A(z) = 1 + a_1 z^-1 + ... + a_n z^-n``.

    Examples
    --------
    >>> import numpy as np
    >>> a = step_up([0.5, -0.25])
    >>> a
    array([ 0.375, -0.25 ])
    >>> bool(np.all(np.abs(np.roots(np.r_[1.0, a])) < 1))
    True
    """
    kk, single = _as_batch(k, "k")
    m, n = kk.shape
    a = np.zeros((m, n))
    for j in range(n):
        kj = kk[:, j]
        # a^{(j+1)}_i = a^{(j)}_i + k_{j+1} a^{(j)}_{j+1-i}, 0-based below.
        prev = a[:, :j].copy()
        a[:, :j] = prev + kj[:, None] * prev[:, ::-1]
        a[:, j] = kj
    return a[0] if single else a


def step_down(a) -> np.ndarray:
    """Map monic polynomial coefficients to reflection coefficients.

    The inverse of :func:`step_up` for polynomials whose reflection
    coefficients all have ``|k_j| < 1`` (stable polynomials). For an unstable
    polynomial the recursion meets some ``|k_j| >= 1``; that ``k_j`` is
    returned as is and the lower-order coefficients are set to ``nan`` (they
    are undefined).

    Parameters
    ----------
    a : array_like, shape (n,) or (m, n)
        ``a_1..a_n`` of ``A(z) = 1 + a_1 z^-1 + ... + a_n z^-n``.

    Returns
    -------
    k : ndarray, same shape as `a`

    Examples
    --------
    >>> step_down([0.375, -0.25])
    array([ 0.5 , -0.25])
    """
    aa, single = _as_batch(a, "a")
    k = _step_down_kernel(np.ascontiguousarray(aa))
    return k[0] if single else k


@numba.njit(cache=True)
def _step_down_kernel(a):  # pragma: no cover - compiled
    m, n = a.shape
    k = np.full((m, n), np.nan)
    work = np.empty(n)
    tmp = np.empty(n)
    for r in range(m):
        for i in range(n):
            work[i] = a[r, i]
        for j in range(n - 1, -1, -1):
            kj = work[j]
            k[r, j] = kj
            den = 1.0 - kj * kj
            if not (abs(kj) < 1.0):
                break
            for i in range(j):
                tmp[i] = (work[i] - kj * work[j - 1 - i]) / den
            for i in range(j):
                work[i] = tmp[i]
    return k


@numba.njit(cache=True)
def _schur_stable_kernel(a, out):  # pragma: no cover - compiled
    m, n = a.shape
    work = np.empty(n)
    for r in range(m):
        ok = True
        for i in range(n):
            work[i] = a[r, i]
            if not np.isfinite(work[i]):
                ok = False
        if ok:
            for j in range(n - 1, -1, -1):
                kj = work[j]
                if not (abs(kj) < 1.0):
                    ok = False
                    break
                inv = 1.0 / (1.0 - kj * kj)
                # Update the pair (i, j-1-i) together: no scratch copy.
                for i in range((j + 1) // 2):
                    lo = work[i]
                    hi = work[j - 1 - i]
                    work[i] = (lo - kj * hi) * inv
                    work[j - 1 - i] = (hi - kj * lo) * inv
        out[r] = ok


def is_stable_polynomial(a) -> np.ndarray | bool:
    """Schur-Cohn (Jury) test: are all roots strictly inside the unit circle?

    Parameters
    ----------
    a : array_like, shape (n,) or (m, n)
        ``a_1..a_n`` of ``A(z) = 1 + a_1 z^-1 + ... + a_n z^-n``.

    Returns
    -------
    bool or ndarray of bool, shape (m,)
        ``True`` where every root of ``z^n A(z)`` has ``|z| < 1``. A root on
        the unit circle counts as unstable, as in eq. (2)-(3). Non-finite
        coefficients count as unstable.

    Examples
    --------
    >>> bool(is_stable_polynomial([-1.5, 0.7]))   # roots 0.75 +- 0.37j
    True
    >>> bool(is_stable_polynomial([-2.0, 1.0]))   # double root at z = 1
    False
    """
    aa, single = _as_batch(a, "a")
    out = np.empty(aa.shape[0], dtype=np.bool_)
    if aa.shape[1] == 0:
        out[:] = True
    else:
        _schur_stable_kernel(np.ascontiguousarray(aa), out)
    return bool(out[0]) if single else out


def fold_reflection(x, kmax: float = 1.0 - 1e-6) -> np.ndarray:
    """Fold any real numbers into ``[-kmax, kmax]`` (valid reflection coefficients).

    A triangle wave of period 4 maps the real line onto ``[-1, 1]`` and is
    the identity there, so a search that steps outside ``(-1, 1)`` is
    reflected back continuously rather than piling up on the boundary; the
    result is then clipped to ``kmax < 1`` so the polynomial is strictly
    stable. Never returns ``nan`` for finite input; non-finite input maps to 0.

    Examples
    --------
    >>> fold_reflection([0.3, 1.2, -2.5, 3.5])
    array([ 0.3,  0.8,  0.5, -0.5])
    """
    xx = np.asarray(x, dtype=float)
    xx = np.where(np.isfinite(xx), xx, 0.0)
    folded = 1.0 - np.abs(np.mod(xx + 1.0, 4.0) - 2.0)
    # Identity inside [-1, 1] exactly, avoiding rounding from the mod.
    folded = np.where(np.abs(xx) <= 1.0, xx, folded)
    return np.clip(folded, -kmax, kmax)


def random_stable_polynomial(n: int, size: int | None = None, rng=None) -> np.ndarray:
    """Draw stable monic polynomials: reflection coefficients uniform in (-1, 1).

    Parameters
    ----------
    n : int
        Degree.
    size : int or None
        Number of polynomials; ``None`` returns one of shape (n,).
    rng : int, numpy.random.Generator or None
        Source of randomness.

    Returns
    -------
    ndarray, shape (n,) or (size, n)
        Coefficients ``a_1..a_n``, each polynomial stable (DESIGN.md item 12).

    Examples
    --------
    >>> a = random_stable_polynomial(8, size=1000, rng=0)
    >>> bool(is_stable_polynomial(a).all())
    True
    """
    if not isinstance(n, (int, np.integer)) or n < 0:
        raise ValueError(f"`n` must be a non-negative integer; got {n!r}")
    rng = np.random.default_rng(rng)
    m = 1 if size is None else int(size)
    k = rng.uniform(-1.0, 1.0, size=(m, int(n)))
    a = step_up(k)
    return a[0] if size is None else a
