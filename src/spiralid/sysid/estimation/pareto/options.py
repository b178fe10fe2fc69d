"""The options of :func:`~spiralid.sysid.identify_pareto`: which apply to
which objectives (:func:`pareto_options`) with their defaults, which are
refused (:func:`refused_pareto_options`, the command line's check too), and
the checked settings of one call."""

from __future__ import annotations

import numpy as np

from spiralid._checks import integer, is_default, refuse_options
from spiralid.optim.pareto import PARETO_OPTIONS, minimize_pareto

from ..linear.frequency import DEFAULT_MIN_COHERENCE

__all__ = ["pareto_options", "refused_pareto_options"]


def pareto_options(objectives) -> dict:
    """The options :func:`identify_pareto` takes through ``**options`` for
    these objectives, with their defaults: the search's
    (:func:`~spiralid.optim.pareto.minimize_pareto`'s keyword options and
    the keys of its ``options``, flat, less those it sets itself), the
    models' and, with the ``"frequency"``
    objective, its H1 estimate's.

    Examples
    --------
    >>> sorted(pareto_options(("cost", "one-step")))  # doctest: +NORMALIZE_WHITESPACE
    ['extremes_nfev', 'max_nfev', 'max_time', 'n_points', 'neighbours',
     'parametrization', 'seed_estimates']
    """
    out = {**_SEARCH_DEFAULTS, **_MODEL_DEFAULTS}
    if "frequency" in objectives:
        out.update(_FREQUENCY_DEFAULTS)
    return out


def _search_defaults() -> dict:
    import inspect

    from ..core.estimators import _keyword_options

    # What each structure's search sets itself (its seeds, its own archive,
    # the progress callback, the shared generator, the hypervolume's
    # reference point); `options`' other keys are taken flat, as identify
    # takes minimize's.
    own = ("rng", "vectorized", "callback", "x0", "archive", "options", "ref_point")
    signature = inspect.signature(minimize_pareto).parameters
    defaults = {
        name: signature[name].default
        for name in _keyword_options(minimize_pareto, own=own)
    }
    defaults.update((k, v) for k, v in PARETO_OPTIONS.items() if k not in own)
    # Per order, half minimize_pareto's 100 points and 10,000 evaluations:
    # the same iterations per search (49 of the default rule, 99 of a spiral
    # rule), and every order is a search of its own (with its seeds'
    # output-error fits and its polishes besides).
    defaults.update(n_points=50, max_nfev=5_000)
    return defaults


_SEARCH_DEFAULTS = _search_defaults()
_MODEL_DEFAULTS = dict(parametrization="modal", seed_estimates=True, extremes_nfev=200)
_FREQUENCY_DEFAULTS = dict(
    nperseg=None, fmin=None, fmax=None, min_coherence=DEFAULT_MIN_COHERENCE
)


# Every option of identify_pareto with its default, whatever the objectives:
# one left at its default is never refused.
_EVERY_DEFAULT = {**_SEARCH_DEFAULTS, **_MODEL_DEFAULTS, **_FREQUENCY_DEFAULTS}


def refused_pareto_options(objectives, options: dict) -> list[str]:
    """The names in `options` that :func:`identify_pareto` refuses for
    `objectives`, in their order: those :func:`pareto_options` does not
    list, unless equal to their default. The command line refuses its flags
    by this check.

    Examples
    --------
    >>> refused_pareto_options(("cost", "one-step"), {"min_coherence": 0.3})
    ['min_coherence']
    >>> refused_pareto_options(("cost", "one-step"), {"min_coherence": 0.5})
    []
    """
    applicable = pareto_options(objectives)
    return [
        name
        for name, value in options.items()
        if name not in applicable
        and not (name in _EVERY_DEFAULT and is_default(value, _EVERY_DEFAULT[name]))
    ]


def _pareto_settings(method, names, options: dict) -> dict:
    """`options` checked against :func:`pareto_options` (one line naming an
    option that does not apply), completed with the defaults."""
    refuse_options(
        options,
        pareto_options(names),
        f"identify_pareto with method {method!r} and objectives {names}",
        defaults=_EVERY_DEFAULT,
    )
    settings = {**_EVERY_DEFAULT, **options}
    seeded = settings["seed_estimates"]
    if not isinstance(seeded, bool | np.bool_):
        raise TypeError(f"`seed_estimates` must be True or False; got {seeded!r}")
    settings["extremes_nfev"] = integer(settings["extremes_nfev"], "extremes_nfev", 0)
    return settings
