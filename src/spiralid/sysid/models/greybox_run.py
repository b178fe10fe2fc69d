"""The grey box's simulation loops: exact zero-order hold for the linear
kind (compiled, element by element: see :func:`expm_small`), fixed-step
fourth-order Runge-Kutta with sub-steps for the nonlinear kind.

The Runge-Kutta loop exists twice with the same arithmetic in the same
order: in Python, calling any ``f`` and ``g``, and compiled by Numba, taking
the model's functions as arguments when both are Numba functions
(``numba.njit``), so that a sub-step costs no interpreter round trip. The
two agree to rounding (``tests/sysid/test_greybox_x0.py`` checks it);
``benchmarks/greybox_speed.py`` times them.

Every loop stops at the first sample whose state leaves the floating-point
range and leaves the rest of the output NaN: the estimation's cost turns
that into its penalty.
"""

from __future__ import annotations

from collections.abc import Callable

import numba
import numpy as np
from numba.core.registry import CPUDispatcher

__all__ = ["expm_small", "is_compiled", "lti_run", "rk4_compiled", "rk4_python", "zoh"]

# What a Python f may raise where a parameter vector makes the physics
# meaningless (math.sqrt of a negative, a division by zero, an overflow):
# a blown-up run, as a NaN is; anything else is a bug and propagates.
_BLOWN_UP = (ArithmeticError, ValueError)


def is_compiled(*functions: Callable) -> bool:
    """True when every one of `functions` is a Numba (``njit``) function."""
    return all(isinstance(fun, CPUDispatcher) for fun in functions)


def rk4_python(
    f: Callable,
    g: Callable,
    p: np.ndarray,
    x0: np.ndarray,
    u: np.ndarray,
    ts,
    n_sub,
    n_out=1,
) -> np.ndarray:
    """The `n_out` outputs, shape (N, n_out), of ``dx/dt = f(t, x, u, p)``,
    ``y = g(x, u, p)`` from `x0` over the held input `u` (shape (N, m)),
    `n_sub` steps per sample of `ts`."""
    h = ts / n_sub
    x = x0.copy()
    y = np.full((u.shape[0], n_out), np.nan)
    try:
        for k in range(u.shape[0]):
            uk = u[k]
            y[k] = np.asarray(g(x, uk, p), dtype=float).ravel()
            t = k * ts
            for _ in range(n_sub):
                k1 = np.asarray(f(t, x, uk, p), dtype=float)
                k2 = np.asarray(f(t + h / 2, x + h / 2 * k1, uk, p), dtype=float)
                k3 = np.asarray(f(t + h / 2, x + h / 2 * k2, uk, p), dtype=float)
                k4 = np.asarray(f(t + h, x + h * k3, uk, p), dtype=float)
                x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
                t += h
            if not np.all(np.isfinite(x)):
                break
    except _BLOWN_UP:
        pass  # the rest stays NaN, as for a NaN state
    return y


@numba.njit(cache=True)
def _flat(value):  # pragma: no cover - compiled
    # g may return a number or an array of the outputs.
    return np.asarray(value, dtype=np.float64).ravel()


# Not cached on disk: a cached copy names the module of the f and g it was
# compiled for, and a later process that cannot import that module (a test
# module, a script's __main__) fails loading it instead of compiling.
@numba.njit(cache=False)
def rk4_compiled(f, g, p, x0, u, ts, n_sub, n_out=1):  # pragma: no cover
    """:func:`rk4_python` compiled, `f` and `g` Numba functions (each pair
    compiles once per process)."""
    h = ts / n_sub
    x = x0.copy()
    y = np.full((u.shape[0], n_out), np.nan)
    for k in range(u.shape[0]):
        uk = u[k]
        y[k, :] = _flat(g(x, uk, p))
        t = k * ts
        for _ in range(n_sub):
            k1 = np.asarray(f(t, x, uk, p), dtype=np.float64)
            k2 = np.asarray(f(t + h / 2, x + h / 2 * k1, uk, p), dtype=np.float64)
            k3 = np.asarray(f(t + h / 2, x + h / 2 * k2, uk, p), dtype=np.float64)
            k4 = np.asarray(f(t + h, x + h * k3, uk, p), dtype=np.float64)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            t += h
        if not np.all(np.isfinite(x)):
            break
    return y


# The linear kind's loops are written out element by element: its matrices
# are a few states wide, where a BLAS call per product costs more than the
# product, and a threaded BLAS on a loaded machine a thousand times more
# (SciPy's expm of a 7 x 7 matrix: 24 us on one thread, 30 ms on two
# threads with other jobs running).


@numba.njit(cache=True)
def _matmul(a, b):  # pragma: no cover - compiled
    n, k, m = a.shape[0], a.shape[1], b.shape[1]
    out = np.zeros((n, m))
    for i in range(n):
        for j in range(k):
            aij = a[i, j]
            for col in range(m):
                out[i, col] += aij * b[j, col]
    return out


# Taylor degree and the 1-norm the scaled matrix is brought under: the
# remainder is below 0.5**17 / 17! ~ 2e-20 of the norm, under rounding.
_TAYLOR_DEGREE = 16
_TAYLOR_NORM = 0.5


@numba.njit(cache=True)
def expm_small(m):  # pragma: no cover - compiled
    """The matrix exponential of a small square `m` by scaling and
    squaring: ``exp(m) = exp(m / 2**s) ** (2**s)``, the scaled exponential
    by its Taylor polynomial (Horner), so that the 1-norm of ``m / 2**s``
    is at most 0.5; NaN where `m` is not finite."""
    n = m.shape[0]
    norm = 0.0
    for j in range(n):
        col = 0.0
        for i in range(n):
            col += abs(m[i, j])
        norm = max(norm, col)
    if not np.isfinite(norm):
        return np.full((n, n), np.nan)
    s = 0
    while norm > _TAYLOR_NORM:
        norm /= 2.0
        s += 1
    x = m / 2.0**s
    t = np.eye(n)
    for k in range(_TAYLOR_DEGREE, 0, -1):
        t = _matmul(x, t) / k
        for i in range(n):
            t[i, i] += 1.0
    for _ in range(s):
        t = _matmul(t, t)
    return t


@numba.njit(cache=True)
def zoh(a, b, ts):  # pragma: no cover - compiled
    """``(Ad, Bd)`` of ``dx/dt = A x + B u`` with `u` held over `ts`: the
    exponential of the augmented matrix ``[[A, B], [0, 0]] ts`` holds both
    (Van Loan), for any ``A``, singular or defective ones included."""
    n, m = b.shape
    big = np.zeros((n + m, n + m))
    big[:n, :n] = a * ts
    big[:n, n:] = b * ts
    phi = expm_small(big)
    return np.ascontiguousarray(phi[:n, :n]), np.ascontiguousarray(phi[:n, n:])


@numba.njit(cache=True)
def lti_run(ad, bd, c, d, x0, u):  # pragma: no cover - compiled
    """``x[k+1] = Ad x[k] + Bd u[k]``, ``y[k] = C x[k] + D u[k]`` from
    `x0`; NaN after the state leaves the floating-point range."""
    n_samples, n, m, p = u.shape[0], ad.shape[0], bd.shape[1], c.shape[0]
    y = np.full((n_samples, p), np.nan)
    x = x0.copy()
    nxt = np.empty(n)
    for k in range(n_samples):
        for i in range(p):
            acc = 0.0
            for j in range(n):
                acc += c[i, j] * x[j]
            for j in range(m):
                acc += d[i, j] * u[k, j]
            y[k, i] = acc
        finite = True
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += ad[i, j] * x[j]
            for j in range(m):
                acc += bd[i, j] * u[k, j]
            nxt[i] = acc
            finite = finite and np.isfinite(acc)
        x, nxt = nxt, x
        if not finite:
            break
    return y
