"""The estimator table: one entry per model family and method.

:func:`~spiralid.sysid.identify` finds the estimator of ``(family,
method)`` in :data:`ESTIMATORS`, the family being the structure's
``family`` on a record of one output, its ``outputs_family`` on a record of
several (an ARX structure on several outputs is one shared denominator).
Each entry holds the function that fits the family and the options it
takes; nothing else dispatches on a structure's or a model's class.

========================  ======================================================
family                    methods
========================  ======================================================
``"arx"``                 every key of :data:`~.estimators.METHODS`
``"narx"``                ``"spiral"``, ``"ls"``, ``"oe"``, every rule
``"polynomial-narx"``     ``"ls"`` and ``"spiral"`` (forward regression)
``"shared-denominator"``  :data:`~.denominator.SHARED_METHODS`
``"greybox"``             :data:`~.greybox.fit.GREYBOX_METHODS`
``"neural-state-space"``  ``"spiral"``, ``"oe"``, ``"ls"`` (the linear start's)
========================  ======================================================

Adding a family
---------------
A structure module in :mod:`spiralid.sysid.models` whose class names its
``family`` (and ``outputs_family``, None for one output only), a fitted
model that implements
:class:`~spiralid.sysid.models.protocol.FittedModelProtocol` with its
``"model"`` name in :data:`~spiralid.sysid.models.files.MODEL_KINDS`, an
estimator module with ``fit(data, structure, method, given) -> model``, and
one :class:`Estimator` here per method it takes. ``identify``, the option
contract (:func:`~.options.identify_options`), ``validate``, the command
line and the common family test (``tests/sysid/test_families.py``) read
this table.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from spiralid.optim import RULES

from ...data import IOData
from ...models.arx import ARX
from ...models.protocol import FittedModelProtocol
from ..greybox.fit import GREYBOX_METHODS, fit_greybox
from ..narx import training as _narx
from ..narx.frols import frols
from ..shared.denominator import SHARED_METHODS, identify_shared, shared_options
from ..state_space.training import NSS_OPTIONS, identify_neural_state_space
from .arx_fit import fit_arx
from .estimators import (
    _MINIMIZE_OPTIONS,
    DEFAULT_METHOD,
    METHODS,
    _keyword_options,
    method_options,
)
from .problem import IDENTIFY_DEFAULTS

__all__ = ["ESTIMATORS", "Estimator", "arx_estimator", "estimator", "family_of"]


@dataclass(frozen=True)
class Estimator:
    """One entry of :data:`ESTIMATORS`.

    Attributes
    ----------
    fit : callable
        ``fit(data, structure, method, given) -> model``: the model of
        `structure` on `data` by `method`, `given` identify's arguments by
        name (checked against `options`).
    options : callable
        ``options(refine) -> tuple of str``: every option identify takes for
        this family and method (`refine` a search's ``refine`` argument,
        which brings ``max_time_constant`` with it for an ARX).
    """

    fit: Callable[[IOData, Any, str, dict], FittedModelProtocol]
    options: Callable[[Any], tuple[str, ...]]


def _fixed(names: tuple[str, ...]) -> Callable[[Any], tuple[str, ...]]:
    """Options that do not depend on `refine`."""
    return lambda refine=False: names


# -- ARX: one output ----------------------------------------------------------


def _arx_options(method: str, refine=False) -> tuple[str, ...]:
    """An ARX's options by `method`: ``rng``, ``predictor``, ``initial``,
    ``gain``, ``penalty`` and ``integrator`` always; ``max_time_constant``
    for the methods with ``Method.margin`` and a search with
    ``refine=True``; ``cancel`` for those with ``Method.cancel``;
    ``noise`` for those with ``Method.margin``; then
    :func:`~.estimators.method_options`."""
    spec = METHODS[method]
    out = ["rng", "predictor", "initial", "gain", "penalty", "integrator"]
    refining = isinstance(refine, bool | np.bool_) and bool(refine)
    if spec.margin or (spec.search and refining):
        out.append("max_time_constant")
    if spec.cancel:
        out.append("cancel")
    if spec.margin:
        # The output-error methods' disturbance model (arx_fit.NOISE_MODELS).
        out.append("noise")
    return (*out, *method_options(method))


def arx_estimator(method: str) -> Estimator:
    """The ARX family's entry for `method`, a key of
    :data:`~.estimators.METHODS` (a method added to that table joins this
    one through it)."""
    return Estimator(fit_arx, partial(_arx_options, method))


# -- NARX and polynomial NARX ---------------------------------------------------

_NARX_OWN = (
    "rng", "predictor", "initial", "holdout", "decay", "training", "horizon",
    "refit",
)  # fmt: skip


def _default_arx(data: IOData, arx, integrator: int, rng):
    """The default method's ARX theta, a NARX's linear start: as a user's
    ``identify(data, arx, integrator=..., rng=seed)`` with every other
    argument at its default, on the whole record, from a fresh
    generator."""
    given = {k: IDENTIFY_DEFAULTS[k] for k in _IDENTIFY_ARGUMENTS}
    given.update(integrator=integrator, rng=rng)
    return fit_arx(data, arx, DEFAULT_METHOD, given).theta


# identify's own arguments (the rest of IDENTIFY_DEFAULTS are options).
_IDENTIFY_ARGUMENTS = (
    "predictor", "initial", "rng", "gain", "penalty", "integrator",
    "max_time_constant", "cancel",
)  # fmt: skip


def _fit_narx(data, structure, method, given, *, estimate, takes):
    """A NARX or polynomial NARX by the estimator `estimate`
    (:func:`~.training.identify_narx`), with the options it `takes`."""
    return _narx.identify_narx(
        data,
        structure,
        method=method,
        estimate=estimate,
        linear_estimator=_default_arx,
        **{k: v for k, v in given.items() if k in takes},
    )


def _narx_entry(estimate, options: tuple[str, ...]) -> Estimator:
    takes = (*_NARX_OWN, *options)
    return Estimator(partial(_fit_narx, estimate=estimate, takes=takes), _fixed(takes))


def _by_frols(problem, **options):
    """A polynomial NARX's terms by forward regression, whichever method
    asked (a search would not improve a choice of terms)."""
    return frols(problem)


_POLYNOMIAL = ("rng", "predictor", "initial")


# -- neural state space -----------------------------------------------------------

#: The neural state-space family's methods: the linear start's.
NSS_METHODS = ("spiral", "oe", "ls")


def _nss_linear(data: IOData, order: int, method: str, rng):
    """The neural state space's linear start: ``ARX(order, order, 1)`` by
    `method` with identify's other arguments at their defaults."""
    given = {k: IDENTIFY_DEFAULTS[k] for k in _IDENTIFY_ARGUMENTS}
    given["rng"] = rng
    arx = ARX(order, order, 1)
    return fit_arx(data, arx, method, given).theta, f"{arx} by {method}"


def _fit_nss(data, structure, method, given):
    """A neural state space
    (:func:`~.state_space.training.identify_neural_state_space`)."""
    return identify_neural_state_space(
        data,
        structure,
        method=method,
        linear_estimator=_nss_linear,
        **{k: v for k, v in given.items() if k in ("rng", *NSS_OPTIONS)},
    )


# -- several outputs, one denominator ------------------------------------------


def _fit_shared(data, structure, method, given):
    """One denominator for every output
    (:func:`~.denominator.identify_shared`), fitted to the simulation error
    from rest."""
    if given["predictor"] != "simulation" or given["initial"] != "rest":
        raise ValueError(
            "a record of several outputs is fitted to its simulation error from "
            f"rest; got predictor={given['predictor']!r}, initial={given['initial']!r}"
        )
    own = {k: given[k] for k in SHARED_METHODS[method] if k in given}
    return identify_shared(
        data,
        structure,
        method=method,
        rng=given["rng"],
        integrator=given["integrator"],
        **own,
    )


# -- the table ------------------------------------------------------------------

#: ``(family, method) -> Estimator``: the one table identify reads.
ESTIMATORS: dict[tuple[str, str], Estimator] = {
    **{("arx", name): arx_estimator(name) for name in METHODS},
    **{
        ("narx", name): _narx_entry(
            partial(_narx.estimate_search, rule=name), _MINIMIZE_OPTIONS
        )
        for name in RULES
    },
    ("narx", "spiral"): _narx_entry(
        _narx.estimate_spiral, _keyword_options(_narx.estimate_spiral)
    ),
    ("narx", "ls"): _narx_entry(_narx.estimate_ls, _keyword_options(_narx.estimate_ls)),
    ("narx", "oe"): _narx_entry(_narx.estimate_oe, _keyword_options(_narx.estimate_oe)),
    **{
        ("polynomial-narx", name): Estimator(
            partial(_fit_narx, estimate=_by_frols, takes=_POLYNOMIAL),
            _fixed(_POLYNOMIAL),
        )
        for name in ("ls", DEFAULT_METHOD)
    },
    **{
        ("shared-denominator", name): Estimator(
            _fit_shared, _fixed(shared_options(name))
        )
        for name in SHARED_METHODS
    },
    **{
        ("greybox", name): Estimator(fit_greybox, _fixed(options))
        for name, options in GREYBOX_METHODS.items()
    },
    **{
        ("neural-state-space", name): Estimator(_fit_nss, _fixed(("rng", *NSS_OPTIONS)))
        for name in NSS_METHODS
    },
}


def methods_of(family: str) -> tuple[str, ...]:
    """The methods the table holds for `family`, in its order."""
    return tuple(m for f, m in ESTIMATORS if f == family)


def family_of(structure, n_outputs: int = 1) -> str | None:
    """The family of `structure` on a record of `n_outputs` outputs: its
    ``family``, or for several its ``outputs_family`` (None: the structure
    takes one output); a one-line TypeError for what is not a
    structure."""
    family = getattr(structure, "family", None)
    families = tuple(dict.fromkeys(f for f, _ in ESTIMATORS))
    if family not in families:
        raise TypeError(
            "`structure` must be a model structure of a family of the estimator "
            f"table {families} (ARX, NARX, PolynomialNARX...); got "
            f"{type(structure).__name__}"
        )
    return structure.outputs_family if n_outputs > 1 else family


def estimator(family: str, method: str, structure=None) -> Estimator:
    """The table's entry for `family` and `method` (a key of
    :data:`~.estimators.METHODS`), or a one-line ValueError naming the
    methods that do fit the family."""
    entry = ESTIMATORS.get((family, method))
    if entry is None and family == "arx" and method in METHODS:
        # The ARX entries are METHODS' (one entry there adds a method), also
        # for a method added after this table was built.
        entry = arx_estimator(method)
    if entry is None:
        able = methods_of(family)
        if family == "shared-denominator":
            raise ValueError(
                f"`method` {method!r} takes one output (and one input); a record "
                f"of several outputs or inputs is identified by one of {able} (one "
                "shared denominator), or pass data.output(name) / data.input(name)"
            )
        name = type(structure).__name__ if structure is not None else family
        raise ValueError(
            f"`method` {method!r} does not train {name} models; use one of {able}"
        )
    return entry
