"""What every search loop of :func:`~spiralid.optim.minimize` shares (private).

The spiral population (:class:`~spiralid.optim.SpiralSearch`) and the
learned-metric poll (:mod:`spiralid.optim.learned`) stop, check the
objective's output and keep points in the box the same way, so a caller
reads either result alike.
"""

import math
from collections.abc import Mapping

import numpy as np

from spiralid._checks import one_of, positive, refuse_options

# Every stop message comes from here, so `message` is always one of these
# (plus the notes below).
STOPS = {
    "max_iter": "Maximum number of iterations reached.",
    "max_nfev": "Maximum number of function evaluations reached.",
    "max_time": "The time limit (max_time) was passed.",
    "target": "Target cost reached.",
    "callback": "The callback requested a stop.",
    "running": "In progress.",
}
NOTES = {
    "initial_nonfinite": (
        "Every initial cost was non-finite; the first initial point served as "
        "centre until a finite cost was found."
    ),
    "never_finite": "No finite cost was found.",
    "target_missed": "The target cost was not reached.",
}
# The STATUS key (spiralid.optim.result) of each way a search stops.
STATUS_CODE = {
    "max_iter": 2,
    "max_nfev": 1,
    "max_time": 3,
    "target": 0,
    "callback": 0,
    "running": 0,
}
POLICIES = ("none", "clip", "reflect")


def finite_or_inf(value) -> float:
    value = float(value)
    return value if math.isfinite(value) else math.inf


def check_costs(raw, shape: tuple, what: str) -> np.ndarray:
    """Check what the objective returned: real numbers of the given shape."""
    arr = np.asarray(raw)
    # None or strings (object arrays) would turn into NaN or fail deep in
    # NumPy; complex costs cannot be ranked.
    if arr.dtype.kind not in "biuf":
        raise ValueError(f"`fun` must return real numbers; got {raw!r:.80}")
    if arr.shape != shape:
        raise ValueError(f"`fun` must return {what}; got shape {arr.shape}")
    return arr


def check_objective(fun, vectorized) -> bool:
    """Check `fun` is callable and `vectorized` a flag; return the flag."""
    if not callable(fun):
        raise TypeError(f"`fun` must be callable; got {fun!r}")
    if not isinstance(vectorized, bool | np.bool_):
        raise TypeError(f"`vectorized` must be True or False; got {vectorized!r}")
    return bool(vectorized)


def check_policy(bounds_policy) -> str:
    return one_of(bounds_policy, "bounds_policy", POLICIES)


def apply_bounds(points: np.ndarray, lo, hi, policy: str) -> None:
    """Bring escaped coordinates of `points` back into ``[lo, hi]`` in place."""
    if policy == "clip":
        np.clip(points, lo, hi, out=points)
    elif policy == "reflect":
        out = (points < lo) | (points > hi)
        if out.any():
            # Only touch escaped coordinates so that points inside the box
            # are not perturbed by rounding.
            w = hi - lo
            y = np.mod(points - lo, 2.0 * w)
            y = np.where(y > w, 2.0 * w - y, y)
            points[out] = (lo + y)[out]


def stop_report(status: str, fun: float, target, initial_nonfinite: bool) -> dict:
    """``status``, ``success`` and ``message`` of a search that stopped as
    `status` (a key of :data:`STOPS`) with best cost `fun`."""
    one_of(status, "status", STOPS)
    finite = math.isfinite(fun)
    reached = target is None or (finite and fun <= target)
    notes = [STOPS[status]]
    if initial_nonfinite and finite:
        notes.append(NOTES["initial_nonfinite"])
    if not finite:
        notes.append(NOTES["never_finite"])
    if status != "running" and not reached and finite:
        notes.append(NOTES["target_missed"])
    # A budget used up (evaluations, iterations or time) is a search that
    # ended as asked.
    success = (
        status in ("max_iter", "max_nfev", "max_time", "target") and finite and reached
    )
    return {
        "status": STATUS_CODE[status],
        "success": success,
        "message": " ".join(notes),
    }


def check_max_time(max_time) -> float | None:
    """`max_time` in seconds (None: no limit), or a ValueError naming it."""
    return None if max_time is None else positive(max_time, "max_time")


def point_in_box(x, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """`x` as a finite vector within ``[lo, hi]`` (a centre moved from
    outside a search), or a ValueError naming it."""
    pt = np.asarray(x, dtype=np.float64)
    if pt.shape != lo.shape or not np.all(np.isfinite(pt)):
        raise ValueError(f"`x` must be a finite vector of shape {lo.shape}; got {x!r}")
    if np.any((pt < lo) | (pt > hi)):
        raise ValueError("`x` must lie within `bounds`")
    return pt


def seed_points(x0, lo: np.ndarray, hi: np.ndarray, m: int) -> np.ndarray:
    """``x0`` as ``(k, n)`` seeds of an ``m``-point population in ``[lo, hi]``."""
    n = lo.size
    if x0 is None:
        return np.empty((0, n))
    try:
        arr = np.array(x0, dtype=np.float64, ndmin=1)
    except (TypeError, ValueError):
        raise ValueError(
            f"`x0` must be an array of shape ({n},) or (k, {n}) with "
            f"1 <= k <= n_points={m}; got {x0!r}"
        ) from None
    if arr.ndim == 1:
        arr = arr.reshape(1, -1)
    if arr.ndim != 2 or arr.shape[1] != n or not 1 <= arr.shape[0] <= m:
        raise ValueError(
            f"`x0` must have shape ({n},) or (k, {n}) with 1 <= k <= "
            f"n_points={m}; got shape {np.shape(x0)}"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError("`x0` must be finite; got non-finite entries")
    outside = np.flatnonzero(np.any((arr < lo) | (arr > hi), axis=1))
    if outside.size:
        raise ValueError(
            f"`x0` must lie within `bounds`; got {outside.size} point(s) "
            f"outside, the first being row {int(outside[0])}"
        )
    return arr


class Trace:
    """A growing float record (a search's history): appending is amortised
    O(1) and :meth:`array` copies, so a callback every iteration does not
    turn a long run quadratic."""

    __slots__ = ("_data", "_size")

    def __init__(self, first: float | None = None):
        self._data = np.empty(64)
        self._size = 0
        if first is not None:
            self.append(first)

    def append(self, value: float) -> None:
        if self._size == self._data.size:
            self._data = np.concatenate([self._data, np.empty(self._size)])
        self._data[self._size] = value
        self._size += 1

    def set_last(self, value: float) -> None:
        self._data[self._size - 1] = value

    def __len__(self) -> int:
        return self._size

    def array(self) -> np.ndarray:
        return self._data[: self._size].copy()


def settings(options, defaults: dict, where: str) -> dict:
    """An optimiser's `options` mapping (None: every default) completed
    with `defaults`; a key that is not one of them is a one-line ValueError
    naming it, `where` and the keys that apply."""
    if options is None:
        return dict(defaults)
    if not isinstance(options, Mapping):
        raise TypeError(
            f"`options` must be a mapping of {', '.join(defaults)} or None; "
            f"got {options!r:.80}"
        )
    refuse_options(options, defaults, where)
    return {**defaults, **options}
