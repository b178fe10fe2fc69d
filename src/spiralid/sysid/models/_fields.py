"""Checks of a saved model's fields, shared by the ``from_dict`` of
``IdentifiedModel``, ``NARXModel`` and ``SharedDenominatorModel`` (private).

A model file may be edited by hand or come from elsewhere: each field is
checked where it is read, and a bad one is refused by its name in the file
("field 'ts' must be ..."), not blamed later on the data or surfacing as a
division by zero.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

_REQUIRED = object()


def plain(value) -> float | None:
    """A number as JSON holds it: NaN and infinities as null."""
    value = float(value)
    return value if np.isfinite(value) else None


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


def integer(
    d: dict,
    name: str,
    allowed: str,
    ok: Callable[[int], bool],
    default=_REQUIRED,
    where: str = "",
) -> int:
    """Field `name` of `d` as an int for which `ok` holds: a JSON integer,
    not a string, a bool or a float (``1.5`` would be truncated)."""
    if default is _REQUIRED and name not in d:
        raise ValueError(f"the field {where + name!r} is missing")
    value = d.get(name, default)
    if isinstance(value, bool) or not isinstance(value, int) or not ok(value):
        raise ValueError(f"field {where + name!r} must be {allowed}; got {value!r}")
    return value


def numbers(
    d: dict, name: str, shape: tuple[int, ...], default=_REQUIRED, null=None
) -> np.ndarray:
    """Field `name` of `d`, a (nested) list of JSON numbers of `shape`, as
    a float array; a ``null`` entry is `null` where that is given (the
    files write NaN or an infinite variance as null), refused otherwise."""
    if default is _REQUIRED and name not in d:
        raise ValueError(f"the field {name!r} is missing")
    value = d.get(name, default)
    wanted = " x ".join(map(str, shape)) if shape else "one"
    allowed = (
        f"a list of {wanted} numbers"
        if len(shape) < 2
        else (f"an array of {wanted} numbers")
    )
    # An object array keeps each entry as the file gave it: a string or a
    # bool is refused here, not converted by NumPy ("1" -> 1.0).
    entries = np.array(value, dtype=object)
    empty = entries.size == 0 == math.prod(shape)
    if entries.shape != shape and not empty:
        raise ValueError(
            f"field {name!r} must be {allowed}; got {_shape_of(value, entries)}"
        )
    out = np.empty(shape)
    if empty:
        return out
    for index, v in np.ndenumerate(entries):
        if v is None and null is not None:
            out[index] = null
        elif isinstance(v, int | float) and not isinstance(v, bool):
            out[index] = float(v)
        else:
            raise ValueError(f"field {name!r} must be {allowed}; got {v!r:.60} in it")
    return out


def _shape_of(value, entries: np.ndarray) -> str:
    if not isinstance(value, list):
        return f"{value!r:.60}"
    return f"{' x '.join(map(str, entries.shape))} entries"


def texts(d: dict, name: str, count: int | None = None, default=_REQUIRED):
    """Field `name` of `d`, a list of `count` strings (any number when
    `count` is None), as a tuple."""
    if default is _REQUIRED and name not in d:
        raise ValueError(f"the field {name!r} is missing")
    value = d.get(name, default)
    size = "" if count is None else f"{count} "
    if (
        not isinstance(value, list | tuple)
        or not all(isinstance(v, str) for v in value)
        or (count is not None and len(value) != count)
    ):
        raise ValueError(
            f"field {name!r} must be a list of {size}strings; got {value!r:.80}"
        )
    return tuple(value)
