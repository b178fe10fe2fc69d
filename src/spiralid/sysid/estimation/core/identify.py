"""identify(): data + ARX structure + method -> IdentifiedModel.

The entry point only checks its arguments and dispatches; the pieces live
in modules named for what they hold, each depending only on those above it:

- :mod:`~spiralid.sysid.estimation.linear.parametrizations`: what a search moves
  (``"coefficients"``, ``"reflection"``), its box, initial points and map to
  the ARX theta; the table ``PARAMETRIZATIONS``.
- :mod:`~spiralid.sysid.estimation.linear.outputerror`: the Levenberg-Marquardt
  polish and Steiglitz-McBride.
- :mod:`~spiralid.sysid.estimation.core.estimators`: one function per method, the table
  ``METHODS``, the result type ``EstimatorResult``, the budget rule and the
  safe start.
- :mod:`~spiralid.sysid.models.identified`: :class:`IdentifiedModel`.
- :mod:`~spiralid.sysid.estimation.core.options`: the one option contract
  (which options each method and structure takes).
- :mod:`~spiralid.sysid.estimation.narx.training`: NARX training, given this
  module's default ARX as its linear start.

Initial condition of the simulation (``initial``)
-------------------------------------------------
The simulation error that ``"oe"``, ``refine=True`` and the search methods
with ``predictor="simulation"`` minimise starts either from rest
(``initial="rest"``, the default: ``e = y - lfilter(b, a, u)`` over all
``N`` samples, the paper's "actual input applied to the estimated model")
or from the measured past outputs at ``t0 = max_lag``
(``initial="measured"``). Use ``"rest"`` for records that start at rest
(the simulated rig's experiments); on such noisy records the measured
start is harmful, because for lightly damped models it maps the noise of
the ``na`` measured outputs into a large initial state (docs/guide/paper.md
and docs/guide/estimation.md measure both). Use ``"measured"`` only
for a record that starts in motion, such as the real arm (a slice of a
periodic sweep). Least squares and the one-step predictor do not depend on
it.

Stability margin and order (``max_time_constant``, ``cancel``)
--------------------------------------------------------------
``"spiral"``, ``"oe"`` and the polish of ``refine=True`` keep every pole
inside radius ``exp(-ts / T)``, ``T`` the estimation record's length by
default (:mod:`~spiralid.sysid.estimation.linear.margin`), and ``"spiral"`` and
``"oe"`` then remove a pole-zero pair closer than the record's frequency
resolution when that raises the cost by at most 1 %
(:mod:`~spiralid.sysid.estimation.spiral.cancellation`). The paper's searches keep
eq. (3) as printed: they refuse either option.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from spiralid._checks import box_bounds, generator, refuse_options

from ...data import IOData, single_output_record
from ...models.arx import ARX
from ...models.identified import IdentifiedModel
from ...models.narx import NARX, PolynomialNARX
from ...models.polynomials import integrator_count, with_integrator
from ..linear.local_estimators import _act_on_modes
from ..linear.margin import AUTO, is_auto, max_radius
from ..linear.outputerror import steiglitz_mcbride
from ..linear.parametrizations import (
    DEFAULT_PARAMETRIZATION,
    PARAMETRIZATIONS,
    default_bounds,
    feasible_initial_points,
    make_parametrization,
)
from ..narx import training as _narx
from ..spiral import margin_choice
from ..spiral.cancellation import effective, embed_covariance, embed_factor
from ..spiral.heldback import HOLDBACK
from .cost import PaperCost
from .estimators import DEFAULT_METHOD, METHODS
from .options import (
    IDENTIFY_DEFAULTS,
    _check_method,
    check_method_options,
    identify_options,
    refused_options,
)
from .problem import Problem
from .uncertainty import parameter_covariance

__all__ = [
    "IDENTIFY_DEFAULTS",
    "IdentifiedModel",
    "check_method_options",
    "default_bounds",
    "feasible_initial_points",
    "identify",
    "identify_options",
    "refused_options",
    "steiglitz_mcbride",
]


def _check_bounds(bounds, p: int) -> np.ndarray:
    return np.column_stack(box_bounds(bounds, p))


def identify(
    data: IOData,
    arx: ARX,
    method: str = DEFAULT_METHOD,
    *,
    predictor: str = "simulation",
    initial: str = "rest",
    rng=None,
    gain: str | float = "auto",
    penalty: float = 1e6,
    integrator: bool | int = False,
    max_time_constant: float | str | None = AUTO,
    cancel: bool | None = None,
    **options,
) -> IdentifiedModel:
    """Estimate an ARX model from input-output data.

    Parameters
    ----------
    data : IOData
        Estimation record.
    arx : ARX, NARX or PolynomialNARX
        Model structure, e.g. ``ARX(8, 8, 0)`` for eq. (6). A NARX
        structure is trained by the method's NARX estimator
        (:mod:`spiralid.sysid.estimation.narx.training`; ``holdout`` passed through
        `options` sets its early-stopping share) and returns a
        :class:`~spiralid.sysid.models.narx.NARXModel`.
    method : str, default "spiral"
        A key of :data:`spiralid.sysid.estimation.core.estimators.METHODS`, in
        any case: ``"spiral"``
        (the recommended spiral identification: Eb-SDA over the modes with
        the numerator projected out, a memetic Levenberg-Marquardt polish,
        restarts and safe starts; it reaches the output-error optimum, see
        docs/results), ``"ebsda"``, ``"sda"``, ``"lasda"`` (the paper's spiral
        searches), ``"de"`` (SciPy's differential evolution over the same
        cost, box and initial points, a baseline), ``"ls"`` or ``"oe"`` (see
        :mod:`spiralid.sysid.estimation.core.estimators`). ``"ls"`` minimises the
        one-step error and ``"oe"`` the simulation error whatever `predictor` says;
        `predictor` then only selects the reported cost. The default is
        not ``identify_pareto``'s (``"learned-metric"``): ``"spiral"``
        minimises one cost, and a front needs a multiobjective search.
    predictor : {"simulation", "one-step"}
        The error of the paper's cost, eq. (2): the free-run simulation
        error or the one-step prediction error.
    rng : int, numpy.random.Generator or None
        Randomness of a search (initial points and the search), or of a
        NARX's initial weights. Every method accepts it, so one call can
        loop over methods; ``"ls"``, ``"oe"`` and forward regression have
        nothing to seed.
    gain, penalty
        The cost's gain ``w`` and stability penalty, see :class:`PaperCost`.
    initial : {"rest", "measured"}, default "rest"
        Initial condition of the simulation error (the cost, ``"oe"`` and
        ``refine``), see :class:`PaperCost` and the module docstring:
        ``"rest"`` (paper-faithful) for records that start at rest,
        ``"measured"`` for records that start in motion.
    integrator : bool or int
        The output integrates (a pole at z = 1 known beforehand, as the
        rig's hub velocity integrates its torque): ``arx.na`` counts it, the
        estimation chooses the other ``na - 1`` poles. A count ``k`` asks
        for ``k`` poles at ``z = 1``: ``2`` for a double integrator, as the
        rig's hub angle from torque (a rigid-body mode); ``True`` is 1. For
        the free run from rest, ``B / (A' (1 - z^-1)^k)`` applied to ``u``
        is ``B / A'`` applied to the ``k``-fold running sum of ``u``, so any
        method estimates ``B / A'`` from (summed ``u``, ``y``) with its cost
        unchanged, and the model is composed back. Needs
        ``predictor="simulation"`` and ``initial="rest"``. The model is
        marginally stable by design: its stability verdict is on the other
        poles.
    max_time_constant : float, "auto" or None, default "auto"
        A stability margin tied to the data, in seconds: every pole inside
        the radius ``r_max = exp(-ts / T)``, the pole of a continuous mode
        with time constant ``T`` (:mod:`~spiralid.sysid.estimation.linear.margin`).
        A mode slower than the record is indistinguishable from drift; an
        unconstrained estimate fits the drift with a pole at ``|z| ~
        0.9999`` nearly cancelled by a zero, and validates badly.
        ``"auto"``: ``T = N ts``, the estimation record's length, for
        ``"spiral"``, ``"oe"`` and the polish of ``refine=True`` (applied
        inside the modal parametrisation, the variable-projection polish and
        the Levenberg-Marquardt polish, so no evaluation is spent outside
        it), and no margin for the others. ``None``: no margin (the unit
        circle). A number or None given to a method it does not apply to
        (the paper's searches and ``"de"`` without ``refine``, ``"ls"``) is
        refused: they keep eq. (3)'s penalty as printed. A plant that
        integrates is ``integrator=True``, never a pole near ``z = 1``.
        Where ``"auto"``'s margin holds a pole, it is lifted if the model
        without it validates with less than half the error on the held-back
        end of the record (``holdback`` of ``"spiral"``, 0.2 for the others;
        :mod:`~spiralid.sysid.estimation.spiral.margin_choice`, ``model.margin``
        says what happened); a number is never lifted.
    cancel : bool, optional
        After ``"spiral"`` and ``"oe"`` (their default, True), remove a pole
        and a zero closer than the record's frequency resolution (``|p - z|
        < 2 pi / N``) when the reduced model, polished by output error,
        costs at most 1 % more
        (:mod:`~spiralid.sysid.estimation.spiral.cancellation`). The model keeps
        the structure asked for, with zero coefficients where the pair was;
        ``effective_order`` and ``cancellations`` say what was removed.
        After ``"spiral"`` it then removes each pole its modes table flags
        (an interval that reaches ``|z| = 1``, a cancelling zero) with its
        nearest zero where a likelihood-ratio test at 5 % allows
        (:mod:`~spiralid.sysid.estimation.spiral.spurious`; ``model.diagnosis``
        says what was removed and what was kept, and why).
        Refused by the other methods.
    **options
        The method's own options (:func:`identify_options` lists them per
        method and structure; the Notes give the table): for a search,
        those under Other Parameters and its optimiser's
        (:func:`spiralid.optim.minimize`'s ``n_points``, ``max_iter``,
        ``max_nfev``, ``target``, ``callback``, ``bounds_policy``,
        ``restarts``, ``x0``...; for ``"de"`` only ``n_points``,
        ``max_iter``, ``max_nfev``, ``x0`` and ``callback``; for
        ``"spiral"`` those of
        :func:`~spiralid.sysid.estimation.spiral.recommended._estimate_recommended`).
        A budget ``max_nfev`` without ``max_iter`` is the stop
        (:func:`~spiralid.sysid.estimation.spiral.population.search_options`).
        For a NARX: ``holdout`` and ``decay``
        (:func:`~spiralid.sysid.estimation.narx.training.identify_narx`) and its
        estimator's. Any option that does not apply to the method and
        structure is refused in one line naming it, the method and the
        options that do, unless it equals its default
        (:data:`IDENTIFY_DEFAULTS`, compared by value).

    Other Parameters
    ----------------
    parametrization : str, optional
        What a search moves, a key of
        :data:`spiralid.sysid.estimation.linear.parametrizations.PARAMETRIZATIONS`:
        ``"coefficients"`` (the paper's), ``"reflection"`` (stable by
        construction) or ``"modal"`` (the denominator's modes, numerator
        projected out; simulation error from rest only). Default: the
        method's (``"modal"`` for ``"spiral"``, which needs it;
        ``"coefficients"`` otherwise). Search methods only.
    bounds : array_like, shape (p, 2), optional
        Search box in the searched parameters (``[a, b]`` or ``[k, b]``);
        default :func:`default_bounds`. Search methods only.
    refine : bool, default False
        Polish a search's result locally with the ``"oe"`` machinery applied
        to the `predictor`'s error (kept only if it lowers the cost).
        Search methods only.
    safe_start : bool, optional
        Seed a search's first population with the stabilised least-squares
        estimate and the zero model, and let ``refine`` start from least
        squares and Steiglitz-McBride too, so the result is never worse than
        either (see :mod:`spiralid.sysid.estimation.core.estimators`). Default: the
        method's (off for the paper's ``"sda"``, ``"ebsda"`` and for ``"lasda"``,
        ``"de"``). Search methods only.

    Returns
    -------
    IdentifiedModel
        Its ``result`` is the estimator's
        :class:`~spiralid.sysid.estimation.core.estimators.EstimatorResult`.

    Notes
    -----
    Options by method, beside ``rng``, ``predictor``, ``initial``,
    ``gain``, ``penalty`` and ``integrator``, which every method takes for
    an ARX structure (with ``"ls"`` and ``"oe"``, `predictor`, `gain` and `penalty`
    only set the reported cost):

    - ``"ls"``: none.
    - ``"oe"``: ``max_time_constant``, ``cancel``.
    - ``"spiral"``: ``max_time_constant``, ``cancel``,
      ``parametrization``, ``bounds``, ``refine``, ``safe_start``,
      ``rule``, ``n_points``, ``max_nfev``, ``polish_every``,
      ``polish_nfev``, ``restarts``, ``frequency_seeds``, ``holdback``,
      ``stop``, ``x0``, ``max_iter``, ``callback``.
    - ``"de"``: ``max_time_constant`` (with ``refine=True``),
      ``parametrization``, ``bounds``, ``refine``, ``safe_start``,
      ``n_points``, ``max_iter``, ``max_nfev``, ``x0``, ``callback``.
    - every rule of :data:`spiralid.optim.RULES` (``"sda"``, ``"ebsda"``,
      ``"lasda"``, ...): ``max_time_constant`` (with
      ``refine=True``), ``parametrization``, ``bounds``, ``refine``,
      ``safe_start``, ``n_points``, ``max_iter``, ``max_nfev``,
      ``max_time``, ``target``, ``x0``, ``callback``, ``bounds_policy``,
      ``restarts``.

    For a NARX structure every method takes ``rng``, ``predictor``,
    ``initial``, ``holdout`` and ``decay``, and: ``"ls"`` and ``"oe"``
    ``max_rounds``, ``patience``, ``patience_share``; ``"spiral"``
    ``rule``, ``n_points``, ``max_nfev``, ``polish_every``,
    ``polish_nfev``, ``max_iter``, ``max_rounds``, ``patience``,
    ``patience_share``; a rule
    ``n_points``, ``max_iter``, ``max_nfev``, ``max_time``, ``target``,
    ``x0``, ``callback``, ``bounds_policy``, ``restarts``. A
    PolynomialNARX (``"ls"`` only) takes ``rng``, ``predictor`` and
    ``initial``.
    ``tests/test_option_contract.py`` checks this table against
    :func:`identify_options` and the command line.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(300)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> fit = identify(IOData(u, y, ts=0.01), ARX(2, 2, 1), method="ls")
    >>> fit.theta.round(9), fit.is_stable, fit.result["status"]
    (array([-1.5,  0.7,  1. ,  0.5]), True, 0)
    """
    t_start = time.perf_counter()
    given = dict(
        predictor=predictor,
        initial=initial,
        rng=rng,
        gain=gain,
        penalty=penalty,
        integrator=integrator,
        max_time_constant=max_time_constant,
        cancel=cancel,
        **options,
    )
    if isinstance(data, IOData) and data.n_outputs > 1 and isinstance(arx, ARX):
        return _identify_shared(data, arx, method, given)
    single_output_record(data, "identify")
    if not isinstance(arx, ARX | NARX | PolynomialNARX):
        raise ValueError(
            f"`arx` must be an ARX, NARX or PolynomialNARX; got {type(arx).__name__}"
        )
    method = _check_method(method)
    check_method_options(method, given, arx)
    if not isinstance(arx, ARX):
        takes = identify_options(method, arx)
        narx = {k: v for k, v in given.items() if k in takes}
        return _narx.identify_narx(
            data,
            arx,
            method=method,
            estimate=METHODS[method].narx,
            linear_estimator=_default_arx,
            **narx,
        )
    count = integrator_count(integrator, arx.na)
    if count:
        del given["integrator"]
        return _identify_integrating(data, arx, count, dict(method=method, **given))
    problem, options = _problem(method, data, arx, given)
    res = METHODS[method].estimate(problem, **options)
    margin = None
    if is_auto(max_time_constant):
        # The default margin only: a time constant the user gave is kept.
        chosen = margin_choice.choose(problem, res, _holdback(method, options))
        if chosen is not None:
            problem, res, margin = chosen
    if method == DEFAULT_METHOD and problem.cancel and arx.na:
        # The recommended method acts on its own modes table's diagnosis:
        # a flagged pole is removed where the cost allows.
        _act_on_modes(problem, res, (res.get("caps") or {}).get("cancel"))
    return _packaged(method, problem, res, t_start, margin)


def _default_arx(data: IOData, arx: ARX, integrator: int, rng) -> np.ndarray:
    """The default method's ARX theta, a NARX's linear start: handed to
    the NARX estimator so that it does not import this module back. With
    the default stop, as a user's call: on the whole record, from a fresh
    generator, it is the model ``identify(data, arx, integrator=...,
    rng=seed)`` returns."""
    return identify(data, arx, integrator=integrator, rng=rng).theta


def _problem(method: str, data: IOData, arx: ARX, given: dict):
    """identify's checked arguments as a :class:`Problem`, and the options
    left for the estimator."""
    spec = METHODS[method]
    settings = {**IDENTIFY_DEFAULTS, **given}
    options = {k: v for k, v in given.items() if k not in IDENTIFY_DEFAULTS}
    refine, safe_start = settings["refine"], settings["safe_start"]
    if not isinstance(refine, bool | np.bool_):
        raise TypeError(f"`refine` must be True or False; got {refine!r}")
    if safe_start is not None and not isinstance(safe_start, bool | np.bool_):
        raise TypeError(f"`safe_start` must be True, False or None; got {safe_start!r}")
    parametrization = settings["parametrization"]
    if parametrization is None:
        parametrization = spec.parametrization
        if arx.na == 0 and parametrization == "modal":
            # An FIR model has no modes; the recommended method solves it
            # exactly over the coefficients (see `_estimate_fir`).
            parametrization = DEFAULT_PARAMETRIZATION
    radius, cancel = margin_options(
        method, data, refine, settings["max_time_constant"], settings["cancel"]
    )
    # The margin inside the search: for the methods that apply it, in a
    # parametrisation that can hold it (a paper search's refine polishes alone).
    kind = (
        PARAMETRIZATIONS.get(parametrization)
        if isinstance(parametrization, str)
        else None
    )
    inside = spec.margin and getattr(kind, "takes_margin", False)
    par = make_parametrization(parametrization, data, arx, radius if inside else None)
    predictor, initial = settings["predictor"], settings["initial"]
    gain, penalty, bounds = settings["gain"], settings["penalty"], settings["bounds"]
    cost = PaperCost(
        arx, data, predictor=predictor, gain=gain, penalty=penalty, initial=initial
    )
    problem = Problem(
        data=data,
        arx=arx,
        cost=cost,
        predictor=predictor,
        initial=initial,
        gain=gain,
        penalty=penalty,
        parametrization=par,
        rng=generator(settings["rng"]),
        bounds=None if bounds is None else _check_bounds(bounds, par.n_search),
        refine=bool(refine),
        safe_start=spec.safe_start if safe_start is None else bool(safe_start),
        max_radius=radius,
        cancel=cancel,
    )
    return problem, options


def _holdback(method: str, options: dict) -> float:
    """The share of the record the margin's choice holds back: the
    recommended method's `holdback` (None or 0: choose by the cost alone,
    which keeps the margin), :data:`~spiralid.sysid.estimation.spiral.heldback.
    HOLDBACK` for the others."""
    if method == DEFAULT_METHOD:
        return options.get("holdback", HOLDBACK) or 0.0
    return HOLDBACK


def _packaged(
    method: str,
    problem: Problem,
    res,
    t_start: float,
    margin: margin_choice.MarginChoice | None = None,
) -> IdentifiedModel:
    """The method's result on the problem as a model with its covariance."""
    spec = METHODS[method]
    data, arx, cost = problem.data, problem.arx, problem.cost
    predictor, initial = problem.predictor, problem.initial
    refined = res.get("refine")
    t_refine = 0.0 if refined is None else refined.elapsed
    cancelled = res.get("cancelled") or []
    if cancelled:
        # The removed coefficients are fixed at zero, not estimated: the
        # covariance is the reduced model's, with zero variance for them.
        order = res.effective_order
        theta_r, arx_r = effective(res.x, arx, order)
        cov_r, s2, root_r = parameter_covariance(
            theta_r, arx_r, data, spec.minimises or predictor, initial, factor=True
        )
        covariance = embed_covariance(cov_r, arx, order)
        root = None if root_r is None else embed_factor(root_r, arx, order)
    else:
        covariance, s2, root = parameter_covariance(
            res.x, arx, data, spec.minimises or predictor, initial, factor=True
        )
    return IdentifiedModel(
        res.x,
        arx=arx,
        ts=data.ts,
        method=method,
        predictor=predictor,
        parametrization=problem.parametrization.name,
        initial=initial,
        gain=cost.w,
        penalty=cost.penalty,
        cost=res.fun,
        result=res,
        refine_result=refined,
        history=res.history,
        timings={
            "search": res.elapsed,
            "refine": t_refine,
            "total": time.perf_counter() - t_start,
        },
        bounds=res.get("bounds"),
        covariance=covariance,
        covariance_factor=root,
        noise_variance=s2,
        cancellations=tuple(cancelled),
        selection=None if res.get("selection") is None else res.selection.to_dict(),
        margin=None if margin is None else margin.to_dict(),
        diagnosis=_diagnosis(res),
        **data.provenance(),
    )


def _diagnosis(res) -> dict | None:
    """What acting on the modes table did, when it found a flagged pole."""
    found = res.get("diagnosis")
    if found is None or not (found.removed or found.kept or found.untried):
        return None
    return found.to_dict()


def margin_options(method: str, data: IOData, refine, max_time_constant, cancel):
    """identify's ``max_time_constant`` and ``cancel`` for `method`: the
    margin's radius (None: none) and whether to cancel. Whether they apply
    at all is :func:`check_method_options`' rule; here their values."""
    spec = METHODS[method]
    applies = spec.margin or (spec.search and bool(refine))
    if is_auto(max_time_constant):
        seconds = data.n * data.ts if applies else None
    else:
        seconds = _time_constant(max_time_constant, data.ts)
    if cancel is None:
        cancel = spec.cancel
    elif not isinstance(cancel, bool | np.bool_):
        raise TypeError(f"`cancel` must be True, False or None; got {cancel!r}")
    return max_radius(data.ts, seconds), bool(cancel)


def _time_constant(value, ts: float) -> float | None:
    """An explicit ``max_time_constant`` in seconds (None: no margin)."""
    if value is None:
        return None
    bad = isinstance(value, bool | np.bool_ | str)
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        bad = True
    if bad or not (np.isfinite(seconds) and seconds > 0):
        raise ValueError(
            "`max_time_constant` must be a number of seconds > 0, "
            f"{AUTO!r} or None; got {value!r}"
        )
    if seconds < ts:
        # Every pole inside exp(-1) = 0.37 and below: no sampled plant's
        # margin, and r_max^na would underflow.
        raise ValueError(
            "`max_time_constant` must be at least the sample time "
            f"ts = {ts:g} s; got {value!r}"
        )
    return seconds


def _identify_shared(data: IOData, arx: ARX, method, given: dict):
    """`identify` on a record of several outputs: one denominator for all
    (:func:`~spiralid.sysid.estimation.shared.denominator.identify_shared`) by the
    methods of :data:`~spiralid.sysid.estimation.shared.denominator.SHARED_METHODS`."""
    from ..shared.denominator import SHARED_METHODS, identify_shared, shared_options

    method = _check_method(method)
    if method not in SHARED_METHODS:
        raise ValueError(
            f"`method` {method!r} takes one output; a record of several outputs "
            f"{data.output_names} is identified by one of {tuple(SHARED_METHODS)} "
            "(one shared denominator), or pass data.output(name)"
        )
    if given["predictor"] != "simulation" or given["initial"] != "rest":
        raise ValueError(
            "a record of several outputs is fitted to its simulation error from "
            f"rest; got predictor={given['predictor']!r}, initial={given['initial']!r}"
        )
    takes = shared_options(method)
    refuse_options(
        given,
        takes,
        f"method {method!r} on a record of {data.n_outputs} outputs (one shared "
        "denominator)",
        IDENTIFY_DEFAULTS,
    )
    own = {k: given[k] for k in SHARED_METHODS[method] if k in given}
    return identify_shared(
        data,
        arx,
        method=method,
        rng=given["rng"],
        integrator=given["integrator"],
        **own,
    )


def _identify_integrating(
    data: IOData, arx: ARX, count: int, options: dict
) -> IdentifiedModel:
    """`identify` with `count` known integrators: ``B / A'`` from the
    `count`-fold running sum of the input, composed back into
    ``B / (A' (1 - z^-1)^count)``."""
    if options["predictor"] != "simulation" or options["initial"] != "rest":
        raise ValueError(
            "`integrator` needs predictor='simulation' and initial='rest' (the "
            "running sum of the input stands for the integrator's state from "
            f"rest); got predictor={options['predictor']!r}, "
            f"initial={options['initial']!r}"
        )
    u = data.u
    for _ in range(count):
        u = np.cumsum(u)
    inner = identify(replace(data, u=u), ARX(arx.na - count, arx.nb, arx.nk), **options)
    free = inner.theta[: arx.na - count]
    theta = np.r_[with_integrator(free, count), inner.theta[arx.na - count :]]
    return replace(
        inner,
        theta=theta,
        arx=arx,
        input_unit=data.input_unit,
        u_offset=data.u_offset,
        integrator=count,
    )
