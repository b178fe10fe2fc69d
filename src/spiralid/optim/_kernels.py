"""Compiled inner loops of the spiral update (private).

Per-point angles (Eb-SDA) rule out one shared rotation matrix, and a NumPy
loop over the n(n-1)/2 planes costs several microseconds per point at n = 16,
so the plane sweep is compiled with Numba. ``cache=True`` keeps the compile
cost to the first call on a machine.
"""

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def sweep(v, c, s, planes):  # pragma: no cover - compiled
    """Rotate each row of ``v`` in place by its own angle.

    ``planes`` lists the (p, q) planes (0-based) in the order they are
    applied to a vector, i.e. the reverse of the matrix-product order.
    """
    m, _ = v.shape
    k = planes.shape[0]
    for i in range(m):
        ci = c[i]
        si = s[i]
        for t in range(k):
            p = planes[t, 0]
            q = planes[t, 1]
            a = v[i, p]
            b = v[i, q]
            v[i, p] = ci * a - si * b
            v[i, q] = si * a + ci * b


@numba.njit(cache=True, nogil=True)
def spiral_step(x, r, c, s, planes):  # pragma: no cover - compiled
    """Move rows 1.. of ``x`` in place: x_i <- x_0 + r_i R(theta_i) (x_i - x_0).

    Row 0 is the centre and is left untouched.
    """
    m, n = x.shape
    k = planes.shape[0]
    w = np.empty(n)
    for i in range(1, m):
        for j in range(n):
            w[j] = x[i, j] - x[0, j]
        ci = c[i - 1]
        si = s[i - 1]
        for t in range(k):
            p = planes[t, 0]
            q = planes[t, 1]
            a = w[p]
            b = w[q]
            w[p] = ci * a - si * b
            w[q] = si * a + ci * b
        ri = r[i - 1]
        for j in range(n):
            x[i, j] = x[0, j] + ri * w[j]
