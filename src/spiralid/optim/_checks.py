"""Argument checks shared by the optim modules (private).

Each raises a ``ValueError`` that starts with the argument's name in
backticks, says what is allowed and shows what came in, so that bad input
never surfaces as a NumPy or Numba traceback from deep inside a kernel.
"""

import math
import operator

import numpy as np


def real(value, name: str) -> float:
    """``value`` as a finite Python float."""
    try:
        if isinstance(value, str | bytes):
            raise TypeError
        out = float(value)
    except (TypeError, ValueError):
        raise ValueError(
            f"`{name}` must be a finite real number; got {value!r}"
        ) from None
    if not math.isfinite(out):
        raise ValueError(f"`{name}` must be a finite real number; got {value!r}")
    return out


def positive(value, name: str) -> float:
    """``value`` as a finite float > 0."""
    out = real(value, name)
    if out <= 0.0:
        raise ValueError(f"`{name}` must be a finite number > 0; got {value!r}")
    return out


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
