"""Compiled kernel of the variable-projection cost (private).

Loaded by :mod:`spiralid.sysid.estimation.linear.varpro` on first use only, so that
``import spiralid`` does not pay for Numba. Candidates lie along the fast
axis (as in :mod:`spiralid.sysid.estimation.core.cost`): the filter recursion is a
serial
chain in time, so the work vectorises across candidates.
"""

import numba
import numpy as np


@numba.njit(cache=True)
def _solve_equilibrated(g, c, out):  # pragma: no cover - compiled
    """Solve ``g x = c`` (symmetric positive semi-definite) into `out`.

    The matrix is scaled to a unit diagonal first: filtering by a lightly
    damped 1/A spreads the regressors' scales over orders of magnitude.
    A zero column gives a zero coefficient. If the Cholesky factorisation
    meets a non-positive pivot (regressors collinear to rounding), a ridge
    of 1e-13 on the unit diagonal is added and it is repeated.
    """
    n = c.size
    d = np.empty(n)
    for i in range(n):
        d[i] = 1.0 / np.sqrt(g[i, i]) if g[i, i] > 0.0 else 0.0
    ridge = 0.0
    chol = np.empty((n, n))
    for _attempt in range(2):
        ok = True
        for i in range(n):
            for j in range(i + 1):
                s = g[i, j] * d[i] * d[j]
                if i == j:
                    s += ridge if d[i] > 0.0 else 1.0
                for k in range(j):
                    s -= chol[i, k] * chol[j, k]
                if i == j:
                    if s <= 0.0:
                        ok = False
                        break
                    chol[i, i] = np.sqrt(s)
                else:
                    chol[i, j] = s / chol[j, j]
            if not ok:
                break
        if ok:
            break
        ridge = 1e-13
    if not ok:
        for i in range(n):
            out[i] = 0.0
        return
    z = np.empty(n)
    for i in range(n):
        s = c[i] * d[i]
        for k in range(i):
            s -= chol[i, k] * z[k]
        z[i] = s / chol[i, i]
    for i in range(n - 1, -1, -1):
        s = z[i]
        for k in range(i + 1, n):
            s -= chol[k, i] * out[k]
        out[i] = s / chol[i, i]
    for i in range(n):
        out[i] *= d[i]


@numba.njit(cache=True)
def projected_sse(u, y, a, nk, b, sse):  # pragma: no cover - compiled
    """Numerator and simulation SSE of each candidate denominator, from rest.

    ``a[i, r]`` is candidate r's ``a_(i+1)``; on return ``b[j, r]`` is the
    least-squares ``b_j`` of ``y ~ sum_j b_j v(t - nk - j)`` with ``v`` the
    input filtered by ``1 / A_r`` from rest, and ``sse[r]`` the sum of
    squared simulation errors at that numerator, computed from the residual
    itself (not from the normal equations, which would cancel digits when
    the fit is good).
    """
    n = u.size
    na, m = a.shape
    nb = b.shape[0]
    v = np.empty((n, m))
    for t in range(n):
        for r in range(m):
            v[t, r] = u[t]
        top = na if t >= na else t
        for i in range(top):
            vt = v[t - 1 - i]
            for r in range(m):
                v[t, r] -= a[i, r] * vt[r]
    length = n - nk
    # Lagged products R[d] = sum_{s < length - d} v(s) v(s + d) and the
    # cross terms c[j] = sum_{s < length - j} v(s) y(s + nk + j).
    lagged = np.zeros((nb, m))
    cross = np.zeros((nb, m))
    for d in range(nb):
        for s in range(length - d):
            vs = v[s]
            vd = v[s + d]
            ys = y[s + nk + d]
            for r in range(m):
                lagged[d, r] += vs[r] * vd[r]
                cross[d, r] += vs[r] * ys
    _solve_gram(v, lagged, cross, length, b, False)
    # One step of iterative refinement: b += G^-1 V'e with the residual e
    # computed directly. The normal equations lose digits to the squared
    # conditioning; this recovers them (the seminormal-equations fix).
    corr = np.zeros((nb, m))
    _accumulate_residual(v, y, b, nk, sse, corr, True)
    _solve_gram(v, lagged, corr, length, b, True)
    for r in range(m):
        sse[r] = 0.0
    _accumulate_residual(v, y, b, nk, sse, corr, False)


@numba.njit(cache=True)
def _solve_gram(v, lagged, rhs, length, b, add):  # pragma: no cover - compiled
    """For each candidate r solve ``G_r x = rhs[:, r]`` into ``b[:, r]``
    (``+=`` with `add`), ``G_r = V_r' V_r`` from the lagged products:
    ``G[i, j] (i <= j) = sum_{s < length - j} v(s) v(s + j - i)``, the full
    lagged product less its last ``i`` terms."""
    nb, m = b.shape
    g = np.empty((nb, nb))
    c = np.empty(nb)
    x = np.empty(nb)
    for r in range(m):
        for j in range(nb):
            for i in range(j + 1):
                dd = j - i
                acc = lagged[dd, r]
                for s in range(length - j, length - dd):
                    acc -= v[s, r] * v[s + dd, r]
                g[i, j] = acc
                g[j, i] = acc
            c[j] = rhs[j, r]
        _solve_equilibrated(g, c, x)
        for j in range(nb):
            if add:
                b[j, r] += x[j]
            else:
                b[j, r] = x[j]


@numba.njit(cache=True)
def _accumulate_residual(v, y, b, nk, sse, corr, want_corr):  # pragma: no cover
    """sse[r] = sum_t e_r(t)^2 with e_r = y - sum_j b_j v(t - nk - j); with
    `want_corr`, corr[j, r] = sum_t v(t - nk - j) e_r(t) instead."""
    n, m = v.shape
    nb = b.shape[0]
    acc = np.empty(m)
    for t in range(n):
        top = t - nk + 1
        if top > nb:
            top = nb
        for r in range(m):
            acc[r] = y[t]
        for j in range(top):
            vj = v[t - nk - j]
            for r in range(m):
                acc[r] -= b[j, r] * vj[r]
        if want_corr:
            for j in range(top):
                vj = v[t - nk - j]
                for r in range(m):
                    corr[j, r] += vj[r] * acc[r]
        else:
            for r in range(m):
                sse[r] += acc[r] * acc[r]


@numba.njit(cache=True)
def _filter(x, a, out):  # pragma: no cover - compiled
    """out = x filtered by 1 / A from rest (A monic, coefficients a)."""
    n = x.size
    na = a.size
    for t in range(n):
        acc = x[t]
        top = na if t >= na else t
        for i in range(top):
            acc -= a[i] * out[t - 1 - i]
        out[t] = acc


@numba.njit(cache=True)
def residual_jacobian(u, y, a, nb, nk):  # pragma: no cover - compiled
    """Projected residual ``r = y - V b(A)`` of one denominator and its exact
    Jacobian ``d r / d a`` (Golub and Pereyra), shape (N, na).

    With ``G = V'V``, ``D_i = d(V b)/d a_i`` at fixed ``b`` (``-1/A`` applied
    to ``yhat`` delayed by ``i + 1``) and ``z_i = (dV/d a_i)' r``:

        d r / d a_i = -(I - V G^-1 V') D_i - V G^-1 z_i
                    = -D_i + V G^-1 (V' D_i - z_i).

    Loops, not BLAS: on a shared machine a threaded BLAS on these thin
    matrices is an order of magnitude slower than one core.
    """
    n = u.size
    na = a.size
    v = np.empty(n)
    _filter(u, a, v)
    b = np.empty((nb, 1))
    sse = np.empty(1)
    projected_sse(u, y, np.ascontiguousarray(a.reshape(na, 1)), nk, b, sse)
    yhat = np.zeros(n)
    for t in range(n):
        acc = 0.0
        for j in range(nb):
            k = t - nk - j
            if k >= 0:
                acc += b[j, 0] * v[k]
        yhat[t] = acc
    r = y - yhat
    w_y = np.empty(n)
    _filter(yhat, a, w_y)
    w_v = np.empty(n)
    _filter(v, a, w_v)
    # Gram G = V'V (from the lagged products, as in projected_sse).
    g = np.empty((nb, nb))
    length = n - nk
    for j in range(nb):
        for i in range(j + 1):
            dd = j - i
            acc = 0.0
            for s in range(length - j):
                acc += v[s] * v[s + dd]
            g[i, j] = acc
            g[j, i] = acc
    jac = np.empty((n, na))
    rhs = np.empty(nb)
    m_col = np.empty(nb)
    for i in range(na):
        # D_i(t) = -w_y(t - i - 1)
        for t in range(n):
            k = t - i - 1
            jac[t, i] = w_y[k] if k >= 0 else 0.0  # -D_i
        for j in range(nb):
            # (V' D_i)_j = sum_t v(t - nk - j) D_i(t)
            acc = 0.0
            for t in range(nk + j, n):
                k = t - i - 1
                if k >= 0:
                    acc -= v[t - nk - j] * w_y[k]
            # z_ij = -sum_t w_v(t - (i + 1 + nk + j)) r(t)
            lag = i + 1 + nk + j
            zz = 0.0
            for t in range(lag, n):
                zz -= w_v[t - lag] * r[t]
            rhs[j] = acc - zz
        _solve_equilibrated(g, rhs, m_col)
        for t in range(n):
            acc = 0.0
            for j in range(nb):
                k = t - nk - j
                if k >= 0:
                    acc += v[k] * m_col[j]
            jac[t, i] += acc
    return r, jac


@numba.njit(cache=True)
def normal_equations(u, y, a, nb, nk):  # pragma: no cover - compiled
    """``(sse, J'r, J'J)`` of :func:`residual_jacobian`, reduced in loops."""
    r, jac = residual_jacobian(u, y, a, nb, nk)
    n, na = jac.shape
    grad = np.zeros(na)
    hess = np.zeros((na, na))
    sse = 0.0
    for t in range(n):
        sse += r[t] * r[t]
        for i in range(na):
            ji = jac[t, i]
            grad[i] += ji * r[t]
            for k in range(i + 1):
                hess[i, k] += ji * jac[t, k]
    for i in range(na):
        for k in range(i):
            hess[k, i] = hess[i, k]
    return sse, grad, hess
