"""The grey box's simulation loops: exact zero-order hold for the linear
kind, fixed-step fourth-order Runge-Kutta with sub-steps for the nonlinear
kind.

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

__all__ = ["is_compiled", "lti_run", "rk4_compiled", "rk4_python"]

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


@numba.njit(cache=True)
def lti_run(ad, bd, c, d, x0, u):  # pragma: no cover - compiled
    """``x[k+1] = Ad x[k] + Bd u[k]``, ``y[k] = C x[k] + D u[k]`` from
    `x0`; NaN after the state leaves the floating-point range."""
    n_samples = u.shape[0]
    y = np.full((n_samples, c.shape[0]), np.nan)
    x = x0.copy()
    for k in range(n_samples):
        y[k] = c @ x + d @ u[k]
        x = ad @ x + bd @ u[k]
        if not np.all(np.isfinite(x)):
            break
    return y
