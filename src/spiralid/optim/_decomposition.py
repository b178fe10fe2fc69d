"""The machinery of :func:`~spiralid.optim.minimize_pareto`: Tchebycheff
subproblems (MOEA/D), the archive of non-dominated points, and the two ways
of proposing new points, a spiral about each subproblem's centre
(:class:`SpiralMoves`) and the learned-metric poll (:class:`PollMoves`).
"""

import numpy as np

from spiralid.optim.encoding import AdaptiveEncoding
from spiralid.optim.front import non_dominated, thin_front, weight_vectors
from spiralid.optim.learned_rule import LearnedMetricSpiral
from spiralid.optim.rotation import rotate
from spiralid.optim.rules import SpiralRule

# Replacements per new point (MOEA/D's n_r) and the smallest weight (a zero
# weight would make a subproblem blind to an objective).
_REPLACE = 2
_MIN_WEIGHT = 1e-6
# A point within this share of the box's width of its centre (every
# coordinate) has converged onto it.
_SPENT = 1e-3
# The poll's first step, and the step below which a subproblem's poll starts
# again from it, in the unit cube (a step never exceeds the cube's width).
_POLL_STEP = 0.25
_POLL_TOL = 1e-3
# The archive is thinned to twice the population when it grows past four.
_ARCHIVE_SLACK = 4
# The objectives of points the thinning dropped are kept up to this many
# times the population (see Archive._remember).
_GHOSTS = 10


def tchebycheff(f: np.ndarray, w: np.ndarray, z: np.ndarray, s: np.ndarray):
    """``g(f | w) = max_j w_j (f_j - z_j) / s_j``; f (..., k), w (..., k)."""
    return np.max(w * (f - z) / s, axis=-1)


class Subproblems:
    """One Tchebycheff subproblem per weight vector, each with its
    incumbent, and the neighbourhoods they share points in."""

    def __init__(self, k: int, m: int, neighbours: int, x, f):
        self.weights = np.maximum(weight_vectors(k, m), _MIN_WEIGHT)
        m = self.weights.shape[0]
        w = self.weights
        distance = np.linalg.norm(w[:, None] - w[None], axis=2)
        order = np.argsort(distance, axis=1, kind="stable")
        self.near = order[:, : min(neighbours, m)]
        self.x, self.f = x[:m].copy(), f[:m].copy()
        self.ideal = self.f.min(axis=0)

    def see(self, fy) -> None:
        """Move the ideal point to new objective vectors `fy`, before the
        moves learn from them and they are offered."""
        self.ideal = np.minimum(self.ideal, fy.min(axis=0))

    @property
    def size(self) -> int:
        return self.weights.shape[0]

    def scale(self) -> np.ndarray:
        """Each objective's spread, so objectives of any unit weigh alike."""
        return np.maximum(self.f.max(axis=0) - self.ideal, 1e-12)

    def g(self, f: np.ndarray) -> np.ndarray:
        """Each subproblem's scalar cost of its row of `f`."""
        return tchebycheff(f, self.weights, self.ideal, self.scale())

    def centres(self) -> np.ndarray:
        """Each subproblem's centre: the best incumbent for it among its
        neighbours'."""
        near, w = self.near, self.weights[:, None]
        g_near = tchebycheff(self.f[near], w, self.ideal, self.scale())
        return near[np.arange(self.size), np.argmin(g_near, axis=1)]

    def offer(self, y, fy, owners, gen) -> None:
        """Each new point replaces at most ``_REPLACE`` incumbents of its
        owner's neighbourhood that it improves, in random order (against the
        ideal point as :meth:`see` left it)."""
        scale = self.scale()
        for q in gen.permutation(y.shape[0]):
            pool = self.near[owners[q]]
            w = self.weights[pool]
            better = tchebycheff(fy[q], w, self.ideal, scale) < tchebycheff(
                self.f[pool], w, self.ideal, scale
            )
            for j in pool[better][:_REPLACE]:
                self.x[j], self.f[j] = y[q], fy[q]


def _dominated_by(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Mask of the rows of `b` that some row of `a` dominates."""
    a, b = a[:, None, :], b[None, :, :]
    return np.any(np.all(a <= b, axis=2) & np.any(a < b, axis=2), axis=0)


class Archive:
    """The non-dominated points of every evaluation offered to it.

    With a size ``m`` it is bounded: thinned by
    :func:`~spiralid.optim.front.thin_front` to ``2 m`` whenever it exceeds
    ``4 m``, and :meth:`final` gives at most ``m`` points evenly spread. Like
    every bounded archive it can deteriorate (Laumanns et al., 2002): a point
    thinned away no longer keeps out a later point it dominates. Without
    ``m`` it keeps every non-dominated point (``identify_pareto``, where each
    is a candidate model).

    Parameters
    ----------
    x, f : array_like, shape (N, n) and (N, k)
        The first points and their objectives (N may be 0).
    m : int, optional
        The population size the bound is reckoned in; None for no bound.
    """

    def __init__(self, x, f, m: int | None = None):
        self.m = m
        x, f = np.asarray(x, float), np.asarray(f, float)
        keep = non_dominated(f)
        self.x, self.f = x[keep], f[keep]
        self._ghosts = np.empty((0, f.shape[1]))

    def add(self, y, fy) -> None:
        """Offer the points `y` of objectives `fy`."""
        # The archive is non-dominated already: compare the new points among
        # themselves and against it, O(A B) rather than O((A + B)^2). A new
        # point equal to an archived one counts as dominated (the first kept).
        y, fy = np.asarray(y, float), np.asarray(fy, float)
        fresh = non_dominated(fy)
        y, fy = y[fresh], fy[fresh]
        taken = ~np.any(np.all(self.f[:, None, :] <= fy[None, :, :], axis=2), axis=0)
        if self._ghosts.shape[0] and taken.any():
            taken[taken] = ~_dominated_by(self._ghosts, fy[taken])
        y, fy = y[taken], fy[taken]
        old, new_f = self.f[:, None, :], fy[None, :, :]
        dominated = np.all(old >= new_f, axis=2) & np.any(old > new_f, axis=2)
        dropped = np.any(dominated, axis=1)
        x = np.concatenate([self.x[~dropped], y])
        f = np.concatenate([self.f[~dropped], fy])
        if self.m is not None and f.shape[0] > _ARCHIVE_SLACK * self.m:
            keep = thin_front(f, 2 * self.m)
            dropped = np.ones(f.shape[0], bool)
            dropped[keep] = False
            self._remember(f[dropped])
            x, f = x[keep], f[keep]
        self.x, self.f = x, f

    def _remember(self, dropped: np.ndarray) -> None:
        """Keep the objectives of the points the thinning dropped, so that
        a later point one of them dominates is refused. Without them the
        learned-metric poll's crossover pairs left up to a third of a small
        front dominated by points the search had seen. They are bounded
        too, more loosely than the archive (thinned to ``_GHOSTS / 2`` times
        the population past ``_GHOSTS`` times)."""
        # No remembered point dominates a dropped one (each was checked when
        # it came in, and the archive holds no dominated pair), so only the
        # remembered ones can fall.
        ghosts = np.concatenate(
            [self._ghosts[~_dominated_by(dropped, self._ghosts)], dropped]
        )
        if ghosts.shape[0] > _GHOSTS * self.m:
            ghosts = ghosts[thin_front(ghosts, _GHOSTS // 2 * self.m)]
        self._ghosts = ghosts

    def final(self) -> tuple[np.ndarray, np.ndarray]:
        """At most ``m`` points, evenly spread (every point without ``m``)."""
        if self.m is None:
            return self.x, self.f
        keep = thin_front(self.f, self.m)
        return self.x[keep], self.f[keep]


class SpiralMoves:
    """SDA's or Eb-SDA's move of each subproblem's point about its centre.

    ``x_i <- x*_i + r_i R(theta_i) (x_i - x*_i)`` with ``r_i, theta_i`` from
    the rule, fed Eb-SDA's deviation as ``g_i(f(x_i)) - g_i(f(x*_i))``. A
    point that reaches its centre starts again from a uniform draw.
    """

    def __init__(self, rule: SpiralRule, sub: Subproblems, lo, hi):
        self.rule, self.lo, self.hi = rule, lo, hi
        self.x, self.f = sub.x.copy(), sub.f.copy()
        self.owners = np.arange(sub.size)
        self.batch = sub.size
        self.n_restarts = 0

    def propose(self, sub: Subproblems, gen) -> np.ndarray:
        lo, hi = self.lo, self.hi
        m = sub.size
        centre = sub.centres()
        deviation = sub.g(self.f) - sub.g(sub.f[centre])
        r, theta = self.rule(np.maximum(deviation, 0.0), gen)
        theta = np.broadcast_to(np.asarray(theta, dtype=float), (m,))
        x = sub.x[centre] + np.reshape(r, (-1, 1)) * rotate(
            self.x - sub.x[centre], theta
        )
        spent = np.max(np.abs(x - sub.x[centre]) / (hi - lo), axis=1) < _SPENT
        if spent.any():
            x[spent] = gen.uniform(lo, hi, size=(int(spent.sum()), lo.size))
            self.n_restarts += int(spent.sum())
        return np.clip(x, lo, hi)

    def learn(self, sub: Subproblems, y, fy) -> None:
        self.x, self.f = y, fy


class PollMoves:
    """The learned-metric rule's poll, one per subproblem.

    Subproblem ``i`` polls the opposite pair ``x*_i +- u s_ij b_j`` about
    its centre, one direction ``j`` of the basis per iteration in turn; the
    step ``s_ij`` (of the unit cube) grows by the rule's ``grow`` when the
    better of the pair improves the subproblem's cost over the centre's and
    shrinks by ``shrink`` otherwise. ``u`` is uniform in [0.5, 1.5]: a
    ladder of steps in powers of two alone misses basins spaced otherwise
    (ZDT4). A subproblem whose steps have all shrunk below ``1e-3`` starts
    its steps again. With the rule's ``basis`` the directions are a basis
    learned by Adaptive Encoding from every successful step of the
    population; without, the box's axes.

    With the rule's ``crossover`` share ``p``, each subproblem polls instead,
    with probability ``p`` per iteration, the pair ``x*_i +- M (x_r - x*_i)``:
    ``x_r`` the incumbent of a random subproblem of the whole population and
    ``M`` a random half of the coordinates (one at least). A poll moves one
    direction at a time and keeps only improvements, so it cannot cross a
    ridge that no single direction descends, nor the gap between two pieces
    of a disconnected front: on WFG2 the outermost subproblems stop at an
    inner piece, and its non-separable distance stays unconverged. The
    crossover point carries coordinates that another part of the front has
    already made good; its mirror steps past the centre away from ``x_r``,
    which at an end of the front is outwards. Such a pair leaves the
    direction's step and the turn of directions as they were.
    """

    def __init__(self, rule: LearnedMetricSpiral, sub: Subproblems, lo, hi, gen):
        self.rule, self.lo, self.hi = rule, lo, hi
        n, m = lo.size, sub.size
        self.steps = np.full((m, n), _POLL_STEP)
        self.direction = gen.integers(n, size=m)
        self.encoding = AdaptiveEncoding(n, 1) if rule.basis else None
        self.basis = np.eye(n)
        self.owners = np.tile(np.arange(m), 2)
        self.batch = 2 * m
        self.n_restarts = 0
        self._centre = None
        self._crossed = np.zeros(m, bool)

    def propose(self, sub: Subproblems, gen) -> np.ndarray:
        m = sub.size
        self._centre = sub.centres()
        step = self.steps[np.arange(m), self.direction]
        step = step * gen.uniform(0.5, 1.5, size=m)
        offset = (self.basis[:, self.direction] * step).T * (self.hi - self.lo)
        centre = sub.x[self._centre]
        if self.rule.crossover > 0.0:
            # Drawn only when on, so that crossover=0 is the poll as it was,
            # number for number.
            self._crossed = gen.uniform(size=m) < self.rule.crossover
            offset[self._crossed] = self._crossover(sub, centre, gen)
        return np.vstack(
            [
                np.clip(centre + offset, self.lo, self.hi),
                np.clip(centre - offset, self.lo, self.hi),
            ]
        )

    def _crossover(self, sub: Subproblems, centre, gen) -> np.ndarray:
        """The offsets ``M (x_r - x*)`` of the crossing subproblems."""
        rows = np.flatnonzero(self._crossed)
        q, n = rows.size, self.lo.size
        partner = sub.x[gen.integers(sub.size, size=q)]
        mask = gen.uniform(size=(q, n)) < 0.5
        mask[np.arange(q), gen.integers(n, size=q)] = True
        return mask * (partner - centre[rows])

    def learn(self, sub: Subproblems, y, fy) -> None:
        m = sub.size
        rows = np.arange(m)
        g_centre = sub.g(sub.f[self._centre])
        g_pair = np.column_stack([sub.g(fy[:m]), sub.g(fy[m:])])
        better = np.argmin(g_pair, axis=1)
        success = g_pair[rows, better] < g_centre
        polled = ~self._crossed
        j = self.direction
        self.steps[rows, j] = np.where(
            polled,
            np.where(
                success,
                np.minimum(self.steps[rows, j] * self.rule.grow, 1.0),
                self.steps[rows, j] * self.rule.shrink,
            ),
            self.steps[rows, j],
        )
        # The basis learns from the poll's own successes only: fed the
        # crossover's, long steps between distant incumbents, it turned the
        # poll off ZDT4's front (hypervolume 0 on 4 seeds of 4, against
        # 0.64-0.74 without them).
        learnt = success & polled
        if self.encoding is not None and learnt.any():
            moved = (y[rows + m * better] - sub.x[self._centre])[learnt]
            self._learn_basis(moved / (self.hi - self.lo))
        self.direction = np.where(polled, (j + 1) % self.lo.size, j)
        stuck = self.steps.max(axis=1) < _POLL_TOL
        if stuck.any():
            self.steps[stuck] = _POLL_STEP
            self.n_restarts += int(stuck.sum())

    def _learn_basis(self, moved: np.ndarray) -> None:
        moved = moved[np.any(moved != 0.0, axis=1)]
        if moved.shape[0] == 0:
            return
        weights = np.full(moved.shape[0], 1.0 / moved.shape[0])
        # There is no moving mean, so the rank-one path gets no step: fed the
        # successes' mean, it turned the basis towards the direction every
        # subproblem shares (ZDT's distance variables) and ZDT4 fell to 0.
        self.encoding.learn(np.zeros(moved.shape[1]), moved, weights=weights)
        if np.isfinite(self.encoding.condition):
            # The steps carry the scale; the basis only the directions.
            basis = self.encoding.basis
            self.basis = basis / np.linalg.norm(basis, axis=0)
