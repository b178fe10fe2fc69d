"""Instrumentation of the rig: encoder, tachometer, accelerometer, anti-aliasing.

The Sheffield rig (paper, section "Flexible manipulator system") measures the
hub angle with a 2048-pulse/revolution incremental encoder, the hub velocity
with a tachometer and the end-point acceleration with a piezoelectric
accelerometer.  :class:`Sensors` describes those channels, and optional
deflection sensors and accelerometers along the beam (``deflection_at``,
``acceleration_at``); the rig's ``simulate`` applies them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spiralid._checks import integer, is_integer, nonneg, real

__all__ = [
    "Sensors",
    "acceleration_name",
    "butterworth_ss",
    "deflection_name",
    "quantise",
]


def deflection_name(position: float) -> str:
    """The output name of a deflection sensor at `position` (a fraction of
    the beam's length): ``"deflection_<position>"`` with ``%g``.

    Examples
    --------
    >>> deflection_name(0.47), deflection_name(1.0)
    ('deflection_0.47', 'deflection_1')
    """
    return f"deflection_{position:g}"


def acceleration_name(position: float) -> str:
    """The output name of an accelerometer at `position` (a fraction of the
    beam's length): ``"acceleration_<position>"`` with ``%g``.

    Examples
    --------
    >>> acceleration_name(0.832)
    'acceleration_0.832'
    """
    return f"acceleration_{position:g}"


@dataclass(frozen=True, kw_only=True)
class Sensors:
    """Sensor models of the rig, all optional.

    Parameters
    ----------
    encoder_lines : int or None
        Encoder lines per revolution (the paper's rig: 2048).  ``None``
        records the exact hub angle.
    quadrature : int
        Counts per line (1, 2 or 4 for x1/x2/x4 decoding).  The hub angle is
        rounded to the nearest multiple of ``2 pi / (encoder_lines *
        quadrature)``.  Default 4, the usual x4 decoding of a quadrature
        encoder (the paper does not say which decoding was used).
    tach_noise, accel_noise : float
        Standard deviations of white Gaussian noise added to the sampled hub
        velocity (rad/s) and end-point acceleration (m/s^2).  Zero (the
        default) draws nothing, so the record is exactly noise-free.
    antialias_order : int
        Order of the Butterworth analogue low-pass in front of the sampler of
        the analogue channels (tachometer and accelerometer); 0 switches it
        off.  The filter is appended to the continuous model and discretised
        exactly with it.  The encoder is a digital count and is not filtered.
    antialias_cutoff : float
        Cut-off as a fraction of the Nyquist frequency, in (0, 1].  Default
        0.35: with order 4 that is 87.5 Hz at 500 Hz, inside the paper's
        0-100 Hz band of interest.  On the default rig it passes the three
        modes the paper identifies (13.3, 35.1, 64.8 Hz; the third loses
        0.4 dB, with phase lag), attenuates the fourth (116 Hz) by 10 dB, the
        fifth (188 Hz) by 27 dB and anything at or above Nyquist by at least
        36 dB (e.g. the sixth mode, 280 Hz, which would alias to 220 Hz, by
        40 dB).  Why not higher: at 0.5 x Nyquist the fourth mode stays in
        the record at -1.9 dB, the sampled acceleration then holds four
        modes plus the filter, and an 8th-order output-error ARX fit of the
        paper experiment fell into a local optimum without the first mode
        (validation fit ~30 % against ~85 % at 0.35, six noise seeds).  This
        is an instrument choice; the rig's physical constants are untouched.
    deflection_at : tuple of float
        Positions along the beam of deflection sensors, as fractions of its
        length from the hub, each in (0, 1]: the beam's deflection ``w(x)``
        there, relative to the hub frame, as the tip deflection is (1.0 is
        the tip), from the finite elements' shape functions.  Exact,
        unfiltered and noise-free like the tip deflection (a strain gauge's
        or an optical sensor's own dynamics and noise are not modelled).
        Each adds an output ``deflection_<x>`` (:func:`deflection_name`) to
        the record.  Default none: the record is then exactly as without
        this option.  A node of a mode is where that mode's deflection
        vanishes (:meth:`FlexibleManipulator.mode_nodes`): a sensor there
        barely sees the mode.
    acceleration_at : tuple of float
        Positions along the beam of further accelerometers, fractions of its
        length from the hub, each in (0, 1]: the acceleration ``x theta'' +
        w''(x)`` of that point in the plane of motion (1.0 is the end
        point's, ``end_acceleration``), through the same anti-aliasing filter
        and with white noise of ``accel_noise`` each, drawn after the other
        channels' noise.  Each adds an output ``acceleration_<x>``
        (:func:`acceleration_name`).  A node of a mode for an accelerometer
        is a node of :meth:`FlexibleManipulator.mode_shape` with
        ``frame="inertial"``.  Default none.

    Examples
    --------
    >>> round(Sensors().encoder_resolution, 10)   # rad per count, 2048 lines x4
    0.0007669904
    >>> Sensors.ideal().antialias_order
    0
    """

    encoder_lines: int | None = 2048
    quadrature: int = 4
    tach_noise: float = 0.0
    accel_noise: float = 0.0
    antialias_order: int = 4
    antialias_cutoff: float = 0.35
    deflection_at: tuple[float, ...] = ()
    acceleration_at: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.encoder_lines is not None:
            integer(self.encoder_lines, "encoder_lines", 1)
        integer(self.quadrature, "quadrature", 1)
        for name in ("tach_noise", "accel_noise"):
            object.__setattr__(self, name, nonneg(getattr(self, name), name))
        order = self.antialias_order
        if not is_integer(order) or not 0 <= order <= 12:
            raise (ValueError if is_integer(order) else TypeError)(
                "`antialias_order` must be an integer in [0, 12]; "
                f"got {self.antialias_order!r}"
            )
        what = f"`antialias_cutoff` must be in (0, 1]; got {self.antialias_cutoff!r}"
        try:
            c = real(self.antialias_cutoff, "antialias_cutoff")
        except TypeError:
            raise TypeError(what) from None
        except ValueError:
            c = math.nan
        if not 0.0 < c <= 1.0:
            raise ValueError(what)
        object.__setattr__(self, "antialias_cutoff", c)
        for name in ("deflection_at", "acceleration_at"):
            object.__setattr__(self, name, _positions(getattr(self, name), name))

    @classmethod
    def ideal(
        cls,
        deflection_at: tuple[float, ...] = (),
        acceleration_at: tuple[float, ...] = (),
    ) -> Sensors:
        """Exact, unfiltered, noise-free sampling of every channel.

        Parameters
        ----------
        deflection_at, acceleration_at : tuple of float
            Sensors along the beam, as the fields of those names.
        """
        return cls(
            encoder_lines=None,
            antialias_order=0,
            deflection_at=deflection_at,
            acceleration_at=acceleration_at,
        )

    @property
    def positional_names(self) -> tuple[str, ...]:
        """The output names of the sensors along the beam, in the record's
        order: every deflection, then every accelerometer."""
        return tuple(deflection_name(x) for x in self.deflection_at) + tuple(
            acceleration_name(x) for x in self.acceleration_at
        )

    @property
    def encoder_resolution(self) -> float | None:
        """Angle of one encoder count in rad, or None without quantisation."""
        if self.encoder_lines is None:
            return None
        return 2.0 * math.pi / (self.encoder_lines * self.quadrature)


def _positions(value, name: str) -> tuple[float, ...]:
    """`name` as a tuple of distinct fractions in (0, 1]."""
    what = (
        f"`{name}` must be a tuple of positions along the beam, "
        f"fractions of its length in (0, 1]; got {value!r}"
    )
    if not isinstance(value, list | tuple | np.ndarray):
        raise TypeError(what)
    out = []
    for v in list(value):
        try:
            x = real(v, name)
        except TypeError:
            raise TypeError(what) from None
        except ValueError:
            x = math.nan
        if not 0.0 < x <= 1.0:
            raise ValueError(what)
        out.append(x)
    names = [f"{x:g}" for x in out]
    if len(set(names)) != len(names):
        raise ValueError(
            f"`{name}` must name distinct positions (to 6 digits); got {value!r}"
        )
    return tuple(out)


def quantise(angle: np.ndarray, resolution: float | None) -> np.ndarray:
    """Round ``angle`` to the nearest multiple of ``resolution`` (None: copy).

    Examples
    --------
    >>> quantise(np.array([0.04, 0.06, -0.26]), 0.1)
    array([ 0. ,  0.1, -0.3])
    """
    a = np.asarray(angle, dtype=float)
    if resolution is None:
        return a.copy()
    return np.round(a / resolution) * resolution


def butterworth_ss(
    order: int, cutoff_hz: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Analogue Butterworth low-pass as a well-scaled state-space cascade.

    Each conjugate pole pair is the section ``wc^2 / (s^2 + 2 z wc s +
    wc^2)`` with states ``(x1, x2 = x1' / wc)``, so every matrix entry is of
    order ``wc`` (a companion form would have entries ``wc^order``, which
    spoils the exponential used for the exact discretisation).

    Returns
    -------
    A, B, C : ndarray
        ``x' = A x + B v``, ``y = C x`` with unit DC gain; shapes
        ``(order, order)``, ``(order,)``, ``(order,)``.

    Examples
    --------
    >>> A, B, C = butterworth_ss(2, 1.0 / (2 * np.pi))
    >>> round(float(-C @ np.linalg.solve(A, B)), 12)   # DC gain
    1.0
    """
    wc = 2.0 * math.pi * cutoff_hz
    A = np.zeros((order, order))
    B = np.zeros(order)
    C = np.zeros(order)
    prev = None  # index of the previous section's output state
    i = 0
    sections = [
        math.sin(math.pi * (2 * k + 1) / (2 * order)) for k in range(order // 2)
    ]
    for zeta in sections:
        A[i, i + 1] = wc
        A[i + 1, i] = -wc
        A[i + 1, i + 1] = -2.0 * zeta * wc
        if prev is None:
            B[i + 1] = wc
        else:
            A[i + 1, prev] = wc
        prev = i
        i += 2
    if order % 2:
        A[i, i] = -wc
        if prev is None:
            B[i] = wc
        else:
            A[i, prev] = wc
        prev = i
    if prev is not None:
        C[prev] = 1.0
    return A, B, C
