"""Training a neural state-space model
(:class:`~spiralid.sysid.models.neural_state_space.NeuralStateSpace`) on
the simulation error over overlapping subsequences.

1. **Linear start.** An ``ARX(order, order, 1)`` fitted by the method
   asked (``"oe"``: output error; ``"spiral"``: the default spiral
   identification), realised in observer canonical form; the networks'
   output weights are zero, so the model starts as that linear model, and
   the encoder at its exact state from the past ``window`` samples.
2. **Held back.** A `holdout` share of the record, in
   :data:`~spiralid.sysid.estimation.narx.subsequences.HOLD_BLOCKS` blocks
   spread over it (a short record's end can hold what its start never
   does), is never in the training error; it is scored by the free run
   from rest over the whole record, the error on the held-back samples
   (what a free-run benchmark scores).
3. **Subsequences.** Stretches of ``horizon`` samples, ``horizon / 2``
   apart, each run from the encoder's state of the measured samples before
   it (encoder windows with no held-back sample); the mean squared error
   over their training samples plus ``decay`` times the mean square of the
   networks' weights is minimised by L-BFGS with the exact gradient
   (backpropagation through time, :mod:`~spiralid.sysid.models._nss_kernels`),
   the encoder's ``E`` trained with the rest.
4. **Early stopping and the length.** Every ``_CHUNK`` iterations the
   held-back RMS is measured and the best point kept; a stage stops after
   ``_PATIENCE`` chunks without a better one. With ``horizon=None`` the
   stages run through :data:`HORIZONS` (each from the best point so far),
   so the length is grown and the held-back samples choose where to stop.
5. **Never worse than the linear start.** The linear start is the first
   point scored; the model returned is the best on the held-back samples,
   so it is the linear start (``result["kept_linear"]``) unless training
   beat it there.

Short stretches keep the sensitivities bounded (a free run's grow along
the run); long ones reach the long-run behaviour the free run is scored
on.
"""

from __future__ import annotations

import math
import time

import numpy as np

from spiralid._checks import generator

from ...data import IOData
from ...models._nss_kernels import nss_batch_loss
from ...models.neural_state_space import NeuralStateSpace
from ...models.neural_state_space_model import NeuralStateSpaceModel
from ..narx.subsequences import (
    HOLD_BLOCKS,
    check_holdout_decay,
    check_horizon,
    subsequence_starts,
)

__all__ = ["HORIZONS", "NSS_OPTIONS", "identify_neural_state_space"]

#: The stages' subsequence lengths of ``horizon=None`` (those shorter than
#: the record's training part), each starting from the best point so far.
HORIZONS = (50, 100, 200)

#: The family's options beside identify's ``rng``.
NSS_OPTIONS = ("holdout", "decay", "horizon", "max_iter", "free_run")

# L-BFGS iterations between two held-back scores, and chunks without a
# better score before a stage stops.
_CHUNK = 25
_PATIENCE = 10
# Curvature pairs L-BFGS keeps.
_MEMORY = 10
# Iterations a stage may take at most (the default of `max_iter`).
_MAX_ITER = 1000
# Starts from the linear model, each with its own random input weights:
# the held-back samples keep the best (seeds 0-2 on the cascaded tanks
# spread from 0.38 to 0.60 V on one start).
_STARTS = 3
# Glorot-uniform scale of the networks' input weights at the start.
_INIT = 1.0


def _hold_mask(n: int, holdout: float) -> np.ndarray:
    """True at the held-back samples: `holdout` of `n` in HOLD_BLOCKS equal
    blocks evenly spread over the record."""
    held = np.zeros(n, dtype=bool)
    size = round(holdout * n / HOLD_BLOCKS)
    if size < 1:
        return held
    for i in range(HOLD_BLOCKS):
        mid = int((i + 0.5) * n / HOLD_BLOCKS)
        held[max(0, mid - size // 2) : mid - size // 2 + size] = True
    return held


class _Problem:
    """The scaled record, the held-back samples and the training loss."""

    def __init__(self, st: NeuralStateSpace, data: IOData, holdout: float, decay):
        self.st = st
        self.u_scale = float(np.std(data.u)) or 1.0
        self.y_scale = float(np.std(data.y)) or 1.0
        self.us = np.asarray(data.u, dtype=float) / self.u_scale
        self.ys = np.asarray(data.y, dtype=float) / self.y_scale
        self.held = _hold_mask(data.n, holdout)
        self.decay = float(decay)
        self.net = st.network_mask()
        self.nfev = 0

    def batch(self, horizon: int | None) -> None:
        """The stretches of `horizon` samples (training weights 1, held-back
        0), each encoder window free of held-back samples; None: the free
        run from rest over the whole record, the one stretch the held-back
        score runs (the encoder is not used, its state is zero)."""
        st, n = self.st, self.us.size
        if horizon is None:
            self.U, self.Y = self.us[None, :].copy(), self.ys[None, :].copy()
            self.W = (~self.held[None, :]).astype(float)
            self.W /= max(self.W.sum(), 1.0)
            self.Z = np.zeros((1, 2 * st.window))
            return
        horizon = max(2, min(horizon, n - st.window))
        starts = subsequence_starts(st.window, n, horizon)
        starts = np.array(
            [t for t in starts if not self.held[t - st.window : t].any()], np.intp
        )
        idx = starts[:, None] + np.arange(horizon)[None, :]
        self.U = np.ascontiguousarray(self.us[idx])
        self.Y = np.ascontiguousarray(self.ys[idx])
        self.W = (~self.held[idx]).astype(float)
        self.W /= max(self.W.sum(), 1.0)
        self.Z = st.regressors(self.ys, self.us, starts)

    def loss(self, p: np.ndarray) -> tuple[float, np.ndarray]:
        """The training loss and its exact gradient."""
        st = self.st
        self.nfev += 1
        E = p[st.n_theta :].reshape(st.order, -1)
        X0 = np.ascontiguousarray(self.Z @ E.T)
        grad = np.zeros(p.size)
        gx0 = np.empty_like(X0)
        theta = np.ascontiguousarray(p[: st.n_theta])
        with np.errstate(all="ignore"):
            f = nss_batch_loss(
                theta, self.U, self.Y, self.W, X0, st.order, st.h, grad, gx0
            )
        grad[st.n_theta :] = (gx0.T @ self.Z).ravel()
        n_net = max(int(self.net.sum()), 1)
        w = p[self.net]
        f += self.decay * float(w @ w) / n_net
        grad[self.net] += 2.0 * self.decay * w / n_net
        if not (math.isfinite(f) and np.isfinite(grad).all()):
            return 1e10, np.zeros(p.size)
        return f, grad

    def held_rms(self, p: np.ndarray) -> float:
        """RMS (output unit) of the free run from rest over the whole
        record, on the held-back samples (on all with none held back)."""
        with np.errstate(all="ignore"):
            e = self.st.free_run(p, self.us) - self.ys
        sel = self.held if self.held.any() else slice(None)
        rms = self.y_scale * float(np.sqrt(np.mean(e[sel] ** 2)))
        return rms if math.isfinite(rms) else math.inf


def _lbfgs(fun, p, iters: int, memory: list) -> tuple[np.ndarray, int, bool]:
    """`iters` iterations of L-BFGS (two-loop recursion, backtracking to
    Armijo's condition) on ``fun(p) -> (f, grad)`` from `p`, continuing
    the curvature pairs in `memory` (updated in place); returns the point,
    the iterations run and whether it converged. Our own, not SciPy's: its
    L-BFGS-B spends its time in threaded BLAS calls on vectors this small
    (most of a fit on a shared machine)."""
    f, g = fun(p)
    for it in range(iters):
        q = g.copy()
        alphas = []
        for s_k, y_k, rho in reversed(memory):
            a = rho * (s_k @ q)
            alphas.append(a)
            q -= a * y_k
        if memory:
            s_k, y_k, _ = memory[-1]
            q *= (s_k @ y_k) / (y_k @ y_k)
        for (s_k, y_k, rho), a in zip(memory, reversed(alphas), strict=True):
            q += s_k * (a - rho * (y_k @ q))
        d = -q
        slope = float(g @ d)
        if slope >= 0.0:  # not a descent direction: restart from the gradient
            memory.clear()
            d, slope = -g, -float(g @ g)
        step = 1.0 if memory else min(1.0, 1e-2 / max(np.abs(g).max(), 1e-12))
        for _ in range(30):
            p_new = p + step * d
            f_new, g_new = fun(p_new)
            if f_new <= f + 1e-4 * step * slope:
                break
            step *= 0.3
        else:
            return p, it, True
        s_k, y_k = p_new - p, g_new - g
        if s_k @ y_k > 1e-12:
            memory.append((s_k, y_k, 1.0 / (s_k @ y_k)))
            del memory[:-_MEMORY]
        converged = f - f_new <= 1e-10 * max(abs(f), 1e-12)
        p, f, g = p_new, f_new, g_new
        if converged:
            return p, it + 1, True
    return p, iters, False


def _stage(problem: _Problem, p0, best, max_iter: int):
    """L-BFGS from `p0` in chunks, the held-back RMS after each; returns
    the best ``(rms, p)`` (`best` unless beaten) and the iterations run."""
    p, used, stale, memory = p0, 0, 0, []
    while used < max_iter and stale < _PATIENCE:
        p, nit, converged = _lbfgs(
            problem.loss, p, min(_CHUNK, max_iter - used), memory
        )
        used += max(nit, 1)
        rms = problem.held_rms(p)
        if rms < best[0]:
            best, stale = (rms, p.copy()), 0
        else:
            stale += 1
        if converged:
            break
    return best, used


def _linear_start(st: NeuralStateSpace, problem: _Problem, theta, rng) -> tuple:
    """The linear start's parameters (ARX theta realised, scaled) and the
    training's start (the same with random input weights, which leave the
    output unchanged while the output weights are zero)."""
    a, b = theta[: st.order], theta[st.order :]
    p_lin = st.from_linear(a, b * problem.u_scale / problem.y_scale)
    p0 = p_lin.copy()
    blocks = st.split(p0)
    if st.h:
        lim = _INIT * math.sqrt(6.0 / (st.order + 1 + st.h))
        for name in ("Wf", "Wh"):
            blocks[name][:] = rng.uniform(-lim, lim, blocks[name].shape)
    return p_lin, p0


def _checked(holdout, decay, horizon, max_iter) -> tuple:
    holdout, decay = check_holdout_decay(holdout, decay)
    horizon = check_horizon(horizon)
    if max_iter is None:
        max_iter = _MAX_ITER
    if isinstance(max_iter, bool) or not isinstance(max_iter, int | np.integer):
        raise TypeError(f"`max_iter` must be an integer >= 1; got {max_iter!r}")
    if max_iter < 1:
        raise ValueError(f"`max_iter` must be an integer >= 1; got {max_iter!r}")
    return float(holdout), float(decay), horizon, int(max_iter)


def identify_neural_state_space(
    data: IOData,
    structure: NeuralStateSpace,
    *,
    method: str,
    linear_estimator,
    rng=None,
    holdout: float = 0.2,
    decay: float = 1e-3,
    horizon: int | None = None,
    max_iter: int | None = None,
    free_run: bool = False,
) -> NeuralStateSpaceModel:
    """A neural state-space model of `structure` on `data` (the module
    docstring says how).

    Parameters
    ----------
    data : IOData
        One input, one output.
    structure : NeuralStateSpace
    method : str
        The linear start's method (``"oe"`` or ``"spiral"``).
    linear_estimator : callable
        ``linear_estimator(data, arx, method, rng) -> (theta, text)``: the
        ARX theta of ``arx`` on `data` and how it was fitted.
    rng : int, numpy.random.Generator or None
        The networks' initial input weights.
    holdout : float
        Share of the record held back for early stopping, in [0, 0.5); 0
        trains to convergence and scores the free run on the whole record.
    decay : float
        Weight decay: the mean square of the networks' weights, times
        `decay`, is added to the mean squared (scaled) error.
    horizon : int or None
        Subsequence length (>= 2); None grows it through :data:`HORIZONS`.
    max_iter : int or None
        L-BFGS iterations per stage at most (default 1000).
    free_run : bool
        Add a last stage on the free run from rest over the whole record
        (its training samples), the run the held-back score and a free-run
        benchmark measure, from each start's best point on the
        subsequences. Its early stopping is the other stages': it ends
        where the held-back RMS was lowest, so it never ends above its
        start there. Default False.

    Returns
    -------
    NeuralStateSpaceModel
    """
    t_start = time.perf_counter()
    holdout, decay, horizon, max_iter = _checked(holdout, decay, horizon, max_iter)
    if not isinstance(free_run, bool | np.bool_):
        raise TypeError(f"`free_run` must be True or False; got {free_run!r}")
    if not isinstance(structure, NeuralStateSpace):
        raise TypeError(
            f"`structure` must be a NeuralStateSpace; got {type(structure).__name__}"
        )
    structure.check_length(data)
    gen = generator(rng)
    problem = _Problem(structure, data, holdout, decay)
    theta, text = linear_estimator(data, structure.order, method, gen)
    p_lin, p0 = _linear_start(structure, problem, theta, gen)
    linear_cost = problem.held_rms(p_lin)
    best = (linear_cost, p_lin)
    schedule = []
    horizons = (horizon,) if horizon is not None else HORIZONS
    room = data.n - structure.window
    horizons = tuple(h for h in horizons if h < room) or (room,)
    if free_run:
        horizons = (*horizons, None)
    for run in range(_STARTS if structure.h else 0):
        if run:
            p0 = _linear_start(structure, problem, theta, gen)[1]
        ours = (linear_cost, p_lin)
        start = p0
        for h in horizons:
            problem.batch(h)
            ours, used = _stage(problem, start, ours, max_iter)
            schedule.append([None if h is None else int(h), int(used), float(ours[0])])
            # The next (longer) stage starts from this start's best point;
            # from the random input weights while that is the linear start.
            start = start if ours[1] is p_lin else ours[1]
        if ours[0] < best[0]:
            best = ours
    kept = best[1] is p_lin
    return NeuralStateSpaceModel(
        structure=structure,
        params=best[1],
        linear_params=p_lin,
        u_scale=problem.u_scale,
        y_scale=problem.y_scale,
        ts=data.ts,
        method=method,
        cost=float(best[0]) if holdout > 0 else math.nan,
        result={
            "kept_linear": bool(kept),
            "linear_cost": float(linear_cost),
            "schedule": schedule,
            "nfev": int(problem.nfev),
            "seconds": time.perf_counter() - t_start,
        },
        linear_model=text,
        **data.provenance(),
    )
