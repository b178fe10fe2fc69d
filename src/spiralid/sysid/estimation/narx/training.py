"""Training NARX models: the estimators the table
:data:`~spiralid.sysid.estimation.core.families.ESTIMATORS` holds for a
:class:`~spiralid.sysid.models.narx.NARX` or
:class:`~spiralid.sysid.models.narx.PolynomialNARX` structure.

:func:`~spiralid.sysid.identify` with a NARX structure goes through the same
table as ARX: each ``("narx", method)`` entry names its NARX estimator.
What each method does to a NARX:

``"ls"``
    Least squares of the one-step error. For the MLP, Levenberg-Marquardt
    with the exact Jacobian (:meth:`NARX.jacobian`) from the least-squares
    ARX model (the linear bypass) plus small random hidden weights; for the
    polynomial NARX, forward-regression orthogonal least squares (FROLS:
    terms chosen by their error reduction ratio, Billings 2013, ch. 3).
``"oe"``
    The gradient baseline on the free-run error: Levenberg-Marquardt with
    the exact forward-sensitivity Jacobian (the Jacobian backpropagation
    through time computes, accumulated forwards) from two starts, the
    polished one-step model (``"ls"``) and the output-error ARX model in
    the bypass; the start whose polish scores lower on the held-back part
    is kept.
``"sda"``, ``"ebsda"`` (every rule of :data:`spiralid.optim.RULES`)
    The paper's spiral search over the weights, uniform first population
    in the box, no polish: the paper's algorithms as printed.
``"spiral"``
    The recommended spiral method: Eb-SDA over the weights whose first
    population holds the ``"oe"`` starts (safe start), the centre polished
    by a few Levenberg-Marquardt steps every `polish_every` iterations
    (memetic, as the ARX ``"spiral"``), and a final polish with early
    stopping.

Scaling, initialisation and early stopping
------------------------------------------
Signals are scaled by the estimation record's mean and standard deviation
(:class:`~spiralid.sysid.models.narx.Scaling`). Hidden weights start
Glorot-uniform (``+-sqrt(6 / (n_in + h))``), hidden biases and output
weights at zero, so every start is exactly its linear (ARX) model. The last
`holdout` share (default 0.2) of the estimation record is held back: the
free run covers the whole record but the training residuals only the part
before it; Levenberg-Marquardt (:mod:`.levenberg`, the one implementation
of the ARX polish too) runs in rounds of 10 evaluations and stops
after `patience` (3) rounds without a lower held-back cost, returning the
parameters with the lowest held-back cost. For the default method the
patience grows with the best round (``patience_share=0.5``: a polish whose
best round is 100 waits 50 rounds) and the cap of 500 rounds is a safety,
so the held-back cost decides the training length; ``"ls"`` and ``"oe"``
keep a fixed patience and 50 rounds. Searches minimise the training
cost only. The Levenberg-Marquardt fits add a weight decay on the
network's weights (``decay``, default 1e-3; see :func:`identify_narx`).
With ``training="subsequences"`` each Levenberg-Marquardt polish runs on
the error of short stretches started from measured samples, through a
curriculum of lengths, and the held-back share is spread over the record
in blocks (:mod:`.subsequences`).
The reported ``cost`` is the paper's (eq. (2) with the gain
``100 sqrt(K) / rms(y)``, the error's RMS in percent of the output's) over
the whole estimation record.
"""

from __future__ import annotations

import math
import time

import numpy as np

from spiralid._checks import generator, integer
from spiralid.optim import MINIMIZE_OPTIONS, SpiralSearch, minimize
from spiralid.optim.result import OptimiserResult
from spiralid.optim.spiral import _parse_method

from ...data import IOData
from ...models.narx import NARXModel
from ..linear.levenberg import levenberg_marquardt
from ..spiral.population import search_options
from .problem import (
    _TOL,
    MAX_ROUNDS,
    PATIENCE,
    PATIENCE_SHARE,
    NARXProblem,
    narx_result,
    stopping_options,
)
from .starts import _starts
from .subsequences import (
    HOLD_BLOCKS,
    TRAININGS,
    check_holdout_decay,
    check_horizon,
    curriculum,
    replay_stages,
    train_stages,
)

__all__ = ["REFITS", "NARXProblem", "identify_narx"]

#: What follows the early stopping: ``"replay"`` the winning start's rounds
#: again on the whole record (from the whole record's linear start), or
#: ``"none"``, the network as trained on the training part.
REFITS = ("replay", "none")


def _fit(
    problem: NARXProblem,
    starts: dict,
    predictor: str,
    options: dict,
    refit: dict | None = None,
):
    """Train from `starts` with early stopping, then refit on every sample.

    Each start is polished in rounds on the training part while the
    held-back part is scored; the start and round count with the lowest
    held-back cost win (:func:`_early_stopped`). With ``refit="replay"``
    that start (or its entry in `refit`: the same network on the whole
    record's linear model) is then polished again on the whole record for
    exactly that many rounds, so the end of the record is not thrown away;
    with ``refit="none"`` the winner is returned as trained. Returns
    ``(params, start name, rounds)``; with nothing held back the rounds run
    until `max_rounds` or convergence.
    """
    p, name, schedule = _early_stopped(problem, starts, predictor, options)
    rounds = sum(r for _, r in schedule)
    if problem.hold is None or getattr(problem, "refit", "replay") == "none":
        return p, name, rounds
    whole = problem.whole()
    p0 = (refit or {}).get(name, starts[name])
    p = replay_stages(whole, p0, predictor, schedule)
    problem.nfev += whole.nfev
    return p, name, rounds


def _early_stopped(problem: NARXProblem, starts: dict, predictor: str, options):
    """Each start polished through the problem's stages with early stopping;
    the one with the lowest held-back cost (the training cost with nothing
    held back): ``(params, start name, schedule)``."""
    best = None
    stages = problem.stages if predictor == "simulation" else (None,)
    pick = 1 if problem.hold is not None else 0
    for name, p0 in starts.items():
        p, schedule = train_stages(problem, p0, predictor, stages, options)
        score = problem._score(p, predictor, pick)
        if best is None or score < best[0]:
            best = (score, name, p, schedule)
    return best[2], best[1], best[3]


def _contain(problem: NARXProblem, p, linear, predictor: str):
    """`p`, or the linear start when `p` costs more than it on the whole
    estimation record: training never ends above its linear start."""
    if linear is None:
        return p, False
    whole = problem.whole()
    cost = whole._score(p, predictor, 0)
    if cost <= whole._score(linear, predictor, 0):
        return p, False
    return np.asarray(linear, dtype=float).copy(), True


def _train(
    problem,
    starts: dict,
    linear,
    predictor: str,
    options: dict,
    t0,
    refit: dict | None = None,
    **extra,
):
    """:func:`_fit` then :func:`_contain`, as an OptimiserResult."""
    p, name, rounds = _fit(problem, starts, predictor, options, refit)
    p, kept = _contain(problem, p, linear, predictor)
    if kept:
        name, rounds = "linear", 0
    return narx_result(
        problem,
        p,
        t0,
        nit=rounds,
        start=name,
        linear_params=linear,
        kept_linear=kept,
        **extra,
    )


# -- the estimators -------------------------------------------------------------


def estimate_ls(
    problem: NARXProblem,
    *,
    max_rounds: int = 50,
    patience: int = 3,
    patience_share: float = 0.0,
) -> OptimiserResult:
    """``"ls"``: one-step least squares (LM for the MLP, FROLS for the
    polynomial).

    Parameters
    ----------
    problem : NARXProblem
    max_rounds, patience : int
        Of the early stopping (:meth:`NARXProblem.polish`).
    patience_share : float
        Of the early stopping: the patience grows to this share of the best
        round (0: the fixed `patience`, this method's default; the default
        method ``"spiral"`` uses 0.5 and 500 rounds).

    Returns
    -------
    OptimiserResult
    """
    t0 = time.perf_counter()
    start, refit, linear, what = _starts(problem, "ls")
    options = stopping_options(max_rounds, patience, patience_share)
    return _train(
        problem,
        {"linear": start},
        linear,
        "one-step",
        options,
        t0,
        refit={"linear": refit},
        linear_model=what,
        message="Levenberg-Marquardt, one-step error.",
    )


def estimate_oe(
    problem: NARXProblem,
    *,
    max_rounds: int = 50,
    patience: int = 3,
    patience_share: float = 0.0,
) -> OptimiserResult:
    """``"oe"``: the gradient baseline on the predictor's error, from the
    linear start (:func:`~spiralid.sysid.estimation.narx.starts._linear_start`).

    Parameters
    ----------
    problem : NARXProblem
    max_rounds, patience : int
        Of the early stopping (:meth:`NARXProblem.polish`).
    patience_share : float
        Of the early stopping: the patience grows to this share of the best
        round (0: the fixed `patience`, this method's default; the default
        method ``"spiral"`` uses 0.5 and 500 rounds).

    Returns
    -------
    OptimiserResult
        ``start`` names the start that won, ``linear_params`` and
        ``linear_cost`` the linear start and its cost, ``kept_linear``
        whether training ended at it.
    """
    t0 = time.perf_counter()
    start, refit, linear, what = _starts(problem)
    options = stopping_options(max_rounds, patience, patience_share)
    return _train(
        problem,
        {"linear": start},
        linear,
        problem.predictor,
        options,
        t0,
        refit={"linear": refit},
        linear_model=what,
        message="Levenberg-Marquardt with early stopping from the linear start.",
    )


def default_box(problem: NARXProblem, starts=()) -> np.ndarray:
    """Search box: +-3 in every scaled weight, widened to hold the starts.

    Parameters
    ----------
    problem : NARXProblem
    starts : sequence of ndarray
        Points the box must hold (with a margin of half their magnitude).

    Returns
    -------
    ndarray, shape (n_params, 2)
    """
    n = problem.structure.n_params
    half = np.full(n, 3.0)
    for p in starts:
        half = np.maximum(half, 1.5 * np.abs(p))
    return np.column_stack([-half, half])


def estimate_search(problem: NARXProblem, *, rule: str, **options) -> OptimiserResult:
    """The paper's spiral search (rule `rule`) over the weights.

    Parameters
    ----------
    problem : NARXProblem
    rule : str
        A key of :data:`spiralid.optim.RULES`.
    **options
        :func:`spiralid.optim.minimize`'s keyword options and the keys of
        its ``options`` mapping, all flat; ``max_nfev`` defaults to 10,000.

    Returns
    -------
    OptimiserResult
    """
    t0 = time.perf_counter()
    opts = dict(options)
    opts.setdefault("max_nfev", 10_000)
    opts = search_options(opts)
    # identify() takes minimize's `options` keys flat, as its own.
    opts["options"] = {k: opts.pop(k) for k in MINIMIZE_OPTIONS if k in opts}
    box = default_box(problem)
    raw = minimize(
        problem.objective,
        box,
        method=rule,
        rng=problem.rng,
        vectorized=True,
        **opts,
    )
    return narx_result(
        problem,
        raw.x,
        t0,
        nit=int(raw.nit),
        history=np.asarray(raw.history, dtype=float),
        message=str(raw.message),
    )


def estimate_spiral(
    problem: NARXProblem,
    *,
    rule: str = "ebsda",
    n_points: int = 50,
    max_nfev: int = 10_000,
    polish_every: int = 10,
    polish_nfev: int = 5,
    max_iter: int | None = None,
    max_rounds: int = MAX_ROUNDS,
    patience: int = PATIENCE,
    patience_share: float = PATIENCE_SHARE,
) -> OptimiserResult:
    """``"spiral"``: Eb-SDA with safe starts and a memetic polish.

    Parameters
    ----------
    problem : NARXProblem
    rule : str
        The spiral rule (default Eb-SDA).
    n_points : int
        Population size.
    max_nfev : int
        Budget of cost evaluations (the polish's count too).
    polish_every : int
        Polish the centre every this many iterations.
    polish_nfev : int
        Levenberg-Marquardt evaluations per polish (the ARX ``"spiral"``'s
        option of the same name and meaning).
        The defaults differ from the ARX method's (every 5 iterations, 10
        evaluations) because each step here is a free run of the network
        with its forward sensitivities, not a projected linear solve; they
        are the values the NARX method was added with, not tuned since.
    max_iter : int, optional
        Cap on the iterations.
    max_rounds, patience : int
        The final polish's early stopping (:meth:`NARXProblem.polish`):
        at most `max_rounds` rounds of 10 evaluations (default 500, a
        safety: the held-back cost decides), stopping after `patience`
        rounds without a lower held-back cost, or more (`patience_share`).
    patience_share : float
        The patience grows with the best round: the polish stops after
        ``max(patience, ceil(patience_share * best_round))`` rounds without
        a lower held-back cost (default 0.5; 0 with ``max_rounds=50`` is a
        fixed patience over 50 rounds).

    Returns
    -------
    OptimiserResult
        ``start`` names the point whose final polish won.
    """
    t0 = time.perf_counter()
    n_points = integer(n_points, "n_points", 2)
    max_nfev = integer(max_nfev, "max_nfev", n_points)
    polish_every = integer(polish_every, "polish_every", 1)
    polish_nfev = integer(polish_nfev, "polish_nfev", 1)
    if max_iter is not None:
        max_iter = integer(max_iter, "max_iter", 1)
    _parse_method(rule, "rule")
    stopping = stopping_options(max_rounds, patience, patience_share)
    start, refit, linear, what = _starts(problem)
    starts = {"linear": start}
    seeds = np.array(list(starts.values()))
    box = default_box(problem, seeds)
    seeds = np.clip(seeds, box[:, 0], box[:, 1])
    search = SpiralSearch(
        problem.objective,
        box,
        rule,
        n_points=n_points,
        rng=problem.rng,
        vectorized=True,
        x0=seeds,
        bounds_policy="clip",
    )
    fun, jac = problem.residual_and_jacobian(problem.predictor)
    history = [search.fun]
    nit = n_polish = 0
    while problem.nfev + n_points - 1 <= max_nfev:
        if max_iter is not None and nit >= max_iter:
            break
        search.step()
        nit += 1
        if nit % polish_every == 0:
            with np.errstate(all="ignore"):
                res = levenberg_marquardt(
                    fun, jac, search.x, max_nfev=polish_nfev, tol=_TOL
                )
            # The centre must stay in the box: a polish that left it is
            # clipped back (and scored there).
            x = np.clip(res.x, box[:, 0], box[:, 1])
            f = float(problem.objective(x[None, :])[0])
            n_polish += bool(search.move_centre(x, f))
        history.append(search.fun)
    # The final polish with early stopping, from the search's centre and
    # from the linear start: the lowest held-back cost wins, then the
    # winner is refitted on the whole record.
    finals = {"search": search.x, **starts}
    res = _train(
        problem,
        finals,
        linear,
        problem.predictor,
        stopping,
        t0,
        refit={"linear": refit},
        linear_model=what,
        n_polish=n_polish,
        history=np.asarray(history, dtype=float),
    )
    res.nit, res.final_rounds = nit, res.nit
    res.message = (
        f"Eb-SDA with memetic polish; final polish from the {res.start} point."
    )
    return res


def identify_narx(
    data: IOData,
    structure,
    *,
    method: str,
    estimate,
    predictor: str = "simulation",
    initial: str = "rest",
    rng=None,
    holdout: float = 0.2,
    decay: float = 1e-3,
    training: str = "free-run",
    linear_estimator=None,
    **options,
) -> NARXModel:
    """Estimate a NARX model with the estimator `estimate` (the method's
    entry in the estimator table); :func:`~spiralid.sysid.identify` calls it.

    Parameters
    ----------
    data : IOData
        Estimation record.
    structure : NARX or PolynomialNARX
        The structure.
    method : str
        The method's name (recorded in the model).
    estimate : callable
        ``estimate(problem, **options)``, from the method's table entry.
    predictor : {"simulation", "one-step"}
        The error the cost measures.
    initial : {"rest", "measured"}
        Start of the free run.
    rng : int, Generator or None
        Randomness of the initial weights and of a search.
    holdout : float
        Share of the record held back for early stopping, in [0, 0.5).
    decay : float
        Weight decay of the Levenberg-Marquardt fits: the network's weights
        (not the linear bypass) cost ``decay M |w|^2`` beside the ``M``
        squared scaled residuals (MATLAB's ``trainbr`` regularises the same
        way, with a Bayesian choice of the weight). Default 1e-3, chosen on
        seeds 0-4 of ``benchmarks/nonparametric.py``'s nonlinear
        acceleration record (median validation fit 58.7 % without, 62.2 %
        with; 1e-4 gave 61.1 %, 1e-2 62.2 %).
    training : {"free-run", "subsequences"}
        What the Levenberg-Marquardt fits of the simulation error minimise
        (a key of :data:`~.subsequences.TRAININGS`): ``"free-run"`` the
        free run's error over the training part; ``"subsequences"`` the
        error of overlapping stretches of `horizon` samples, each run from
        the measured samples before it (:mod:`.subsequences`), with the
        held-back part in 10 blocks spread over the record instead of its
        end. The early stopping scores the free run either way; the
        searches (and ``"spiral"``'s memetic polish) still move on the
        free run's cost, and every final Levenberg-Marquardt polish runs
        through the stretches' lengths. The
        option ``horizon`` (in `options`) is the stretches' length
        (>= 2), or None (default) for the curriculum
        :data:`~.subsequences.HORIZONS` (each stage starting where the one
        before stopped, up to the training part's length).
    linear_estimator : callable or None
        ``linear_estimator(data, arx, integrator, rng) -> theta``: the
        default method's ARX, the linear start of a free run from rest.
        :func:`~spiralid.sysid.identify` passes its own, so this module
        imports neither it nor the estimators' table (no import circle,
        tests/test_layout.py). None: the least-squares ARX.
    **options
        The estimator's own options (a search's ``max_nfev``...),
        ``horizon`` (see `training`) and ``refit``, what follows the early
        stopping (a key of :data:`REFITS`): ``"replay"`` (default) runs
        the winning start's rounds again on the whole record, from the
        whole record's linear start; ``"none"`` returns the network the
        held-back cost chose, trained on the training part only (the
        held-back samples then only stop the training). Either way the
        result is contained by the whole record's linear start.

    Returns
    -------
    NARXModel
    """
    t_start = time.perf_counter()
    if predictor not in ("simulation", "one-step"):
        raise ValueError(
            f"`predictor` must be 'simulation' or 'one-step'; got {predictor!r}"
        )
    if initial not in ("rest", "measured"):
        raise ValueError(f"`initial` must be 'rest' or 'measured'; got {initial!r}")
    holdout, decay = check_holdout_decay(holdout, decay)
    if training not in TRAININGS:
        raise ValueError(f"`training` must be one of {TRAININGS}; got {training!r}")
    horizon = check_horizon(options.pop("horizon", None))
    refit = options.pop("refit", "replay")
    if refit not in REFITS:
        raise ValueError(f"`refit` must be one of {REFITS}; got {refit!r}")
    if training == "subsequences" and predictor != "simulation":
        raise ValueError(
            "`training` 'subsequences' trains the simulation error; got "
            f"predictor={predictor!r}"
        )
    if horizon is not None and training != "subsequences":
        raise ValueError("`horizon` needs `training='subsequences'`")
    structure.check_length(data)
    blocks = HOLD_BLOCKS if training == "subsequences" else 1
    problem = NARXProblem(
        data, structure, predictor, initial, float(holdout), generator(rng), blocks
    )
    problem.stages = (None,)
    if training == "subsequences":
        problem.stages = curriculum(horizon, structure.max_lag, data.n)
    problem.decay = float(decay)
    problem.refit = refit
    problem.linear_estimator = linear_estimator
    res = estimate(problem, **options)
    history = res.get("history")
    return NARXModel(
        params=res.x,
        structure=problem.structure,
        scaling=problem.scaling,
        ts=data.ts,
        method=method,
        predictor=predictor,
        initial=initial,
        cost=float(res.fun),
        gain=100.0 * math.sqrt(max(data.n - problem.lo, 1)) / problem.rms_all,
        result=res,
        history=history,
        timings={"total": time.perf_counter() - t_start},
        linear_params=res.get("linear_params"),
        linear_model=res.get("linear_model", ""),
        **data.provenance(),
    )
