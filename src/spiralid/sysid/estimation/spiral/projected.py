"""Spiral search over denominators with the numerator projected out, a
memetic local step, and starts from the measured frequency response.

:func:`projected_spiral` runs a spiral optimiser
(:class:`spiralid.optim.SpiralSearch`) over the coordinates of a
denominator parametrisation (e.g. :class:`~spiralid.sysid.estimation.linear.modal.
ModalParametrization`), scoring each candidate with
:class:`~spiralid.sysid.estimation.linear.varpro.ProjectedCost` (the paper's cost at the
least-squares numerator). Two optional ingredients:

- ``polish_every=k``: every ``k`` iterations (and once at the end, the
  best point) the centre is polished by a few Levenberg-Marquardt steps of the projected
  problem (:func:`~spiralid.sysid.estimation.linear.varpro.gauss_newton_polish`) and
  moved to the polished point if that is better: a memetic algorithm (a
  population search with individual learning; Moscato 1989). The spiral
  moves then rotate about the polished centre.
- :func:`frequency_seeds`: initial points whose natural frequencies sit at
  the peaks of the estimated frequency response ``|P_uy / P_uu|``.

The evaluation budget counts every cost evaluation: the population's, each
trial point of the polish and each of its Jacobians (one evaluation each:
a Jacobian costs about as much as a few cost evaluations of one candidate,
but far less than a population step).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy import signal

from spiralid._checks import integer
from spiralid.optim import OptimiserResult, Restarts, SpiralSearch, minimize

from ...data import IOData
from ...spectra import PSD, default_nperseg, find_resonances
from ..linear.varpro import ProjectedCost, gauss_newton_polish

__all__ = ["RTOL", "PatientRestarts", "frequency_seeds", "projected_spiral"]

#: A population "found a new basin" when it lowered the best cost by more
#: than this share of it. Two runs into one minimum end within the polish's
#: tolerances of each other (about 1e-8 of the cost); a different minimum of
#: the simulation error differs by far more than 1e-6.
RTOL = 1e-6


@dataclass(frozen=True)
class PatientRestarts(Restarts):
    """Restarts that also end the search (:func:`projected_spiral`): once
    ``patience`` populations in a row have stalled without lowering the
    best cost by more than ``rtol`` of it, the search stops before its
    budget.

    Each such population fell into a basin already found (or a worse one),
    and the restarts are drawn alike, so more of them are not expected to
    pay. The first population counts too: with ``patience=1`` a search
    whose first population ends at its safe start's minimum and whose first
    restart finds nothing lower stops there. With patience a population
    also stalls when its best falls by no more than ``rtol`` (not 1e-9)
    over ``stall`` iterations: smaller gains are the final polish's work.

    Parameters
    ----------
    growth, tol_radius, stall
        As :class:`~spiralid.optim.Restarts`.
    patience : int
        Populations in a row without a new basin that stop the search.
    rtol : float
        A new basin lowers the best cost by more than this share of it
        (default :data:`RTOL`).
    """

    patience: int = 1
    rtol: float = RTOL

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "patience", integer(self.patience, "patience", 1))
        rtol = float(self.rtol)
        if not 0.0 < rtol < 1.0:
            raise ValueError(f"`rtol` must be in (0, 1); got {self.rtol!r}")
        object.__setattr__(self, "rtol", rtol)


def frequency_seeds(data: IOData, parametrization, m: int, rng=None) -> np.ndarray:
    """``m`` modal starting points placed at the frequency response's peaks.

    The response is the H1 estimate ``P_uy / P_uu`` (Welch averages,
    Hann window, the segment length of :func:`~spiralid.sysid.spectra.psd`);
    its most prominent peaks (:func:`~spiralid.sysid.spectra.find_resonances`,
    at most one per second-order section) give the sections' frequencies,
    each jittered uniformly within one resolution cell. Sections without a
    peak get a uniform frequency; every damping is log-uniform in
    ``[1e-2.5, 1e-0.5]`` (the lightly damped modes a peak shows); first-order
    poles are uniform.

    Parameters
    ----------
    data : IOData
    parametrization : ModalParametrization
    m : int
        Number of points.
    rng : int, Generator or None

    Returns
    -------
    ndarray, shape (m, na), inside ``parametrization.bounds``
    """
    m = integer(m, "m", 1)
    gen = np.random.default_rng(rng)
    fs = 1.0 / data.ts
    nperseg = default_nperseg(data.n)
    kw = dict(fs=fs, window="hann", nperseg=nperseg, nfft=4 * nperseg)
    f, puy = signal.csd(data.u, data.y, **kw)
    _, puu = signal.welch(data.u, **kw)
    with np.errstate(divide="ignore", invalid="ignore"):
        gain2 = np.where(puu > 0, np.abs(puy / puu) ** 2, 0.0)
    spectrum = PSD(f=f, p=gain2, fs=fs, nperseg=nperseg, resolution=fs / nperseg)
    s = parametrization.n_sections
    peaks = find_resonances(spectrum, n_peaks=max(s, 1)).frequency[:s]
    box = parametrization.bounds
    pts = parametrization.initial_points(m, gen)
    k = peaks.size
    jitter = gen.uniform(-0.5, 0.5, size=(m, k)) * spectrum.resolution
    pts[:, :k] = peaks + jitter
    pts[:, s : 2 * s] = gen.uniform(-2.5, -0.5, size=(m, s))
    return np.clip(pts, box[:, 0], box[:, 1])


def projected_spiral(
    cost: ProjectedCost,
    parametrization,
    method,
    *,
    n_points: int,
    max_nfev: int,
    polish_every: int | None,
    polish_nfev: int,
    restarts: Restarts | None,
    x0=None,
    max_iter: int | None = None,
    callback=None,
    rng=None,
) -> OptimiserResult:
    """Spiral search over denominator coordinates, numerator projected out.

    :func:`spiralid.optim.minimize` drives the search (its budget); the
    memetic polish and the restarts are its callback, which then calls
    `callback`.
    The settings have no defaults here: the recommended method's are
    :func:`~spiralid.sysid.estimation.spiral.recommended._estimate_recommended`'s.

    Parameters
    ----------
    cost : ProjectedCost
    parametrization
        Denominator coordinates: ``bounds``, ``to_denominator``, and
        ``jacobian`` when `polish_every` is set.
    method : str or SpiralRule
        As in :func:`spiralid.optim.minimize` (``"sda"``, ``"ebsda"``...).
    n_points : int
        Population size.
    max_nfev : int
        Budget of cost evaluations, polish included; no population step or
        polish is started that would exceed it.
    polish_every : int or None
        Polish the centre every this many iterations and the best point
        once at the end; ``None``: a pure spiral search.
    polish_nfev : int
        Evaluations per polish.
    restarts : Restarts or None
        Start a fresh population of ``restarts.next_size`` points, uniform
        in the box (:meth:`~spiralid.optim.SpiralSearch.restart`), when the
        best cost has not fallen by more than 1e-9 of itself for
        ``restarts.stall`` iterations (a move of the centre by the polish
        does not count: its ever smaller steps would keep a stalled
        population alive); the best point over all populations is
        returned. ``tol_radius`` is not used (the polished centre is not a
        collapse test). A :class:`PatientRestarts` also stops the search
        before the budget once its ``patience`` populations in a row found
        no lower basin. ``None``: no restarts.
    x0 : array_like, shape (k, na), optional
        Initial points (the rest of the population is uniform in the box).
    max_iter : int, optional
        Cap on the iterations (all populations together).
    callback : callable, optional
        As in :func:`spiralid.optim.minimize`: after every iteration with
        the result so far (``x`` in the searched coordinates); returning
        True stops the search.
    rng : int, Generator or None
    Returns
    -------
    OptimiserResult
        ``x`` the ARX theta ``[a, b]``, ``fun`` its cost (eq. (2)-(3)),
        ``z`` the searched coordinates, ``status`` (1: budget used, 2:
        `max_iter`, 0: the callback or a :class:`PatientRestarts`'
        patience), ``n_polish`` (polishes that moved the centre),
        ``populations`` (``(nfev, cost)`` at which each population stalled
        or the search ended, its centre's cost), ``converged`` (whether the
        patience stopped it) and the rest of
        :func:`~spiralid.optim.minimize`'s result.
    """
    t_start = time.perf_counter()
    n_points = integer(n_points, "n_points", 2)
    max_nfev = integer(max_nfev, "max_nfev", n_points)
    polish_nfev = integer(polish_nfev, "polish_nfev", 2)
    if polish_every is not None:
        polish_every = integer(polish_every, "polish_every", 1)
    if restarts is not None and not isinstance(restarts, Restarts):
        raise TypeError(f"`restarts` must be a Restarts or None; got {restarts!r}")
    max_iter = max_nfev if max_iter is None else integer(max_iter, "max_iter", 1)
    step = _Memetic(
        cost,
        parametrization,
        polish_every=polish_every,
        polish_nfev=polish_nfev,
        max_nfev=max_nfev,
        restarts=restarts,
        callback=callback,
    )

    def fun(z):
        return cost(parametrization.to_denominator(z))

    res = minimize(
        fun,
        parametrization.bounds,
        method,
        n_points=n_points,
        max_iter=max_iter,
        max_nfev=max_nfev,
        rng=rng,
        vectorized=True,
        x0=x0,
        callback=step,
        options={"bounds_policy": "clip"},
    )
    return step.finish(res, t_start)


class _Memetic:
    """The callback :func:`projected_spiral` gives
    :func:`~spiralid.optim.minimize`: after each iteration the polish of
    the centre, the restart of a stalled population (and the patience's
    stop), then the caller's `callback`; and, after the search, the final
    polish and the result. It keeps the record of the populations."""

    def __init__(
        self,
        cost: ProjectedCost,
        parametrization,
        *,
        polish_every: int | None,
        polish_nfev: int,
        max_nfev: int,
        restarts: Restarts | None,
        callback,
    ) -> None:
        self.cost, self.parametrization = cost, parametrization
        self.polish_every, self.polish_nfev = polish_every, polish_nfev
        self.max_nfev, self.restarts, self.callback = max_nfev, restarts, callback
        patient = isinstance(restarts, PatientRestarts)
        self.patience = restarts.patience if patient else None
        self.rtol = restarts.rtol if self.patience is not None else RTOL
        # With `patience` a population whose best falls by less than `rtol`
        # has converged as far as the search can tell (the final polish
        # takes it further, to its tolerances); without, only a 1e-9 fall
        # is none.
        self.progress = 1e-9 if self.patience is None else max(float(self.rtol), 1e-9)
        self.n_dim = parametrization.bounds.shape[0]
        self.n_polish = 0
        self.stalled, self.before = 0, np.inf
        # The best cost when the current population started, and how many
        # populations in a row have ended without lowering it (`patience`).
        self.populations: list[tuple[int, float]] = []
        self.at_start, self.idle = np.inf, 0
        self.converged, self.ended = False, False
        self.tail = (0, np.inf)

    def __call__(self, intermediate):
        called = time.perf_counter()
        search: SpiralSearch = intermediate.search
        self._polish(search)
        if self._restart(search):
            return True
        if self.callback is None:
            return False
        # The caller's callback sees the search after the polish and restart.
        now = search.result(
            "running", intermediate.elapsed + time.perf_counter() - called
        )
        now.search = search
        return self.callback(now)

    def _polish(self, search: SpiralSearch) -> None:
        """Polish the centre when it is due and the budget allows."""
        due = self.polish_every and search.nit % self.polish_every == 0
        if due and search.nfev + self.polish_nfev <= self.max_nfev:
            res = gauss_newton_polish(
                self.cost, self.parametrization, search.centre, self.polish_nfev
            )
            self.n_polish += search.move_centre(res.x, res.fun, nfev=res.nfev)

    def _restart(self, search: SpiralSearch) -> bool:
        """Restart a stalled population; whether the patience stops the
        search."""
        # Progress is a fall of the best cost by more than `progress` of it:
        # the polish moves the centre by less at every call near a minimum,
        # and that must not keep a stalled population alive.
        if search.fun < self.before * (1.0 - self.progress):
            self.stalled = 0
        else:
            self.stalled += 1
        self.before = min(self.before, search.fun)
        self.tail = (search.nfev, search.centre_cost)
        restarts = self.restarts
        if restarts is None or self.stalled < restarts.stall_for(self.n_dim):
            return False
        if not self.ended:
            self.ended = True
            self.populations.append((search.nfev, search.centre_cost))
            # A population that ends within `rtol` of the best it started
            # from found no new basin (the first starts from none, so it
            # always counts as new).
            no_new = search.fun >= self.at_start * (1.0 - self.rtol)
            self.idle = self.idle + 1 if no_new else 0
            self.at_start = min(self.at_start, search.fun)
            if self.patience is not None and self.idle >= self.patience:
                self.converged = True
                return True
        size = restarts.next_size(search.n_points)
        if search.nfev + 2 * size - 1 <= self.max_nfev:
            search.restart(size)
            self.stalled, self.ended = 0, False
        return False

    def finish(self, res: OptimiserResult, t_start: float) -> OptimiserResult:
        """`res` of the search completed: the final polish of its best
        point (budget allowing), the ARX theta and the record."""
        cost, par = self.cost, self.parametrization
        z, nfev = res.x, res.nfev
        if not self.ended and np.isfinite(self.tail[1]):
            self.populations.append(self.tail)
        if (
            self.polish_every
            and (res.status != 0 or self.converged)
            and nfev + self.polish_nfev <= self.max_nfev
        ):
            end = gauss_newton_polish(cost, par, z, self.polish_nfev)
            nfev += end.nfev
            if end.fun < res.fun:
                z = end.x
                self.n_polish += 1
        f_best, b_best = cost.evaluate(par.to_denominator(z)[None, :])
        res.update(
            x=np.r_[par.to_denominator(z), b_best[0]],
            fun=float(f_best[0]),
            z=z,
            nfev=nfev,
            n_polish=self.n_polish,
            populations=self.populations,
            converged=self.converged,
            elapsed=time.perf_counter() - t_start,
        )
        if self.converged:
            res.message = (
                f"Converged: {self.patience} population(s) in a row found no "
                f"basin lower than the best by more than {self.rtol:g} of its "
                "cost."
            )
        if res.history.size:
            res.history[-1] = min(res.history[-1], res.fun)
        return res
