"""What a population search moves: parametrisations of an ARX model.

A parametrisation maps the searched coordinates ``x`` to the ARX parameter
vector ``theta = [a_1..a_na, b_0..b_(nb-1)]`` that the cost, the model and
every result hold. Each one knows its default search box, its stable initial
points, its map to theta and back (the back map seeds a search with a known
model, see the safe start in :mod:`spiralid.sysid.estimation.core.estimators`).

``"coefficients"`` (paper-faithful; the default)
    ``x = theta``: the optimiser moves the raw coefficients and unstable
    candidates pay the penalty of eq. (3). The initial denominators are
    drawn uniformly in reflection coefficients and mapped by the step-up
    recursion, so every initial point is stable ("feasible").
``"modal"`` (numerator projected out)
    ``x`` = the denominator's modes, ``[f_1..f_S, log10 zeta_1..log10
    zeta_S, p_1..p_R]``
    (:class:`~spiralid.sysid.estimation.linear.modal.ModalParametrization`:
    second-order sections in natural frequency (Hz) and log damping ratio,
    stable by construction), and no numerator: for every candidate
    denominator the numerator is the least-squares solution of the
    simulation error from rest (:class:`~spiralid.sysid.ProjectedCost`),
    so a search moves ``na`` coordinates, not ``na + nb``. Only for the
    simulation error from rest (the cost's ``predictor="simulation"``,
    ``initial="rest"``).
``"reflection"`` (beyond the paper)
    ``x = [k_1..k_na, b]``; each ``k`` is folded into ``(-1, 1)``
    (:func:`~spiralid.sysid.models.polynomials.fold_reflection`, clipped to
    ``KMAX = 1 - 1e-6``) and mapped by step-up, so every candidate is stable
    and the penalty never fires. The initial points are uniform in the box.

A stability margin ``r_max`` (``max_radius``; identify's
``max_time_constant``, see :mod:`~spiralid.sysid.estimation.linear.margin`) is
applied inside ``"modal"`` (every pole scaled by ``r_max``) and
``"reflection"`` (the step-up polynomial's roots ``p -> r_max p``, i.e.
``a_k -> a_k r_max^k``), so every candidate has its poles inside radius
``r_max``; ``"coefficients"``, the paper's, has none (eq. (3)'s penalty).

Default box: ``|a_i| <= binom(na, i)`` (every stable monic polynomial of
degree na lies in that box, so it loses no stable model), ``k_i`` in
``[-1, 1]``, and ``|b_j| <= s`` with ``s = 2 max_j |b_j^LS|`` scaled from
the least-squares estimate (``2 rms(y) / rms(u)`` if that is zero). The RMS
ratio alone is a poor scale for a sparse input: for the simulated rig's
bang-bang record it is 567 while the largest LS numerator coefficient is 43.

Adding a parametrisation
------------------------
Subclass :class:`Parametrization` in this module, set ``name``, implement
:meth:`~Parametrization.denominator_bounds` (or all of
:meth:`~Parametrization.default_bounds` when the search does not hold the
numerator), :meth:`~Parametrization.to_theta` and
:meth:`~Parametrization.from_theta` (override
:meth:`~Parametrization.initial_points` for stable initial points and
:meth:`~Parametrization.objective` when the cost of a population can be
computed faster than ``cost(to_theta(x))``), and add one entry to
:data:`PARAMETRIZATIONS`. ``identify(parametrization=...)``, the command
line's ``--parametrization`` choices and ``default_bounds`` read that table;
nothing else lists parametrisations. Heavy mathematics (a modal map,
variable projection) can live in a module of its own that this one imports.
"""

from __future__ import annotations

from math import comb
from typing import ClassVar

import numpy as np

from spiralid._checks import one_of
from spiralid.choices import PARAMETRIZATION_NAMES, require_names

from ...data import IOData
from ...models.arx import ARX, arx_least_squares
from ...models.polynomials import fold_reflection, step_down, step_up
from .margin import project_denominator, scaled, unscaled

__all__ = [
    "DEFAULT_PARAMETRIZATION",
    "KMAX",
    "PARAMETRIZATIONS",
    "Coefficients",
    "Modal",
    "Parametrization",
    "Reflection",
    "default_bounds",
    "feasible_initial_points",
    "make_parametrization",
    "stabilise",
]

DEFAULT_PARAMETRIZATION = "coefficients"

# Largest |k| of a stable-by-construction denominator: reflection search,
# output error and the stabilised least-squares start.
KMAX = 1.0 - 1e-6


class Parametrization:
    """Searched coordinates ``x`` of an ARX model on one record.

    Parameters
    ----------
    data : IOData
        The estimation record (scales the default numerator box).
    arx : ARX
        The model structure.
    max_radius : float, optional
        A stability margin ``r_max``: every candidate's poles inside that
        radius (``"modal"`` and ``"reflection"`` only; see the module
        docstring). Default None: the unit circle.

    Attributes
    ----------
    name : str
        Its key in :data:`PARAMETRIZATIONS`.
    n_search : int
        Number of searched coordinates (``arx.n_params`` unless a
        parametrisation solves for some of theta itself).
    """

    name: ClassVar[str] = ""
    # Whether the parametrisation can keep the poles inside a margin.
    takes_margin: ClassVar[bool] = False

    def __init__(self, data: IOData, arx: ARX, max_radius: float | None = None):
        if max_radius is not None and not self.takes_margin:
            raise ValueError(
                f"`parametrization` {self.name!r} has no stability margin; "
                "use 'modal' or 'reflection'"
            )
        self.data = data
        self.arx = arx
        self.max_radius = max_radius
        self._theta_ls: np.ndarray | None = None

    @property
    def n_search(self) -> int:
        return self.arx.n_params

    @property
    def theta_ls(self) -> np.ndarray:
        """The least-squares estimate (computed once)."""
        if self._theta_ls is None:
            self._theta_ls = arx_least_squares(self.data, self.arx)
        return self._theta_ls

    def numerator_scale(self) -> float:
        """``s = 2 max |b^LS|`` (``2 rms(y) / rms(u)`` if that is zero)."""
        s = 2.0 * float(np.max(np.abs(self.theta_ls[self.arx.na :])))
        if s == 0.0:
            # An exactly zero estimate gives no scale: fall back to the RMS ratio.
            y, u = self.data.y, self.data.u
            s = 2.0 * float(np.sqrt(np.mean(y**2) / np.mean(u**2)))
        return s

    def default_bounds(self) -> np.ndarray:
        """The default search box, shape ``(n_search, 2)``: the denominator's
        box above ``|b_j| <= s`` (:meth:`numerator_scale`)."""
        s = self.numerator_scale()
        numerator = np.tile([-s, s], (self.arx.nb, 1))
        return np.concatenate([self.denominator_bounds(), numerator])

    def denominator_bounds(self) -> np.ndarray:
        """The denominator's part of the default box, shape ``(na, 2)``."""
        raise NotImplementedError

    def initial_points(self, box: np.ndarray, m: int, rng) -> np.ndarray | None:
        """``m`` initial points in `box`, or None to let the optimiser draw
        them uniformly in the box."""
        return None

    def to_theta(self, x) -> np.ndarray:
        """Searched ``x`` -> ARX theta; ``(m, n_search)`` gives ``(m, p)``,
        a 1-D ``x`` a 1-D theta."""
        raise NotImplementedError

    def from_theta(self, theta) -> np.ndarray:
        """ARX theta -> searched ``x`` with ``to_theta(x) == theta`` (up to
        rounding) for a stable theta; an unstable one is stabilised first."""
        raise NotImplementedError

    def objective(self, cost):
        """The searched function: the cost of a population ``x`` (m, n_search)."""

        def fun(x):
            return cost(self.to_theta(x))

        return fun


class Coefficients(Parametrization):
    """``x = theta``, the paper's search (see the module docstring)."""

    name = "coefficients"

    def denominator_bounds(self) -> np.ndarray:
        na = self.arx.na
        half = np.array([float(comb(na, i + 1)) for i in range(na)])
        return np.column_stack([-half, half]).reshape(na, 2)

    def initial_points(self, box: np.ndarray, m: int, rng) -> np.ndarray:
        return feasible_initial_points(box, self.arx, m, rng)

    def to_theta(self, x) -> np.ndarray:
        return np.asarray(x, dtype=float)

    def from_theta(self, theta) -> np.ndarray:
        th = np.asarray(theta, dtype=float)
        na = self.arx.na
        return np.r_[step_up(stabilise(th, self.arx)[:na]), th[na:]]

    def objective(self, cost):
        # The cost itself: no per-call copy of the population.
        return cost


class Reflection(Parametrization):
    """``x = [k, b]``, stable by construction (see the module docstring)."""

    name = "reflection"
    takes_margin = True

    def denominator_bounds(self) -> np.ndarray:
        return np.tile([-1.0, 1.0], (self.arx.na, 1))

    def to_theta(self, x) -> np.ndarray:
        xx = np.asarray(x, dtype=float)
        x2 = np.atleast_2d(xx)
        na = self.arx.na
        a = step_up(fold_reflection(x2[:, :na], KMAX))
        if self.max_radius is not None:
            a = unscaled(a, self.max_radius)
        theta = np.concatenate([a, x2[:, na:]], axis=1)
        return theta[0] if xx.ndim == 1 else theta

    def from_theta(self, theta) -> np.ndarray:
        th = np.asarray(theta, dtype=float)
        if self.max_radius is None:
            return stabilise(th, self.arx)
        na = self.arx.na
        a = project_denominator(th[:na], self.max_radius, KMAX)
        k = step_down(scaled(a, self.max_radius)) if na else a
        return np.r_[k, th[na:]]


class Modal(Parametrization):
    """Modal denominator, numerator projected out (see the module docstring)."""

    name = "modal"
    takes_margin = True

    def __init__(self, data: IOData, arx: ARX, max_radius: float | None = None):
        super().__init__(data, arx, max_radius)
        from .modal import ModalParametrization

        if arx.na == 0:
            raise ValueError(
                f"`parametrization` 'modal' needs a denominator; got {arx} (na = 0)"
            )
        self.modes = ModalParametrization(arx.na, data.ts, max_radius=max_radius)
        self._projected = None

    @property
    def n_search(self) -> int:
        return self.arx.na

    def projected(self, cost=None):
        """The :class:`~spiralid.sysid.estimation.linear.varpro.ProjectedCost` of this
        record, with `cost`'s gain and penalty (default: the paper's
        defaults)."""
        from .varpro import ProjectedCost

        if cost is None:
            if self._projected is None:
                self._projected = ProjectedCost(self.arx, self.data)
            return self._projected
        return ProjectedCost(
            self.arx,
            self.data,
            gain=cost.w,
            penalty=cost.penalty,
            predictor=cost.predictor,
            initial=cost.initial,
        )

    def default_bounds(self) -> np.ndarray:
        return self.modes.bounds.copy()

    def to_theta(self, x) -> np.ndarray:
        xx = np.asarray(x, dtype=float)
        a = self.modes.to_denominator(np.atleast_2d(xx))
        theta = np.concatenate([a, self.projected().numerator(a)], axis=1)
        return theta[0] if xx.ndim == 1 else theta

    def from_theta(self, theta) -> np.ndarray:
        th = np.asarray(theta, dtype=float)
        return self.modes.from_denominator(th[: self.arx.na])

    def objective(self, cost):
        projected = self.projected(cost)
        modes = self.modes

        def fun(x):
            return projected(modes.to_denominator(x))

        return fun


# One entry per parametrisation; its key is the name users pass.
PARAMETRIZATIONS: dict[str, type[Parametrization]] = {
    Coefficients.name: Coefficients,
    Reflection.name: Reflection,
    Modal.name: Modal,
}
require_names(
    PARAMETRIZATIONS, PARAMETRIZATION_NAMES, "spiralid.sysid.PARAMETRIZATIONS"
)


def make_parametrization(
    name, data: IOData, arx: ARX, max_radius: float | None = None
) -> Parametrization:
    """The parametrisation called `name` on this record and structure, with
    the stability margin `max_radius` (``"modal"`` and ``"reflection"``)."""
    one_of(name, "parametrization", PARAMETRIZATIONS)
    return PARAMETRIZATIONS[name](data, arx, max_radius)


def default_bounds(
    data: IOData, arx: ARX, parametrization: str = DEFAULT_PARAMETRIZATION
) -> np.ndarray:
    """The default search box, shape (p, 2) (see the module docstring).

    Parameters
    ----------
    data : IOData
        The estimation record (it sets the numerator's scale).
    arx : ARX
        The structure.
    parametrization : str, default "coefficients"
        The parametrisation's name (:data:`PARAMETRIZATIONS`).

    Returns
    -------
    ndarray, shape (p, 2)
        Lower and upper bound of every searched parameter.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(200)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> default_bounds(IOData(u, y, ts=1.0), ARX(2, 2, 1))[:2]
    array([[-2.,  2.],
           [-1.,  1.]])
    """
    return make_parametrization(parametrization, data, arx).default_bounds()


def feasible_initial_points(box: np.ndarray, arx: ARX, m: int, rng=None) -> np.ndarray:
    """``m`` initial points "in the feasible region", as the paper asks.

    Denominators: reflection coefficients uniform in (-1, 1) mapped by
    step-up, so every point is stable (a uniform draw in the coefficient box
    almost never is for na = 8); numerators uniform in their box.

    Returns
    -------
    ndarray, shape (m, p)
    """
    gen = np.random.default_rng(rng)
    na = arx.na
    k = gen.uniform(-1.0, 1.0, size=(m, na))
    b = gen.uniform(box[na:, 0], box[na:, 1], size=(m, arx.nb))
    return np.clip(np.concatenate([step_up(k), b], axis=1), box[:, 0], box[:, 1])


def stabilise(theta: np.ndarray, arx: ARX) -> np.ndarray:
    """Reflect poles with ``|z| >= 1`` into the unit circle; return ``[k, b]``.

    A pole ``z`` outside goes to ``1 / conj(z)``; one on the circle is
    pulled just inside; every ``|k|`` is then at most :data:`KMAX`.
    """
    na = arx.na
    a, b = theta[:na], theta[na:]
    if na == 0:
        return theta.copy()
    if not arx.is_stable(theta):
        roots = np.roots(np.r_[1.0, a])
        mag = np.abs(roots)
        out = mag >= 1.0
        roots[out] = 1.0 / np.conj(roots[out])
        # A root on the circle reflects onto itself: pull it just inside.
        roots = np.where(np.abs(roots) >= KMAX, roots * KMAX / np.abs(roots), roots)
        a = np.real(np.poly(roots))[1:]
    k = step_down(a)
    k = np.clip(np.nan_to_num(k, nan=0.0), -KMAX, KMAX)
    return np.r_[k, b]
