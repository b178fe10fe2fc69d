"""The ARX estimators: one function per method, chosen by name from
:data:`METHODS`.

As ``scipy.optimize`` has one ``_minimize_<method>`` per method, the ARX
family's fit (:func:`~spiralid.sysid.estimation.core.arx_fit.fit_arx`, the ARX
entries of :data:`~spiralid.sysid.estimation.core.families.ESTIMATORS`) gathers
identify's checked arguments in a :class:`Problem` and calls
``METHODS[method].estimate(problem, **options)``. Other families' estimators
are their entries in that table.
Every estimator returns an :class:`EstimatorResult`, an ``OptimizeResult``
whose ``x`` is the ARX theta.

Methods
-------
``"sda"``, ``"ebsda"``, ``"lasda"`` (and every other rule in
:data:`spiralid.optim.RULES`)
    The spiral optimisers of :func:`spiralid.optim.minimize` over the
    paper's cost :class:`~spiralid.sysid.PaperCost` (eq. (2)-(3)), in a
    parametrisation of :mod:`spiralid.sysid.estimation.linear.parametrizations`.
``"de"``
    SciPy's differential evolution over the same cost, box and initial
    points (:func:`spiralid.optim.differential_evolution`), a baseline.
``"ls"``
    Least squares, the exact minimiser of the one-step error.
``"oe"``
    Output error (:mod:`spiralid.sysid.estimation.linear.outputerror`):
    Levenberg-Marquardt on the simulation error from the least-squares and
    the Steiglitz-McBride starts, keeping the lower estimation cost.

Budget
------
:func:`search_options` is the one budget rule (``identify``, the command
line and ``spiralid reproduce`` use it): a budget of evaluations
``max_nfev`` is the stop; without an explicit ``max_iter`` the iteration
cap is set to ``max_nfev``, which never binds first (every iteration costs
at least one evaluation). Without ``max_nfev`` the optimiser's own
``max_iter`` default (500) applies.

Safe start
----------
With ``safe_start=True`` a search's first population holds the stabilised
least-squares estimate and the zero model (mapped into the searched
coordinates and clipped into the box), and ``refine`` polishes from the
least-squares and Steiglitz-McBride starts too, beside the search's best.
The centre of a spiral search and the best member of DE never get worse,
and a polish is kept only if it lowers the cost, so the result costs no
more than either model (when the box holds them, as the default boxes
do). The paper's configurations leave it off (``Method.safe_start=False``
for ``sda``, ``ebsda``, ``lasda`` and ``de``): their first populations are
the paper's, so their numbers per seed stay as printed. A method added for
usable models turns it on in its table entry.

Stability margin and pole-zero cancellation
--------------------------------------------
``"spiral"`` and ``"oe"`` (``Method.margin``, ``Method.cancel``) keep every
pole inside radius ``exp(-ts / T)``, ``T`` the estimation record's length by
default (identify's ``max_time_constant``,
:mod:`~spiralid.sysid.estimation.linear.margin`; also the polish of
``refine=True``), and remove a pole-zero pair closer than the record's
frequency resolution when that costs at most 1 % (identify's ``cancel``,
:mod:`~spiralid.sysid.estimation.spiral.cancellation`). The paper's searches and
``"de"`` keep eq. (3)'s penalty alone.

Status
------
``status`` is a key of :data:`STATUS`: ``1`` when the estimator stopped at
its evaluation cap (a search's ``max_nfev``; the Levenberg-Marquardt polish
of ``"oe"`` and ``refine`` at ``least_squares``' ``max_nfev``, before its
tolerances were met), ``2`` at an iteration cap, ``0`` otherwise. The polish
of ``refine`` is in ``result.refine`` with its own status.

Adding a method
---------------
Write ``_estimate_<name>(problem, **options) -> EstimatorResult`` in a
module that this one imports, as the others are: ``ls`` and ``oe`` in
:mod:`~spiralid.sysid.estimation.linear.local_estimators`, the paper's searches and
``de`` in :mod:`~spiralid.sysid.estimation.spiral.population`, ``spiral`` in
:mod:`~spiralid.sysid.estimation.spiral.recommended`; the :class:`Problem` it
takes and the :class:`EstimatorResult` it returns are in
:mod:`~spiralid.sysid.estimation.core.problem`. A population search builds on
``population._search`` with its optimiser, which gives it the
parametrisation, the box, the initial points, the safe start, the status
and ``refine``.
Then add one entry to :data:`METHODS`::

    METHODS["name"] = Method(_estimate_name, search=True, safe_start=True)

``identify(method=...)``, the command line's ``--method`` choices and
``spiralid reproduce``'s configurations read that table; nothing else lists
methods. :data:`DEFAULT_METHOD` is the default of ``identify`` and of
``spiralid identify``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

from spiralid.choices import DEFAULT_METHOD, METHOD_NAMES, require_names
from spiralid.optim import MINIMIZE_OPTIONS, RULES, differential_evolution, minimize
from spiralid.optim.result import STATUS

from ..linear.local_estimators import _estimate_ls, _estimate_oe
from ..linear.parametrizations import DEFAULT_PARAMETRIZATION
from ..spiral.population import _estimate_de, _estimate_spiral, search_options
from ..spiral.recommended import _estimate_recommended
from .problem import EstimatorResult, Problem

__all__ = [
    "DEFAULT_METHOD",
    "METHODS",
    "SEARCH_PROBLEM_OPTIONS",
    "STATUS",
    "EstimatorResult",
    "Method",
    "Problem",
    "method_options",
    "search_options",
]


@dataclass(frozen=True)
class Method:
    """One entry of :data:`METHODS`.

    Attributes
    ----------
    estimate : callable
        ``estimate(problem, **options) -> EstimatorResult``.
    search : bool
        A population search over a parametrisation: takes optimiser options,
        ``rng``, ``bounds``, ``refine`` and ``safe_start``.
    options : tuple of str
        The optimiser options it accepts (the keyword-only parameters of
        what runs it, :func:`_keyword_options`); empty for a method that
        does not search.
    safe_start : bool
        Default of ``identify(safe_start=None)`` (see the module docstring).
    parametrization : str
        Default of ``identify(parametrization=None)``.
    minimises : str or None
        The error the estimate minimises, for its covariance
        (:mod:`~spiralid.sysid.estimation.core.uncertainty`): a predictor name, or
        None for the cost's own predictor.
    margin : bool
        Applies identify's ``max_time_constant`` (by default the record's
        length) to its parametrisation and polish; a search without it
        applies it to ``refine``'s polish only.
    cancel : bool
        Default of ``identify(cancel=None)``: remove near-cancelling
        pole-zero pairs after the estimate; False: the option does not
        apply.
    """

    estimate: Callable[..., EstimatorResult]
    search: bool = True
    options: tuple[str, ...] = ()
    safe_start: bool = False
    parametrization: str = DEFAULT_PARAMETRIZATION
    minimises: str | None = None
    margin: bool = False
    cancel: bool = False


def _keyword_options(function: Callable, own: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The keyword-only parameters of `function`, less those in `own` (what
    the estimator sets itself): a method's options come from the signature
    of what runs it, so the list cannot drift from the code."""
    import inspect

    return tuple(
        name
        for name, par in inspect.signature(function).parameters.items()
        if par.kind is inspect.Parameter.KEYWORD_ONLY and name not in own
    )


# minimize's keywords and the keys of its `options`, all passed flat here.
_MINIMIZE_OPTIONS = _keyword_options(
    minimize, own=("method", "rng", "vectorized", "options")
) + tuple(MINIMIZE_OPTIONS)

# One entry per method; its key is the name users pass.
METHODS: dict[str, Method] = {
    **{
        name: Method(
            partial(_estimate_spiral, rule=name),
            # The rule is the method's own, so a method bound to one rule
            # cannot be re-ruled.
            options=_MINIMIZE_OPTIONS,
        )
        for name in RULES
    },
    "de": Method(
        _estimate_de,
        options=_keyword_options(differential_evolution, own=("rng",)),
    ),
    "spiral": Method(
        _estimate_recommended,
        options=_keyword_options(_estimate_recommended),
        safe_start=True,
        parametrization="modal",
        margin=True,
        cancel=True,
    ),
    "ls": Method(
        _estimate_ls,
        search=False,
        options=(),
        minimises="one-step",
    ),
    "oe": Method(
        _estimate_oe,
        search=False,
        options=(),
        margin=True,
        cancel=True,
    ),
}

# What identify() takes beside a search's optimiser options: what the
# search moves, its box, the polish after it and the safe start. Methods
# that do not search (ls, oe) take none of them.
SEARCH_PROBLEM_OPTIONS = ("parametrization", "bounds", "refine", "safe_start")


def method_options(method: str) -> tuple[str, ...]:
    """The options `method` takes through ``identify(**options)`` for an
    ARX structure: a search's :data:`SEARCH_PROBLEM_OPTIONS` and its
    optimiser's; a method that does not search takes none. Another
    family's options are its entries' in
    :data:`~spiralid.sysid.estimation.core.families.ESTIMATORS`.

    Examples
    --------
    >>> method_options("ls")
    ()
    """
    spec = METHODS[method]
    return (*SEARCH_PROBLEM_OPTIONS, *spec.options) if spec.search else ()


require_names(METHODS, METHOD_NAMES, "spiralid.sysid.METHODS")
