"""When a spiral search has collapsed, and how large its restart is.

IPOP-CMA-ES (Auger & Hansen 2005) restarts a converged search from fresh
uniform points with a larger population, so that later runs explore more
widely; :func:`spiralid.optim.minimize` does the same for every spiral rule
with ``restarts=True`` or a :class:`Restarts`, within the same iteration
and evaluation budget. The paper's configurations keep it off.
"""

import math
from dataclasses import dataclass

import numpy as np

from spiralid._checks import integer, positive

__all__ = ["Restarts"]

# A restart must leave room for this many iterations of the new population,
# or it would spend its evaluations on the initial draw alone.
MIN_ITER = 10


@dataclass(frozen=True)
class Restarts:
    """Settings of the IPOP-style restarts of a spiral search.

    A run has collapsed when every point lies within ``tol_radius`` times
    the box's largest width of the centre (in the max-norm), or when the
    centre has not moved for ``stall`` iterations. It is then replaced by
    ``growth`` times as many fresh uniform points (rounded up); the best
    point of all runs is the result.

    Parameters
    ----------
    growth : float
        Population factor per restart, ``>= 1``; default 2 as in IPOP.
    tol_radius : float
        Collapse radius relative to the box's largest width; default 1e-9.
    stall : int or None
        Iterations without a centre update that count as a collapse.
        ``None`` (default) uses ``max(30, 4 n)`` for dimension ``n``: longer
        than the ``2 n`` iterations the convergence setting spends polling
        before it contracts.

    Examples
    --------
    >>> Restarts().next_size(50)
    100
    """

    growth: float = 2.0
    tol_radius: float = 1e-9
    stall: int | None = None

    def __post_init__(self):
        growth = positive(self.growth, "growth")
        if growth < 1.0:
            raise ValueError(f"`growth` must be >= 1; got {self.growth!r}")
        object.__setattr__(self, "growth", growth)
        object.__setattr__(self, "tol_radius", positive(self.tol_radius, "tol_radius"))
        if self.stall is not None:
            object.__setattr__(self, "stall", integer(self.stall, "stall", 1))

    def next_size(self, n_points: int) -> int:
        """Population of the next run."""
        return max(n_points, math.ceil(n_points * self.growth - 1e-9))

    def stall_for(self, n: int) -> int:
        """Periods without progress that count as a collapse in dimension
        ``n`` (``stall``, or ``max(30, 4 n)`` by default)."""
        return max(30, 4 * n) if self.stall is None else self.stall

    def collapsed(self, offsets: np.ndarray, width: float, stalled: int) -> bool:
        """Whether a run has collapsed.

        Parameters
        ----------
        offsets : ndarray, shape (m - 1, n)
            Moving points minus the centre.
        width : float
            The box's largest width.
        stalled : int
            Iterations since the centre last moved.
        """
        if stalled >= self.stall_for(offsets.shape[1]):
            return True
        radius = float(np.abs(offsets).max()) if offsets.size else 0.0
        # NaN offsets (escaped points) are not a collapse.
        return radius <= self.tol_radius * width


def parse_restarts(restarts) -> Restarts | None:
    """``restarts`` argument of :func:`~spiralid.optim.minimize`: False,
    True or a :class:`Restarts`."""
    if isinstance(restarts, Restarts):
        return restarts
    if isinstance(restarts, bool | np.bool_):
        return Restarts() if restarts else None
    raise TypeError(
        f"`restarts` must be True, False or a Restarts instance; got {restarts!r}"
    )
