"""Argument checks shared across the package (private leaf): numbers,
integers, arrays, boxes, a choice among names, options.

Each raises an error that starts with the argument's name in backticks,
says what is allowed and shows what came in, so that bad input never
surfaces as a NumPy or Numba traceback from deep inside a kernel. As in
SciPy, a value of the wrong type (a string where a number goes, a float
where an integer goes) is a ``TypeError`` and a value of the right type
but out of range (a negative size, a NaN, a name not among the choices) a
``ValueError``; both messages read the same.

This module imports nothing of ours, so ``optim`` and ``fms`` can both use it
and still depend on nothing else in the package (docs/design-notes.md,
"Layout and dependencies").

A scalar is a Python or NumPy real number or a 0-d array; strings, bools
and sequences are of the wrong type, and every message says "a finite
number" (with the allowed range when there is one).
"""

from __future__ import annotations

import math
import operator

import numpy as np


def real(value, name: str) -> float:
    """``value`` as a finite Python float."""
    return _ranged(value, name, "", lambda v: True)


def _as_float(value) -> float | None:
    """``float(value)`` for a real scalar, None for any other type."""
    if isinstance(value, str | bytes | bool | np.bool_) or np.ndim(value) != 0:
        return None
    try:
        return float(value)
    except (TypeError, ValueError):
        return None


def _ranged(value, name: str, allowed: str, ok) -> float:
    v = _as_float(value)
    if v is None or not (math.isfinite(v) and ok(v)):
        error = TypeError if v is None else ValueError
        what = f"a finite number {allowed}" if allowed else "a finite number"
        raise error(f"`{name}` must be {what}; got {value!r}")
    return v


def positive(value, name: str) -> float:
    """``value`` as a finite float > 0."""
    return _ranged(value, name, "> 0", lambda v: v > 0.0)


def nonneg(value, name: str) -> float:
    """``value`` as a finite float >= 0."""
    return _ranged(value, name, ">= 0", lambda v: v >= 0.0)


def integer(value, name: str, minimum: int) -> int:
    """``value`` as an int >= ``minimum``; bools and floats are refused
    (a TypeError)."""
    try:
        if isinstance(value, bool | np.bool_):
            raise TypeError
        out = operator.index(value)
    except TypeError:
        raise TypeError(
            f"`{name}` must be an integer >= {minimum}; got {value!r}"
        ) from None
    if out < minimum:
        raise ValueError(f"`{name}` must be an integer >= {minimum}; got {value!r}")
    return out


def one_of(value, name: str, choices) -> str:
    """``value`` if it is one of the strings ``choices`` (a sequence, or a
    mapping's keys); anything else is refused with the choices listed: a
    non-string a TypeError, another string a ValueError."""
    allowed = tuple(choices)
    if not isinstance(value, str) or value not in allowed:
        error = ValueError if isinstance(value, str) else TypeError
        raise error(f"`{name}` must be one of {allowed}; got {value!r}")
    return value


def named_index(value, name: str, names) -> int:
    """The 0-based position of `value` among `names` (an output's, say),
    given as one of the names or as an index (a NumPy integer too)."""
    names = tuple(names)
    if isinstance(value, str):
        if value not in names:
            raise ValueError(f"`{name}` must be one of {names}; got {value!r}")
        return names.index(value)
    if is_integer(value):
        if not 0 <= value < len(names):
            raise ValueError(
                f"`{name}` must be an index in [0, {len(names) - 1}] or one of "
                f"{names}; got {value!r}"
            )
        return int(value)
    raise TypeError(f"`{name}` must be an index or one of {names}; got {value!r}")


def is_integer(value) -> bool:
    """True for Python and NumPy integers, False for bools and floats."""
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def real_array(value, name: str) -> np.ndarray:
    """``value`` as a float64 array; strings, None and complex are refused
    with a TypeError, ragged sequences with a ValueError.

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
        # The message only when refused: the repr of a long record is slow.
        error = ValueError if arr is None else TypeError
        raise error(f"`{name}` must be an array of real numbers; got {value!r:.80}")
    return arr.astype(np.float64, copy=False)


def generator(rng) -> np.random.Generator:
    """``numpy.random.default_rng(rng)``, with a clear error for bad seeds:
    a TypeError for a seed of the wrong type (a float, a string), a
    ValueError for a negative integer, as NumPy raises."""
    if isinstance(rng, np.random.Generator):
        return rng
    what = (
        "`rng` must be None, a non-negative integer, a SeedSequence or a "
        f"numpy.random.Generator; got {rng!r}"
    )
    try:
        if isinstance(rng, bool | float | str | bytes):
            raise TypeError
        return np.random.default_rng(rng)
    except TypeError:
        raise TypeError(what) from None
    except ValueError:
        raise ValueError(what) from None


def box_bounds(bounds, n: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(low, high)`` of a box given as (low, high) pairs, an (n, 2) array
    or a ``scipy.optimize.Bounds``: finite, ``low < high``, finite widths,
    and `n` dimensions when `n` is given. Anything else, or entries that
    are not numbers, is a TypeError; a wrong shape or values a ValueError."""
    from scipy.optimize import Bounds

    what = (
        "`bounds` must be a sequence of (low, high) pairs, an (n, 2) array or "
        "a scipy.optimize.Bounds"
    )
    try:
        if isinstance(bounds, Bounds):
            lo = np.asarray(bounds.lb, dtype=np.float64)
            hi = np.asarray(bounds.ub, dtype=np.float64)
            if lo.ndim > 1 or hi.ndim > 1 or (lo.ndim == 0 and hi.ndim == 0):
                raise ValueError(
                    f"{what}; a Bounds needs 1-D lb/ub; got lb={bounds.lb!r}, "
                    f"ub={bounds.ub!r}"
                )
            lo, hi = (np.array(a) for a in np.broadcast_arrays(lo, hi))
        else:
            if not isinstance(bounds, list | tuple | np.ndarray):
                raise TypeError
            arr = np.asarray(bounds, dtype=np.float64)
            if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 1:
                raise ValueError(f"{what}; got shape {arr.shape}")
            lo, hi = arr[:, 0].copy(), arr[:, 1].copy()
    except (TypeError, ValueError) as err:
        if str(err).startswith("`bounds`"):
            raise
        raise TypeError(f"{what}; got {bounds!r:.80}") from None
    if n is not None and lo.size != n:
        raise ValueError(
            f"`bounds` must have {n} (low, high) pairs; got {lo.size} pairs"
        )
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ValueError(f"`bounds` must be finite; got low={lo!r}, high={hi!r}")
    bad = np.flatnonzero(lo >= hi)
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"`bounds` must have low < high in every dimension; got "
            f"({float(lo[i])!r}, {float(hi[i])!r}) in dimension {i}"
        )
    with np.errstate(over="ignore"):
        width = hi - lo
    if not np.all(np.isfinite(width)):
        raise ValueError(
            f"`bounds` must have a finite width high - low; got low={lo!r}, high={hi!r}"
        )
    return lo, hi


def is_default(value, default) -> bool:
    """`value` is an option's default: the same object, or an equal number
    or string (``penalty=float("1e6")`` is the default 1e6, ``True`` is not
    ``1``)."""
    if value is default:
        return True
    if isinstance(default, bool):
        return isinstance(value, bool | np.bool_) and bool(value) == default
    if isinstance(value, bool | np.bool_):
        return False
    if isinstance(default, int | float) and isinstance(value, int | float | np.number):
        return bool(value == default)
    return isinstance(default, str) and isinstance(value, str) and value == default


def refuse_options(given, applicable, where: str, defaults=None) -> None:
    """The one rule of every public entry point: an option that does not
    apply to `where` (a method, a structure) is a one-line ValueError
    naming it, `where` and the options that do apply, unless it equals its
    default (`defaults[name]`, compared by value with :func:`is_default`).

    Parameters
    ----------
    given : dict
        The options passed, by name.
    applicable : iterable of str
        The options `where` takes.
    where : str
        What the options were given to, e.g. ``"method 'ls'"``.
    defaults : dict, optional
        Defaults of options that are accepted when left at them.
    """
    applicable = tuple(applicable)
    defaults = {} if defaults is None else defaults
    for name, value in given.items():
        if name in applicable:
            continue
        if name in defaults and is_default(value, defaults[name]):
            continue
        takes = ", ".join(applicable) if applicable else "none"
        raise ValueError(
            f"`{name}` does not apply to {where}; the options that do: {takes}"
        )
