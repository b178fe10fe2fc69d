"""The one protocol every fitted model implements: :class:`FittedModelProtocol`.

Every family's fitted model (an ARX fit,
:class:`~spiralid.sysid.models.identified.IdentifiedModel`; a NARX fit,
:class:`~spiralid.sysid.models.narx.NARXModel`; a model of several outputs
with one denominator,
:class:`~spiralid.sysid.models.shared.SharedDenominatorModel`) answers the
same names with the same meaning, and :func:`~spiralid.sysid.identify`,
:func:`~spiralid.sysid.validate`, the command line and the report read a
model through these names only, never by its class.

Why a :class:`typing.Protocol` and not an abstract base class: the families
do not share one base (a model of several outputs holds one output name per
output, not :class:`~spiralid.sysid.models.fitted.FittedModel`'s one), and
a new family conforms by having the members, not by inheriting; a type
checker verifies it statically, and ``isinstance(model,
FittedModelProtocol)`` (runtime checkable) verifies that the members are
present, which the common family test asserts for every family.

Names and meanings
------------------
``structure``
    The structure the model was fitted in (``ARX``, ``NARX``,
    ``PolynomialNARX``); its ``family`` names the table entry that fitted
    it.
``params``
    Every estimated parameter as one flat array (``theta`` is the same
    array where a family calls it so).
``simulate(u)``
    The free run from rest over the input `u` (an ``IOData`` gives its
    ``u``), shape ``(N,)`` for one output, ``(N, p)`` for ``p`` outputs.
``predict(data)``
    The one-step-ahead prediction on the record `data`, shaped as
    ``simulate``'s.
``linear_part``
    The linear model inside this one: the model itself for a linear
    family; for a NARX its linear start, or None without a linear bypass.
``is_linear``
    Whether the model is linear in the signals: then it has ``modes``
    (its modes table with intervals), ``is_stable`` (from its poles),
    ``poles``, ``zeros``, ``polynomials`` (its transfer function's
    numerator and denominator in ``z^-1``) and ``free_denominator`` (the
    denominator without the poles at ``z = 1`` it has by design), which
    :func:`~spiralid.sysid.validate` reads for its linear checks; a
    nonlinear model has none of them (its free run, in
    :func:`~spiralid.sysid.validate`, says whether it stays bounded).
``output_names``, ``output_model(which)``
    The outputs the model predicts, and the model of one of them: the
    model itself for a model of one output, which
    :func:`~spiralid.sysid.validate` uses to validate each output.
``method``, ``ts``, ``input_name``, ``input_unit``, ``u_offset``
    How it was estimated and on what record: the method's name, the sample
    time, and the input's name, unit and the offset removed from it before
    estimation (``spiralid validate`` removes the same from new data); each
    output model's ``output_name``, ``output_unit`` and ``y_offset`` say
    the same of its output.
``to_dict()`` / ``from_dict(d)``
    The JSON form of ``model.json``, whose ``"model"`` field names the
    family; :func:`~spiralid.sysid.models.files.load_model` reads any.
``summary()``
    A few lines of plain text: structure, method, cost and what the
    family adds.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = ["FittedModelProtocol", "check_fitted", "is_fitted"]


@runtime_checkable
class FittedModelProtocol(Protocol):
    """What every fitted model answers, whatever its family (see the
    module docstring for each name's meaning).

    A protocol is not instantiated: ``isinstance(model,
    FittedModelProtocol)`` (or :func:`is_fitted`) asks whether a model has
    every member.

    Parameters
    ----------
    *args, **kwargs
        None taken (a protocol class cannot be instantiated).
    """

    method: str
    ts: float
    input_name: str
    input_unit: str
    u_offset: float

    @property
    def structure(self) -> Any: ...

    @property
    def params(self) -> np.ndarray: ...

    @property
    def linear_part(self) -> Any: ...

    @property
    def is_linear(self) -> bool: ...

    @property
    def output_names(self) -> tuple[str, ...]: ...

    def output_model(self, which: int | str) -> FittedModelProtocol: ...

    def simulate(self, u) -> np.ndarray: ...

    def predict(self, data) -> np.ndarray: ...

    def to_dict(self, *, timings: bool = True) -> dict: ...

    @classmethod
    def from_dict(cls, d: dict) -> FittedModelProtocol: ...

    def summary(self) -> str: ...


def is_fitted(value) -> bool:
    """Whether `value` implements :class:`FittedModelProtocol` (has every
    member; a type checker verifies their types)."""
    return isinstance(value, FittedModelProtocol)


def check_fitted(value, name: str = "model") -> None:
    """`value` implements :class:`FittedModelProtocol`, or a one-line
    TypeError naming the argument `name` and what `value` is."""
    if not is_fitted(value):
        raise TypeError(
            f"`{name}` must be a fitted model (from identify() or load_model); "
            f"got {type(value).__name__}"
        )
