"""The checks every signal of sysid goes through: finite, real, 1-D (or one
column per output), equally long, and of a magnitude double precision
can square."""

from __future__ import annotations

import numpy as np


def check_signal(x, name: str, min_size: int = 1) -> np.ndarray:
    """A finite 1-D float signal from a list, (N,) or (N, 1) array.

    The one check every signal of sysid goes through, so bad input gives
    the same message everywhere: the argument's name, what is allowed and,
    for a non-finite value, the first bad sample. Not a copy when `x` is
    already a float array.
    """
    try:
        arr = np.asarray(x)
        complex_ = arr.dtype.kind == "c"
        if not complex_:
            arr = arr.astype(float, copy=False)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`{name}` must be a numeric 1-D signal; got {exc}") from None
    if complex_:
        # Casting would drop the imaginary part with only a ComplexWarning:
        # whether the real part, the magnitude or the phase is the signal is
        # the caller's to say.
        raise ValueError(
            f"`{name}` must be real-valued; got complex values (pass its real "
            "part or magnitude, e.g. np.real(x) or np.abs(x))"
        )
    if arr.ndim == 2 and arr.shape[1] == 1:
        arr = arr[:, 0]
    if arr.ndim != 1:
        raise ValueError(
            f"`{name}` must be a 1-D signal of shape (N,) or (N, 1); "
            f"got shape {arr.shape}"
        )
    if arr.size < min_size:
        raise ValueError(
            f"`{name}` must have at least {min_size} sample"
            f"{'s' if min_size > 1 else ''}; got {arr.size}"
        )
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(
            f"`{name}` must be finite; got {float(arr[i])!r} at sample {i} "
            f"({int(bad.sum())} non-finite samples in all)"
        )
    return arr


def check_pair(a, b, name_a: str, name_b: str) -> tuple[np.ndarray, np.ndarray]:
    """Two signals through :func:`check_signal`, refused unless equally long."""
    a = check_signal(a, name_a)
    b = check_signal(b, name_b)
    if a.size != b.size:
        raise ValueError(
            f"`{name_a}` and `{name_b}` must have the same length; "
            f"got {a.size} and {b.size}"
        )
    return a, b


def check_outputs(y, name: str = "y") -> np.ndarray:
    """A finite float output: a 1-D signal (one output, as
    :func:`check_signal`), or an (N, p) array of p >= 2 outputs, each
    column checked as a signal named ``y[:, k]``."""
    arr = np.asarray(y) if not isinstance(y, np.ndarray) else y
    if arr.ndim == 2 and arr.shape[1] >= 2:
        cols = [check_signal(arr[:, k], f"{name}[:, {k}]") for k in range(arr.shape[1])]
        return np.column_stack(cols)
    return check_signal(y, name)


# Sums of squares of N samples overflow beyond about 1e154 / sqrt(N), and
# products of small samples underflow below about 1e-154; the limits leave
# room for the regression's cross products on records of any practical size.
_LARGEST = 1e100
_SMALLEST = 1e-100


def _check_magnitude(x: np.ndarray, name: str) -> None:
    """Refuse a signal whose squares overflow or underflow in double precision."""
    peak = float(np.max(np.abs(x))) if x.size else 0.0
    if peak > _LARGEST or 0.0 < peak < _SMALLEST:
        raise ValueError(
            f"`{name}` must be rescaled: its largest magnitude {peak:.3g} is "
            f"outside [{_SMALLEST:g}, {_LARGEST:g}], where sums of squares "
            "overflow or vanish in double precision (e.g. convert it to SI units)"
        )


def per_channel(value, p: int, name: str, kind, what: str = "output"):
    """`value` for each of p channels (outputs or inputs): one value for
    all, or a sequence of p values; converted by `kind` (str or float)."""
    if isinstance(value, str | int | float | np.number) and not isinstance(value, bool):
        return (kind(value),) * p
    try:
        values = tuple(kind(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(
            f"`{name}` must be one value or one per {what} ({p}); got {value!r}"
        ) from None
    if len(values) != p:
        raise ValueError(
            f"`{name}` must have one entry per {what} ({p}); got {len(values)}"
        )
    return values
