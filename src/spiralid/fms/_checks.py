"""Argument checks shared by the fms modules (private).

Each raises a ``ValueError`` that starts with the argument's name in
backticks, says what is allowed and shows what came in. (``fms`` depends on
nothing else of ours, so it does not borrow ``optim``'s checks.)
"""

from __future__ import annotations

import math

import numpy as np


def real(name: str, value) -> float:
    """``value`` as a finite Python float; strings, arrays and None refused."""
    if isinstance(value, str | bytes | bool | np.bool_) or not np.isscalar(value):
        v = math.nan
    else:
        try:
            v = float(value)
        except (TypeError, ValueError):
            v = math.nan
    if not math.isfinite(v):
        raise ValueError(f"`{name}` must be a finite number; got {value!r}")
    return v


def _signed(name: str, value, allowed: str, ok) -> float:
    try:
        v = real(name, value)
    except ValueError:
        v = math.nan  # reported below with the range, not just "finite"
    if not ok(v):
        raise ValueError(f"`{name}` must be a finite number {allowed}; got {value!r}")
    return v


def positive(name: str, value) -> float:
    """``value`` as a finite float > 0."""
    return _signed(name, value, "> 0", lambda v: v > 0.0)


def nonneg(name: str, value) -> float:
    """``value`` as a finite float >= 0."""
    return _signed(name, value, ">= 0", lambda v: v >= 0.0)


def is_integer(value) -> bool:
    """True for Python and NumPy integers, False for bools and floats."""
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def real_array(name: str, value) -> np.ndarray:
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
