"""The compiled loops of the NARX structures (Numba): the perceptron's free
run and its sensitivities, and the polynomial's free run, each over a
population of parameter vectors. :mod:`.neural_narx` and
:mod:`.polynomial_narx` call them; nothing here knows a structure."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def _act(z, kind):  # pragma: no cover - compiled
    if kind == 0:
        return math.tanh(z)
    if kind == 1:
        return 1.0 / (1.0 + math.exp(-z))
    return z


@numba.njit(cache=True, inline="always")
def _dact(a, kind):  # pragma: no cover - compiled
    """Derivative from the activation's value."""
    if kind == 0:
        return 1.0 - a * a
    if kind == 1:
        return a * (1.0 - a)
    return 1.0


@numba.njit(cache=True)
def _mlp_free_run(
    P, ulag, hist, ny, h, kind, linear, out
):  # pragma: no cover - compiled
    """Free run of every parameter row of ``P``: ``out[j, t]``.

    ``hist`` holds the ``ny`` scaled outputs before ``t = 0`` (oldest
    first); ``ulag[t]`` the scaled input regressors of step ``t``.
    """
    m = P.shape[0]
    n_t = ulag.shape[0]
    nu = ulag.shape[1]
    n = ny + nu
    ob = h * n
    ov = ob + h
    oc = ov + h
    ol = oc + 1
    reg = np.empty(n)
    past = np.empty(n_t + ny)
    for j in range(m):
        for i in range(ny):
            past[i] = hist[i]
        for t in range(n_t):
            for i in range(ny):
                reg[i] = past[ny + t - 1 - i]
            for i in range(nu):
                reg[ny + i] = ulag[t, i]
            s = P[j, oc]
            if linear:
                for i in range(n):
                    s += P[j, ol + i] * reg[i]
            for k in range(h):
                z = P[j, ob + k]
                row = k * n
                for i in range(n):
                    z += P[j, row + i] * reg[i]
                s += P[j, ov + k] * _act(z, kind)
            if not math.isfinite(s) or abs(s) > 1e150:
                # A diverging candidate (linear activation) is cut off here
                # rather than overflowing; its cost is then infinite.
                for r in range(t, n_t):
                    out[j, r] = np.inf
                break
            out[j, t] = s
            past[ny + t] = s


@numba.njit(cache=True, inline="always")
def _fill_regressors(reg, past, ulag, t, ny):  # pragma: no cover - compiled
    """Step ``t``'s regressors: the ``ny`` outputs before it, newest first,
    then its inputs."""
    for i in range(ny):
        reg[i] = past[ny + t - 1 - i]
    for i in range(ulag.shape[1]):
        reg[ny + i] = ulag[t, i]


@numba.njit(cache=True, inline="always")
def _mlp_output(p, reg, h, kind, linear, act):  # pragma: no cover - compiled
    """The network's output at ``reg``, its hidden activations left in
    ``act`` for the derivatives."""
    n = reg.size
    ob = h * n
    ov = ob + h
    oc = ov + h
    ol = oc + 1
    s = p[oc]
    if linear:
        for i in range(n):
            s += p[ol + i] * reg[i]
    for k in range(h):
        z = p[ob + k]
        row = k * n
        for i in range(n):
            z += p[row + i] * reg[i]
        act[k] = _act(z, kind)
        s += p[ov + k] * act[k]
    return s


@numba.njit(cache=True, inline="always")
def _direct_sensitivity(
    p, reg, act, h, kind, linear, grad
):  # pragma: no cover - compiled
    """``grad = d out / d p`` with the regressors held fixed."""
    n = reg.size
    ob = h * n
    ov = ob + h
    oc = ov + h
    ol = oc + 1
    for q in range(p.size):
        grad[q] = 0.0
    for k in range(h):
        g = p[ov + k] * _dact(act[k], kind)
        row = k * n
        for i in range(n):
            grad[row + i] = g * reg[i]
        grad[ob + k] = g
        grad[ov + k] = act[k]
    grad[oc] = 1.0
    if linear:
        for i in range(n):
            grad[ol + i] = reg[i]


@numba.njit(cache=True, inline="always")
def _feedback_sensitivity(
    p, act, h, kind, linear, n, ny, t, dreg, sens
):  # pragma: no cover - compiled
    """Add to ``sens[t]`` the chain through the ``ny`` fed-back outputs:
    ``d out[t] / d reg[i]`` times the earlier ``sens[t - 1 - i]``."""
    ol = h * n + 2 * h + 1
    ov = h * n + h
    for i in range(ny):
        d = p[ol + i] if linear else 0.0
        for k in range(h):
            d += p[ov + k] * _dact(act[k], kind) * p[k * n + i]
        dreg[i] = d
    for i in range(ny):
        if t - 1 - i < 0 or dreg[i] == 0.0:
            continue
        for q in range(p.size):
            sens[t, q] += dreg[i] * sens[t - 1 - i, q]


@numba.njit(cache=True)
def _mlp_sensitivity(
    p, ulag, hist, ny, h, kind, linear, out, sens
):  # pragma: no cover - compiled
    """Free run of one parameter vector and its exact Jacobian
    ``sens[t] = d out[t] / d p`` by forward sensitivity (real-time
    recurrent learning): the direct derivative plus the chain through the
    ``ny`` fed-back outputs."""
    n_t = ulag.shape[0]
    n = ny + ulag.shape[1]
    reg = np.empty(n)
    act = np.empty(h)
    dreg = np.empty(ny)  # d out[t] / d reg[i] for the fed-back outputs
    past = np.empty(n_t + ny)
    for i in range(ny):
        past[i] = hist[i]
    for t in range(n_t):
        _fill_regressors(reg, past, ulag, t, ny)
        s = _mlp_output(p, reg, h, kind, linear, act)
        out[t] = s
        past[ny + t] = s
        _direct_sensitivity(p, reg, act, h, kind, linear, sens[t])
        _feedback_sensitivity(p, act, h, kind, linear, n, ny, t, dreg, sens)


@numba.njit(cache=True)
def _poly_free_run(coef, terms, ulag, hist, ny, out):  # pragma: no cover - compiled
    """Free run of a polynomial NARX: ``sum_j coef[j] prod_d reg[terms[j, d]]``
    with index 0 the constant 1 and ``i >= 1`` regressor ``i - 1``."""
    n_t = ulag.shape[0]
    nu = ulag.shape[1]
    n = ny + nu
    reg = np.empty(n + 1)
    reg[0] = 1.0
    past = np.empty(n_t + ny)
    for i in range(ny):
        past[i] = hist[i]
    for t in range(n_t):
        for i in range(ny):
            reg[1 + i] = past[ny + t - 1 - i]
        for i in range(nu):
            reg[1 + ny + i] = ulag[t, i]
        s = 0.0
        for j in range(coef.size):
            v = coef[j]
            for d in range(terms.shape[1]):
                v *= reg[terms[j, d]]
            s += v
        if not math.isfinite(s) or abs(s) > 1e150:
            for r in range(t, n_t):
                out[r] = np.inf
            break
        out[t] = s
        past[ny + t] = s
