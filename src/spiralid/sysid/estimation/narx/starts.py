"""Where NARX training starts: the linear model of the structure's lags
in the bypass, estimated on the training part and on the whole record, and
the network around it with Glorot-uniform hidden weights and zero output
weights, so that every start is exactly its linear model
(:mod:`.narx` trains from these).
"""

from __future__ import annotations

import numpy as np

from spiralid.choices import DEFAULT_METHOD

from ...data import IOData
from ...models.arx import ARX, arx_least_squares
from .problem import NARXProblem


def _linear_start(problem: NARXProblem, method: str = "default", n: int | None = None):
    """The linear model of the structure's lags in the bypass, and what it
    is; ``(None, "")`` for a structure without a bypass. Estimated on the
    first `n` samples of the record (default all).

    ``"default"``: for a free run from rest, the default method's ARX
    (``identify(data, ARX(ny + 1, nu, nk), integrator=k)`` for ``k``
    integrators, ``ARX(ny, nu, nk)`` without, through the problem's
    ``linear_estimator``), so a NARX contains the linear model a user would
    get; otherwise (a one-step predictor, a run from measured samples,
    which ``"spiral"`` does not fit, or no ``linear_estimator``) and for
    ``"ls"``: least squares of the one-step error.
    """
    st = problem.structure
    if st.family != "narx" or not st.linear:
        return None, ""
    data = problem.data if n is None else problem.data[:n]
    k = st.integrator
    free_run = problem.predictor == "simulation" and problem.initial == "rest"
    estimator = getattr(problem, "linear_estimator", None)
    if method == "ls" or not free_run or estimator is None:
        arx = ARX(st.ny, st.nu, st.nk)
        if k:
            # One step ahead, the increment's error is the output's.
            data = IOData(data.u, np.diff(data.y, prepend=0.0), ts=data.ts)
        theta = arx_least_squares(data, arx)
        a, b = theta[: st.ny], theta[st.ny :]
        what = f"ARX({st.ny}, {st.nu}, {st.nk}) of the increments" if k else str(arx)
        return st.from_arx(a, b, problem.scaling), f"{what} by least squares"
    arx = ARX(st.ny + (1 if k else 0), st.nu, st.nk)
    theta = estimator(data, arx, k, problem.rng)
    a = theta[: arx.na]
    if k:
        # A = C (1 - z^-1): the increments' denominator C is A's running sum
        # (its last term, A(1), is zero); C keeps any second integrator.
        a = np.cumsum(np.r_[1.0, a])[1:-1]
    what = f"{arx}, integrator={k}" if k else str(arx)
    return (
        st.from_arx(a, theta[arx.na :], problem.scaling),
        f"{what}, by {DEFAULT_METHOD}",
    )


def _linear_starts(problem: NARXProblem, method: str = "default"):
    """``(for training, for the whole record, what)``: the linear start of
    :func:`_linear_start` estimated on the training part and on the whole
    estimation record.

    Early stopping scores the start and every training round on the
    held-back part; a start fitted on the whole record has seen that part
    and would be scored in-sample against rounds scored out of sample, so
    training would stop at it (the cascaded tanks: 23.7 % held-back error
    in-sample against 32.0 % out of sample). Training runs from the first;
    the refit on the whole record and the containment guarantee use the
    second, which is the linear model a user would get (estimated first, from
    the generator as a user's `identify` call would find it).
    """
    whole, what = _linear_start(problem, method)
    if whole is None or problem.hold is None or problem.split >= problem.data.n:
        # Held-back blocks inside the record (training on subsequences): the
        # start is the whole record's, in sample on them, so training must
        # beat it there to move (conservative).
        return whole, whole, what
    train, _ = _linear_start(problem, method, n=problem.split)
    return train, whole, what


def _same_hidden(problem: NARXProblem, start: np.ndarray, linear) -> np.ndarray:
    """`linear` with `start`'s hidden weights (`linear`'s output weights stay
    zero, so it is still the linear model)."""
    st = problem.structure
    out = np.asarray(linear, dtype=float).copy()
    hidden = st.h * st.n_regressors
    out[:hidden] = start[:hidden]
    return out


def _with_hidden(problem: NARXProblem, p: np.ndarray) -> np.ndarray:
    """`p` with Glorot-uniform hidden weights (output weights stay zero, so
    the map is unchanged but its gradient reaches the network)."""
    return _same_hidden(problem, problem.structure.initial_params(problem.rng), p)


def _starts(problem: NARXProblem, method: str = "default"):
    """``(start, refit, linear, what)``: the network training starts from
    (the training part's linear model with Glorot hidden weights), the same
    network on the whole record's linear model (the refit's start), that
    linear model, and what it is (:func:`_linear_starts`)."""
    train, whole, what = _linear_starts(problem, method)
    start = _starting_network(problem, train)
    refit = start if whole is None else _same_hidden(problem, start, whole)
    return start, refit, whole, what


def _starting_network(problem: NARXProblem, linear) -> np.ndarray:
    """The linear start with Glorot hidden weights (the map unchanged), or
    a network's initial weights when there is no bypass."""
    if linear is None:
        return problem.structure.initial_params(problem.rng)
    return _with_hidden(problem, linear)
