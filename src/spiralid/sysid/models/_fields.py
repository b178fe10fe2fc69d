"""Checks of a saved model's fields, shared by ``IdentifiedModel.from_dict``
and ``NARXModel.from_dict`` (private).

A model file may be edited by hand or come from elsewhere: each field is
checked where it is read, and a bad one is refused by its name in the file
("field 'ts' must be ..."), not blamed later on the data or surfacing as a
division by zero.
"""

from __future__ import annotations

import math
from collections.abc import Callable

_REQUIRED = object()


def number(
    d: dict,
    name: str,
    allowed: str,
    ok: Callable[[float], bool],
    default=_REQUIRED,
    where: str = "",
) -> float:
    """Field `name` of `d` (`default` when absent; required without one) as
    a float for which `ok` holds; `where` prefixes the name in the message
    (``"scaling."``)."""
    if default is _REQUIRED and name not in d:
        raise ValueError(f"the field {where + name!r} is missing")
    value = d.get(name, default)
    # JSON's numbers only: a string or a bool is not a number in the file.
    numeric = isinstance(value, int | float) and not isinstance(value, bool)
    v = float(value) if numeric else math.nan
    if not (numeric and ok(v)):
        raise ValueError(f"field {where + name!r} must be {allowed}; got {value!r}")
    return v


def finite(v: float) -> bool:
    return math.isfinite(v)


def positive(v: float) -> bool:
    return math.isfinite(v) and v > 0


def nonneg(v: float) -> bool:
    return math.isfinite(v) and v >= 0


def anything(v: float) -> bool:
    return True


def gain(d: dict) -> float:
    """Field 'gain', the cost's ``w``: a positive number, or NaN (the
    default) for a model that does not know it."""
    return number(
        d,
        "gain",
        "a number > 0 (or NaN: unknown)",
        lambda v: math.isnan(v) or positive(v),
        math.nan,
    )


def method(d: dict, known) -> str:
    """Field 'method', one of `known`."""
    value = d["method"]
    if not isinstance(value, str) or value not in known:
        raise ValueError(
            f"field 'method' must be one of {', '.join(known)}; got {value!r}"
        )
    return value
