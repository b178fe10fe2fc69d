"""A physical model of the Cascaded Tanks benchmark (:func:`cascaded_tanks`)
as a :class:`~spiralid.sysid.GreyBox`: two tanks with outflow through an
opening (Torricelli's law), the upper tank's overflow, a pump that moves
no water below a threshold voltage, and the level sensor that saturates at
10 V.

States (both in volts of the level sensor's scale): ``x[0]`` the upper
tank's level, ``x[1]`` the lower tank's. With ``p`` as
:data:`TANKS_PARAMETERS` names it::

    q_up   = upper_outflow * x0**upper_exponent            (Torricelli: 0.5)
    dx0/dt = pump_gain * max(u - pump_threshold, 0) - q_up
    dx1/dt = area_ratio * q_up - lower_outflow * x1**lower_exponent
             + overflow_share * (what the upper tank spills)
    y      = min(x1 + sensor_offset, 10)

The upper tank spills once ``x0`` reaches :data:`UPPER_TOP` (it then stays
there), and the lower tank stops filling at ``lower_top`` (its own
overflow; ``tanks_greybox(lower_top=False)`` leaves it without one). What
the upper tank spills is one of :data:`OVERFLOWS`: ``"surplus"``
(:func:`tanks_f`), its surplus inflow ``pump - q_up``, a share of it into
the lower tank and the rest away; or ``"inflow"`` (:func:`tanks_f_inflow`),
a share of the pump's whole inflow ``pump``
falling on into the lower tank while the upper one is full (the form of
the published grey boxes of the benchmark, Rogers et al. 2017 and Worden
et al. 2018: a term ``k5 u`` added to the lower tank above the upper
one's top); or ``"mixed"`` (:func:`tanks_f_mixed`), both: a share of the
pump's inflow and another, ``surplus_share`` (:data:`SURPLUS_SHARE`, the
one parameter the form adds), of the surplus. The upper level is never
measured: its scale is the model's choice, fixed by :data:`UPPER_TOP`, or
the record could not tell the pump's gain from the upper tank's size.

:func:`tanks_hybrid` adds a learned correction of a fitted grey box's
output (a second model, trained on the grey box's free-run error and run
free beside it), the "grey box plus learned residual" form of the
published grey boxes.

Why here and not in an example: ``model.json`` names the model's functions
by import path, and an example's functions live in ``__main__`` when it
runs; shipped with the package, a fitted tanks model saves and loads
anywhere spiralid is installed. ``f`` and ``g`` are Numba functions, so the
grey box integrates them in compiled code (a Python ``f`` would work too,
tens of times slower: ``benchmarks/greybox_speed.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from spiralid.sysid import IOData, identify
from spiralid.sysid.data import single_output_record
from spiralid.sysid.models.greybox import GreyBox, Parameter

__all__ = [
    "NO_TOP",
    "OVERFLOWS",
    "SURPLUS_SHARE",
    "TANKS_PARAMETERS",
    "UPPER_TOP",
    "TanksHybrid",
    "tanks_f",
    "tanks_f_inflow",
    "tanks_f_mixed",
    "tanks_g",
    "tanks_greybox",
    "tanks_hybrid",
]

#: The upper tank's overflow level, in the model's volts.
UPPER_TOP = 10.0
#: The level sensor's saturation (both records reach it).
SENSOR_MAX = 10.0
#: ``lower_top`` of a lower tank without a top (:func:`tanks_greybox`'s
#: ``lower_top=False``): no level reaches it.
NO_TOP = 1e6

#: name -> (initial value, bounds, unit, Torricelli's fixed value or None):
#: the order ``p`` is read in.
TANKS_PARAMETERS: dict[str, tuple] = {
    "upper_outflow": (0.05, (1e-3, 1.0), "V^(1-e)/s", None),
    "area_ratio": (1.0, (1e-2, 10.0), "", None),
    "lower_outflow": (0.05, (1e-3, 1.0), "V^(1-e)/s", None),
    "pump_gain": (0.05, (1e-3, 1.0), "1/s", None),
    "overflow_share": (0.5, (1e-3, 10.0), "", None),
    "sensor_offset": (0.0, (-3.0, 3.0), "V", None),
    "pump_threshold": (0.5, (0.0, 2.0), "V", None),
    "lower_top": (10.0, (5.0, 15.0), "V", None),
    "upper_exponent": (0.5, (0.2, 1.0), "", 0.5),
    "lower_exponent": (0.5, (0.2, 1.0), "", 0.5),
}


#: The mixed overflow's second share (:func:`tanks_greybox`'s
#: ``overflow="mixed"`` appends it to :data:`TANKS_PARAMETERS`, as ``p[10]``).
SURPLUS_SHARE: dict[str, tuple] = {
    "surplus_share": (0.25, (1e-3, 10.0), "", None),
}

# The `form` codes of _rates.
_SURPLUS, _INFLOW, _MIXED = 0, 1, 2


@numba.njit(cache=True)
def _rates(x, u, p, form):  # pragma: no cover - compiled
    # The overflows share everything but what reaches the lower tank while
    # the upper one is full (`form`, a value of _FORMS): a share of its
    # surplus, of the pump's whole inflow, or a share of each (the second,
    # surplus_share, read from p[10]: only the mixed form has it).
    up = max(x[0], 0.0)
    low = max(x[1], 0.0)
    q_up = p[0] * up ** p[8]
    pump = p[3] * max(u[0] - p[6], 0.0)
    dx0 = pump - q_up
    spill = 0.0
    if x[0] >= UPPER_TOP and dx0 > 0.0:
        if form == _SURPLUS:
            spill = p[4] * dx0
        elif form == _INFLOW:
            spill = p[4] * pump
        else:
            spill = p[4] * pump + p[10] * dx0
        dx0 = 0.0
    dx1 = p[1] * q_up - p[2] * low ** p[9] + spill
    if x[1] >= p[7] and dx1 > 0.0:
        dx1 = 0.0
    return np.array([dx0, dx1])


@numba.njit(cache=True)
def tanks_f(t, x, u, p):  # pragma: no cover - compiled
    """``dx/dt`` of the two tanks, the upper one's surplus spilling (see
    the module docstring)."""
    return _rates(x, u, p, _SURPLUS)


@numba.njit(cache=True)
def tanks_f_inflow(t, x, u, p):  # pragma: no cover - compiled
    """``dx/dt`` of the two tanks, a share of the pump's inflow reaching
    the lower tank while the upper one is full (see the module
    docstring)."""
    return _rates(x, u, p, _INFLOW)


@numba.njit(cache=True)
def tanks_f_mixed(t, x, u, p):  # pragma: no cover - compiled
    """``dx/dt`` of the two tanks, a share of the pump's inflow and a share
    of the upper tank's surplus reaching the lower tank while the upper one
    is full (see the module docstring)."""
    return _rates(x, u, p, _MIXED)


#: overflow name -> the ``f`` that models it (:func:`tanks_greybox`'s
#: `overflow`).
#: The first is :func:`tanks_greybox`'s default.
OVERFLOWS = {"inflow": tanks_f_inflow, "surplus": tanks_f, "mixed": tanks_f_mixed}


@numba.njit(cache=True)
def tanks_g(x, u, p):  # pragma: no cover - compiled
    """The lower tank's sensor: its level plus an offset, saturating."""
    return min(x[1] + p[5], SENSOR_MAX)


def tanks_greybox(
    *,
    exponents: bool = False,
    overflow: str = "inflow",
    lower_top: bool = True,
    x0="estimated",
    substeps: int = 4,
) -> GreyBox:
    """The tanks model as a grey box ready for
    :func:`~spiralid.sysid.identify`.

    Parameters
    ----------
    exponents : bool, default False
        Estimate the outflow exponents too (else fixed at Torricelli's 0.5).
    overflow : {"inflow", "surplus", "mixed"}, default "inflow"
        What reaches the lower tank while the upper one is full (a key of
        :data:`OVERFLOWS`): ``overflow_share`` times the pump's whole
        inflow, or times the upper tank's surplus inflow (the model's form
        before the inflow one predicted held-back data better), or the
        first plus ``surplus_share`` times the surplus (one more free
        parameter).
    lower_top : bool, default True
        Give the lower tank a top it fills no further than (the free
        parameter ``lower_top``); False holds ``lower_top`` at
        :data:`NO_TOP`, out of the levels' reach: no lower overflow, one
        free parameter fewer.
    x0 : "estimated" or sequence of float, default "estimated"
        The initial levels: estimated within ``[0, 10]`` V (the records
        start from an unknown state), or given.
    substeps : int, default 4
        Runge-Kutta steps per 4 s sample.

    Returns
    -------
    GreyBox
    """
    if not isinstance(overflow, str):
        raise TypeError(f"`overflow` must be a str; got {type(overflow).__name__}")
    if overflow not in OVERFLOWS:
        raise ValueError(
            f"`overflow` must be one of {sorted(OVERFLOWS)}; got {overflow!r}"
        )
    table = TANKS_PARAMETERS | (SURPLUS_SHARE if overflow == "mixed" else {})
    params = [
        Parameter(
            name,
            value,
            bounds,
            unit,
            free=exponents or fixed is None,
            log=bounds[0] > 0 and fixed is None,
        )
        for name, (value, bounds, unit, fixed) in table.items()
    ]
    if not isinstance(lower_top, bool):
        raise TypeError(f"`lower_top` must be a bool; got {type(lower_top).__name__}")
    if not lower_top:
        top = list(table).index("lower_top")
        params[top] = Parameter(
            "lower_top", NO_TOP, (NO_TOP / 2, NO_TOP), "V", free=False
        )
    if isinstance(x0, str):
        if x0 != "estimated":
            raise ValueError(f"`x0` must be 'estimated' or two levels; got {x0!r}")
        x0 = [
            Parameter("upper_level_0", 5.0, (0.0, UPPER_TOP), "V"),
            Parameter("lower_level_0", 5.0, (0.0, SENSOR_MAX), "V"),
        ]
    return GreyBox(
        params, f=OVERFLOWS[overflow], g=tanks_g, n_states=2, x0=x0, substeps=substeps
    )


@dataclass(eq=False)
class TanksHybrid:
    """A fitted tanks grey box plus a learned correction of its output
    (:func:`tanks_hybrid`): ``min(y_gb + r_hat, 10)``, both in free run.

    Attributes
    ----------
    greybox : GreyBoxModel
        The fitted grey box; ``y_gb`` is its free run.
    correction : FittedModel or None
        The correction: a model of the residual ``y - y_gb`` whose input is
        ``y_gb`` (or ``u`` and ``y_gb``), shifted by `offsets`; None where
        the residual was constant on the record (its mean, in `offsets`,
        is then the whole correction).
    with_input : bool
        Whether the correction sees the input ``u`` beside ``y_gb``.
    offsets : tuple of (ndarray, float)
        The means removed from the correction's inputs and output on the
        record it was fitted on (:meth:`IOData.detrend`).
    """

    greybox: object
    correction: object
    with_input: bool
    offsets: tuple

    def correct(self, u, y_gb) -> np.ndarray:
        """The correction's free run ``r_hat`` (from rest, its own past
        outputs simulated) over the input `u` and the grey box's run `y_gb`.

        Parameters
        ----------
        u, y_gb : array_like, shape (N,)
        """
        y_gb = np.ravel(y_gb)
        u_offset, y_offset = self.offsets
        if self.correction is None:
            return np.full(y_gb.size, y_offset)
        inputs = _correction_inputs(np.ravel(u), y_gb, self.with_input)
        return np.ravel(self.correction.simulate(inputs - u_offset)) + y_offset

    def simulate(self, u) -> np.ndarray:
        """The hybrid's free run over `u` (an ``IOData`` gives its ``u``),
        shape (N,): the grey box's run plus the correction's, saturating
        as the sensor does.

        Parameters
        ----------
        u : array_like or IOData
        """
        u = np.ravel(u.u if isinstance(u, IOData) else u).astype(float)
        y_gb = np.ravel(self.greybox.simulate(u))
        return np.minimum(y_gb + self.correct(u, y_gb), SENSOR_MAX)


def _correction_inputs(u, y_gb, with_input: bool) -> np.ndarray:
    # One list of the correction's input columns: y_gb, after u when asked.
    return np.column_stack([u, y_gb]) if with_input else y_gb


def tanks_hybrid(
    greybox,
    data: IOData,
    correction,
    *,
    with_input: bool = False,
    method: str = "oe",
    rng=None,
) -> TanksHybrid:
    """The fitted grey box `greybox` plus a correction of structure
    `correction` trained on its free-run error on `data` (a two-stage
    hybrid: the grey box stays as fitted).

    The residual ``r = y - y_gb`` of the grey box's free run ``y_gb`` on
    `data` becomes the output of a record whose input is ``y_gb`` (and
    ``u``), shifted by its means; ``identify(record, correction,
    method=method, rng=rng)`` fits it. The correction runs free too (its
    past outputs simulated, never measured), so the hybrid needs only the
    input: see :class:`TanksHybrid`.

    Parameters
    ----------
    greybox : GreyBoxModel
        A fitted tanks grey box (``identify(data, tanks_greybox())``).
    data : IOData
        The record to learn the correction on (one input, one output):
        the grey box's own estimation record, or a part of it.
    correction : structure
        Any one-output structure :func:`~spiralid.sysid.identify` fits:
        ``NeuralStateSpace(1, hidden=(8,))``, ``NARX(...)`` (one input),
        ``ARX(2, 2, 0)`` (a shared denominator with `with_input`).
    with_input : bool, default False
        Give the correction ``u`` beside ``y_gb`` (two inputs: the
        families that take several).
    method : str, default "oe"
        The correction's estimation method.
    rng : int, numpy.random.Generator or None
        The correction's randomness (its initial weights).

    Returns
    -------
    TanksHybrid
    """
    single_output_record(data, "tanks_hybrid")
    if not isinstance(with_input, bool):
        raise TypeError(f"`with_input` must be a bool; got {type(with_input).__name__}")
    if not callable(getattr(greybox, "simulate", None)):
        raise TypeError(
            f"`greybox` must be a fitted model; got {type(greybox).__name__}"
        )
    u = np.ravel(data.u)
    y_gb = np.ravel(greybox.simulate(u))
    inputs = _correction_inputs(u, y_gb, with_input)
    record = IOData(inputs, np.ravel(data.y) - y_gb, ts=data.ts).detrend()
    # A residual that is constant on the record leaves nothing to learn
    # (identify refuses an all-zero output): its mean alone corrects it.
    fitted = np.any(record.y != 0.0)
    model = identify(record, correction, method=method, rng=rng) if fitted else None
    return TanksHybrid(
        greybox,
        model,
        with_input,
        (np.asarray(record.u_offset, dtype=float), float(record.y_offset)),
    )
