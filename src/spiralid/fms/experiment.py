"""The bang-bang experiment used to reproduce the paper's identification.

The paper identifies an ARX(8, 8, 0) model of the end-point acceleration
sampled at 500 Hz but does not publish its input record.  Its rig is usually
excited with bang-bang torque, so :func:`paper_experiment` runs a train of
bang-bang pulses of alternating sign on the default rig (see
:class:`Experiment` for the numbers and why).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spiralid._checks import integer, positive, real
from spiralid.fms.rig import FlexibleManipulator, Recording, _position
from spiralid.fms.sensors import Sensors
from spiralid.fms.signals import _nsamples, bang_bang

__all__ = ["Experiment", "paper_experiment"]


@dataclass(frozen=True, kw_only=True)
class Experiment:
    """A train of bang-bang torque pulses of alternating sign.

    Pulse ``j`` starts at ``start + j period`` with sign ``(-1)^j``; with an
    even ``n_pulses`` the rigid hub ends where it started, so it never runs
    away.  Defaults (all our choices; the paper gives none):

    - ``amplitude = 0.3`` N m, ``width = 0.04`` s: a bang-bang of width T
      excites frequency f in proportion to ``sin^2(pi f T)``; T = 0.04 s puts
      the default rig's first three modes (13.3, 35.1, 64.8 Hz) near maxima
      of that pattern (0.99, 0.91, 0.92), away from its nulls at k/T.  Each
      pulse turns the hub by ``amplitude width^2 / J``, about 0.7 degrees.
    - ``period = 1.0`` s, ``n_pulses = 6``, ``duration = 6.0`` s at
      ``fs = 500`` Hz (3000 samples): one pulse per second, so that the
      validation third of the record (the paper's 2/3-1/3 split) still holds
      excited vibration; a single bang-bang would leave it nearly silent
      (the first mode's envelope decays as exp(-zeta w t), e^-1.7 per second
      at zeta = 0.02).
    - ``accel_noise = 1.0`` m/s^2 (about 2 % of the acceleration's RMS,
      34 dB SNR), ``tach_noise = 0.01`` rad/s; the default
      :class:`~spiralid.fms.sensors.Sensors` otherwise (encoder x4,
      4th-order Butterworth anti-aliasing at 0.35 x Nyquist, 87.5 Hz).
    - ``deflection_at = ()``, ``acceleration_at = ()``: no sensors along the
      beam besides the tip's; positions (fractions of the length) add the
      outputs ``deflection_<x>`` and ``acceleration_<x>`` (see
      :class:`~spiralid.fms.sensors.Sensors`), and leave the four channels
      and their noise as without them.
    - ``force_at = None``: no shaker. A position (a fraction of the length
      in (0, 1]) adds a second input, a shaker's force there
      (:meth:`force`): a train of ``n_pulses`` bang-bang pulses of
      ``force_amplitude`` (default 1 N: at 0.6 of the length its moment
      about the hub, 0.54 N m, is of the torque's order) and the torque's
      width, each half a period after a torque pulse: with a period of at
      least four widths (the default's is 25) the two inputs never act at
      once.
    """

    amplitude: float = 0.3
    width: float = 0.04
    start: float = 0.1
    period: float = 1.0
    n_pulses: int = 6
    duration: float = 6.0
    fs: float = 500.0
    accel_noise: float = 1.0
    tach_noise: float = 0.01
    deflection_at: tuple[float, ...] = ()
    acceleration_at: tuple[float, ...] = ()
    force_at: float | None = None
    force_amplitude: float = 1.0

    def __post_init__(self) -> None:
        integer(self.n_pulses, "n_pulses", 1)
        # The scalars first, so that a bad one is named before arithmetic on
        # it fails (round(nan) in torque(), say).
        for name in ("width", "period", "duration", "fs"):
            positive(getattr(self, name), name)
        if not self.period >= 2 * self.width:
            raise ValueError(
                f"`period` must be finite and >= 2 * width = {2 * self.width:g}; "
                f"got {self.period!r}"
            )
        # Validate the rest by building the signals once.
        self.torque()
        real(self.force_amplitude, "force_amplitude")
        if self.force_at is not None:
            object.__setattr__(self, "force_at", _position(self.force_at, "force_at"))
            self.force()
        sensors = self.sensors()
        object.__setattr__(self, "deflection_at", sensors.deflection_at)
        object.__setattr__(self, "acceleration_at", sensors.acceleration_at)

    def torque(self) -> np.ndarray:
        """The torque record (N m), sampled at ``fs``.

        Examples
        --------
        >>> u = paper_experiment().torque()
        >>> u.size, float(u.max()), int(np.count_nonzero(u))
        (3000, 0.3, 240)
        """
        u = np.zeros(_nsamples(self.duration, self.fs))
        for j in range(self.n_pulses):
            u += (-1) ** j * bang_bang(
                self.amplitude,
                self.width,
                self.start + j * self.period,
                self.duration,
                self.fs,
            )
        return u

    def force(self) -> np.ndarray | None:
        """The shaker's force record (N), sampled at ``fs``: pulse ``j``
        starts half a period after torque pulse ``j``, with its sign; None
        without a shaker (``force_at`` None).

        Examples
        --------
        >>> from dataclasses import replace
        >>> f = replace(paper_experiment(), force_at=0.6).force()
        >>> f.size, float(f.max()), int(np.argmax(f != 0)) / 500
        (3000, 1.0, 0.6)
        """
        if self.force_at is None:
            return None
        f = np.zeros(_nsamples(self.duration, self.fs))
        for j in range(self.n_pulses):
            f += (-1) ** j * bang_bang(
                self.force_amplitude,
                self.width,
                self.start + (j + 0.5) * self.period,
                self.duration,
                self.fs,
            )
        return f

    def sensors(self) -> Sensors:
        """Default sensors with this experiment's noise levels and sensors
        along the beam."""
        return Sensors(
            accel_noise=self.accel_noise,
            tach_noise=self.tach_noise,
            deflection_at=self.deflection_at,
            acceleration_at=self.acceleration_at,
        )

    def run(self, rig: FlexibleManipulator | None = None, rng=None) -> Recording:
        """Simulate the experiment on ``rig`` (default rig if None): the
        torque, and the shaker's force when ``force_at`` is set.

        Examples
        --------
        >>> rec = paper_experiment().run(rng=0)
        >>> rec.iodata("end_acceleration").n
        3000
        """
        if rig is None:
            rig = FlexibleManipulator()
        elif not isinstance(rig, FlexibleManipulator):
            raise TypeError(f"`rig` must be a FlexibleManipulator or None; got {rig!r}")
        if self.force_at is None:
            return rig.simulate(
                self.torque(), fs=self.fs, rng=rng, sensors=self.sensors()
            )
        return rig.simulate(
            self.torque(),
            fs=self.fs,
            rng=rng,
            sensors=self.sensors(),
            force=self.force(),
            force_at=self.force_at,
        )


def paper_experiment() -> Experiment:
    """The default experiment of the paper reproduction (see :class:`Experiment`).

    Examples
    --------
    >>> exp = paper_experiment()
    >>> exp.fs, exp.duration, exp.width
    (500.0, 6.0, 0.04)
    """
    return Experiment()
