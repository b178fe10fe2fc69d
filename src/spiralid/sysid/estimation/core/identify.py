"""identify(): data + structure + method -> the family's fitted model.

The entry point only checks its arguments and finds the estimator of the
structure's family and the method in the one table,
:data:`~spiralid.sysid.estimation.core.families.ESTIMATORS`; the pieces live
in modules named for what they hold, each depending only on those above it:

- :mod:`~spiralid.sysid.estimation.core.families`: the estimator table, keyed
  by family and method.
- :mod:`~spiralid.sysid.estimation.core.arx_fit`: the ARX family (the problem,
  the margin's choice, the model with its covariance).
- :mod:`~spiralid.sysid.estimation.linear.parametrizations`: what a search moves
  (``"coefficients"``, ``"reflection"``), its box, initial points and map to
  the ARX theta; the table ``PARAMETRIZATIONS``.
- :mod:`~spiralid.sysid.estimation.linear.outputerror`: the
  Levenberg-Marquardt polish and Steiglitz-McBride.
- :mod:`~spiralid.sysid.estimation.core.estimators`: one function per ARX
  method, the table ``METHODS``, the result type ``EstimatorResult``, the
  budget rule and the safe start.
- :mod:`~spiralid.sysid.models.identified`: :class:`IdentifiedModel`.
- :mod:`~spiralid.sysid.estimation.core.options`: the one option contract
  (which options each method and structure takes).
- :mod:`~spiralid.sysid.estimation.narx.training`: NARX training, given the default
  ARX as its linear start.

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

from spiralid._checks import refuse_options

from ...data import IOData, single_output_record
from ...models.arx import ARX
from ...models.greybox import GreyBox
from ...models.identified import IdentifiedModel
from ...models.narx import NARX, PolynomialNARX
from ...models.protocol import FittedModelProtocol
from ..linear.margin import AUTO
from ..linear.outputerror import steiglitz_mcbride
from ..linear.parametrizations import default_bounds, feasible_initial_points
from .estimators import DEFAULT_METHOD
from .families import estimator, family_of
from .options import (
    IDENTIFY_DEFAULTS,
    _check_method,
    check_method_options,
    identify_options,
    refused_options,
)

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


def identify(
    data: IOData,
    structure: ARX | NARX | PolynomialNARX | GreyBox,
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
) -> FittedModelProtocol:
    """Estimate a model of `structure` from input-output data.

    Parameters
    ----------
    data : IOData
        Estimation record.
    structure : ARX, NARX, PolynomialNARX or GreyBox
        Model structure, e.g. ``ARX(8, 8, 0)`` for eq. (6). Its ``family``
        and the method name the estimator in
        :data:`~spiralid.sysid.estimation.core.families.ESTIMATORS`. A NARX
        structure is trained by the method's NARX estimator
        (:mod:`spiralid.sysid.estimation.narx.training`; ``holdout`` passed through
        `options` sets its early-stopping share) and returns a
        :class:`~spiralid.sysid.models.narx.NARXModel`; an ARX structure on
        a record of several outputs, one denominator for all, returns a
        :class:`~spiralid.sysid.models.shared.SharedDenominatorModel`; a
        :class:`~spiralid.sysid.models.greybox.GreyBox` returns a
        :class:`~spiralid.sysid.models.greybox_model.GreyBoxModel`
        (:mod:`spiralid.sysid.estimation.greybox.fit`).
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
        For a NARX: ``holdout``, ``decay``, ``training`` and ``horizon``
        (:func:`~spiralid.sysid.estimation.narx.training.identify_narx`) and its
        estimator's. Any option that does not apply to the method and
        structure is refused in one line naming it, the method and the
        options that do, unless it equals its default
        (:data:`IDENTIFY_DEFAULTS`, compared by value).

    Other Parameters
    ----------------
    noise : {"white", "integrated"}, default "white"
        The disturbance model of ``"spiral"`` and ``"oe"``: ``"white"``,
        output error (``y = B/A u + e``); ``"integrated"``, output error
        with integrated noise (``y = B/A u + e / (1 - q^-1)``, MATLAB's
        ``IntegrateNoise``): the same method on the differenced record
        ``(du, dy)``, so a slow drift of the output is not fitted by the
        plant's poles. The model is the plant ``B / A``; its cost and
        noise variance are the differenced record's.
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
    FittedModelProtocol
        The family's fitted model (an ARX's
        :class:`~spiralid.sysid.models.identified.IdentifiedModel`, whose
        ``result`` is the estimator's
        :class:`~spiralid.sysid.estimation.core.estimators.EstimatorResult`).

    Notes
    -----
    Options by method, beside ``rng``, ``predictor``, ``initial``,
    ``gain``, ``penalty`` and ``integrator``, which every method takes for
    an ARX structure (with ``"ls"`` and ``"oe"``, `predictor`, `gain` and `penalty`
    only set the reported cost):

    - ``"ls"``: none.
    - ``"oe"``: ``max_time_constant``, ``cancel``, ``noise``.
    - ``"spiral"``: ``max_time_constant``, ``cancel``, ``noise``,
      ``parametrization``, ``bounds``, ``refine``, ``safe_start``,
      ``rule``, ``n_points``, ``max_nfev``, ``polish_every``,
      ``polish_nfev``, ``restarts``, ``frequency_seeds``, ``holdback``,
      ``folds``, ``stop``, ``x0``, ``max_iter``, ``callback``.
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
    ``initial``, ``holdout``, ``decay``, ``training`` and ``horizon``, and:
    ``"ls"`` and ``"oe"``
    ``max_rounds``, ``patience``, ``patience_share``; ``"spiral"``
    ``rule``, ``n_points``, ``max_nfev``, ``polish_every``,
    ``polish_nfev``, ``max_iter``, ``max_rounds``, ``patience``,
    ``patience_share``; a rule
    ``n_points``, ``max_iter``, ``max_nfev``, ``max_time``, ``target``,
    ``x0``, ``callback``, ``bounds_policy``, ``restarts``. A
    PolynomialNARX (``"ls"`` only) takes ``rng``, ``predictor`` and
    ``initial``. A :class:`~spiralid.sysid.models.greybox.GreyBox`
    (:data:`~spiralid.sysid.estimation.greybox.fit.GREYBOX_METHODS`) takes
    ``rng``, ``gain``, ``penalty`` and ``workers`` (its simulations on
    several processes, :mod:`~spiralid.sysid.estimation.greybox.parallel`),
    and: ``"spiral"`` ``n_points``, ``max_nfev``, ``polish_nfev``,
    ``horizons``, ``restarts``, ``explore``; ``"oe"`` ``polish_nfev``,
    ``horizons``;
    ``"sda"`` and ``"ebsda"`` ``n_points``, ``max_nfev``.
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
    # Several outputs or several inputs: one shared denominator.
    several = isinstance(data, IOData) and max(data.n_outputs, data.n_inputs) > 1
    family = family_of(structure, 2 if several else 1)
    if family is None or not several:
        single_output_record(data, "identify")
    # A family that fits several outputs itself (the grey box: its outputs
    # are its functions') takes its options as for one.
    several = several and family != structure.family
    method = _check_method(method)
    entry = estimator(family, method, structure)
    if several:
        refuse_options(
            given,
            entry.options(given.get("refine", False)),
            f"method {method!r} on a record of {data.n_outputs} "
            + (
                "outputs (one shared denominator)"
                if data.n_inputs == 1
                else f"output(s) and {data.n_inputs} inputs (one shared denominator)"
            ),
            IDENTIFY_DEFAULTS,
        )
    else:
        check_method_options(method, given, structure)
    return entry.fit(data, structure, method, given)
