"""What every search loop of :func:`~spiralid.optim.minimize` shares (private).

The spiral population (:class:`~spiralid.optim.SpiralSearch`) and the
learned-metric poll (:mod:`spiralid.optim.learned`) stop, check the
objective's output and keep points in the box the same way, so a caller
reads either result alike.
"""

import math

import numpy as np

# Every stop message comes from here, so `message` is always one of these
# (plus the notes below).
STOPS = {
    "max_iter": "Maximum number of iterations reached.",
    "max_nfev": "Maximum number of function evaluations reached.",
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
STATUS_CODE = {"max_iter": 2, "max_nfev": 1, "target": 0, "callback": 0, "running": 0}
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


def check_policy(bounds_policy) -> str:
    if not isinstance(bounds_policy, str) or bounds_policy not in POLICIES:
        raise ValueError(
            f"`bounds_policy` must be one of {POLICIES}; got {bounds_policy!r}"
        )
    return bounds_policy


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
    if status not in STOPS:
        raise ValueError(f"`status` must be one of {tuple(STOPS)}; got {status!r}")
    finite = math.isfinite(fun)
    reached = target is None or (finite and fun <= target)
    notes = [STOPS[status]]
    if initial_nonfinite and finite:
        notes.append(NOTES["initial_nonfinite"])
    if not finite:
        notes.append(NOTES["never_finite"])
    if status != "running" and not reached and finite:
        notes.append(NOTES["target_missed"])
    success = status in ("max_iter", "max_nfev", "target") and finite and reached
    return {
        "status": STATUS_CODE[status],
        "success": success,
        "message": " ".join(notes),
    }
