"""Spiral search over denominators with the numerator projected out, a
memetic local step, and starts from the measured frequency response.

:func:`projected_spiral` runs a spiral optimiser
(:class:`spiralid.optim.SpiralSearch`) over the coordinates of a
denominator parametrisation (e.g. :class:`~spiralid.sysid.modal.
ModalParametrization`), scoring each candidate with
:class:`~spiralid.sysid.varpro.ProjectedCost` (the paper's cost at the
least-squares numerator). Two optional ingredients:

- ``polish_every=k``: every ``k`` iterations (and once at the end) the
  centre is polished by a few Levenberg-Marquardt steps of the projected
  problem (:func:`~spiralid.sysid.varpro.gauss_newton_polish`) and moved to
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

from spiralid.optim import SpiralSearch

from .data import IOData
from .spectra import PSD, default_nperseg, find_resonances
from .varpro import ProjectedCost, gauss_newton_polish

__all__ = ["frequency_seeds", "modal_spiral", "projected_spiral", "safe_denominators"]


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
    rng : int, Generator or None

    Returns
    -------
    OptimizeResult
        ``x`` the ARX theta ``[a, b]``, ``fun`` its cost (eq. (2)-(3)),
        ``z`` the searched coordinates, ``nfev``, ``nit``, ``n_polish``
        (polishes that moved the centre), ``history`` (best cost after each
        iteration), ``status`` (1: budget used), ``message``, ``success``,
        ``elapsed``.
    """
    t_start = time.perf_counter()
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

    while spent() + per_step <= max_nfev:
        before = search.fun
        search.step()
        nit += 1
        if polish_every and search.nit % polish_every == 0:
            if spent() + polish_nfev > max_nfev:
                break
            polish()
        improved = search.fun < before * (1.0 - 1e-9)
        stalled = 0 if improved else stalled + 1
        if search.fun < best_f:
            best_z, best_f = search.x, search.fun
        history.append(best_f)
        if restart_after and stalled >= restart_after:
            if spent() + n_points + per_step > max_nfev:
                break
            used += search.nfev
            search = new_search(restart_points)
            n_restarts += 1
            stalled = 0
    if polish_every and spent() + polish_nfev <= max_nfev:
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
        status=1,
        success=True,
        message="Maximum number of function evaluations reached.",
        elapsed=time.perf_counter() - t_start,
    )


def safe_denominators(data: IOData, arx, steiglitz: bool = True) -> np.ndarray:
    """Denominators every projected search should hold from the start.

    The least-squares estimate with its unstable poles reflected into the
    unit circle and, with `steiglitz`, the Steiglitz-McBride estimate
    started from it (the classical output-error start). With the numerator
    projected out, the search's cost at either is at most the paper's cost
    of the full estimate, and any stable denominator costs at most the zero
    model (``b = 0`` is always available).

    Returns
    -------
    ndarray, shape (k, na)
    """
    from .arx import arx_least_squares
    from .identify import _stabilise, steiglitz_mcbride
    from .polynomials import step_up

    theta_ls = arx_least_squares(data, arx)
    rows = [step_up(_stabilise(theta_ls, arx)[: arx.na])]
    if steiglitz:
        rows.append(steiglitz_mcbride(data, arx, theta_ls)[: arx.na])
    return np.array(rows)


def modal_spiral(
    data: IOData,
    arx,
    method="ebsda",
    *,
    n_points: int = 50,
    max_nfev: int = 20_000,
    polish_every: int | None = 5,
    polish_nfev: int = 10,
    restart_after: int | None = 20,
    safe_starts: bool = True,
    steiglitz: bool = True,
    seeds: int = 0,
    gain="auto",
    penalty: float = 1e6,
    rng=None,
) -> optimize.OptimizeResult:
    """Spiral identification over modal coordinates with the numerator
    projected out: the building block of ``identify(method="spiral")``.

    Parameters
    ----------
    data : IOData
    arx : ARX
    method : str or SpiralRule
        The spiral rule.
    n_points, max_nfev, polish_every, polish_nfev, restart_after
        As in :func:`projected_spiral`.
    safe_starts : bool
        Put :func:`safe_denominators` in the first population (mapped to
        modal coordinates) and return whichever is best of the search and
        their exact projected models, so the result is never worse than the
        stabilised least-squares estimate or the zero model.
    steiglitz : bool
        Include the Steiglitz-McBride start among the safe starts.
    seeds : int
        Points of the first population placed at the frequency response's
        peaks (:func:`frequency_seeds`).
    gain, penalty
        As in :class:`~spiralid.sysid.PaperCost`.
    rng : int, Generator or None

    Returns
    -------
    OptimizeResult
        As :func:`projected_spiral`, plus ``start`` ("search" or the index
        of the safe start that won).
    """
    from .modal import ModalParametrization

    gen = np.random.default_rng(rng)
    cost = ProjectedCost(arx, data, gain=gain, penalty=penalty)
    par = ModalParametrization(arx.na, data.ts)
    rows = []
    safe = safe_denominators(data, arx, steiglitz) if safe_starts else None
    if safe is not None:
        rows += [par.from_denominator(a) for a in safe]
    if seeds:
        rows += list(frequency_seeds(data, par, seeds, gen))
    x0 = np.array(rows[:n_points]) if rows else None
    res = projected_spiral(
        cost,
        par,
        method,
        n_points=n_points,
        max_nfev=max_nfev,
        polish_every=polish_every,
        polish_nfev=polish_nfev,
        x0=x0,
        restart_after=restart_after,
        rng=gen,
    )
    res.start = "search"
    if safe is not None:
        f_safe, b_safe = cost.evaluate(safe)
        i = int(np.argmin(f_safe))
        if f_safe[i] < res.fun:
            res.x, res.fun, res.start = np.r_[safe[i], b_safe[i]], float(f_safe[i]), i
    return res
