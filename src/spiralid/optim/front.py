"""What a Pareto front is: the non-dominated filter, the hypervolume, evenly
spread weight vectors, the thinning of a front to a given size and its knee.

:func:`~spiralid.optim.minimize_pareto` builds on these; they are public so
that a front from any source can be filtered, measured and thinned alike.
"""

import numpy as np

from spiralid._checks import integer

__all__ = ["hypervolume", "knee_point", "non_dominated", "thin_front", "weight_vectors"]


def non_dominated(objectives) -> np.ndarray:
    """Mask of the non-dominated rows of `objectives` (minimisation).

    Row ``a`` dominates row ``b`` when it is nowhere larger and somewhere
    smaller. Of rows that are exactly equal, only the first is kept.

    Parameters
    ----------
    objectives : array_like, shape (N, k)

    Returns
    -------
    ndarray of bool, shape (N,)

    Examples
    --------
    >>> non_dominated([[1, 3], [2, 2], [2, 3], [1, 3]]).tolist()
    [True, True, False, False]
    """
    f = _objective_array(objectives, "objectives")
    le = np.all(f[:, None, :] <= f[None, :, :], axis=2)  # le[a, b]: a <= b
    lt = np.any(f[:, None, :] < f[None, :, :], axis=2)
    dominated = np.any(le & lt, axis=0)
    equal = le & le.T
    earlier_twin = np.any(np.triu(equal, k=1), axis=0)
    return ~(dominated | earlier_twin)


def hypervolume(objectives, ref) -> float:
    """Volume dominated by `objectives` and bounded by `ref` (minimisation).

    Exact for 2 objectives (a sweep) and 3 (slices along the third, each
    slice's area grown by the points in the order of the third objective).
    Points not strictly below `ref` in every objective add nothing.

    Parameters
    ----------
    objectives : array_like, shape (N, k), k in {2, 3}
    ref : array_like, shape (k,)

    Returns
    -------
    float

    Examples
    --------
    >>> hypervolume([[1, 3], [2, 2], [3, 1]], [4, 4])
    6.0
    """
    f = _objective_array(objectives, "objectives")
    r = np.asarray(ref, dtype=float)
    k = f.shape[1]
    if k not in (2, 3):
        raise ValueError(f"`objectives` must have 2 or 3 columns; got {k}")
    if r.shape != (k,) or not np.all(np.isfinite(r)):
        raise ValueError(f"`ref` must be a finite vector of length {k}; got {ref!r}")
    f = f[np.all(f < r, axis=1)]
    if f.shape[0] == 0:
        return 0.0
    f = f[non_dominated(f)]
    if k == 2:
        return _hypervolume_2d(f, r)
    return _hypervolume_3d(f, r)


# Rows of the 3-objective sweep handled at once (memory: this times N).
_BLOCK = 512


def _hypervolume_3d(f: np.ndarray, r: np.ndarray) -> float:
    """Sum over the slices between consecutive third objectives of the area
    the points so far dominate in the first two. Point ``i`` adds to that
    area, on each interval ``[X_t, X_t+1)`` of the sorted first objectives
    right of it, the height between its second objective and the staircase
    of the points before it (the running minimum of their second objectives
    over those left of ``X_t``)."""
    f = f[np.argsort(f[:, 2], kind="stable")]
    grid = np.sort(f[:, 0])
    widths = np.diff(np.r_[grid, r[0]])
    added = np.empty(f.shape[0])
    stair = np.full(grid.size, r[1])
    for start in range(0, f.shape[0], _BLOCK):
        x, y = f[start : start + _BLOCK, 0], f[start : start + _BLOCK, 1]
        right = x[:, None] <= grid[None, :]
        # Row i: the staircase of the points before i.
        heights = np.where(right, y[:, None], np.inf)
        before = np.minimum.accumulate(np.vstack([stair, heights[:-1]]), axis=0)
        gain = np.where(right, np.maximum(before - y[:, None], 0.0), 0.0)
        added[start : start + x.size] = gain @ widths
        stair = np.minimum(stair, heights.min(axis=0))
    area = np.cumsum(added)
    depth = np.diff(np.r_[f[:, 2], r[2]])
    return float(area @ depth)


def _hypervolume_2d(f: np.ndarray, r: np.ndarray) -> float:
    # Sorted by the first objective (ties by the second), a point is on the
    # front when it improves on every earlier point's second objective: an
    # O(N log N) sweep (the search's history calls it every iteration).
    f = f[np.lexsort((f[:, 1], f[:, 0]))]
    earlier = np.minimum.accumulate(np.r_[np.inf, f[:-1, 1]])
    f = f[f[:, 1] < earlier]
    right = np.r_[f[1:, 0], r[0]]
    return float(np.sum((right - f[:, 0]) * (r[1] - f[:, 1])))


def weight_vectors(k: int, m: int) -> np.ndarray:
    """Evenly spread weight vectors on the simplex (Das and Dennis): for 2
    objectives `m` of them; for 3 the largest lattice with at most `m`.

    Examples
    --------
    >>> weight_vectors(2, 3).tolist()
    [[0.0, 1.0], [0.5, 0.5], [1.0, 0.0]]
    """
    k = integer(k, "k", 2)
    m = integer(m, "m", 2)
    if k == 2:
        a = np.linspace(0.0, 1.0, m)
        return np.column_stack([a, 1.0 - a])
    if k != 3:
        raise ValueError(f"`k` must be 2 or 3; got {k}")
    h = 1
    while (h + 2) * (h + 3) // 2 <= m:
        h += 1
    rows = [(i, j, h - i - j) for i in range(h + 1) for j in range(h + 1 - i)]
    return np.array(rows, dtype=float) / h


def _objective_array(value, name: str) -> np.ndarray:
    try:
        f = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be an (N, k) array of numbers") from None
    if f.ndim != 2 or f.shape[1] < 1:
        raise ValueError(f"`{name}` must have shape (N, k); got shape {f.shape}")
    if not np.all(np.isfinite(f)):
        raise ValueError(f"`{name}` must be finite; got NaN or infinite values")
    return f


def thin_front(objectives, size: int) -> np.ndarray:
    """Indices of `size` rows of a front kept evenly spread: SPEA2's
    truncation (Zitzler, Laumanns and Thiele, 2001) repeatedly drops the
    point nearest to its nearest neighbour, in objectives scaled to the
    front's range; each objective's best point is never dropped.

    Parameters
    ----------
    objectives : array_like, shape (N, k)
        Usually non-dominated rows.
    size : int
        How many to keep (all when ``N <= size``).

    Returns
    -------
    ndarray of int
        Sorted row indices, ``min(N, size)`` of them.

    Examples
    --------
    >>> thin_front([[0, 4], [1, 3], [1.1, 2.9], [2, 2], [4, 0]], 4).tolist()
    [0, 1, 3, 4]
    """
    f = _objective_array(objectives, "objectives")
    size = integer(size, "size", 1)
    count = f.shape[0]
    if count <= size:
        return np.arange(count)
    low, high = f.min(axis=0), f.max(axis=0)
    z = (f - low) / np.where(high > low, high - low, 1.0)
    distance = np.linalg.norm(z[:, None, :] - z[None, :, :], axis=2)
    np.fill_diagonal(distance, np.inf)
    alive = np.ones(count, bool)
    protected = np.zeros(count, bool)
    protected[np.argmin(f, axis=0)] = True
    nearest_index = np.argmin(distance, axis=1)
    nearest = distance[np.arange(count), nearest_index]
    for _ in range(count - size):
        candidates = np.where(alive & ~protected, nearest, np.inf)
        drop = int(np.argmin(candidates))
        if not np.isfinite(candidates[drop]):  # only protected points left
            drop = int(np.argmin(np.where(alive, nearest, np.inf)))
        partner = nearest_index[drop]
        if not protected[partner] and nearest[partner] == nearest[drop]:
            # Of two mutual nearest, drop the one crowded on its other side.
            second = np.partition(distance[[drop, partner]], 1, axis=1)[:, 1]
            drop = int(partner) if second[1] < second[0] else drop
        alive[drop] = False
        distance[drop, :] = np.inf
        distance[:, drop] = np.inf
        nearest[drop] = np.inf
        # Only the points whose nearest neighbour it was need a new one.
        stale = np.flatnonzero(alive & (nearest_index == drop))
        nearest_index[stale] = np.argmin(distance[stale], axis=1)
        nearest[stale] = distance[stale, nearest_index[stale]]
    return np.flatnonzero(alive)


def knee_point(objectives) -> int:
    """The knee of a front: farthest from the extremes' line (plane).

    With the objectives normalised to [0, 1] over the front, the point
    farthest from the line through the two extreme points (for three
    objectives the plane through the three), on the side of the ideal point:
    where a unit of one objective costs most of the others. When the
    extremes do not span a line (plane), the point nearest the ideal point.
    Parameter-free and scale-free: a property of the front's shape only.

    Parameters
    ----------
    objectives : array_like, shape (m, k)
        A non-dominated set (minimisation), ``k`` >= 2.

    Returns
    -------
    int
        Row index (the first of equals).

    Examples
    --------
    >>> knee_point([[0, 10], [1, 2], [5, 1], [10, 0]])
    1
    """
    f = np.asarray(objectives, dtype=float)
    if f.ndim != 2 or f.shape[0] < 1 or f.shape[1] < 2 or not np.all(np.isfinite(f)):
        raise ValueError(
            "`objectives` must be a finite (m, k) array with m >= 1, k >= 2; got "
            f"shape {f.shape}"
        )
    lo, hi = f.min(axis=0), f.max(axis=0)
    g = (f - lo) / np.where(hi > lo, hi - lo, 1.0)
    nearest = int(np.argmin(np.linalg.norm(g, axis=1)))
    k = g.shape[1]
    # Each objective's best point (ties: the one best in the others).
    extremes = [int(np.lexsort((g.sum(axis=1), g[:, j]))[0]) for j in range(k)]
    if len(set(extremes)) < k:
        return nearest
    e = g[extremes]
    # The hyperplane n . x = 1 through the extremes.
    try:
        normal = np.linalg.solve(e, np.ones(k))
    except np.linalg.LinAlgError:
        return nearest
    if not np.all(np.isfinite(normal)) or np.linalg.cond(e) > 1e12:
        return nearest
    if np.all(normal <= 0):
        return nearest
    distance = (1.0 - g @ normal) / np.linalg.norm(normal)
    return int(np.argmax(distance))
