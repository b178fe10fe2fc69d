"""Compiled inner loops of the optimisers (private).

Per-point angles (Eb-SDA) rule out one shared rotation matrix, and a NumPy
loop over the n(n-1)/2 planes costs several microseconds per point at n = 16,
so the plane sweep is compiled with Numba. ``cache=True`` keeps the compile
cost to the first call on a machine.

The sweep kernels hold the vectors transposed, one row per coordinate, and
sweep each plane across all points at once: consecutive planes share a
coordinate, so sweeping one point at a time would be a serial chain of
dependent multiply-adds, while across points the work is independent and
contiguous. Each point still sees exactly the same operations in the same
order.

The learned-metric search's kernels (Adaptive Encoding's update, the basis
from its eigenvectors, a poll period's points) each replace several NumPy
calls on arrays of 10-40 rows, whose dispatch cost more than their
arithmetic; the element-wise ones round as NumPy does, so the search runs
bit for bit as with NumPy.
"""

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _sweep_columns(w, c, s, planes):  # pragma: no cover - compiled
    k = w.shape[1]
    for t in range(planes.shape[0]):
        wp = w[planes[t, 0]]
        wq = w[planes[t, 1]]
        for i in range(k):
            a = wp[i]
            b = wq[i]
            wp[i] = c[i] * a - s[i] * b
            wq[i] = s[i] * a + c[i] * b


@numba.njit(cache=True, nogil=True)
def sweep(v, theta, planes):  # pragma: no cover - compiled
    """Return the rows of ``v`` (m, n) each rotated by its own ``theta[i]``.

    ``planes`` lists the (p, q) planes (0-based) in the order they are
    applied to a vector, i.e. the reverse of the matrix-product order.
    """
    w = np.ascontiguousarray(v.T)
    _sweep_columns(w, np.cos(theta), np.sin(theta), planes)
    return np.ascontiguousarray(w.T)


@numba.njit(cache=True, nogil=True)
def spiral_step(x, r, theta, planes):  # pragma: no cover - compiled
    """Move rows 1.. of ``x`` in place: x_i <- x_0 + r_i R(theta_i) (x_i - x_0).

    ``r`` and ``theta`` hold one value per moving row. Row 0 is the centre
    and is left untouched.
    """
    m, n = x.shape
    k = m - 1
    w = np.empty((n, k))
    for i in range(k):
        for j in range(n):
            w[j, i] = x[i + 1, j] - x[0, j]
    _sweep_columns(w, np.cos(theta), np.sin(theta), planes)
    for i in range(k):
        ri = r[i]
        for j in range(n):
            x[i + 1, j] = x[0, j] + ri * w[j, i]


@numba.njit(cache=True, nogil=True)
def promote(x, f):  # pragma: no cover - compiled
    """Swap the best finite point into row 0; ties keep the lowest index.

    Non-finite costs never win; if no cost is finite nothing moves.
    """
    best = -1
    for i in range(f.size):
        fi = f[i]
        if np.isfinite(fi) and (best < 0 or fi < f[best]):
            best = i
    if best > 0:
        for j in range(x.shape[1]):
            t = x[0, j]
            x[0, j] = x[best, j]
            x[best, j] = t
        t = f[0]
        f[0] = f[best]
        f[best] = t


@numba.njit(cache=True, nogil=True)
def deviations(f):  # pragma: no cover - compiled
    """``|f[i] - f[0]|`` for i >= 1; ``inf`` where either cost is non-finite."""
    k = f.size - 1
    d = np.empty(k)
    fc = f[0]
    ok = np.isfinite(fc)
    for i in range(k):
        fi = f[i + 1]
        # Costs of opposite sign may differ by more than the largest float:
        # the difference then rounds to inf, which is what it should rank as.
        d[i] = abs(fi - fc) if ok and np.isfinite(fi) else np.inf
    return d


@numba.njit(cache=True, nogil=True)
def exponential(d, lower, span, c2, log_c1, cap):  # pragma: no cover - compiled
    """Eq. (4) for each row's constants: ``lower + span * expit(ln c1 - c2 d)``.

    Returns the (rows, k) values, how many ``d`` are exactly 0 and how many
    are invalid (NaN or negative), so that the caller can check its input
    without another pass in NumPy.
    """
    rows = lower.size
    k = d.size
    out = np.empty((rows, k))
    zeros = 0
    invalid = 0
    for i in range(k):
        if d[i] == 0.0:
            zeros += 1
        elif not d[i] >= 0.0:
            invalid += 1
    for j in range(rows):
        for i in range(k):
            u = log_c1[j] - min(d[i], cap[j]) * c2[j]
            # expit(u) without overflow for either sign of u.
            if u >= 0.0:
                e = 1.0 / (1.0 + np.exp(-u))
            else:
                t = np.exp(u)
                e = t / (1.0 + t)
            out[j, i] = lower[j] + span[j] * e
    return out, zeros, invalid


@numba.njit(cache=True, nogil=True)
def orthonormal_rows(g):  # pragma: no cover - compiled
    """Orthonormalise the rows of ``g`` (k, n), k <= n, in place by modified
    Gram-Schmidt and return it.

    For Gaussian rows this gives the first k rows of a uniformly random
    rotation (the Q of a QR with R's diagonal positive), without the
    Python-level work of ``np.linalg.qr`` on a small matrix.
    """
    k, n = g.shape
    for i in range(k):
        for j in range(i):
            d = 0.0
            for t in range(n):
                d += g[i, t] * g[j, t]
            for t in range(n):
                g[i, t] -= d * g[j, t]
        s = 0.0
        for t in range(n):
            s += g[i, t] * g[i, t]
        s = np.sqrt(s)
        for t in range(n):
            g[i, t] /= s
    return g


@numba.njit(cache=True, nogil=True)
def covariance_update(
    covariance, path, z, weights, inverse, c_p, c_1, c_mu, normalise
):  # pragma: no cover - compiled
    """Adaptive Encoding's update of ``covariance`` (n, n) and ``path`` (n,).

    Row 0 of ``z`` is the mean's shift, rows 1.. the selected steps, best
    first, with ``weights``. With ``normalise`` each row of ``z`` is first
    scaled, in place, to length ``sqrt(n)`` in the metric ``inverse``
    (``B^-1``; zero rows stay zero). ``path`` is updated in place; the new
    covariance is returned, symmetric by construction:
    ``(1 - c_1 - c_mu) C + c_1 p p^T + c_mu sum_i w_i z_i z_i^T``.

    One compiled pass instead of about fifteen NumPy calls on small arrays,
    which cost more than their arithmetic at n = 10-40.
    """
    k, n = z.shape
    if normalise:
        root_n = np.sqrt(n)
        # B^-1 z_i with the inner loop along rows of B^-T: independent sums
        # that the compiler vectorises without reordering any of them.
        inverse_t = np.ascontiguousarray(inverse.T)
        t = np.empty(n)
        for i in range(k):
            t[:] = 0.0
            for b in range(n):
                zb = z[i, b]
                for a in range(n):
                    t[a] += inverse_t[b, a] * zb
            s = 0.0
            for a in range(n):
                s += t[a] * t[a]
            length = np.sqrt(s)
            scale = root_n / length if length > 0.0 else 0.0
            for a in range(n):
                z[i, a] *= scale
    gain = np.sqrt(c_p * (2.0 - c_p))
    for a in range(n):
        path[a] = (1.0 - c_p) * path[a] + gain * z[0, a]
    # The rank-mu sum row by row of z, so the inner loop runs along memory,
    # and over whole rows: a loop starting at the diagonal is not
    # vectorised, and one of fixed length is twice as fast at n = 20-40 with
    # twice the products. Only the upper triangle is read.
    rank_mu = np.zeros((n, n))
    for i in range(1, k):
        wi = weights[i - 1]
        zi = z[i]
        for a in range(n):
            wa = wi * zi[a]
            row = rank_mu[a]
            for b in range(n):
                row[b] += wa * zi[b]
    keep = 1.0 - c_1 - c_mu
    out = np.empty((n, n))
    for a in range(n):
        for b in range(a, n):
            v = keep * covariance[a, b] + c_1 * path[a] * path[b] + c_mu * rank_mu[a, b]
            out[a, b] = v
            out[b, a] = v
    return out


@numba.njit(cache=True, nogil=True)
def eigen_frame(values, vectors):  # pragma: no cover - compiled
    """The learned basis from a decomposition ``C = V diag(values) V^T``
    (``vectors`` holds ``V``, in any layout): the lengths ``d = sqrt(values)``,
    ``B = V D`` (C order) and ``B^-1 = (V / d)^T`` (a transposed C-order
    array), element for element the products NumPy gives, in one call
    instead of five."""
    n = values.size
    lengths = np.sqrt(values)
    basis = np.empty((n, n))
    inverse_t = np.empty((n, n))
    for a in range(n):
        for b in range(n):
            v = vectors[a, b]
            basis[a, b] = v * lengths[b]
            inverse_t[a, b] = v / lengths[b]
    return lengths, basis, inverse_t.T


@numba.njit(cache=True, nogil=True)
def poll_offsets(
    basis, steps, width, centre, directions, signed, polled
):  # pragma: no cover - compiled
    """A poll period's directions and points, written in place.

    ``directions[j] = (B[:, j] s_j) w`` in the problem's coordinates (``w``
    the box's widths), ``signed`` the directions interleaved with their
    opposites (rows ``2j`` and ``2j + 1``) and ``polled = centre + signed``:
    the same roundings as the NumPy expressions, in one call instead of
    five."""
    n = steps.size
    for j in range(n):
        s = steps[j]
        for i in range(n):
            d = (basis[i, j] * s) * width[i]
            directions[j, i] = d
            signed[2 * j, i] = d
            signed[2 * j + 1, i] = -d
            polled[2 * j, i] = centre[i] + d
            polled[2 * j + 1, i] = centre[i] + -d


@numba.njit(cache=True, nogil=True)
def add_rows(centre, offsets, out):  # pragma: no cover - compiled
    """``out[r] = centre + offsets[r]`` for each row: a poll pair from a
    moved centre, in a third of ``np.add(..., out=)``'s call time."""
    for r in range(offsets.shape[0]):
        for i in range(centre.size):
            out[r, i] = centre[i] + offsets[r, i]
