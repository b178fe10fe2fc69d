"""The compiled loops of the neural state-space structure (Numba): its free
run, and the simulation error over a batch of subsequences with its exact
gradient by backpropagation through time. :mod:`.neural_state_space` and
the family's estimator call them; nothing here knows a structure.

The parameter vector ``theta`` holds, in this order: ``A`` (``nx x nx``,
row by row), ``B`` (``nx``), ``C`` (``nx``), ``D``; the state network's
``Wf`` (``h x (nx + 1)``), ``bf`` (``h``), ``Vf`` (``nx x h``); the output
network's ``Wh`` (``h x (nx + 1)``), ``bh`` (``h``), ``vh`` (``h``). One
step, with ``v = [x; u]``::

    x+ = A x + B u + Vf tanh(Wf v + bf)
    y  = C x + D u + vh . tanh(Wh v + bh)
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def _offsets(nx, h):  # pragma: no cover - compiled
    """Start of each block of ``theta`` (A, B, C, D, Wf, bf, Vf, Wh, bh, vh,
    end)."""
    oa = 0
    ob = oa + nx * nx
    oc = ob + nx
    od = oc + nx
    owf = od + 1
    obf = owf + h * (nx + 1)
    ovf = obf + h
    owh = ovf + nx * h
    obh = owh + h * (nx + 1)
    ovh = obh + h
    end = ovh + h
    return oa, ob, oc, od, owf, obf, ovf, owh, obh, ovh, end


@numba.njit(cache=True)
def _step(theta, x, u, nx, h, af, ah, xn):  # pragma: no cover - compiled
    """One step from state ``x`` and input ``u``: fills the hidden
    activations ``af``, ``ah`` and the next state ``xn``; returns ``y``."""
    oa, ob, oc, od, owf, obf, ovf, owh, obh, ovh, _ = _offsets(nx, h)
    for k in range(h):
        sf = theta[obf + k] + theta[owf + k * (nx + 1) + nx] * u
        sh = theta[obh + k] + theta[owh + k * (nx + 1) + nx] * u
        for i in range(nx):
            sf += theta[owf + k * (nx + 1) + i] * x[i]
            sh += theta[owh + k * (nx + 1) + i] * x[i]
        af[k] = math.tanh(sf)
        ah[k] = math.tanh(sh)
    y = theta[od] * u
    for i in range(nx):
        y += theta[oc + i] * x[i]
    for k in range(h):
        y += theta[ovh + k] * ah[k]
    for i in range(nx):
        s = theta[ob + i] * u
        for j in range(nx):
            s += theta[oa + i * nx + j] * x[j]
        for k in range(h):
            s += theta[ovf + i * h + k] * af[k]
        xn[i] = s
    return y


@numba.njit(cache=True)
def nss_free_run(theta, u, x0, nx, h, y):  # pragma: no cover - compiled
    """Free run from the state ``x0`` over the inputs ``u``: ``y[t]``; a
    run that leaves the floating-point range returns NaN from there on."""
    x = x0.copy()
    xn = np.empty(nx)
    af = np.empty(h)
    ah = np.empty(h)
    for t in range(u.size):
        y[t] = _step(theta, x, u[t], nx, h, af, ah, xn)
        for i in range(nx):
            x[i] = xn[i]


@numba.njit(cache=True)
def nss_batch_loss(theta, U, Y, W, X0, nx, h, grad, gx0):  # pragma: no cover - compiled
    """Weighted squared simulation error of the subsequences ``U[k]``,
    ``Y[k]`` each run from ``X0[k]``: ``sum W (y - Y)^2``; ``grad`` (the
    gradient in ``theta``) and ``gx0`` (in each ``X0[k]``) filled by
    backpropagation through time."""
    oa, ob, oc, od, owf, obf, ovf, owh, obh, ovh, _ = _offsets(nx, h)
    n_k, n_t = U.shape
    xs = np.empty((n_t + 1, nx))
    afs = np.empty((n_t, h))
    ahs = np.empty((n_t, h))
    g = np.empty(n_t)
    lam = np.empty(nx)
    lam_new = np.empty(nx)
    df = np.empty(h)
    dh = np.empty(h)
    grad[:] = 0.0
    loss = 0.0
    for k in range(n_k):
        for i in range(nx):
            xs[0, i] = X0[k, i]
        for t in range(n_t):
            yt = _step(theta, xs[t], U[k, t], nx, h, afs[t], ahs[t], xs[t + 1])
            e = yt - Y[k, t]
            loss += W[k, t] * e * e
            g[t] = 2.0 * W[k, t] * e
        lam[:] = 0.0  # d loss / d x(t + 1); the last state is not used
        for t in range(n_t - 1, -1, -1):
            x = xs[t]
            u = U[k, t]
            gt = g[t]
            for kk in range(h):
                s = 0.0
                for i in range(nx):
                    s += theta[ovf + i * h + kk] * lam[i]
                df[kk] = s * (1.0 - afs[t, kk] ** 2)
                dh[kk] = gt * theta[ovh + kk] * (1.0 - ahs[t, kk] ** 2)
            for i in range(nx):
                for j in range(nx):
                    grad[oa + i * nx + j] += lam[i] * x[j]
                grad[ob + i] += lam[i] * u
                grad[oc + i] += gt * x[i]
                for kk in range(h):
                    grad[ovf + i * h + kk] += lam[i] * afs[t, kk]
            grad[od] += gt * u
            for kk in range(h):
                grad[ovh + kk] += gt * ahs[t, kk]
                grad[obf + kk] += df[kk]
                grad[obh + kk] += dh[kk]
                for i in range(nx):
                    grad[owf + kk * (nx + 1) + i] += df[kk] * x[i]
                    grad[owh + kk * (nx + 1) + i] += dh[kk] * x[i]
                grad[owf + kk * (nx + 1) + nx] += df[kk] * u
                grad[owh + kk * (nx + 1) + nx] += dh[kk] * u
            for j in range(nx):
                s = gt * theta[oc + j]
                for i in range(nx):
                    s += theta[oa + i * nx + j] * lam[i]
                for kk in range(h):
                    s += theta[owf + kk * (nx + 1) + j] * df[kk]
                    s += theta[owh + kk * (nx + 1) + j] * dh[kk]
                lam_new[j] = s
            for j in range(nx):
                lam[j] = lam_new[j]
        for i in range(nx):
            gx0[k, i] = lam[i]
    return loss
