"""The stabilisation diagram: which modes hold as the order grows.

Modal analysts pick a structure's modes from a stabilisation diagram: the
model is identified at increasing orders, each order's modes are drawn at
their frequencies, and a mode that comes back at the next order with
nearly the same frequency and damping is physical; one that wanders or
vanishes is the model spending spare poles on noise. The usual criteria
(those of operational-modal-analysis tools such as pyOMA) are a frequency
within 1 % and a damping ratio within 5 % of a mode of the order below.

:func:`stabilisation` identifies ``ARX(n, n, nk)`` for each order (any
record: one output, or several with one shared denominator) with
:func:`~spiralid.sysid.identify` and classifies every mode;
:func:`~spiralid.sysid.validation.mode_plots.plot_stabilisation` draws it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spiralid._checks import integer, positive

from ..data import IOData
from ..estimation.core.identify import identify
from ..models.arx import ARX

__all__ = ["StabilisationDiagram", "stabilisation"]

# The usual criteria: a mode is stable when the order below has one within
# these relative distances in frequency and damping.
FREQUENCY_TOLERANCE = 0.01
DAMPING_TOLERANCE = 0.05


@dataclass(frozen=True)
class StabilisationDiagram:
    """Every order's modes and how each compares with the order below.

    Attributes
    ----------
    order : ndarray of int, shape (m,)
        The denominator order ``na`` of each row's model.
    frequency, damping : ndarray, shape (m,)
        The mode's natural frequency (Hz) and damping ratio.
    status : ndarray of str, shape (m,)
        ``"stable"`` (frequency and damping within the tolerances of a mode
        of the order below), ``"frequency"`` (the frequency only) or
        ``"new"``.
    orders : tuple of int
        The orders identified.
    frequency_tolerance, damping_tolerance : float
        The relative tolerances used.
    """

    order: np.ndarray
    frequency: np.ndarray
    damping: np.ndarray
    status: np.ndarray
    orders: tuple[int, ...]
    frequency_tolerance: float = FREQUENCY_TOLERANCE
    damping_tolerance: float = DAMPING_TOLERANCE

    def stable_modes(self, min_orders: int = 3) -> np.ndarray:
        """Frequencies (Hz) of modes stable at `min_orders` successive
        orders or more, the highest order's value of each, ascending."""
        min_orders = integer(min_orders, "min_orders", 1)
        top = max(self.orders)
        found = []
        for f in self.frequency[(self.order == top)]:
            run = 0
            ref = f
            for n in sorted(self.orders, reverse=True):
                rows = self.order == n
                near = (
                    np.abs(self.frequency[rows] - ref) <= self.frequency_tolerance * ref
                )
                if not near.any():
                    break
                run += 1
                ref = self.frequency[rows][near][
                    np.argmin(np.abs(self.frequency[rows][near] - ref))
                ]
            if run >= min_orders:
                found.append(f)
        return np.sort(np.array(found))

    def to_dict(self) -> dict:
        return {
            "orders": list(self.orders),
            "frequency_tolerance": self.frequency_tolerance,
            "damping_tolerance": self.damping_tolerance,
            "modes": [
                {
                    "order": int(n),
                    "frequency_hz": float(f),
                    "damping": float(z),
                    "status": str(s),
                }
                for n, f, z, s in zip(
                    self.order, self.frequency, self.damping, self.status, strict=True
                )
            ],
        }


def _classify(prev_f, prev_z, f, z, f_tol, z_tol) -> str:
    if prev_f.size == 0:
        return "new"
    near_f = np.abs(prev_f - f) <= f_tol * f
    if not near_f.any():
        return "new"
    near_z = np.abs(prev_z - z) <= z_tol * max(z, 1e-12)
    return "stable" if np.any(near_f & near_z) else "frequency"


def stabilisation(
    data: IOData,
    orders,
    *,
    nk: int = 0,
    frequency_tolerance: float = FREQUENCY_TOLERANCE,
    damping_tolerance: float = DAMPING_TOLERANCE,
    **options,
) -> StabilisationDiagram:
    """Identify ``ARX(n, n, nk)`` at each order and classify every mode.

    Parameters
    ----------
    data : IOData
        The estimation record: one output, or several (one shared
        denominator, :func:`~spiralid.sysid.identify` on a record of
        several outputs).
    orders : iterable of int
        Denominator orders ``n >= 1``, e.g. ``range(2, 21, 2)``.
    nk : int, default 0
        The input delay of every structure.
    frequency_tolerance, damping_tolerance : float
        Relative distances within which a mode of the order below makes a
        mode stable (defaults 1 % and 5 %).
    **options
        Passed to :func:`~spiralid.sysid.identify` for every order (e.g.
        ``rng``, ``method``, ``max_nfev``, ``integrator``).

    Returns
    -------
    StabilisationDiagram
    """
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData; got {type(data).__name__}")
    try:
        orders = tuple(sorted({integer(n, "orders", 1) for n in orders}))
    except TypeError:
        raise ValueError(f"`orders` must be integers >= 1; got {orders!r}") from None
    if not orders:
        raise ValueError("`orders` must hold at least one order")
    nk = integer(nk, "nk", 0)
    f_tol = positive(frequency_tolerance, "frequency_tolerance")
    z_tol = positive(damping_tolerance, "damping_tolerance")
    rows = []
    prev_f, prev_z = np.zeros(0), np.zeros(0)
    for n in orders:
        model = identify(data, ARX(n, n, nk), **options)
        modes = model.modes
        table = getattr(modes, "table", modes)
        for f, z in zip(table.frequency, table.damping, strict=True):
            rows.append((n, f, z, _classify(prev_f, prev_z, f, z, f_tol, z_tol)))
        prev_f, prev_z = np.asarray(table.frequency), np.asarray(table.damping)
    if rows:
        order, freq, damp, status = (np.array(c) for c in zip(*rows, strict=True))
    else:
        order, freq, damp, status = (
            np.zeros(0, int),
            np.zeros(0),
            np.zeros(0),
            np.zeros(0, str),
        )
    return StabilisationDiagram(
        order.astype(int),
        freq.astype(float),
        damp.astype(float),
        status,
        orders,
        f_tol,
        z_tol,
    )
