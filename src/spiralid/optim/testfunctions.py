"""Standard test functions for the optimisers, vectorised.

Each function takes ``x`` of shape (n,) and returns a float, or a batch of
shape (m, n) and returns shape (m,), so it can be passed to
:func:`spiralid.optim.minimize` with either ``vectorized`` setting. The
definitions and search boxes are the usual ones (Surjanovic & Bingham's
Virtual Library of Simulation Experiments; Jamil & Yang 2013). Each has a
:class:`Problem` in :data:`PROBLEMS` with its box, optimum and optimal value.

Examples
--------
>>> import numpy as np
>>> p = PROBLEMS["rastrigin"]
>>> p.bounds(2).tolist(), p.optimum(2).tolist(), p.f_opt
([[-5.12, 5.12], [-5.12, 5.12]], [0.0, 0.0], 0.0)
>>> round(float(rastrigin([1.0, 0.5])), 9)
21.25
>>> rastrigin(np.zeros((3, 4))).tolist()
[0.0, 0.0, 0.0]
"""

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spiralid._checks import real_array

__all__ = [
    "PROBLEMS",
    "Problem",
    "ackley",
    "griewank",
    "rastrigin",
    "rosenbrock",
    "schwefel",
    "sphere",
]

# The maximiser of x sin(sqrt(x)) on [0, 500] (root of tan(u) = -u/2 with
# u = sqrt(x)) and the maximum, so that Schwefel's minimum is 0 to rounding
# (the often-quoted 418.9829 leaves about 1.3e-5 per dimension).
_SCHWEFEL_X = 420.9687463599821
_SCHWEFEL_C = 418.98288727243374


def _points(x, name: str, min_n: int = 1) -> np.ndarray:
    arr = real_array(x, "x")
    if arr.ndim not in (1, 2) or arr.shape[-1] < min_n:
        raise ValueError(
            f"`x` must have shape (n,) or (m, n) with n >= {min_n} for {name}; "
            f"got shape {arr.shape}"
        )
    # The search never proposes non-finite points; a NaN here is a caller's
    # bug, better named than returned as a NaN cost.
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"`x` must be finite for {name}; got NaN or infinite entries")
    return arr


def sphere(x):
    """Sphere ``sum x_i^2``; box [-5.12, 5.12]^n, minimum 0 at 0.

    Examples
    --------
    >>> float(sphere([1.0, 2.0, 3.0]))
    14.0
    """
    x = _points(x, "sphere")
    return np.sum(x * x, axis=-1)


def rastrigin(x):
    """Rastrigin ``10 n + sum (x_i^2 - 10 cos(2 pi x_i))``; [-5.12, 5.12]^n, 0 at 0."""
    x = _points(x, "rastrigin")
    return 10.0 * x.shape[-1] + np.sum(x * x - 10.0 * np.cos(2.0 * np.pi * x), axis=-1)


def rosenbrock(x):
    """Rosenbrock ``sum 100 (x_{i+1} - x_i^2)^2 + (1 - x_i)^2``; [-5, 10]^n, 0 at 1.

    Needs n >= 2.

    Examples
    --------
    >>> float(rosenbrock([-1.0, 1.0]))
    4.0
    """
    x = _points(x, "rosenbrock", min_n=2)
    head, tail = x[..., :-1], x[..., 1:]
    return np.sum(100.0 * (tail - head * head) ** 2 + (1.0 - head) ** 2, axis=-1)


def ackley(x):
    """Ackley, a = 20, b = 0.2, c = 2 pi; box [-32.768, 32.768]^n, 0 at 0.

    ``-20 exp(-0.2 sqrt(mean x_i^2)) - exp(mean cos(2 pi x_i)) + 20 + e``,
    evaluated as ``20 (1 - exp(..)) + (e - exp(..))`` so that the value at
    the optimum is exactly 0.
    """
    x = _points(x, "ackley")
    rms = np.sqrt(np.mean(x * x, axis=-1))
    mean_cos = np.mean(np.cos(2.0 * np.pi * x), axis=-1)
    return 20.0 * (1.0 - np.exp(-0.2 * rms)) + (math.e - np.exp(mean_cos))


def griewank(x):
    """Griewank ``1 + sum x_i^2 / 4000 - prod cos(x_i / sqrt(i))``.

    Box [-600, 600]^n, minimum 0 at 0.
    """
    x = _points(x, "griewank")
    i = np.arange(1, x.shape[-1] + 1)
    return np.sum(x * x, axis=-1) / 4000.0 + (
        1.0 - np.prod(np.cos(x / np.sqrt(i)), axis=-1)
    )


def schwefel(x):
    """Schwefel 2.26 ``418.98 n - sum x_i sin(sqrt|x_i|)``; [-500, 500]^n.

    The minimum, 0 (to rounding), is at ``x_i = 420.9687...`` near the box's
    corner, far from the second-best basins: deceptive for local search.
    """
    x = _points(x, "schwefel")
    return _SCHWEFEL_C * x.shape[-1] - np.sum(x * np.sin(np.sqrt(np.abs(x))), axis=-1)


@dataclass(frozen=True)
class Problem:
    """A test function with its search box and known optimum.

    Attributes
    ----------
    name : str
    fun : callable
        The vectorised function.
    low, high : float
        Search box ``[low, high]^n``.
    x_opt : float
        Every coordinate of the minimiser.
    f_opt : float
        The minimum value.
    min_n : int
        Smallest dimension the function is defined for.
    """

    __test__ = False  # not a pytest class, despite the subject

    name: str
    fun: Callable
    low: float
    high: float
    x_opt: float
    f_opt: float
    min_n: int = 1

    def __call__(self, x):
        return self.fun(x)

    def _check_n(self, n) -> int:
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < self.min_n:
            raise ValueError(
                f"`n` must be an integer >= {self.min_n} for {self.name}; got {n!r}"
            )
        return int(n)

    def bounds(self, n: int) -> np.ndarray:
        """The box as an (n, 2) array of (low, high) rows."""
        n = self._check_n(n)
        return np.tile([self.low, self.high], (n, 1))

    def optimum(self, n: int) -> np.ndarray:
        """The minimiser in n dimensions."""
        return np.full(self._check_n(n), self.x_opt)


PROBLEMS: dict[str, Problem] = {
    p.name: p
    for p in (
        Problem("sphere", sphere, -5.12, 5.12, 0.0, 0.0),
        Problem("rastrigin", rastrigin, -5.12, 5.12, 0.0, 0.0),
        Problem("rosenbrock", rosenbrock, -5.0, 10.0, 1.0, 0.0, min_n=2),
        Problem("ackley", ackley, -32.768, 32.768, 0.0, 0.0),
        Problem("griewank", griewank, -600.0, 600.0, 0.0, 0.0),
        Problem("schwefel", schwefel, -500.0, 500.0, _SCHWEFEL_X, 0.0),
    )
}
