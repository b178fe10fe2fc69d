"""Monic polynomials and reflection coefficients (Levinson step-up / step-down).

A denominator ``A(z) = 1 + a_1 z^-1 + ... + a_n z^-n`` has all its roots
strictly inside the unit circle exactly when its reflection (Schur)
coefficients ``k_1..k_n`` all satisfy ``|k_j| < 1``. The step-up recursion
maps any ``k`` in ``(-1, 1)^n`` to a stable polynomial (and reaches every
stable one); the step-down recursion maps back, and doubles as the
Schur-Cohn (Jury) stability test: ``O(n^2)`` per polynomial, vectorised
over a population, and much cheaper than ``numpy.roots``.

This is how the initial points are put "in the feasible region" (the
paper's wording) and how ``parametrization="reflection"`` keeps every
candidate stable.

The stability verdict
---------------------
One test decides whether a model is stable everywhere in spiralid (the
cost's penalty, ``ARX.is_stable``, ``IdentifiedModel.is_stable``,
``validate``, ``results.json``, the report and the command line):
:func:`is_stable_polynomial`, the Schur-Cohn recursion on the denominator's
coefficients. Its margin is zero: a model is stable when every pole has
``|z| < 1`` strictly, as eq. (2)-(3) put the penalty on ``|z| >= 1``. It
never looks at roots from ``numpy.roots``: for clustered poles near the
circle those are wrong by far more than the distance to the circle (an
eightfold pole moves by ~eps^(1/8) ~ 0.01), so two tests, one of them on
roots, could call a model with a pole at ``|z| = 1 - 4e-7`` stable and
unstable. A positive margin would call unstable the models the
reflection parametrisation and output error build stable by construction
(``|k_j| <= 1 - 1e-6`` allows poles within ~1e-12 of the circle).
:func:`max_pole_radius` reports the largest ``|z|`` from the same test (by
bisection on the radius), so the radius printed beside a verdict is below 1
exactly when the verdict says stable; :func:`format_pole_radius` prints it
with the digits that show why.

Convention: with ``a^{(j)}`` the coefficients of the degree-``j`` polynomial,

    a^{(j)}_i = a^{(j-1)}_i + k_j a^{(j-1)}_{j-i},  i = 1..j-1,   a^{(j)}_j = k_j.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = [
    "deflate_integrator",
    "fold_reflection",
    "format_pole_radius",
    "integrator_count",
    "is_stable_polynomial",
    "max_pole_radius",
    "random_stable_polynomial",
    "step_down",
    "step_up",
    "with_integrator",
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


_BELOW_ONE, _ABOVE_ONE = np.nextafter(1.0, 0.0), np.nextafter(1.0, 2.0)


def max_pole_radius(a) -> np.ndarray | float:
    """The largest pole radius ``max |z|`` of ``A``, agreeing with the verdict.

    The largest ``|root|`` of the companion matrix (``numpy.roots``), unless
    root finding puts it on the other side of the unit circle than
    :func:`is_stable_polynomial` does (clustered poles near the circle, see
    the module docstring). Then it is found by bisection on ``rho`` with the
    Schur-Cohn test of the scaled polynomial ``A(rho z)`` (coefficients
    ``a_i / rho^i``, poles ``z / rho``), whose answer at ``rho = 1`` is the
    verdict itself. Either way the radius is ``< 1`` exactly when the
    verdict says stable.

    Parameters
    ----------
    a : array_like, shape (n,) or (m, n)
        ``a_1..a_n`` of ``A(z) = 1 + a_1 z^-1 + ... + a_n z^-n``.

    Returns
    -------
    float or ndarray, shape (m,)
        ``0`` for ``n = 0``; ``inf`` for non-finite coefficients.

    Examples
    --------
    >>> round(float(max_pole_radius([-1.5, 0.7])) ** 2, 12)   # |0.75 +- 0.37j|^2
    0.7
    >>> k = [1 - 1e-6, 1 - 1e-6]              # stable by construction
    >>> r = max_pole_radius(step_up(k))
    >>> bool(is_stable_polynomial(step_up(k))), bool(r < 1), f"{1 - r:.2g}"
    (True, True, '5e-07')
    """
    aa, single = _as_batch(a, "a")
    m, n = aa.shape
    out = np.zeros(m)
    if n:
        stable = np.atleast_1d(is_stable_polynomial(aa))
        powers = np.arange(1, n + 1)
        for r, row in enumerate(aa):
            if not np.all(np.isfinite(row)):
                out[r] = np.inf
                continue
            out[r] = np.max(np.abs(np.roots(np.r_[1.0, row])))
            if (out[r] < 1.0) == stable[r]:
                continue
            # Invariant: poles not all inside |z| < lo, all inside |z| < hi
            # (Cauchy's bound: every root has |z| <= 1 + max |a_i|).
            lo, hi = (0.0, 1.0) if stable[r] else (1.0, 1.0 + np.max(np.abs(row)))
            for _ in range(64):
                mid = 0.5 * (lo + hi)
                if mid in (lo, hi):
                    break
                inside = is_stable_polynomial(row / mid**powers)
                lo, hi = (lo, mid) if inside else (mid, hi)
            # Rounding can keep the scaled test from flipping monotonically;
            # the radius still stays on the verdict's side of the circle.
            out[r] = min(hi, _BELOW_ONE) if stable[r] else max(lo, _ABOVE_ONE)
    return float(out[0]) if single else out


def format_pole_radius(radius: float) -> str:
    """``max |pole|`` with the digits that show the verdict.

    Radii within 1e-4 of the unit circle are printed as their distance from
    it, so ``1 - 4e-07`` (stable) and ``1 + 3e-08`` (unstable) do not both
    read ``1.0000000``.

    Parameters
    ----------
    radius : float
        The largest pole radius.

    Returns
    -------
    str

    Examples
    --------
    >>> format_pole_radius(0.98765), format_pole_radius(1 - 4e-7)
    ('0.98765', '1 - 4e-07')
    >>> format_pole_radius(1.0), format_pole_radius(1 + 3e-8)
    ('1', '1 + 3e-08')
    """
    r = float(radius)
    gap = r - 1.0
    if not np.isfinite(r) or abs(gap) >= 1e-4:
        return f"{r:.5f}"
    if gap == 0.0:
        return "1"
    return f"1 {'+' if gap > 0 else '-'} {abs(gap):.2g}"


def fold_reflection(x, kmax: float = 1.0 - 1e-6) -> np.ndarray:
    """Fold any real numbers into ``[-kmax, kmax]`` (valid reflection coefficients).

    A triangle wave of period 4 maps the real line onto ``[-1, 1]`` and is
    the identity there, so a search that steps outside ``(-1, 1)`` is
    reflected back continuously rather than piling up on the boundary; the
    result is then clipped to ``kmax < 1`` so the polynomial is strictly
    stable. Never returns ``nan`` for finite input; non-finite input maps to 0.

    Parameters
    ----------
    x : array_like
        Any real numbers.
    kmax : float, default 1 - 1e-6
        The largest magnitude returned.

    Returns
    -------
    ndarray
        The folded values, the shape of `x`.

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
        Coefficients ``a_1..a_n``, each polynomial stable.

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


def integrator_count(integrator, na: float) -> int:
    """The number of known integrators that `integrator` asks for, checked
    against a denominator of order `na`: ``False``/``True`` are 0/1, an
    integer ``0 <= k <= na`` is ``k`` (``2`` for a double integrator); a
    one-line ValueError otherwise."""
    if isinstance(integrator, bool | np.bool_):
        count = int(integrator)
    elif isinstance(integrator, int | np.integer):
        count = int(integrator)
    else:
        count = -1
    if count < 0:
        raise ValueError(
            "`integrator` must be True, False or a count of integrators >= 0; "
            f"got {integrator!r}"
        )
    if count > na:
        raise ValueError(
            f"`integrator` = {count} needs a denominator of order na >= {count}; "
            f"got na = {na}"
        )
    return count


def deflate_integrator(a, count: int = 1) -> np.ndarray:
    """``a'`` with ``1 + a_1 z^-1 + .. = (1 + a'_1 z^-1 + ..)(1 - z^-1)^count``:
    the denominator without `count` known integrators (roots at z = 1).

    Examples
    --------
    >>> deflate_integrator(np.convolve([1.0, -0.5], [1.0, -1.0])[1:]).tolist()
    [-0.5]
    >>> deflate_integrator(with_integrator([-0.5], 2), 2).round(12).tolist()
    [-0.5]
    """
    a = np.r_[1.0, np.asarray(a, dtype=float)]
    for _ in range(int(count)):
        # Synthetic division by (1 - z^-1): the running sum of the coefficients.
        a = np.cumsum(a)[:-1]
    return a[1:]


def with_integrator(a, count: int = 1) -> np.ndarray:
    """The coefficients of ``(1 + a_1 z^-1 + ..)(1 - z^-1)^count`` after the 1.

    >>> with_integrator([-0.5]).tolist()
    [-1.5, 0.5]
    >>> with_integrator([], 2).tolist()
    [-2.0, 1.0]
    """
    a = np.r_[1.0, np.asarray(a, dtype=float)]
    for _ in range(int(count)):
        a = np.convolve(a, [1.0, -1.0])
    return a[1:]
