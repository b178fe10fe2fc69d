"""Argument checks shared by optim and fms (private leaf).

Each raises a ``ValueError`` that starts with the argument's name in
backticks, says what is allowed and shows what came in, so that bad input
never surfaces as a NumPy or Numba traceback from deep inside a kernel.

This module imports nothing of ours, so ``optim`` and ``fms`` can both use it
and still depend on nothing else in the package (docs/design-notes.md,
"Layout and dependencies").

The scalar checks have two readings, chosen by ``strict`` (default ``True``):

* ``strict=True`` refuses bools and non-scalars (lists, arrays of any shape)
  and, in ``positive``/``nonneg``, names the allowed range for every bad
  value; the word is "a finite number".
* ``strict=False`` takes whatever ``float()`` takes except strings and bytes
  (so bools and 0-d arrays pass) and reports a value that is not a finite
  real as such before looking at its range; the word is "a finite real
  number".

``fms`` uses the strict reading and ``optim`` the other; both wordings are
pinned by the tests, which is why they are kept.
"""

from __future__ import annotations

import math
import operator

import numpy as np


def real(value, name: str, *, strict: bool = True) -> float:
    """``value`` as a finite Python float (see the module for ``strict``)."""
    if strict:
        ok = not isinstance(value, str | bytes | bool | np.bool_) and np.isscalar(value)
    else:
        ok = not isinstance(value, str | bytes)
    v = math.nan
    if ok:
        try:
            v = float(value)
        except (TypeError, ValueError):
            pass
    if not math.isfinite(v):
        what = "a finite number" if strict else "a finite real number"
        raise ValueError(f"`{name}` must be {what}; got {value!r}")
    return v


def _ranged(value, name: str, strict: bool, allowed: str, ok) -> float:
    if strict:
        try:
            v = real(value, name)
        except ValueError:
            v = math.nan  # reported below with the range, not just "finite"
    else:
        v = real(value, name, strict=False)
    if not ok(v):
        raise ValueError(f"`{name}` must be a finite number {allowed}; got {value!r}")
    return v


def positive(value, name: str, *, strict: bool = True) -> float:
    """``value`` as a finite float > 0."""
    return _ranged(value, name, strict, "> 0", lambda v: v > 0.0)


def nonneg(value, name: str, *, strict: bool = True) -> float:
    """``value`` as a finite float >= 0."""
    return _ranged(value, name, strict, ">= 0", lambda v: v >= 0.0)


def integer(value, name: str, minimum: int) -> int:
    """``value`` as an int >= ``minimum``; bools and floats are refused."""
    try:
        if isinstance(value, bool | np.bool_):
            raise TypeError
        out = operator.index(value)
    except TypeError:
        raise ValueError(
            f"`{name}` must be an integer >= {minimum}; got {value!r}"
        ) from None
    if out < minimum:
        raise ValueError(f"`{name}` must be an integer >= {minimum}; got {value!r}")
    return out


def is_integer(value) -> bool:
    """True for Python and NumPy integers, False for bools and floats."""
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def real_array(value, name: str) -> np.ndarray:
    """``value`` as a float64 array; strings, None, ragged and complex refused.

    Cheap for float64 arrays (the hot path of the search): no copy, no
    conversion, no warning filters.
    """
    if isinstance(value, np.ndarray) and value.dtype == np.float64:
        return value
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):  # ragged nested sequences
        arr = None
    # Kinds b, i, u, f convert exactly enough; complex would lose its
    # imaginary part and object/str arrays would fail or become NaN.
    if arr is None or arr.dtype.kind not in "biuf":
        raise ValueError(
            f"`{name}` must be an array of real numbers; got {value!r:.80}"
        )
    return arr.astype(np.float64, copy=False)


def generator(rng) -> np.random.Generator:
    """``numpy.random.default_rng(rng)``, with a clear error for bad seeds."""
    if isinstance(rng, np.random.Generator):
        return rng
    try:
        if isinstance(rng, bool | float | str | bytes):
            raise TypeError
        return np.random.default_rng(rng)
    except (TypeError, ValueError):
        raise ValueError(
            "`rng` must be None, a non-negative integer, a SeedSequence or a "
            f"numpy.random.Generator; got {rng!r}"
        ) from None
