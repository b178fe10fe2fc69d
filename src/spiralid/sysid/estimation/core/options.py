"""identify's one option contract: which options each method takes for
each structure (:func:`identify_options`), their defaults
(:data:`IDENTIFY_DEFAULTS`, never refused when passed by value), and the one
check (:func:`check_method_options`) that :func:`~spiralid.sysid.identify`,
the command line and study files share."""

from __future__ import annotations

from spiralid._checks import is_default, one_of, refuse_options

from ...models.arx import ARX
from ...models.narx import NARX  # noqa: F401 (the doctests' structure)
from .estimators import METHODS
from .families import estimator, family_of
from .problem import IDENTIFY_DEFAULTS

__all__ = [
    "IDENTIFY_DEFAULTS",
    "check_method_options",
    "identify_options",
    "refused_options",
]


def identify_options(
    method: str, structure, refine: bool = False, n_outputs: int = 1
) -> tuple[str, ...]:
    """Every option :func:`identify` takes for `method` and `structure` (on
    a record of `n_outputs` outputs), its own arguments and ``**options``
    alike: the options of the estimator table's entry
    (:data:`~.families.ESTIMATORS`); the one table `identify`, the command
    line and the tests check against.

    ``rng`` for every method and structure: one call can then loop over
    methods, and a deterministic method (``"ls"``, ``"oe"``, forward
    regression) has nothing to seed (a documented acceptance, not an
    option ignored by mistake).
    For an ARX structure: ``predictor``, ``initial``, ``gain``,
    ``penalty`` and ``integrator`` always;
    ``max_time_constant`` for the methods with ``Method.margin`` and a
    search with ``refine=True``; ``cancel`` for those with
    ``Method.cancel``; then
    :func:`~spiralid.sysid.estimation.core.estimators.method_options`.
    For a NARX: ``predictor``, ``initial``, ``holdout``, ``decay``,
    ``training``, ``horizon`` and the
    method's NARX estimator's options; a PolynomialNARX (forward
    regression) takes ``predictor`` and ``initial`` only.

    Examples
    --------
    >>> identify_options("ls", ARX(2, 2, 1))
    ('rng', 'predictor', 'initial', 'gain', 'penalty', 'integrator')
    >>> identify_options("oe", NARX(2, 2, 1))  # doctest: +NORMALIZE_WHITESPACE
    ('rng', 'predictor', 'initial', 'holdout', 'decay', 'training', 'horizon',
     'refit', 'max_rounds', 'patience', 'patience_share')
    """
    family = family_of(structure, n_outputs)
    return estimator(family, method, structure).options(refine)


def _check_method(method) -> str:
    """`method` as a key of METHODS (any case), or a one-line ValueError."""
    if isinstance(method, str):
        # As minimize and scipy.optimize.minimize: names in any case.
        method = method.lower()
    return one_of(method, "method", METHODS)


def refused_options(method: str, options: dict, structure=None) -> list[str]:
    """The names in `options` that :func:`check_method_options` refuses
    for `method` and `structure` (default an ARX), in their order."""
    structure = ARX(1, 1, 0) if structure is None else structure
    applicable = identify_options(method, structure, options.get("refine", False))
    defaults = IDENTIFY_DEFAULTS
    return [
        name
        for name, value in options.items()
        if name not in applicable
        and not (name in defaults and is_default(value, defaults[name]))
    ]


def check_method_options(method: str, options: dict, structure=None) -> None:
    """The one check of the options given to `method` for `structure`
    (default an ARX) against :func:`identify_options`, for `identify`, the
    command line and study files alike: a one-line ValueError naming the
    first option that does not apply, the method and the options that do,
    before any work. An option equal to :data:`IDENTIFY_DEFAULTS`' value is
    never refused."""
    method = _check_method(method)
    structure = ARX(1, 1, 0) if structure is None else structure
    family = family_of(structure)
    kind = "" if family == "arx" else f" for a {type(structure).__name__}"
    applicable = identify_options(method, structure, options.get("refine", False))
    refuse_options(
        options, applicable, f"method {method!r}{kind}", defaults=IDENTIFY_DEFAULTS
    )
