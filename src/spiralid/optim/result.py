"""The one result type of every optimiser in spiralid.

:func:`~spiralid.optim.minimize` (every rule), the restarted and memetic
searches, :func:`~spiralid.optim.differential_evolution`, the local polishes
(Levenberg-Marquardt, Gauss-Newton on the projected problem) and the
identification estimators all return an :class:`OptimiserResult`, a
``scipy.optimize.OptimizeResult`` whose ``status`` is a key of
:data:`STATUS`, so a caller reads why any of them stopped in one way.
"""

from __future__ import annotations

from scipy import optimize

__all__ = ["STATUS", "OptimiserResult"]

# Why an optimiser stopped. A finer reason (the target reached, a tolerance
# met, the callback's request) is in ``message``.
STATUS = {
    0: "Finished: exact, converged, or stopped by the target or the callback.",
    1: "Stopped at the evaluation cap (max_nfev).",
    2: "Stopped at the iteration cap (max_iter).",
    3: "Stopped after the iteration that passed the time limit (max_time).",
}


class OptimiserResult(optimize.OptimizeResult):
    """What every optimiser returns; behaves like ``scipy.optimize.OptimizeResult``.

    Attributes
    ----------
    x : ndarray, shape (n,)
        The best point found.
    fun : float or ndarray
        Its cost (a least-squares polish, as SciPy's ``least_squares``, puts
        the residual vector here and the cost ``0.5 |r|^2`` in ``cost``).
    status : int
        A key of :data:`STATUS`.
    success : bool
        Whether the optimiser ended as it should (a search that used its
        budget succeeded; a polish stopped by its cap did not).
    message : str
        Why it stopped, in words.
    nit, nfev : int
        Iterations and objective evaluations (a vectorised call of ``k``
        points counts ``k``).
    n_restarts : int
        Fresh populations started after the first (0 for a method without
        restarts).
    history : ndarray or None
        Best cost after each iteration (index 0: the initial population),
        or ``None`` for a method that keeps none.

    Optimisers add their own keys (``elapsed``, a spiral search's
    ``mean_radius``, a polish's ``optimality``...).
    """
