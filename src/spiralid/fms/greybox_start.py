"""A physically informed start for :class:`~spiralid.fms.greybox.RigGreyBox`:
the free fields chosen so that the finite-element model's first flexible
modes are those a black box found in the record.

A search of the rig's fields from a preset far from the record's arm ends
where the output is nearly zero (every wrongly phased fit costs more). The
modes of an ARX or OE fit (``model.modes``) are cheap and reliable; the
rig's frequencies are a smooth function of its fields, so a bounded least
squares on the log frequencies, from several starts, lands on fields with
those modes. With the record, the output gain and the initial state follow
by linear least squares: the linear rig's output is linear in both.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.optimize import least_squares, nnls

from spiralid._checks import generator, integer
from spiralid.fms.greybox import RigGreyBox
from spiralid.fms.rig import DAMPING_SHARES
from spiralid.sysid.models.greybox import Parameter
from spiralid.sysid.models.greybox_run import lti_run

__all__ = ["rig_start_from_modes"]

# The fields that set the FEM's frequencies (and the damping, set apart).
_MODAL_FIELDS = (
    "length",
    "width",
    "thickness",
    "youngs_modulus",
    "density",
    "flexural_rigidity",
    "mass_per_length",
    "hub_inertia",
    "payload_mass",
    "payload_inertia",
)
# A start that misses its frequencies by more than this (log, RMS) is no
# match: the structure cannot hold those modes within its bounds.
_MATCHED = 1e-3
# Bounds of a started parameter that does not hold its start: a factor
# either side.
_WIDEN = 4.0


def _targets(modes) -> tuple[np.ndarray, np.ndarray | None]:
    """Frequencies (Hz) and damping ratios (None when not given) of
    `modes`: a fitted model (its ``modes``), a mode table (its modes not
    marked spurious) or frequencies."""
    table = getattr(modes, "modes", None)
    table = modes if table is None else table
    if hasattr(table, "frequency") and hasattr(table, "spurious"):
        keep = ~np.asarray(table.spurious, dtype=bool)
        freq = np.asarray(table.frequency, dtype=float)[keep]
        damping = np.asarray(table.damping, dtype=float)[keep]
    else:
        try:
            freq = np.asarray(table, dtype=float).ravel()
        except (TypeError, ValueError):
            raise TypeError(
                "`modes` must be a fitted model, a mode table or frequencies in "
                f"Hz; got {type(modes).__name__}"
            ) from None
        damping = None
    if freq.size == 0 or not np.all(np.isfinite(freq) & (freq > 0)):
        raise ValueError(
            f"`modes` must give at least one positive frequency; got {freq!r}"
        )
    order = np.argsort(freq)
    return freq[order], None if damping is None else damping[order]


def _box_map(params: list[Parameter]):
    """Unit-box point -> values of `params` (log scale where theirs is)."""
    log = np.array([p.log for p in params])
    low = np.array([p.bounds[0] for p in params])
    high = np.array([p.bounds[1] for p in params])
    lo = np.where(log, np.log(np.where(log, low, 1.0)), low)
    hi = np.where(log, np.log(np.where(log, high, 1.0)), high)

    def values(z):
        c = lo + np.clip(z, 0.0, 1.0) * (hi - lo)
        return np.clip(np.where(log, np.exp(c), c), low, high)

    def point(v):
        c = np.where(log, np.log(np.where(log, v, 1.0)), v)
        return (c - lo) / (hi - lo)

    return values, point


def _match(box: RigGreyBox, freq: np.ndarray, starts: int, rng) -> list[np.ndarray]:
    """Every parameter's values with the modal fields set to match `freq`:
    one vector per local fit (from the initial values and `starts` random
    points) that matches, the closest match first."""
    values = box.initial_values
    rows = [
        i
        for i, p in enumerate(box.parameters[: box._n_fields])
        if p.free and p.name in _MODAL_FIELDS
    ]
    if not rows:
        raise ValueError(
            "`box` frees no field that sets the modes ("
            + ", ".join(_MODAL_FIELDS)
            + ")"
        )
    to_values, to_point = _box_map([box.parameters[i] for i in rows])
    m = freq.size

    def residual(z):
        v = values.copy()
        v[rows] = to_values(z)
        try:
            f = box.rig_at(v).modes(m)
        except ValueError:
            return np.full(m, 1e3)
        return np.log(f) - np.log(freq)

    points = [to_point(values[rows]), *rng.uniform(0.0, 1.0, (starts, len(rows)))]
    fits = [
        least_squares(residual, np.clip(z0, 0.0, 1.0), bounds=(0.0, 1.0))
        for z0 in points
    ]
    fits.sort(key=lambda fit: fit.cost)
    matched = [fit for fit in fits if np.sqrt(2.0 * fit.cost / m) <= _MATCHED]
    if not matched:
        found = box.rig_at(values).modes(m)
        raise ValueError(
            f"`modes`: no rig within the bounds has the modes {np.round(freq, 3)} Hz; "
            f"the nearest found at this start {np.round(found, 3)}"
        )
    out = []
    for fit in matched:
        v = values.copy()
        v[rows] = to_values(fit.x)
        out.append(v)
    return out


def _error(box: RigGreyBox, values: np.ndarray, data) -> float:
    """The simulation error's norm at `values` on `data` (inf for a run
    that blew up)."""
    e = np.asarray(data.y, dtype=float).ravel() - box.simulate(
        values, data.u, float(data.ts)
    )
    return float(np.linalg.norm(e)) if np.all(np.isfinite(e)) else np.inf


def _state_and_gain(box: RigGreyBox, values: np.ndarray, data) -> np.ndarray:
    """`values` with the estimated output gain and initial state at their
    least-squares values on `data` (the rig's output is linear in both)."""
    gain_free = isinstance(box.output_gain, Parameter) and box.output_gain.free
    state_rows = box._x0_free_rows[[p.free for p in box.state_parameters]]
    if not gain_free and state_rows.size == 0:
        return values
    u = np.ascontiguousarray(np.asarray(data.u, dtype=float).reshape(len(data.u), -1))
    y = np.asarray(data.y, dtype=float).ravel()
    k = box.gain_at(values)
    ad, bd, c, d = box.discretise(values, float(data.ts))
    c, d = c / k, d / k
    x0 = box.initial_state(values)
    x0[state_rows] = 0.0
    if box.delay_at(values) is None:
        forced = lti_run(ad, bd, c, d, x0, u)[:, 0]
    else:
        # The delayed model's discrete state holds past inputs: run the
        # box itself, its estimated state at rest.
        rest = values.copy()
        rest[[len(box.parameters) + i for i, p in enumerate(box.state_parameters)
              if p.free]] = 0.0  # fmt: skip
        forced = box.simulate(rest, u, float(data.ts)) / k
    free_response = np.zeros((y.size, state_rows.size))
    x = np.eye(ad.shape[0])[:, state_rows]
    for t in range(y.size):
        free_response[t] = c[0] @ x
        x = ad @ x
    if gain_free:
        columns = np.column_stack([forced, free_response])
        coef = np.linalg.lstsq(columns, y, rcond=None)[0]
        k, state = coef[0], coef[1:] / coef[0]
    else:
        state = np.linalg.lstsq(k * free_response, y - k * forced, rcond=None)[0]
    n_p = len(box.parameters)
    if gain_free:
        values[box._n_fields] = k
    free_states = [i for i, p in enumerate(box.state_parameters) if p.free]
    values[[n_p + i for i in free_states]] = state
    return values


def _started(p: Parameter, value: float, scale: float) -> Parameter:
    """`p` started at `value` within `_WIDEN` times its size either side
    (at least `scale`, for a value near zero), on a linear scale: the sign
    may be either, and the record's units set the size."""
    half = max(abs(value) * _WIDEN, scale)
    return dataclasses.replace(
        p, value=float(value), bounds=(value - half, value + half), log=False
    )


def _rebuilt(box: RigGreyBox, values: np.ndarray) -> RigGreyBox:
    """`box` with every parameter started at `values`."""
    params = list(box.parameters[: box._n_fields])
    params = [
        dataclasses.replace(p, value=float(v))
        for p, v in zip(params, values[: len(params)], strict=True)
    ]
    gain = box.output_gain
    if isinstance(gain, Parameter):
        k = values[box._n_fields]
        gain = _started(gain, k, abs(k)) if gain.free else gain
    n_p = len(box.parameters)
    x0: list = box._x0_given.tolist()
    state = values[n_p:]
    scale = float(np.max(np.abs(state))) / _WIDEN if state.size else 1.0
    for row, p, v in zip(box._x0_free_rows, box.state_parameters, state, strict=True):
        x0[row] = _started(p, v, scale or 1.0) if p.free else p
    return RigGreyBox(
        params,
        box.rig,
        output=box.output,
        n_modes=box.n_modes,
        sensors=box.sensors,
        output_gain=gain,
        x0=x0,
    )


def _start_rayleigh(box: RigGreyBox, values, freq, damping) -> None:
    """The free damping fields of `values` (in place) where the modes'
    damping ratios are best matched, in least squares with each field
    non-negative, the held ones' share subtracted; then clipped to their
    bounds."""
    w = 2.0 * np.pi * np.asarray(freq, dtype=float)
    rig = box.rig_at(values)
    names, params = box.names, box.all_parameters
    free = [n for n in DAMPING_SHARES if n in names and params[names.index(n)].free]
    if not free:
        return
    held = sum(
        getattr(rig, n) * DAMPING_SHARES[n](w) for n in DAMPING_SHARES if n not in free
    )
    cols = np.column_stack([DAMPING_SHARES[n](w) for n in free])
    # Scaled columns: the fields differ by orders of magnitude.
    size = np.linalg.norm(cols, axis=0)
    coef = nnls(cols / size, np.asarray(damping, dtype=float) - held)[0] / size
    for n, c in zip(free, coef, strict=True):
        i = names.index(n)
        values[i] = np.clip(c, *params[i].bounds)


def rig_start_from_modes(
    box: RigGreyBox, modes, data=None, *, starts: int = 20, rng=None
) -> RigGreyBox:
    """`box` started where the rig's first flexible modes are `modes`.

    The free fields that set the frequencies (among length, width,
    thickness, Young's modulus, density, flexural rigidity, mass per
    length, hub and payload mass and inertia) are moved, within their
    bounds, so that the finite-element model's first flexible modes are
    `modes`' frequencies: a bounded least squares on the log frequencies
    from the box's initial values and `starts` random points, the best
    kept (with `data`, of the fits that match, the one whose simulation
    is closest to the record: the modes fix the frequencies, not the
    residues). A free damping ratio starts at the modes' mean damping;
    with Rayleigh's ``mass_damping`` or ``stiffness_damping`` free, the
    free damping fields start where they best give each mode its damping
    (non-negative least squares).
    With `data` (the linear kind), the output gain and the initial state,
    where estimated, start at their least-squares values on the record, the
    simulation being linear in both, and their bounds become 4 times the
    value's size either side of it (the record's units are not known
    before; an initial state's entry near zero takes a quarter of the
    largest entry's size).

    Parameters
    ----------
    box : RigGreyBox
        The structure; its bounds bound the start.
    modes : fitted model, ModeTable or array_like
        A black box fitted to the record (its ``modes``, those not marked
        spurious), its mode table, or frequencies in Hz. At most
        ``box.n_modes`` of them.
    data : IOData, optional
        The estimation record, for the gain and the initial state.
    starts : int, default 20
        Random starts of the frequency match beside the initial values.
    rng : None, int or numpy.random.Generator
        Seed of the random starts.

    Returns
    -------
    RigGreyBox
        The same structure, its parameters' initial values (and, see
        above, bounds) at the start.

    Examples
    --------
    >>> box = RigGreyBox(["flexural_rigidity", "hub_inertia"], n_modes=2)
    >>> start = rig_start_from_modes(box, [10.0, 30.0], rng=0)
    >>> start.rig_at(start.initial_values).modes(2).round(3)
    array([10., 30.])
    """
    if not isinstance(box, RigGreyBox):
        raise TypeError(f"`box` must be a RigGreyBox; got {type(box).__name__}")
    freq, damping = _targets(modes)
    limit = box.n_modes if box.n_modes is not None else 2 * box.rig.n_elements
    if freq.size > limit:
        raise ValueError(
            f"`modes` gives {freq.size} modes; the box keeps {limit} flexible modes"
        )
    starts = integer(starts, "starts", 0)
    if data is not None and box.kind != "linear":
        raise ValueError("`data`: the gain and state start need the linear rig")
    if data is not None and box.n_outputs != 1:
        raise ValueError(
            f"`data`: the gain and state start fit one sensor; the box reads "
            f"{box.n_outputs} ({', '.join(box.outputs)})"
        )
    candidates = _match(box, freq, starts, generator(rng))
    names = box.names
    if damping is not None and {"mass_damping", "stiffness_damping"} & set(names):
        for values in candidates:
            _start_rayleigh(box, values, freq, damping)
    elif damping is not None and "damping_ratio" in names:
        i = names.index("damping_ratio")
        p = box.all_parameters[i]
        for values in candidates if p.free else ():
            values[i] = np.clip(np.mean(damping), *p.bounds)
    if data is None:
        return _rebuilt(box, candidates[0])
    candidates = [_state_and_gain(box, v, data) for v in candidates]
    return _rebuilt(box, min(candidates, key=lambda v: _error(box, v, data)))
