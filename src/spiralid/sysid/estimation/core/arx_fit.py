"""The ARX family's estimation: an ARX structure on a record of one
output, by any method of :data:`~.estimators.METHODS`.

:func:`fit_arx` is the ARX entry of the estimator table
(:data:`~spiralid.sysid.estimation.core.families.ESTIMATORS`): given
:func:`~spiralid.sysid.identify`'s checked arguments it builds the
:class:`~.problem.Problem`, runs the method's estimator, makes the default
margin's held-back choice, acts on the modes table (the recommended
method) and packages the :class:`~spiralid.sysid.IdentifiedModel` with its
covariance. Known integrators are estimated on the summed input and
composed back (:func:`_identify_integrating`).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from spiralid._checks import box_bounds, generator

from ...data import IOData
from ...models.arx import ARX
from ...models.identified import IdentifiedModel
from ...models.polynomials import integrator_count, with_integrator
from ..linear.local_estimators import _act_on_modes
from ..linear.margin import AUTO, is_auto, max_radius
from ..linear.parametrizations import (
    DEFAULT_PARAMETRIZATION,
    PARAMETRIZATIONS,
    make_parametrization,
)
from ..spiral import folds, margin_choice
from ..spiral.cancellation import effective, embed_covariance, embed_factor
from ..spiral.heldback import HOLDBACK
from .cost import PaperCost
from .estimators import DEFAULT_METHOD, METHODS
from .problem import IDENTIFY_DEFAULTS, Problem
from .uncertainty import parameter_covariance

__all__ = ["INTEGRATED", "NOISE_MODELS", "WHITE", "fit_arx", "margin_options"]

#: identify's ``noise``: the disturbance model of the output-error fit. White
#: (the default): ``y = B/A u + e``. Integrated: ``y = B/A u + e / (1 -
#: q^-1)``, a drift of independent steps (MATLAB's ``IntegrateNoise``), whose
#: prediction error is ``dy - B/A du``: the same fit on the differenced
#: record, so the plant's poles are not spent on a slow disturbance.
WHITE = "white"
INTEGRATED = "integrated"
NOISE_MODELS = (WHITE, INTEGRATED)


def _check_bounds(bounds, p: int) -> np.ndarray:
    return np.column_stack(box_bounds(bounds, p))


def fit_arx(data: IOData, arx: ARX, method: str, given: dict) -> IdentifiedModel:
    """An ARX model of `data` by `method`, from identify's arguments `given`
    (checked against the option contract; the keys of
    :data:`~.options.IDENTIFY_DEFAULTS` that were passed and the method's
    own options).

    Parameters
    ----------
    data : IOData
        A record of one output.
    arx : ARX
        The structure.
    method : str
        A key of :data:`~.estimators.METHODS`.
    given : dict
        identify's arguments by name.

    Returns
    -------
    IdentifiedModel
    """
    t_start = time.perf_counter()
    given = dict(given)
    if noise_model(given.pop("noise", WHITE)) == INTEGRATED:
        return _identify_integrated_noise(data, arx, method, given)
    max_time_constant = given.get("max_time_constant", AUTO)
    count = integrator_count(given.get("integrator", False), arx.na)
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
    if (
        method == DEFAULT_METHOD
        and arx.na
        and folds.wanted(options.get("folds", folds.DEFAULT), problem, res)
    ):
        # Then the folds across the record choose among it, output error
        # and output error with integrated noise (with "auto" only where the
        # modes table flagged a pole: elsewhere the model is untouched).
        folds.choose(problem, res)
    # Output error's polish kept for the folds (with its problem): not part
    # of the model.
    res.pop("oe_fit", None)
    return _packaged(method, problem, res, t_start, margin)


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
    which keeps the margin), :data:`~.heldback.HOLDBACK` for the others."""
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


def noise_model(noise) -> str:
    """identify's ``noise``, checked: a key of :data:`NOISE_MODELS`."""
    if not isinstance(noise, str):
        raise TypeError(
            f"`noise` must be a string, one of {NOISE_MODELS}; got {noise!r}"
        )
    if noise not in NOISE_MODELS:
        raise ValueError(f"`noise` must be one of {NOISE_MODELS}; got {noise!r}")
    return noise


def _identify_integrated_noise(
    data: IOData, arx: ARX, method: str, given: dict
) -> IdentifiedModel:
    """`identify` with integrated noise: the plant ``B / A`` fitted on the
    differenced record ``(du, dy)`` (every other option as given; the
    default margin's ``T`` is that record's length, one sample shorter),
    then returned with `data`'s provenance. Its cost and noise variance are
    the differenced record's: the integrated noise's innovations."""
    if data.n < 3:
        raise ValueError(
            f"`noise='integrated'` needs a record of at least 3 samples; got {data.n}"
        )
    if "folds" in given and folds.check(given["folds"]) is True:
        # The folds choose between white and integrated noise themselves.
        raise ValueError(
            "`folds=True` already weighs output error with integrated noise; "
            "give it with noise='white'"
        )
    if method == DEFAULT_METHOD:
        # The noise model is chosen: no folds ("auto") on the differenced
        # record.
        given = {**given, "folds": False}
    diff = replace(data, u=np.diff(data.u), y=np.diff(data.y))
    inner = fit_arx(diff, arx, method, given)
    inner.result.noise = INTEGRATED
    inner.result.message = (
        f"{inner.result.message} Fitted on the differenced record (integrated noise)."
    )
    return inner


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
    method = options.pop("method")
    inner = fit_arx(
        replace(data, u=u), ARX(arx.na - count, arx.nb, arx.nk), method, options
    )
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
