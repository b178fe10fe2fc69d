"""Spiral search over denominators with the numerator projected out, a
memetic local step, and starts from the measured frequency response.

:func:`projected_spiral` runs a spiral optimiser
(:class:`spiralid.optim.SpiralSearch`) over the coordinates of a
denominator parametrisation (e.g. :class:`~spiralid.sysid.estimation.modal.
ModalParametrization`), scoring each candidate with
:class:`~spiralid.sysid.estimation.varpro.ProjectedCost` (the paper's cost at the
least-squares numerator). Two optional ingredients:

- ``polish_every=k``: every ``k`` iterations (and once at the end) the
  centre is polished by a few Levenberg-Marquardt steps of the projected
  problem (:func:`~spiralid.sysid.estimation.varpro.gauss_newton_polish`) and moved to
  the polished point if that is better: a memetic algorithm (a population
  search with individual learning; Moscato 1989). The spiral moves then
  rotate about the polished centre.
- :func:`frequency_seeds`: initial points whose natural frequencies sit at
  the peaks of the estimated frequency response ``|P_uy / P_uu|``.

The evaluation budget counts every cost evaluation: the population's, each
trial point of the polish and each of its Jacobians (one evaluation each:
a Jacobian costs about as much as a few cost evaluations of one candidate,
but far less than a population step).
"""

from __future__ import annotations

import time

import numpy as np
from scipy import optimize, signal

from spiralid._checks import integer
from spiralid.optim import SpiralSearch

from ..data import IOData
from ..spectra import PSD, default_nperseg, find_resonances
from .varpro import ProjectedCost, gauss_newton_polish

__all__ = ["frequency_seeds", "projected_spiral"]


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
    method="sda",
    *,
    n_points: int = 50,
    max_nfev: int = 20_000,
    polish_every: int | None = None,
    polish_nfev: int = 10,
    x0=None,
    restart_after: int | None = None,
    restart_points=None,
    max_iter: int | None = None,
    callback=None,
    rng=None,
) -> optimize.OptimizeResult:
    """Spiral search over denominator coordinates, numerator projected out.

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
    polish_every : int, optional
        Polish the centre every this many iterations and once at the end;
        ``None``: a pure spiral search.
    polish_nfev : int
        Evaluations per polish.
    x0 : array_like, shape (k, na), optional
        Initial points (the rest of the population is uniform in the box).
    restart_after : int, optional
        Start a fresh population (uniform in the box plus
        `restart_points`) when the centre has not improved for this many
        iterations; the best point over all populations is returned.
        ``None``: no restarts.
    restart_points : array_like, shape (k, na), optional
        Initial points of every restarted population.
    max_iter : int, optional
        Cap on the iterations (all populations together).
    callback : callable, optional
        ``callback(intermediate)`` after every iteration with an
        ``OptimizeResult`` holding ``x`` (coordinates) and ``fun`` (best so
        far); returning True stops the search.
    rng : int, Generator or None

    Returns
    -------
    OptimizeResult
        ``x`` the ARX theta ``[a, b]``, ``fun`` its cost (eq. (2)-(3)),
        ``z`` the searched coordinates, ``nfev``, ``nit``, ``n_polish``
        (polishes that moved the centre), ``history`` (best cost after each
        iteration), ``status`` (1: budget used, 2: `max_iter`, 0: the
        callback), ``message``, ``success``,
        ``elapsed``.
    """
    t_start = time.perf_counter()
    n_points = integer(n_points, "n_points", 2)
    max_nfev = integer(max_nfev, "max_nfev", n_points)
    polish_nfev = integer(polish_nfev, "polish_nfev", 2)
    if polish_every is not None:
        polish_every = integer(polish_every, "polish_every", 1)
    if restart_after is not None:
        restart_after = integer(restart_after, "restart_after", 1)
    if max_iter is not None:
        max_iter = integer(max_iter, "max_iter", 1)
    gen = np.random.default_rng(rng)

    def fun(z):
        return cost(parametrization.to_denominator(z))

    def new_search(start):
        return SpiralSearch(
            fun,
            parametrization.bounds,
            method,
            n_points=n_points,
            rng=gen,
            vectorized=True,
            x0=start,
            bounds_policy="clip",
        )

    search = new_search(x0)
    per_step = n_points - 1
    used = 0  # evaluations of finished searches and of every polish
    n_polish = n_restarts = nit = 0
    best_z, best_f = search.x, search.fun
    history = [best_f]
    stalled = 0

    def spent() -> int:
        return used + search.nfev

    def polish() -> None:
        nonlocal used, n_polish
        res = gauss_newton_polish(cost, parametrization, search.x, polish_nfev)
        used += res.nfev
        n_polish += bool(search.move_centre(res.x, res.fun))

    status, message = 1, "Maximum number of function evaluations reached."
    while spent() + per_step <= max_nfev:
        if max_iter is not None and nit >= max_iter:
            status, message = 2, "Maximum number of iterations reached."
            break
        before = search.fun
        search.step()
        nit += 1
        due = polish_every and search.nit % polish_every == 0
        if due and spent() + polish_nfev <= max_nfev:
            polish()
        improved = search.fun < before * (1.0 - 1e-9)
        stalled = 0 if improved else stalled + 1
        if search.fun < best_f:
            best_z, best_f = search.x, search.fun
        history.append(best_f)
        if callback is not None and callback(
            optimize.OptimizeResult(x=best_z.copy(), fun=best_f)
        ):
            status, message = 0, "The callback requested a stop."
            break
        if restart_after and stalled >= restart_after:
            if spent() + n_points + per_step > max_nfev:
                break
            used += search.nfev
            search = new_search(restart_points)
            n_restarts += 1
            stalled = 0
    if polish_every and status != 0 and spent() + polish_nfev <= max_nfev:
        polish()
    if search.fun < best_f:
        best_z, best_f = search.x, search.fun
        history[-1] = best_f
    f_best, b_best = cost.evaluate(parametrization.to_denominator(best_z)[None, :])
    theta = np.r_[parametrization.to_denominator(best_z), b_best[0]]
    return optimize.OptimizeResult(
        x=theta,
        fun=float(f_best[0]),
        z=best_z,
        nfev=spent(),
        nit=nit,
        n_polish=n_polish,
        n_restarts=n_restarts,
        history=np.asarray(history, dtype=float),
        status=status,
        success=True,
        message=message,
        elapsed=time.perf_counter() - t_start,
    )
