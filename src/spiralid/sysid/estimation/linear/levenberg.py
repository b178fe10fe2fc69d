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
denominator: its outside poles moved radially onto the region's edge; a
reflection into the unit circle, as Ljung's prediction-error methods
stabilise, undid the step's move along the edge), and the projected point
is the one judged and kept, so LM takes Gauss-Newton steps in the
coefficients (fast near an optimum) and slides along the boundary instead
of stopping at it.

The damping follows Marquardt with the Jacobian's columns scaled to unit
norm (``x_scale="jac"`` in SciPy's terms): ``lambda`` divided by 10 after an
accepted step (by `shrink` after one accepted once a smaller damping was
rejected), multiplied by 10 after a rejected one.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import linalg

from spiralid.optim.result import OptimiserResult

__all__ = ["damped_descent", "levenberg_marquardt"]

# Damping: first value, and the largest before a step is given up (the
# scaled step is then ~1e-8 of a Gauss-Newton step: nothing lowers the cost).
_LAMBDA0 = 1e-3
_LAMBDA_MAX = 1e16

# The race against a rival's cost is judged over a fifth of the stall
# window: a crawl that loses shows it early, and a polish still descending
# fast is never given up (its straight line reaches far).
_RACE_WINDOWS = 5

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
    6: "At its pace over the last fifth of the stall window the evaluations "
    "left could not bring the cost down to the rival's: given up.",
}


def damped_descent(
    evaluate: Callable[[np.ndarray], tuple[float, object]],
    linearise: Callable,
    x0: np.ndarray,
    *,
    max_nfev: int,
    project: Callable[[np.ndarray], np.ndarray | None] | None = None,
    converged: Callable | None = None,
    linearising_counts: bool = False,
    grow: float = 10.0,
    lam_max: float = _LAMBDA_MAX,
    shrink: float = 10.0,
) -> dict:
    """The one Levenberg-Marquardt loop: Marquardt's damping schedule, the
    projected trial point, acceptance and the stops every polish shares.

    How a step is solved is the caller's: :func:`levenberg_marquardt` from
    the residual's Jacobian (QR, columns scaled), the variable-projection
    polish (:func:`~spiralid.sysid.estimation.linear.varpro.gauss_newton_polish`)
    from normal equations formed in compiled loops.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(x) -> (cost, state)``: one evaluation; `state` (the
        residual, say) is handed to `linearise` at an accepted point.
    linearise : callable
        ``linearise(x, cost, state) -> (cost_here, step, stationary)`` at
        the current point: ``step(lam)`` the damped step (None when it
        cannot be solved: the damping grows tenfold), `stationary` True at
        a stationary point, and `cost_here` the cost at `x` when the
        linearisation computes it (used when `x0` was not evaluated).
    x0 : ndarray
        Start, feasible.
    max_nfev : int
        Cap on evaluations.
    project : callable, optional
        ``project(x) -> x'`` into the feasible set, or None when it cannot.
    converged : callable, optional
        ``converged(x_before, x, cost_before, cost, nfev)`` after each
        accepted step: a stop's name, or None to go on.
    linearising_counts : bool
        A linearisation counts as an evaluation, and `x0` is not evaluated
        first (its cost comes from the first linearisation).
    grow : float
        The damping's factor after a rejected trial point.
    lam_max : float
        The largest damping before the step is given up.
    shrink : float
        The damping's divisor after a trial point accepted once a smaller
        damping was rejected (10 otherwise).

    Returns
    -------
    dict
        ``x``, ``cost`` (None when nothing was evaluated), ``state``,
        ``nfev``, ``njev`` (linearisations not counted as evaluations),
        ``nit`` (accepted steps), ``lam`` and ``stop``: ``"cap"`` (the
        evaluations ran out), ``"stationary"``, ``"no decrease"`` (no damped
        step lowers the cost) or what `converged` returned.
    """
    project = project or (lambda x: x)
    x = np.array(x0, dtype=float)
    cost = state = None
    nfev = njev = nit = 0
    if not linearising_counts:
        cost, state = evaluate(x)
        nfev = 1
    lam = _LAMBDA0
    stop = "cap"
    while nfev < max_nfev:
        here, step, stationary = linearise(x, cost, state)
        if linearising_counts:
            nfev += 1
        else:
            njev += 1
        cost = here if cost is None else cost
        if stationary:
            stop = "stationary"
            break
        stepped = rejected = False
        while nfev < max_nfev and lam <= lam_max:
            s = step(lam)
            trial = None if s is None else project(x + s)
            if trial is None:
                lam *= 10.0
                continue
            cost_trial, state_trial = evaluate(trial)
            nfev += 1
            if cost_trial < cost:  # NaN compares False: rejected
                before = (x, cost)
                x, cost, state = trial, cost_trial, state_trial
                lam = max(lam / (shrink if rejected else 10.0), 1e-12)
                nit += 1
                stepped = True
                break
            rejected = True
            lam *= grow
        if not stepped:
            stop = "no decrease" if lam > lam_max else "cap"
            break
        if converged is not None:
            reason = converged(before[0], x, before[1], cost, nfev)
            if reason is not None:
                stop = reason
                break
    return dict(
        x=x, cost=cost, state=state, nfev=nfev, njev=njev, nit=nit, lam=lam, stop=stop
    )


def levenberg_marquardt(
    residual: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    project: Callable[[np.ndarray], np.ndarray | None] | None = None,
    max_nfev: int = 1000,
    tol: float = 1e-12,
    stall: tuple[int, float] | None = None,
    constraints: Callable[[np.ndarray], tuple | None] | None = None,
    shrink: float = 10.0,
    rival: float | None = None,
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
    constraints : callable, optional
        ``constraints(x) -> (G, h)``: the feasible set linearised at `x`, a
        step ``s`` staying inside where ``G @ s <= h`` (None: no row). Each
        damped step then solves the damped least-squares problem under
        these rows (a small active set), so a step towards the boundary
        slides along it instead of crossing it and being projected back:
        with only `project`, a Gauss-Newton step that points outside is
        pulled back by as much as it went out, rejected or accepted for a
        fraction of its gain, and LM crawls along the boundary (thousands of
        evaluations at ARX(24, 24, 0) and above). `project` still corrects
        what the linearisation misses.
    shrink : float
        The damping's divisor after a step accepted once a smaller damping
        was rejected (10, Marquardt's, otherwise). Where the model holds
        only a little beyond such a step, dividing by 10 makes the next
        trial the one just rejected, and accepted and rejected trials
        alternate: half the evaluations wasted.
    rival : float, optional
        ``|r|^2`` that another start's polish of the same residual reached,
        when only the lower of the two is kept. Every fifth of the stall
        window (which `stall` must give) the polish gives up (stop 6) if its
        cost is above `rival` by more than that stretch's fall times the
        stretches its cap leaves: at its own pace it cannot win. A crawl's
        pace falls, so the straight line is optimistic for it.

    Returns
    -------
    OptimiserResult
        ``x``, ``cost`` (``0.5 |r|^2``), ``fun`` (the residual at ``x``),
        ``jac`` (at ``x``), ``optimality`` (the gradient ``J' r``'s largest
        component), ``nfev``, ``njev``, ``nit`` (accepted steps), ``stop``
        (a key of :data:`STOPS`), ``status`` (1 when the cap ended it,
        otherwise 0), ``success`` (False at the cap and when given up to
        the rival: neither met a tolerance) and ``message``.
    """

    if rival is not None and stall is None:
        raise ValueError("`rival` is judged over the stall window: give `stall` too")

    def evaluate(x):
        r = residual(x)
        return float(r @ r), r

    # The last point linearised and its Jacobian: where the polish ends
    # there (a cap or a stop among rejected trials), the result's Jacobian.
    last = [None, None]

    def linearise(x, cost, r):
        jac = jacobian(x)
        last[:] = [x, jac]
        scale = np.linalg.norm(jac, axis=0)
        scale[scale == 0.0] = 1.0
        q, upper = linalg.qr(jac / scale, mode="economic", check_finite=False)
        qtr = q.T @ r
        gradient = upper.T @ qtr
        stationary = cost == 0.0 or np.max(np.abs(gradient)) <= tol * np.sqrt(cost)
        if constraints is None:
            return cost, (lambda lam: _damped_step(upper, qtr, lam) / scale), stationary
        rows = constraints(x)
        # In the scaled coordinates of the step (s = s_scaled / scale).
        rows = None if rows is None else (rows[0] / scale, rows[1])

        return (
            cost,
            (lambda lam: _constrained_step(upper, qtr, lam, rows) / scale),
            stationary,
        )

    # The stall window's start: (evaluations, cost), first the start's; and
    # the race's, a fifth as long.
    checkpoint = [1, None]
    race = [1, None]

    def converged(before, x, cost_before, cost, nfev):
        if checkpoint[1] is None:
            checkpoint[1] = race[1] = cost_before
        if (cost_before - cost) / cost_before <= tol:
            return 2
        if np.linalg.norm(x - before) <= tol * (np.linalg.norm(x) + tol):
            return 3
        if rival is not None and nfev - race[0] >= stall[0] // _RACE_WINDOWS:
            windows_left = (max_nfev - nfev) / (nfev - race[0])
            if cost - rival > (race[1] - cost) * windows_left:
                return 6
            race[:] = [nfev, cost]
        if stall is not None and nfev - checkpoint[0] >= stall[0]:
            if checkpoint[1] - cost <= stall[1] * checkpoint[1]:
                return 5
            checkpoint[:] = [nfev, cost]
        return None

    out = damped_descent(
        evaluate,
        linearise,
        x0,
        max_nfev=max_nfev,
        project=project,
        converged=converged,
        shrink=shrink,
    )
    status = {"cap": 0, "stationary": 1, "no decrease": 4}.get(out["stop"], out["stop"])
    x, r = out["x"], out["state"]
    jac = last[1] if last[0] is x else jacobian(x)
    return OptimiserResult(
        x=x,
        cost=0.5 * out["cost"],
        fun=r,
        jac=jac,
        optimality=float(np.max(np.abs(jac.T @ r))) if x.size else 0.0,
        nfev=out["nfev"],
        njev=out["njev"] + 1,
        nit=out["nit"],
        n_restarts=0,
        history=None,
        stop=status,
        status=1 if status == 0 else 0,
        success=status not in (0, 6),
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


def _constrained_step(
    upper: np.ndarray,
    qtr: np.ndarray,
    lam: float,
    rows: tuple[np.ndarray, np.ndarray] | None,
) -> np.ndarray:
    """The damped step ``min |R s + Q' r|^2 + lam |s|^2`` under ``G s <= h``.

    ``[R; sqrt(lam) I] = Q2 R2`` (a QR of a ``2p x p`` matrix, no normal
    equations of the Jacobian) gives the free step ``s0``; rows it violates
    enter an active set one at a time (the most violated first, a row whose
    multiplier turns negative leaves), and each active set's step is
    ``s0 - M^-1 G_A' mu`` with ``M = R2' R2``, ``mu`` from the small system
    ``(Z_A' Z_A) mu = G_A s0 - h_A``, ``Z = R2^-T G'``. Few rows are ever
    active (a pole or a pair on the boundary), so the loop is short.
    """
    p = upper.shape[1]
    q2, r2 = linalg.qr(
        np.vstack([upper, np.sqrt(lam) * np.eye(p)]),
        mode="economic",
        check_finite=False,
    )
    s0 = -linalg.solve_triangular(r2, q2[:p].T @ qtr, check_finite=False)
    if rows is None or not np.all(np.isfinite(s0)):
        return s0
    g, h = rows
    # Rows are in units of squared radius: a violation below 1e-12 is
    # below what the projection rounds away.
    slack = 1e-12
    violation = g @ s0 - h
    if not np.any(violation > slack):
        return s0
    z = linalg.solve_triangular(r2, g.T, trans="T", check_finite=False)
    active: list[int] = []
    s = s0
    for _ in range(2 * len(h)):
        candidates = np.where(violation > slack)[0]
        candidates = [i for i in candidates if i not in active]
        if not candidates:
            break
        active.append(max(candidates, key=lambda i: violation[i]))
        s = s0
        while active:
            za = z[:, active]
            mu = np.linalg.lstsq(za.T @ za, g[active] @ s0 - h[active], rcond=None)[0]
            if np.all(mu >= 0.0):
                s = s0 - linalg.solve_triangular(r2, za @ mu, check_finite=False)
                break
            active.pop(int(np.argmin(mu)))
        violation = g @ s - h
    return s
