"""The fit %, the RMSE, and what every structure's validation shares (the
record's signals, the gain of eq. (2), the free run and one-step
prediction, a free run that ran away, the run from measured samples):
:func:`~.validate.validate` computes them once for any model, and the
nonlinear part (:mod:`.nonlinear`) reuses them without importing it."""

from __future__ import annotations

import warnings

import numpy as np

from spiralid._checks import positive

from ..estimation.core.cost import auto_gain
from ..estimation.linear.outputerror import error_functions
from ..signals import check_pair

__all__ = ["fit_from_measured", "fit_percent", "rmse"]

# Below this fit % (an error a million percent of the output's spread) the
# digits only tell how long an unstable run grew: a table says it diverged.
_DIVERGED_FIT = -1e6


def _format_fit(fit: float, run: str = "free run", unit: str = "") -> str:
    """A fit % as a table prints it, followed by `unit`: two decimals, or
    for a `run` that ran away its order of magnitude and that it diverged."""
    if not fit < _DIVERGED_FIT:
        return f"{fit:.2f}{unit}"
    return f"{fit:.2g}{unit} (the {run} diverged)"


def fit_percent(y, yhat) -> float:
    """Normalised fit in percent, as MATLAB's ``compare`` reports it.

    ``fit = 100 (1 - ||y - yhat|| / ||y - mean(y)||)``: 100 for a perfect
    model, 0 for one no better than the output's mean, negative for worse.

    Parameters
    ----------
    y : array_like, shape (N,)
        Measured output.
    yhat : array_like, shape (N,)
        Model output (simulated or predicted).

    Returns
    -------
    float

    Examples
    --------
    ``||e|| = 1`` and ``||y - mean(y)|| = sqrt(2)``, so the fit is
    ``100 (1 - 1 / sqrt(2))``:

    >>> round(fit_percent([1.0, 2.0, 3.0], [1.0, 2.0, 4.0]), 6)
    29.289322
    """
    a, b = check_pair(y, yhat, "y", "yhat")
    scale = np.linalg.norm(a - a.mean())
    if scale == 0.0:
        raise ValueError(
            "`y` must not be constant: the fit is relative to its variation; "
            f"got every sample equal to {a[0]!r}"
        )
    return float(100.0 * (1.0 - np.linalg.norm(a - b) / scale))


def rmse(y, yhat) -> float:
    """Root-mean-square error ``sqrt(mean((y - yhat)^2))``.

    Examples
    --------
    >>> rmse([0.0, 0.0], [3.0, 4.0])  # sqrt((9 + 16) / 2)
    3.5355339059327378
    """
    a, b = check_pair(y, yhat, "y", "yhat")
    return float(np.sqrt(np.mean((a - b) ** 2)))


def _signals_of(data, name: str = "data"):
    for attr in ("u", "y", "ts"):
        if not hasattr(data, attr):
            raise TypeError(
                f"`{name}` must be an IOData (with .u, .y, .ts); "
                f"got {type(data).__name__}"
            )
    if np.ndim(data.y) == 2 and np.shape(data.y)[1] > 1:
        # Before .ravel() would interleave the outputs into one signal.
        data.require_single_output(f"validate (`{name}`)")
    if np.ndim(data.u) == 2 and np.shape(data.u)[1] > 1:
        data.require_single_input(f"validate (`{name}`)")
    u = np.asarray(data.u, dtype=float).ravel()
    y = np.asarray(data.y, dtype=float).ravel()
    if u.size != y.size:
        raise ValueError(
            f"`{name}` must have input and output of the same length; "
            f"got {u.size} and {y.size}"
        )
    return u, y, float(data.ts)


# A free run that leaves this many times the measured output's largest
# value has diverged (its fit would be below -1e6 %, where _format_fit says
# so); it is clipped there, so the error range, spectra and tests stay
# finite.
_RUNAWAY = 1e6


def _bounded_run(y_sim: np.ndarray, y: np.ndarray, why: str = ""):
    """The free run, clipped when it ran away, and whether it did (with one
    warning line: validation never raises on a model it accepted)."""

    if y_sim.size != y.size:
        raise ValueError(
            f"`model.simulate(data.u)` must have {y.size} samples; got {y_sim.size}"
        )
    limit = _RUNAWAY * max(float(np.max(np.abs(y), initial=0.0)), 1e-300)
    with np.errstate(invalid="ignore"):
        if np.all(np.isfinite(y_sim)) and np.max(np.abs(y_sim), initial=0.0) < limit:
            return y_sim, False
    warnings.warn(
        f"the model's free run diverges on this record{why}: its fit is "
        "reported but only says so",
        UserWarning,
        stacklevel=3,
    )
    clipped = np.clip(np.nan_to_num(y_sim, nan=0.0), -limit, limit)
    return clipped, True


def _gain(gain, model, y: np.ndarray) -> float:
    """The gain ``w`` of eq. (2) on the validation record (see `validate`)."""
    if isinstance(gain, str) and gain == "auto":
        return auto_gain(y)
    if isinstance(gain, str) and gain == "model":
        w = float(getattr(model, "gain", np.nan))
        if not (np.isfinite(w) and w > 0):
            raise ValueError(
                f"`gain` 'model' needs a model with a finite positive gain; got {w!r}"
            )
        return w
    try:
        return positive(gain, "gain")
    except (TypeError, ValueError) as err:
        # A string other than the two is a wrong value, not a wrong type.
        error = ValueError if isinstance(gain, str) else type(err)
        raise error(
            f"`gain` must be 'auto', 'model' or a finite number > 0; got {gain!r}"
        ) from None


def check_sample_time(model, ts: float) -> None:
    """Refuse a record whose sample time is not the model's (a model
    without one, a bare structure's, takes any)."""
    model_ts = getattr(model, "ts", None)
    if model_ts is not None and not np.isclose(float(model_ts), ts, rtol=1e-9):
        raise ValueError(
            f"`data` sample time must match the model's ts = {float(model_ts)!r}; "
            f"got ts = {ts!r}"
        )


def responses(model, data, warmup):
    """The model's free run and one-step prediction over ``data`` (after
    ``warmup`` when given), and the index of ``data``'s first sample in the
    run: what every model's validation scores, linear or not."""
    u, y, ts = _signals_of(data)
    if warmup is None:
        y_sim = np.asarray(model.simulate(u), dtype=float).ravel()
        y_pred = np.asarray(model.predict(data), dtype=float).ravel()
        start = 0
    else:
        wu, wy, wts = _signals_of(warmup, "warmup")
        if not np.isclose(wts, ts, rtol=1e-9):
            raise ValueError(
                f"`warmup` sample time must match `data`'s ts = {ts!r}; got {wts!r}"
            )
        whole = type(data)(np.r_[wu, u], np.r_[wy, y], ts=ts)
        start = wu.size
        y_sim = np.asarray(model.simulate(whole.u), dtype=float).ravel()[start:]
        y_pred = np.asarray(model.predict(whole), dtype=float).ravel()[start:]
    return y_sim, y_pred, start


def fit_from_measured(model, data) -> float:
    """The free run's fit started from the record's first ``max_lag``
    measured samples (its initial state), on the samples after them; NaN
    for a model that cannot start from measured samples, ``-inf`` for a run
    that diverged.

    An ARX model runs through the output-error residual that
    ``PaperCost(initial="measured")`` sums; any other model through its own
    ``simulate(u, y0=y)``, which returns the measured samples unchanged and
    continues from them.
    """
    y = np.asarray(data.y, dtype=float).ravel()
    arx = getattr(model, "arx", None)
    structure = getattr(model, "structure", None)
    with np.errstate(all="ignore"):
        if arx is not None:
            residual, _ = error_functions(arx, data, "simulation", "measured")
            e = residual(np.asarray(model.theta, dtype=float))
            t0 = arx.max_lag
        elif hasattr(structure, "max_lag"):
            t0 = structure.max_lag
            y_run = np.asarray(model.simulate(data.u, y0=y), dtype=float).ravel()
            e = y_run[t0:] - y[t0:]
        else:
            return float("nan")
        tail = y[t0:]
        fit = 100.0 * (1.0 - np.linalg.norm(e) / np.linalg.norm(tail - tail.mean()))
    return float(fit) if np.isfinite(fit) else -np.inf
