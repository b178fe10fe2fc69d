"""Levenberg-Marquardt whose every accepted point is projected into a
feasible set: the local step of output error and of every polish.

``scipy.optimize.least_squares`` cannot change a trial point, so a stability
constraint has to be either a change of coordinates or a wall of rejected
steps. Both failed output error (docs/design-notes.md, "Where a local polish
ends"): searched as reflection coefficients ``k = KMAX tanh(z)``, LM's
Gauss-Newton steps follow valleys the step-up map bends, and ARX(16, 16, 0)
on the rig's record crept for 36,000 evaluations; searched as coefficients
with unstable trial points rejected, LM ran into the stability boundary from
a start whose way to the optimum passes round it and stayed there. Here a
trial point that leaves the feasible set is first projected back (for a
denominator: its unstable poles reflected into the unit circle, as Ljung's
prediction-error methods do), and the projected point is the one judged and
kept, so LM takes Gauss-Newton steps in the coefficients (fast near an
optimum) and slides along the boundary instead of stopping at it.

The damping follows Marquardt with the Jacobian's columns scaled to unit
norm (``x_scale="jac"`` in SciPy's terms): ``lambda`` divided by 10 after an
accepted step, multiplied by 10 after a rejected one.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import linalg

from spiralid.optim.result import OptimiserResult

__all__ = ["levenberg_marquardt"]

# Damping: first value, and the largest before a step is given up (the
# scaled step is then ~1e-8 of a Gauss-Newton step: nothing lowers the cost).
_LAMBDA0 = 1e-3
_LAMBDA_MAX = 1e16

# Why the polish stopped (``stop``); 0 is the evaluation cap, the only one
# that is status 1 of :data:`~spiralid.optim.result.STATUS`.
STOPS = {
    0: "The evaluation cap was reached before a tolerance was met.",
    1: "The gradient is below its tolerance: a stationary point.",
    2: "The last step lowered the cost by less than its tolerance.",
    3: "The last step was below its tolerance relative to the point.",
    4: "No damped step lowers the cost: a local minimum to working precision.",
    5: "The cost fell by less than its stall tolerance over the stall window: "
    "the end of a flat valley.",
}


def levenberg_marquardt(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    project: Callable[[np.ndarray], np.ndarray | None] | None = None,
    max_nfev: int = 1000,
    tol: float = 1e-12,
    stall: tuple[int, float] | None = None,
) -> OptimiserResult:
    """Minimise ``0.5 |residual(x)|^2`` from `x0` by Levenberg-Marquardt.

    Parameters
    ----------
    residual : callable
        ``residual(x) -> r``, shape (n,).
    jacobian : callable
        ``jacobian(x) -> J``, shape (n, p), ``d r / d x``.
    x0 : ndarray, shape (p,)
        Start; must be feasible (``project(x0)`` is `x0`).
    project : callable, optional
        ``project(x) -> x'`` maps a trial point into the feasible set (the
        point itself when it is feasible), or ``None`` when it cannot; the
        projected point is evaluated and, if it lowers the cost, kept.
    max_nfev : int
        Cap on residual evaluations.
    tol : float
        Tolerance on the gradient (the largest cosine between the residual
        and a column of the Jacobian), on the relative fall of the cost in
        one step, and on the step relative to the point.
    stall : (int, float), optional
        ``(window, gain)``: stop when ``window`` evaluations lowered the
        cost by less than ``gain`` of itself. Near a constraint or along a
        nearly flat valley LM takes step after small step, each above
        `tol`; this ends the crawl where it no longer pays.

    Returns
    -------
    OptimiserResult
        ``x``, ``cost`` (``0.5 |r|^2``), ``fun`` (the residual at ``x``),
        ``jac`` (at ``x``), ``optimality`` (the gradient ``J' r``'s largest
        component), ``nfev``, ``njev``, ``nit`` (accepted steps), ``stop``
        (a key of :data:`STOPS`), ``status`` (1 when the cap ended it,
        otherwise 0), ``success`` and ``message``.
    """
    project = project or (lambda x: x)
    x = np.array(x0, dtype=float)
    r = residual(x)
    cost = float(r @ r)
    nfev, njev, nit, lam = 1, 0, 0, _LAMBDA0
    status = 0
    checkpoint = (nfev, cost)
    while nfev < max_nfev:
        jac = jacobian(x)
        njev += 1
        scale = np.linalg.norm(jac, axis=0)
        scale[scale == 0.0] = 1.0
        q, upper = linalg.qr(jac / scale, mode="economic", check_finite=False)
        qtr = q.T @ r
        gradient = upper.T @ qtr
        if cost == 0.0 or np.max(np.abs(gradient)) <= tol * np.sqrt(cost):
            status = 1
            break
        stepped = False
        while nfev < max_nfev and lam <= _LAMBDA_MAX:
            trial = project(x + _damped_step(upper, qtr, lam) / scale)
            if trial is None:
                lam *= 10.0
                continue
            r_trial = residual(trial)
            nfev += 1
            cost_trial = float(r_trial @ r_trial)
            if cost_trial < cost:  # NaN compares False: rejected
                fall, moved = (cost - cost_trial) / cost, trial - x
                x, r, cost = trial, r_trial, cost_trial
                lam = max(lam / 10.0, 1e-12)
                nit += 1
                stepped = True
                break
            lam *= 10.0
        if not stepped:
            status = 4 if lam > _LAMBDA_MAX else 0
            break
        if fall <= tol:
            status = 2
            break
        if np.linalg.norm(moved) <= tol * (np.linalg.norm(x) + tol):
            status = 3
            break
        if stall is not None and nfev - checkpoint[0] >= stall[0]:
            if checkpoint[1] - cost <= stall[1] * checkpoint[1]:
                status = 5
                break
            checkpoint = (nfev, cost)
    jac = jacobian(x)
    njev += 1
    return OptimiserResult(
        x=x,
        cost=0.5 * cost,
        fun=r,
        jac=jac,
        optimality=float(np.max(np.abs(jac.T @ r))) if x.size else 0.0,
        nfev=nfev,
        njev=njev,
        nit=nit,
        n_restarts=0,
        history=None,
        stop=status,
        status=1 if status == 0 else 0,
        success=status != 0,
        message=STOPS[status],
    )


def _damped_step(upper: np.ndarray, qtr: np.ndarray, lam: float) -> np.ndarray:
    """``-(R'R + lam I)^-1 R' Q' r`` as the least-squares solution of
    ``[R; sqrt(lam) I] s = -[Q' r; 0]`` (no normal equations: ``R'R``
    would square the condition number of lightly damped models' Jacobians)."""
    p = upper.shape[1]
    stacked = np.vstack([upper, np.sqrt(lam) * np.eye(p)])
    rhs = np.r_[qtr, np.zeros(p)]
    return -linalg.lstsq(stacked, rhs, check_finite=False)[0]
