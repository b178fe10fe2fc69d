"""Adaptive Encoding: a coordinate system learned from selected points.

Hansen, "Adaptive Encoding: How to render search coordinate system
invariant", PPSN 2008. The learned-metric spiral (:mod:`spiralid.optim.learned`)
polls its directions in this basis.
"""

import math

import numpy as np
from scipy.linalg import lapack

from spiralid._checks import integer, positive
from spiralid.optim._kernels import covariance_update, eigen_frame

__all__ = ["AdaptiveEncoding"]


class AdaptiveEncoding:
    """A coordinate system learned from selected points (Hansen, PPSN 2008).

    Each :meth:`update` takes the ``mu`` best points of a sample, best first.
    Their weighted mean moves from the previous one; that step and the
    points' offsets from the previous mean, each normalised to length
    ``sqrt(n)`` in the current metric, update a covariance ``C`` (a rank-one
    term from the evolution path of the mean's steps, a rank-``mu`` term
    from the points). The basis is ``B = B_o D`` with ``C = B_o D^2 B_o^T``.
    On a convex quadratic ``C`` approaches the inverse Hessian up to scale.

    Parameters
    ----------
    n : int
        Dimension.
    mu : int
        Points per update; they get CMA-ES's log-decreasing weights.
    c_p, c_1, c_mu : float, optional
        Learning rates of the path and the rank-one and rank-``mu`` terms;
        defaults ``1/sqrt(n)``, ``0.5/n`` and ``0.5/n``, Adaptive
        Coordinate Descent's (Loshchilov et al., GECCO 2011), for a poll
        of ``2n`` points; :meth:`for_population` gives CMA-ES's for a
        sampled population.
    eigen_every : int, optional
        Decompose the covariance into the basis after every this many
        updates (default 1, every update); in between the covariance
        learns while the basis, its inverse and :attr:`condition` stay as
        they were (CMA-ES's lazy update).
    max_condition : float, optional
        Bound the metric's condition: at each decomposition, eigenvalues
        below the largest over `max_condition` are raised to it, in the
        covariance too (default None, unbounded).

    Examples
    --------
    >>> enc = AdaptiveEncoding(2, 2)
    >>> enc.basis.tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """

    def __init__(
        self,
        n: int,
        mu: int,
        *,
        c_p=None,
        c_1=None,
        c_mu=None,
        eigen_every: int = 1,
        max_condition: float | None = None,
    ):
        self.n = n = integer(n, "n", 1)
        mu = integer(mu, "mu", 1)
        w = np.log(mu + 0.5) - np.log(np.arange(1, mu + 1))
        self.weights = w / w.sum()
        self.c_p = 1.0 / math.sqrt(n) if c_p is None else positive(c_p, "c_p")
        self.c_1 = 0.5 / n if c_1 is None else positive(c_1, "c_1")
        self.c_mu = 0.5 / n if c_mu is None else positive(c_mu, "c_mu")
        if self.c_p > 1.0 or self.c_1 + self.c_mu > 1.0:
            raise ValueError("`c_p` and `c_1 + c_mu` must be at most 1")
        self.eigen_every = integer(eigen_every, "eigen_every", 1)
        self._pending = 0
        self.max_condition = (
            None if max_condition is None else positive(max_condition, "max_condition")
        )
        if self.max_condition is not None and self.max_condition < 1.0:
            raise ValueError(f"`max_condition` must be >= 1; got {max_condition!r}")
        self.covariance = np.eye(n)
        self.basis = np.eye(n)
        self.lengths = np.ones(n)
        # Column-major, as every later B^-1 is: one compiled update, not two.
        self._inverse = np.eye(n).T
        self.path = np.zeros(n)
        self.mean = None
        self.condition = 1.0

    @classmethod
    def for_population(
        cls, n: int, mu: int, *, eigen_every: int = 1, max_condition=None
    ) -> "AdaptiveEncoding":
        """The learning rates CMA-ES uses for ``mu`` selected points of a
        sampled population (Hansen's tutorial, 2016, table 1);
        `eigen_every` and `max_condition` as in the class."""
        enc = cls(n, mu, eigen_every=eigen_every, max_condition=max_condition)
        mu_eff = 1.0 / float(np.sum(enc.weights**2))
        enc.c_p = (4.0 + mu_eff / n) / (n + 4.0 + 2.0 * mu_eff / n)
        enc.c_1 = 2.0 / ((n + 1.3) ** 2 + mu_eff)
        enc.c_mu = min(
            1.0 - enc.c_1,
            2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((n + 2.0) ** 2 + mu_eff),
        )
        return enc

    def lazy_gap(self) -> int:
        """Updates between decompositions by the lazy gap of Hansen's
        reference CMA-ES (pycma's ``cma.purecma``: decompose once more than
        ``0.5 n lambda / ((c_1 + c_mu) n^2)`` evaluations have passed,
        ``lambda`` of them per update): the least integer above ``0.5 /
        ((c_1 + c_mu) n)``.

        Examples
        --------
        >>> AdaptiveEncoding(40, 40).lazy_gap()  # the poll's rates: every update
        1
        >>> AdaptiveEncoding.for_population(40, 15).lazy_gap()
        2
        """
        return math.floor(0.5 / ((self.c_1 + self.c_mu) * self.n)) + 1

    @property
    def inverse(self) -> np.ndarray:
        """``B^-1``."""
        return self._inverse

    def update(self, points) -> None:
        """Learn from the ``mu`` best points of a sample, best first."""
        x = np.asarray(points, dtype=np.float64)
        if x.shape != (self.weights.size, self.n):
            raise ValueError(
                f"`points` must have shape ({self.weights.size}, {self.n}); "
                f"got {x.shape}"
            )
        mean = self.weights @ x
        if self.mean is None:
            self.mean = mean
            return
        old = self.mean
        self.mean = mean
        # The shift and the steps written straight into the rows the
        # update takes (as learn() would copy them there).
        z = np.empty((x.shape[0] + 1, self.n))
        np.subtract(mean, old, out=z[0])
        np.subtract(x, old, out=z[1:])
        self._learn(z, self.weights, True)

    def learn(self, shift, steps, *, normalise: bool = True, weights=None) -> None:
        """Update the metric from the mean's `shift` (the path's step) and
        the selected `steps`, best first (the rank-``mu`` term).

        `weights` (summing to one) replace the ``mu`` log-decreasing
        weights for a number of steps that varies from update to update
        (the multi-objective poll's successes).

        With `normalise` (Adaptive Encoding), each is first scaled to length
        ``sqrt(n)`` in the current metric, so only directions count;
        without, they are taken as they are (CMA-ES's update, for steps
        divided by the step size and a shift by ``sigma / sqrt(mu_eff)``).
        """
        w = self.weights if weights is None else np.asarray(weights, dtype=float)
        z = np.empty((w.size + 1, self.n))
        z[0] = shift
        z[1:] = steps
        self._learn(z, w, normalise)

    def _learn(self, z: np.ndarray, w: np.ndarray, normalise: bool) -> None:
        """:meth:`learn` from the shift (row 0 of `z`) and the steps (the
        other rows) with weights `w`; `z` is overwritten."""
        C = covariance_update(
            self.covariance,
            self.path,
            z,
            w,
            self._inverse,
            float(self.c_p),
            float(self.c_1),
            float(self.c_mu),
            normalise,
        )
        self._pending += 1
        if self._pending < self.eigen_every:
            self.covariance = C
            return
        self._pending = 0
        # LAPACK's divide and conquer on the lower triangle, as numpy.linalg.eigh
        # calls it (the same numbers), without its wrapper's 7 us at n = 20:
        # one decomposition every period is most of the search's own time.
        values, vectors, info = lapack.dsyevd(C, lower=1)
        # Python floats: n of them are checked faster than NumPy dispatches
        # one call on the array.
        listed = values.tolist()
        low, high = listed[0], listed[-1]
        if info != 0 or not (low > 0.0 and all(map(math.isfinite, listed))):
            # Rounding broke positive definiteness: keep the last metric.
            self.condition = math.inf
            return
        if self.max_condition is not None and high > self.max_condition * low:
            # A direction every selected step favours grows without bound
            # in the normalised update (the bent cigar's, to 1e13); keep
            # the others' scale within reach of the poll's steps.
            values = np.maximum(values, values[-1] / self.max_condition)
            # In rows, as numpy.linalg.eigh returns them: the product then
            # sums in the same order.
            rows = np.ascontiguousarray(vectors)
            C = (rows * values) @ rows.T
            low = float(values[0])
        self.covariance = C
        self.lengths, self.basis, self._inverse = eigen_frame(values, vectors)
        self.condition = high / low
