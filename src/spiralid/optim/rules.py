"""Radius and angle rules of the spiral model.

A rule maps each moving point's fitness deviation ``d_i = |f(x_i(k)) - min J|``
(``min J`` being the centre's cost at iteration k) to the spiral radius
``r_i`` and rotation angle ``theta_i`` of its next step (paper, Figure-4,
step 2). A non-finite cost gives ``d_i = inf``.

- :class:`ConstantSpiral`: the original SDA, one radius and angle for all.
- :class:`ExponentialSpiral`: Eb-SDA, eq. (4) with the constants of eq. (7)
  and (8).
- :class:`LinearSpiral`: a linear adaptive rule, the alternative the paper
  contrasts Eb-SDA with (our reading; see the class).

A :class:`StepRateRule` is the other kind of setting: one fixed rotation
matrix for every point and a step rate ``r(k)`` that depends on the
iteration, as in Tamura & Yasuda's later settings with convergence
conditions (IEEE Trans. SMC: Systems, 2020):

- :class:`PeriodicSpiral`: the periodic-descent-direction setting,
  ``r = delta^(1 / k_max)``.
- :class:`ConvergentSpiral`: the convergence setting, ``r(k) = 1`` for
  ``2n`` iterations after each centre update, ``h < 1`` otherwise.
"""

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from spiralid._checks import integer, positive, real, real_array
from spiralid.optim import _kernels

__all__ = [
    "ConstantSpiral",
    "ConvergentSpiral",
    "ExponentialSpiral",
    "LinearSpiral",
    "PeriodicSpiral",
    "SpiralRule",
    "StepRateRule",
    "descent_rotation",
    "exponential_rule",
    "rank_condition",
]

# Beyond z = 60 the value moves by under expit(-60) (upper - lower), about
# 1e-26 (upper - lower): below half an ulp of `lower` for any sensible
# limits. Capping z there keeps c2 * d finite for any d, inf included.
_Z_CAP = 60.0


class SpiralRule(ABC):
    """Maps fitness deviations to spiral radii and angles.

    Subclass it and implement ``__call__`` to pass a custom rule as the
    ``method`` of :func:`spiralid.optim.minimize`.
    """

    @abstractmethod
    def __call__(self, d: np.ndarray, rng: np.random.Generator):
        """Radius and angle for each moving point.

        Parameters
        ----------
        d : ndarray, shape (k,)
            Fitness deviations ``|f(x_i(k)) - min J| >= 0``; ``inf`` for a
            non-finite cost.
        rng : numpy.random.Generator
            The search's generator, for rules that draw.

        Returns
        -------
        r, theta : float or ndarray of shape (k,)
            Scalars mean one radius (angle) for all points.
        """


def _check_interval(lo, hi, lo_name, hi_name, radius: bool):
    lo = real(lo, lo_name)
    hi = real(hi, hi_name)
    if radius and not 0.0 < lo < hi <= 1.0:
        raise ValueError(
            f"`{lo_name}` and `{hi_name}` must satisfy 0 < {lo_name} < {hi_name} <= 1; "
            f"got {lo_name}={lo!r}, {hi_name}={hi!r}"
        )
    if not radius and not lo < hi:
        raise ValueError(
            f"`{lo_name}` and `{hi_name}` must satisfy {lo_name} < {hi_name}; "
            f"got {lo_name}={lo!r}, {hi_name}={hi!r}"
        )
    return lo, hi


def _bad_deviations(d) -> ValueError:
    return ValueError(
        f"`d` must be a 1-D array of deviations >= 0 (inf allowed); got {d!r}"
    )


def _deviations(d) -> np.ndarray:
    """``d`` as a 1-D float array (values are checked by the caller)."""
    d = real_array(d, "d")
    if d.ndim != 1:
        raise _bad_deviations(d)
    return d


def _relative(d: np.ndarray) -> np.ndarray:
    """``d`` over its largest finite entry (unchanged if that is 0 or none).

    NaN and negative entries pass through for the caller's check.
    """
    finite = d[np.isfinite(d)]
    spread = float(finite.max()) if finite.size else 0.0
    return d / spread if spread > 0.0 else d


@dataclass(frozen=True)
class ConstantSpiral(SpiralRule):
    """Original SDA: constant radius and angle (Tamura & Yasuda 2011).

    Parameters
    ----------
    radius : float
        Spiral radius in (0, 1]; default 0.95.
    angle : float
        Rotation angle in radians; default pi / 4.

    Examples
    --------
    >>> import numpy as np
    >>> ConstantSpiral()(np.zeros(3), np.random.default_rng(0))
    (0.95, 0.7853981633974483)
    """

    radius: float = 0.95
    angle: float = math.pi / 4

    def __post_init__(self):
        r = real(self.radius, "radius")
        if not 0.0 < r <= 1.0:
            raise ValueError(f"`radius` must be in (0, 1]; got {self.radius!r}")
        object.__setattr__(self, "radius", r)
        object.__setattr__(self, "angle", real(self.angle, "angle"))

    def __call__(self, d, rng):
        return self.radius, self.angle


def exponential_rule(d, lower: float, upper: float, c1: float, c2: float) -> np.ndarray:
    """Eq. (4): ``(lower - upper) / (1 + c1 / exp(c2 d)) + upper``.

    Evaluated as ``lower + (upper - lower) * expit(ln c1 - c2 d)`` (compiled,
    with a sign-split logistic), which is the same function but finite and
    warning-free for any ``d >= 0``, ``inf`` included (penalised costs make
    ``d`` huge). It falls monotonically from
    ``upper + (lower - upper) / (1 + c1)`` at ``d = 0`` to ``lower`` as
    ``d -> inf``.

    Parameters
    ----------
    d : array_like
        Fitness deviations, ``>= 0`` (``inf`` allowed).
    lower, upper : float
        ``r_l, r_u`` (or ``theta_l, theta_u``).
    c1, c2 : float
        Positive constants of eq. (4).

    Raises
    ------
    ValueError
        If ``d`` has NaN or negative entries, ``lower >= upper``, or ``c1``
        or ``c2`` is not a finite positive number.

    Returns
    -------
    ndarray
        Values of eq. (4), same shape as ``d``.

    Examples
    --------
    >>> import numpy as np
    >>> exponential_rule(np.array([0.0, np.inf]), 0.1, 1.0, 100.0, 1.5).round(6)
    array([0.991089, 0.1     ])
    """
    d = real_array(d, "d")
    lower, upper = _check_interval(lower, upper, "lower", "upper", radius=False)
    c1, c2 = positive(c1, "c1"), positive(c2, "c2")
    cap = max((_Z_CAP + math.log(c1)) / c2, 0.0)
    out, _, invalid = _kernels.exponential(
        d.ravel(),
        np.array([lower]),
        np.array([upper - lower]),
        np.array([c2]),
        np.array([math.log(c1)]),
        np.array([cap]),
    )
    if invalid:
        raise ValueError(f"`d` must be >= 0 (inf allowed); got {d!r}")
    return out[0].reshape(d.shape)


@dataclass(frozen=True)
class ExponentialSpiral(SpiralRule):
    """Eb-SDA: exponential-based radius and angle, eq. (4), (7) and (8).

    ``r_i = (r_l - r_u) / (1 + r_c1 / exp(r_c2 d_i)) + r_u`` and likewise
    ``theta_i`` with ``th_l, th_u, th_c1, th_c2``. Points close in cost to
    the centre keep a radius near ``r_u``; points far from it jump towards
    it with radius near ``r_l``. Where ``d_i == 0`` exactly, the radius and
    the angle are drawn uniformly from ``[r_l, r_u]`` and ``[th_l, th_u]``,
    as the paper prescribes (radii first, then angles, from ``rng``). A
    non-finite cost gives ``d_i = inf``, hence ``r_l`` and ``th_l``.

    Defaults are the paper's: eq. (7) ``r_l=0.1, r_u=1, c1=100, c2=1.5``;
    eq. (8), garbled in print, read in the same form with ``th_l=0.1,
    th_u=2`` (radians), ``c1=10, c2=1``.

    ``scale_free=True`` (not the paper's; off by default) divides each
    deviation by the population's current cost spread, the largest finite
    ``d_i`` (worst finite cost minus the centre's), before eq. (4), so that
    multiplying the cost by any positive constant leaves the radii, the
    angles and hence the whole search unchanged. The paper's rule depends
    on the cost's scale through ``c2 d``.

    Parameters
    ----------
    r_l, r_u, r_c1, r_c2 : float
        Radius limits and constants of eq. (4) and (7).
    th_l, th_u, th_c1, th_c2 : float
        Angle limits (radians) and constants, eq. (8).
    scale_free : bool
        Divide the deviations by the population's cost spread first.

    Examples
    --------
    >>> import numpy as np
    >>> r, th = ExponentialSpiral()(np.array([1e300, np.inf]), np.random.default_rng(0))
    >>> r.tolist(), th.tolist()
    ([0.1, 0.1], [0.1, 0.1])
    """

    r_l: float = 0.1
    r_u: float = 1.0
    r_c1: float = 100.0
    r_c2: float = 1.5
    th_l: float = 0.1
    th_u: float = 2.0
    th_c1: float = 10.0
    th_c2: float = 1.0
    scale_free: bool = False

    def __post_init__(self):
        r_l, r_u = _check_interval(self.r_l, self.r_u, "r_l", "r_u", radius=True)
        th_l, th_u = _check_interval(self.th_l, self.th_u, "th_l", "th_u", radius=False)
        if not isinstance(self.scale_free, bool | np.bool_):
            raise TypeError(
                f"`scale_free` must be True or False; got {self.scale_free!r}"
            )
        object.__setattr__(self, "scale_free", bool(self.scale_free))
        values = {"r_l": r_l, "r_u": r_u, "th_l": th_l, "th_u": th_u}
        for name in ("r_c1", "r_c2", "th_c1", "th_c2"):
            values[name] = positive(getattr(self, name), name)
        for name, value in values.items():
            object.__setattr__(self, name, value)
        # Radius and angle evaluated together, as `exponential_rule` does.
        c1 = (values["r_c1"], values["th_c1"])
        c2 = (values["r_c2"], values["th_c2"])
        # Python floats: the cap may overflow to inf without a warning.
        cap = [
            max((_Z_CAP + math.log(a)) / b, 0.0) for a, b in zip(c1, c2, strict=True)
        ]
        consts = (
            np.array([r_l, th_l]),
            np.array([r_u - r_l, th_u - th_l]),
            np.array(c2),
            np.array([math.log(a) for a in c1]),
            np.array(cap),
        )
        object.__setattr__(self, "_consts", consts)

    def radius(self, d) -> np.ndarray:
        """Eq. (4)/(7) without the random draw at ``d == 0``."""
        return exponential_rule(d, self.r_l, self.r_u, self.r_c1, self.r_c2)

    def angle(self, d) -> np.ndarray:
        """Eq. (8) without the random draw at ``d == 0``."""
        return exponential_rule(d, self.th_l, self.th_u, self.th_c1, self.th_c2)

    def __call__(self, d, rng):
        d = _deviations(d)
        if self.scale_free:
            d = _relative(d)
        (r, theta), zeros, invalid = _kernels.exponential(d, *self._consts)
        if invalid:
            raise _bad_deviations(d)
        if zeros:
            zero = d == 0.0
            r[zero] = rng.uniform(self.r_l, self.r_u, zeros)
            theta[zero] = rng.uniform(self.th_l, self.th_u, zeros)
        return r, theta


@dataclass(frozen=True)
class LinearSpiral(SpiralRule):
    """Linear adaptive radius and angle (LASDA; our reading).

    The paper contrasts Eb-SDA with a linear adaptive rule without stating
    it. We read it as ``r_u`` at ``d = 0`` falling linearly to ``r_l`` at
    ``d >= d_max``, and the angle likewise from ``th_u`` to ``th_l``::

        r_i = r_u + (r_l - r_u) * min(d_i / d_max, 1)

    Parameters
    ----------
    r_l, r_u, th_l, th_u : float
        Limits, defaulting to Eb-SDA's (eq. (7)-(8)).
    d_max : float or None
        Deviation at which the lower limits are reached. ``None`` (default)
        uses each iteration's largest finite deviation, which makes the rule
        independent of the cost's scale: the worst finite point gets ``r_l``
        and the centre's ties get ``r_u``. ``inf`` deviations (non-finite
        costs) get the lower limits.

    Examples
    --------
    >>> import numpy as np
    >>> r, th = LinearSpiral()(np.array([0.0, 1.0, 2.0]), np.random.default_rng(0))
    >>> r.tolist()
    [1.0, 0.55, 0.1]
    """

    r_l: float = 0.1
    r_u: float = 1.0
    th_l: float = 0.1
    th_u: float = 2.0
    d_max: float | None = None

    def __post_init__(self):
        r_l, r_u = _check_interval(self.r_l, self.r_u, "r_l", "r_u", radius=True)
        th_l, th_u = _check_interval(self.th_l, self.th_u, "th_l", "th_u", radius=False)
        for name, value in {"r_l": r_l, "r_u": r_u, "th_l": th_l, "th_u": th_u}.items():
            object.__setattr__(self, name, value)
        if self.d_max is not None:
            object.__setattr__(self, "d_max", positive(self.d_max, "d_max"))

    def _fraction(self, d: np.ndarray) -> np.ndarray:
        d_max = self.d_max
        if d_max is None:
            finite = d[np.isfinite(d)]
            d_max = float(finite.max()) if finite.size else 0.0
        if d_max <= 0.0:
            return (d > 0.0).astype(np.float64)
        # Capping d first keeps d / d_max from overflowing for a tiny d_max.
        return np.minimum(d, d_max) / d_max

    def __call__(self, d, rng):
        d = _deviations(d)
        # min() propagates NaN, which then fails the comparison as well.
        if d.size and not d.min() >= 0.0:
            raise _bad_deviations(d)
        g = 1.0 - self._fraction(d)
        r = self.r_l + (self.r_u - self.r_l) * g
        theta = self.th_l + (self.th_u - self.th_l) * g
        return r, theta


class StepRateRule(ABC):
    """A spiral setting with one fixed rotation and a step rate per iteration.

    Every point moves as ``x_i(k+1) = x*(k) + r(k) R (x_i(k) - x*(k))`` with
    the same matrix ``R`` (:meth:`rotation`) and step rate ``r(k)``
    (:meth:`step_rate`), the form of Tamura & Yasuda's settings with
    convergence conditions (IEEE Trans. SMC: Systems, 2020). Subclass it to
    pass a custom setting as the ``method`` of :func:`spiralid.optim.minimize`.
    """

    def rotation(self, n: int) -> np.ndarray:
        """The rotation matrix ``R`` in dimension ``n``; default
        :func:`descent_rotation`."""
        return descent_rotation(n)

    @abstractmethod
    def step_rate(self, k: int, k_star: int, n: int, k_max: int) -> float:
        """Step rate ``r(k)`` in (0, 1].

        Parameters
        ----------
        k : int
            Current iteration, ``0 <= k < k_max``.
        k_star : int
            Last iteration at which the centre moved (0 at the start).
        n : int
            Dimension.
        k_max : int
            The search's iteration budget.
        """


def descent_rotation(n: int) -> np.ndarray:
    """Tamura & Yasuda's rotation for the periodic-descent-direction setting.

    ``R = [[0^T, -1], [I_(n-1), 0]]``: coordinate ``j`` moves to ``j + 1``
    and the last returns, negated, to the first. It is orthogonal with
    ``R^n = -I`` and ``R^(2n) = I``, so a spiral vector ``R^k d`` runs
    through ``d, R d, ..., R^(n-1) d`` and their negatives: with the rank
    condition of :func:`rank_condition`, these ``2n`` directions span the
    space positively and one of them descends in every ``2n`` iterations.

    Parameters
    ----------
    n : int
        Dimension, ``n >= 1`` (``n = 1`` gives ``[[-1.0]]``).

    Examples
    --------
    >>> descent_rotation(3).astype(int).tolist()
    [[0, 0, -1], [1, 0, 0], [0, 1, 0]]
    """
    n = integer(n, "n", 1)
    out = np.zeros((n, n))
    out[0, n - 1] = -1.0
    out[np.arange(1, n), np.arange(n - 1)] = 1.0
    return out


def rank_condition(points, rotation=None) -> bool:
    """The initial-point condition of Tamura & Yasuda's settings.

    ``min_i max_j rank[d_ji, R d_ji, ..., R^(2n-1) d_ji] = n`` with
    ``d_ji = x_j(0) - x_i(0)``: whichever point becomes the centre, some
    other point's spiral vectors span the space. Uniformly drawn points
    satisfy it with probability one.

    Parameters
    ----------
    points : array_like, shape (m, n)
        Initial points, ``m >= 2``.
    rotation : array_like, shape (n, n), optional
        ``R``; default :func:`descent_rotation`.

    Examples
    --------
    >>> import numpy as np
    >>> rank_condition(np.random.default_rng(0).uniform(size=(5, 3)))
    True
    >>> rank_condition([[0.0, 0.0, 0.0], [1.0, -1.0, 1.0]])  # eigenvector of R
    False
    """
    x = real_array(points, "points")
    if x.ndim != 2 or x.shape[0] < 2:
        raise ValueError(f"`points` must have shape (m, n), m >= 2; got {x.shape}")
    m, n = x.shape
    R = descent_rotation(n) if rotation is None else real_array(rotation, "rotation")
    if R.shape != (n, n):
        raise ValueError(f"`rotation` must have shape ({n}, {n}); got {R.shape}")
    for i in range(m):
        d = x - x[i]
        # Columns R^k d_j for k < 2n, all j at once: shape (m, n, 2n).
        krylov = np.empty((m, n, 2 * n))
        for k in range(2 * n):
            krylov[:, :, k] = d
            d = d @ R.T
        ranks = np.linalg.matrix_rank(np.delete(krylov, i, axis=0))
        if ranks.max() < n:
            return False
    return True


def _delta(value, name: str) -> float:
    value = real(value, name)
    if not 0.0 < value < 1.0:
        raise ValueError(f"`{name}` must be in (0, 1); got {value!r}")
    return value


@dataclass(frozen=True)
class PeriodicSpiral(StepRateRule):
    """Periodic-descent-direction setting (Tamura & Yasuda 2020).

    ``R`` is :func:`descent_rotation` and the step rate is constant,
    ``r = delta^(1 / k_max)``, so that the spiral has shrunk by exactly
    ``delta`` when the iteration budget ``k_max`` runs out.

    Parameters
    ----------
    delta : float
        Final contraction in (0, 1); default 1e-3, the value the setting
        suggests.

    Examples
    --------
    >>> rule = PeriodicSpiral(delta=1e-3)
    >>> round(rule.step_rate(0, 0, 2, 100) ** 100, 12)
    0.001
    """

    delta: float = 1e-3

    def __post_init__(self):
        object.__setattr__(self, "delta", _delta(self.delta, "delta"))

    def step_rate(self, k, k_star, n, k_max):
        return self.delta ** (1.0 / k_max)


@dataclass(frozen=True)
class ConvergentSpiral(StepRateRule):
    """Convergence setting (Tamura & Yasuda 2020).

    ``R`` is :func:`descent_rotation`; the step rate is ``r(k) = 1`` while
    ``k <= k* + 2n - 1``, ``k*`` being the last iteration that moved the
    centre, and ``h < 1`` after that. With ``r = 1`` each point's offset
    from an unchanged centre runs through its ``2n`` periodic directions
    ``R^k d``; only when none of them improved does the spiral contract by
    ``h``. This is a direct search with a positive spanning set, so for a
    continuously differentiable cost with bounded level sets the centre
    approaches a stationary point as the iterations go on.

    Parameters
    ----------
    h : float or None
        Contraction in (0, 1) after ``2n`` iterations without a centre
        update. ``None`` (default) uses ``delta^(1 / k_max)`` as the setting
        suggests.
    delta : float
        As in :class:`PeriodicSpiral`, for the default ``h``.

    Examples
    --------
    >>> rule = ConvergentSpiral(h=0.5)
    >>> [rule.step_rate(k, 0, 2, 100) for k in (0, 3, 4)]
    [1.0, 1.0, 0.5]
    """

    h: float | None = None
    delta: float = 1e-3

    def __post_init__(self):
        if self.h is not None:
            object.__setattr__(self, "h", _delta(self.h, "h"))
        object.__setattr__(self, "delta", _delta(self.delta, "delta"))

    def step_rate(self, k, k_star, n, k_max):
        if k <= k_star + 2 * n - 1:
            return 1.0
        return self.delta ** (1.0 / k_max) if self.h is None else self.h
