"""What a Pareto front is: the non-dominated filter, the hypervolume, evenly
spread weight vectors, the thinning of a front to a given size and its knee.

:func:`~spiralid.optim.minimize_pareto` builds on these; they are public so
that a front from any source can be filtered, measured and thinned alike.
"""

import itertools
import math
from typing import NamedTuple

import numba
import numpy as np

from spiralid._checks import generator, integer

__all__ = [
    "HypervolumeEstimate",
    "hypervolume",
    "hypervolume_mc",
    "knee_point",
    "non_dominated",
    "thin_front",
    "weight_vectors",
]


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
    Points not strictly below `ref` in every objective add nothing. For 4 or
    more objectives, :func:`hypervolume_mc` estimates it.

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
        raise ValueError(
            f"`objectives` must have 2 or 3 columns for the exact hypervolume; "
            f"got {k} (hypervolume_mc estimates it for any number)"
        )
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


class HypervolumeEstimate(NamedTuple):
    """A Monte-Carlo hypervolume (:func:`hypervolume_mc`).

    Attributes
    ----------
    value : float
        The estimate.
    stderr : float
        Its standard error, ``V sqrt(p (1 - p) / n)`` for the box's volume
        ``V`` and the share ``p`` of the `n_samples` points dominated.
    n_samples : int
        Uniform points drawn in the box.
    """

    value: float
    stderr: float
    n_samples: int


def hypervolume_mc(objectives, ref, n_samples: int = 100_000, rng=None):
    """Monte-Carlo estimate of :func:`hypervolume`, for any number of
    objectives.

    The exact volume costs time exponential in the objectives at worst
    (and :func:`hypervolume` has it for 2 and 3 only); this draws
    `n_samples` uniform points in the box between the front's best values
    and `ref` and counts those some point of the front dominates (weakly:
    nowhere better than the sample). The standard error shrinks as
    ``1 / sqrt(n_samples)``; with 100,000 samples it is at most 0.16 % of
    the box.

    Parameters
    ----------
    objectives : array_like, shape (N, k), k >= 2
    ref : array_like, shape (k,)
    n_samples : int
        Uniform points drawn (at least 1; default 100,000).
    rng : None, int or numpy.random.Generator
        The draws' generator.

    Returns
    -------
    HypervolumeEstimate
        ``value``, ``stderr`` and ``n_samples``.

    Examples
    --------
    >>> est = hypervolume_mc([[1, 1, 1, 1]], [2, 3, 2, 2], rng=0)
    >>> est.value, est.stderr  # one box: every sample is dominated
    (2.0, 0.0)
    """
    f, r = _front_below(objectives, ref)
    n_samples = integer(n_samples, "n_samples", 1)
    unit = generator(rng).uniform(size=(n_samples, r.size))
    return _estimate(f, r, unit)


def _front_below(objectives, ref) -> tuple[np.ndarray, np.ndarray]:
    """The checked rows strictly below `ref` in every objective, and `ref`."""
    f = _objective_array(objectives, "objectives")
    k = f.shape[1]
    if k < 2:
        raise ValueError(f"`objectives` must have at least 2 columns; got {k}")
    r = np.asarray(ref, dtype=float)
    if r.shape != (k,) or not np.all(np.isfinite(r)):
        raise ValueError(f"`ref` must be a finite vector of length {k}; got {ref!r}")
    return f[np.all(f < r, axis=1)], r


@numba.njit(cache=True, nogil=True)
def _covered(f, samples):  # pragma: no cover - compiled
    """How many rows of `samples` some row of `f` weakly dominates: a loop
    that stops at the first dominating row and the first coordinate that
    rules one out, where NumPy would compare every pair in full."""
    hits = 0
    for i in range(samples.shape[0]):
        for j in range(f.shape[0]):
            inside = True
            for d in range(f.shape[1]):
                if f[j, d] > samples[i, d]:
                    inside = False
                    break
            if inside:
                hits += 1
                break
    return hits


def _estimate(f: np.ndarray, r: np.ndarray, unit: np.ndarray) -> HypervolumeEstimate:
    """The estimate from uniform draws `unit` in [0, 1)^k, mapped onto the
    box between the rows' least values and `r` (the same draws for every
    front: a search's history then moves with its front, not its draws)."""
    n = unit.shape[0]
    if f.shape[0] == 0:
        return HypervolumeEstimate(0.0, 0.0, n)
    low = f.min(axis=0)
    volume = float(np.prod(r - low))
    # Rows nearest the box's low corner first: they dominate the most
    # samples, so the search for a dominating row ends soonest.
    f = np.ascontiguousarray(f[np.argsort(((f - low) / (r - low)).sum(axis=1))])
    share = _covered(f, low + unit * (r - low)) / n
    stderr = volume * math.sqrt(share * (1.0 - share) / n)
    return HypervolumeEstimate(volume * share, stderr, n)


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
    """Evenly spread weight vectors on the simplex (Das and Dennis).

    For 2 objectives `m` of them. For ``k >= 3`` the simplex lattice of
    ``H`` divisions, ``C(H + k - 1, k - 1)`` vectors, with the largest ``H``
    that gives at most `m`. With 4 or more objectives that lattice may have
    no interior (every vector has a zero weight when ``H < k``); then, as in
    NSGA-III (Deb and Jain 2014), a second lattice of ``H2 <= H1`` divisions
    is added, shrunk halfway towards the simplex's centre: of the pairs
    within `m`, the one with the finest inner lattice, then the most
    vectors. Never fewer than the ``k`` corners, even when `m` is smaller.

    Parameters
    ----------
    k : int
        Number of objectives, at least 2.
    m : int
        The most vectors wanted (the population), at least 2.

    Returns
    -------
    ndarray, shape (p, k)
        Rows summing to 1.

    Examples
    --------
    >>> weight_vectors(2, 3).tolist()
    [[0.0, 1.0], [0.5, 0.5], [1.0, 0.0]]
    >>> [weight_vectors(k, 100).shape[0] for k in (3, 4, 5, 8)]
    [91, 84, 70, 72]
    """
    k = integer(k, "k", 2)
    m = integer(m, "m", 2)
    if k == 2:
        a = np.linspace(0.0, 1.0, m)
        return np.column_stack([a, 1.0 - a])
    h = 1
    while _lattice_size(k, h + 1) <= m:
        h += 1
    if k == 3 or h >= k:
        return _lattice(k, h)
    # Two layers: the boundary's divisions h1 and the inner one's h2 <= h1.
    best = (0, _lattice_size(k, h), h, 0)
    for h1 in range(1, h + 1):
        for h2 in range(1, h1 + 1):
            size = _lattice_size(k, h1) + _lattice_size(k, h2)
            if size <= m:
                best = max(best, (h2, size, h1, h2))
    _, _, h1, h2 = best
    if h2 == 0:
        return _lattice(k, h1)
    inner = 0.5 * _lattice(k, h2) + 0.5 / k
    return np.vstack([_lattice(k, h1), inner])


def _lattice_size(k: int, h: int) -> int:
    return math.comb(h + k - 1, k - 1)


def _lattice(k: int, h: int) -> np.ndarray:
    """Every vector of k non-negative multiples of 1/h summing to 1 (the
    first weight largest first, as the 3-objective lattice was listed)."""
    rows = [
        (*head, h - sum(head))
        for head in itertools.product(range(h + 1), repeat=k - 1)
        if sum(head) <= h
    ]
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
