"""The one base of the steppable searches (private): what
:class:`~spiralid.optim.SpiralSearch` and
:class:`~spiralid.optim.LearnedMetricSearch` set up and evaluate alike.

Each subclass checks its own `method` and draws its own first run; the
objective, the box, the bounds policy, the generator, the iteration budget
and the counters are checked and kept here, so the two reject the same bad
argument with the same message.
"""

import numpy as np

from spiralid._checks import box_bounds, generator, integer
from spiralid.optim._loop import check_costs, check_objective, check_policy

_SCALAR = "a scalar when vectorized=False (pass vectorized=True for batches)"


class SearchBase:
    """Common state of a steppable search (see the module's description)."""

    def __init__(self, fun, bounds, *, rng, vectorized, bounds_policy, max_iter):
        self.vectorized = check_objective(fun, vectorized)
        self._fun = fun
        self._lo, self._hi = box_bounds(bounds)
        self.bounds_policy = check_policy(bounds_policy)
        self._rng = generator(rng)
        self._k_max = None
        self._set_budget(max_iter)
        self.nfev = 0
        self.nit = 0
        self.restarts = 0

    def _set_budget(self, max_iter) -> None:
        """Take a run's iteration budget, if one is given."""
        if max_iter is not None:
            self._k_max = integer(max_iter, "max_iter", 1)

    def _draw(self, seeds: np.ndarray, m: int) -> np.ndarray:
        """`m` points of the box: `seeds` first, then uniform draws."""
        n = self._lo.size
        x = np.empty((m, n))
        k = seeds.shape[0]
        x[:k] = seeds
        x[k:] = self._rng.uniform(self._lo, self._hi, size=(m - k, n))
        return x

    def _costs(self, x: np.ndarray) -> np.ndarray:
        """The objective's checked costs of the rows of `x` (not counted)."""
        k = x.shape[0]
        if self.vectorized:
            # A copy: the search reorders its costs in place, and the caller
            # may keep the array it returned.
            raw = self._fun(x.copy())
            out = np.asarray(raw)
            if out.shape != (k,) or out.dtype.kind not in "biuf":
                # Only now build the message: this runs once per period.
                check_costs(raw, (k,), self._batch_shape(x))
            return np.array(out, np.float64)
        out = np.empty(k)
        for i in range(k):
            out[i] = check_costs(self._fun(x[i].copy()), (), _SCALAR)
        return out

    @staticmethod
    def _batch_shape(x: np.ndarray) -> str:
        k, n = x.shape
        return f"shape ({k},) for a ({k}, {n}) batch when vectorized=True"

    def __iter__(self):
        return self

    def __next__(self) -> tuple[np.ndarray, float]:
        return self.step()
