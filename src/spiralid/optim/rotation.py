"""n-dimensional spiral rotation in Tamura & Yasuda's order.

The composite rotation of the spiral dynamic algorithm (Tamura & Yasuda 2011)
is a product of plane (Givens) rotations, all by the same angle ``theta``::

    R^(n)(theta) = prod_{i=1}^{n-1} prod_{j=1}^{i} R_{n-i, n+1-j}(theta)

multiplied left to right, so for n = 3 it is ``R23 @ R13 @ R12``. ``R_ij``
(1-based) is the identity except ``cos`` at (i, i) and (j, j), ``-sin`` at
(i, j) and ``+sin`` at (j, i). Applied to a vector the rightmost factor acts
first, so :func:`rotate` sweeps the planes in reverse product order, O(n^2)
per point, without forming a matrix.
"""

from functools import lru_cache

import numpy as np

from spiralid._checks import integer, real, real_array
from spiralid.optim import _kernels

__all__ = ["planes", "rotate", "rotation_matrix"]


@lru_cache(maxsize=64)
def _planes(n: int) -> np.ndarray:
    pairs = [(n - i - 1, n - j) for i in range(1, n) for j in range(1, i + 1)]
    out = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    out.setflags(write=False)
    return out


@lru_cache(maxsize=64)
def _sweep_order(n: int) -> np.ndarray:
    # Applied to a vector, the rightmost factor acts first.
    out = np.ascontiguousarray(_planes(n)[::-1])
    out.setflags(write=False)
    return out


def planes(n: int) -> np.ndarray:
    """The rotation planes of ``R^(n)`` in matrix-product order (0-based).

    Parameters
    ----------
    n : int
        Dimension, ``n >= 1``.

    Returns
    -------
    ndarray of int, shape (n (n - 1) / 2, 2)
        Row ``t`` holds the (row, column) indices ``(p, q)`` of the t-th
        factor ``R_{p+1, q+1}`` counted from the left.

    Examples
    --------
    >>> planes(3).tolist()
    [[1, 2], [0, 2], [0, 1]]
    """
    return _planes(integer(n, "n", 1))


def rotation_matrix(n: int, theta: float) -> np.ndarray:
    """Dense rotation ``R^(n)(theta)`` of the spiral model, Tamura order.

    Parameters
    ----------
    n : int
        Dimension, ``n >= 1`` (``n = 1`` gives ``[[1.0]]``).
    theta : float
        Angle in radians, shared by every plane.

    Returns
    -------
    ndarray, shape (n, n)
        An orthogonal matrix with determinant 1.

    Examples
    --------
    >>> import numpy as np
    >>> R = rotation_matrix(2, np.pi / 2)
    >>> np.round(R, 12) + 0.0
    array([[ 0., -1.],
           [ 1.,  0.]])
    """
    n = integer(n, "n", 1)
    theta = real(theta, "theta")
    c, s = np.cos(theta), np.sin(theta)
    out = np.eye(n)
    # Right-multiplying by R_pq mixes columns p and q only: O(n) per factor.
    for p, q in _planes(n):
        a = out[:, p].copy()
        b = out[:, q]
        out[:, p] = c * a + s * b
        out[:, q] = c * b - s * a
    return out


def rotate(v, theta) -> np.ndarray:
    """Apply ``R^(n)(theta)`` to a batch of vectors, one angle per vector.

    Equivalent to ``rotation_matrix(n, theta_i) @ v[i]`` for every row, but
    computed as a sweep of plane rotations, O(n^2) per point; no n x n
    matrix is formed.

    Parameters
    ----------
    v : array_like, shape (m, n) or (n,)
        Vectors to rotate, one per row.
    theta : float or array_like, shape (m,)
        One angle for all rows, or one angle per row (radians).

    Returns
    -------
    ndarray
        Rotated vectors, same shape as ``v``.

    Examples
    --------
    >>> import numpy as np
    >>> v = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    >>> out = rotate(v, [np.pi / 2, np.pi])
    >>> np.allclose(out[0], rotation_matrix(3, np.pi / 2) @ v[0])
    True
    """
    arr = real_array(v, "v")
    if arr.ndim not in (1, 2) or arr.shape[-1] < 1:
        raise ValueError(
            f"`v` must have shape (m, n) or (n,) with n >= 1; got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError("`v` must be finite; got NaN or infinite entries")
    batch = np.ascontiguousarray(arr.reshape(-1, arr.shape[-1]))
    m, n = batch.shape
    t = real_array(theta, "theta")
    if t.ndim == 0:
        t = np.full(m, float(t))
    elif t.shape != (m,) or arr.ndim != 2:
        raise ValueError(
            f"`theta` must be a scalar or have shape ({m},) to match `v`; "
            f"got shape {t.shape}"
        )
    if not np.all(np.isfinite(t)):
        raise ValueError(f"`theta` must be finite; got {theta!r}")
    return _kernels.sweep(batch, t, _sweep_order(n)).reshape(arr.shape)
