"""Modes of an identified model with their uncertainty: :class:`ModeTable`.

A mode of vibration is a complex pole pair of the denominator. Its natural
frequency and damping ratio follow from the pole's continuous equivalent
``s = ln(p) / ts`` (exact for a zero-order hold), as in
:func:`~spiralid.sysid.modes_from_poles`. Their standard errors come from
the covariance of the denominator's coefficients by the delta method, with
the derivative of a simple root ``p`` of ``A(z) = z^n + a_1 z^(n-1) + ... +
a_n`` with respect to ``a_k``:

    dp / da_k = -p^(n-k) / A'(p)

then ``ds = dp / (p ts)``, ``d|s| = Re(conj(s) ds) / |s|`` and
``d zeta = -Re(ds) / |s| + Re(s) d|s| / |s|^2``. MATLAB's ``present`` and
``damp`` are what a user compares this table with.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal, stats

from . import _fields

__all__ = ["ModeTable", "mode_table"]

# A mode is reported as probably spurious when its resonant peak holds less
# than this share of the model's peaks, or when its frequency's 95 %
# interval is wider than this share of the frequency on either side.
SPURIOUS_SHARE = 0.01
SPURIOUS_WIDTH = 0.10
# Imaginary parts at or below this are real poles (as modes_from_poles).
_REAL_TOL = 1e-9
_ORIGIN = 1e-2


@dataclass(frozen=True)
class ModeTable:
    """The complex pole pairs of a model as modes, with intervals.

    Attributes
    ----------
    poles : ndarray of complex, shape (m,)
        One pole per pair (positive imaginary part), sorted by frequency.
    frequency, damping : ndarray, shape (m,)
        Natural frequency in Hz and damping ratio.
    frequency_se, damping_se, radius_se : ndarray, shape (m,)
        Their standard errors, and that of ``|p|`` (NaN without a
        covariance).
    share : ndarray, shape (m,)
        The mode's resonant peak ``|r| / (1 - |p|)`` (``r`` its residue in
        ``B / A``) as a share of the sum over every pole: how much of the
        output the mode carries (NaN where the residues are not finite).
    reaches_unit_circle : ndarray of bool, shape (m,)
        The pole's radius interval reaches ``|z| = 1``.
    cancelled : ndarray of bool, shape (m,)
        A zero lies within the pole's interval (a near pole-zero
        cancellation: the mode barely reaches the output).
    spurious : ndarray of bool, shape (m,)
        Probably spurious: a share below :data:`SPURIOUS_SHARE`, a frequency
        interval wider than :data:`SPURIOUS_WIDTH` of the frequency, a
        cancellation, or an interval that reaches the unit circle.
    level : float
        The intervals' confidence level.
    """

    poles: np.ndarray
    frequency: np.ndarray
    damping: np.ndarray
    frequency_se: np.ndarray
    damping_se: np.ndarray
    radius_se: np.ndarray
    share: np.ndarray
    reaches_unit_circle: np.ndarray
    cancelled: np.ndarray
    spurious: np.ndarray
    level: float = 0.95

    def __len__(self) -> int:
        return int(self.poles.size)

    @property
    def _z(self) -> float:
        return float(stats.norm.ppf(0.5 + self.level / 2))

    @property
    def frequency_interval(self) -> np.ndarray:
        """Shape (m, 2): the frequency's interval at :attr:`level`, in Hz."""
        half = self._z * self.frequency_se
        return np.c_[self.frequency - half, self.frequency + half]

    @property
    def damping_interval(self) -> np.ndarray:
        """Shape (m, 2): the damping ratio's interval at :attr:`level`."""
        half = self._z * self.damping_se
        return np.c_[self.damping - half, self.damping + half]

    def notes(self, i: int) -> list[str]:
        """Mode `i`'s flags in words (for tables)."""
        return [
            text
            for flag, text in (
                (self.reaches_unit_circle[i], "interval reaches |z| = 1"),
                (self.cancelled[i], "cancelled by a zero"),
                (self.spurious[i], "probably spurious"),
            )
            if flag
        ]

    def to_dict(self) -> dict:
        """Plain Python values, one dict per mode (for JSON)."""
        f_lo, f_hi = self.frequency_interval.T
        d_lo, d_hi = self.damping_interval.T
        return {
            "level": self.level,
            "modes": [
                {
                    "frequency_hz": _fields.plain(self.frequency[i]),
                    "frequency_interval_hz": [
                        _fields.plain(f_lo[i]),
                        _fields.plain(f_hi[i]),
                    ],
                    "damping": _fields.plain(self.damping[i]),
                    "damping_interval": [
                        _fields.plain(d_lo[i]),
                        _fields.plain(d_hi[i]),
                    ],
                    "pole": [
                        _fields.plain(self.poles[i].real),
                        _fields.plain(self.poles[i].imag),
                    ],
                    "share": _fields.plain(self.share[i]),
                    "reaches_unit_circle": bool(self.reaches_unit_circle[i]),
                    "cancelled": bool(self.cancelled[i]),
                    "spurious": bool(self.spurious[i]),
                }
                for i in range(len(self))
            ],
        }

    def __str__(self) -> str:
        if not len(self):
            return "no modes (no complex pole pair)"
        pct = round(100 * self.level)
        lines = [
            f"mode  frequency (Hz) [{pct} % interval]     damping "
            f"[{pct} % interval]    share",
        ]
        f_int, d_int = self.frequency_interval, self.damping_interval
        for i in range(len(self)):
            notes = self.notes(i)
            ff, fd = interval_format(f_int[i]), interval_format(d_int[i], "f")
            lines.append(
                f"{i + 1:>4}  {self.frequency[i]:9{ff}} "
                f"[{_num(f_int[i, 0], ff)}, {_num(f_int[i, 1], ff)}]  "
                f"{self.damping[i]:8{fd}} "
                f"[{_num(d_int[i, 0], fd)}, {_num(d_int[i, 1], fd)}]"
                f"  {_pct(self.share[i])}"
                + (f"  ({'; '.join(notes)})" if notes else "")
            )
        return "\n".join(lines)


def _num(value: float, fmt: str = ".4g") -> str:
    return format(value, fmt) if np.isfinite(value) else "-"


def interval_format(pair, kind: str = "g", least: int = 4) -> str:
    """The format (``".{d}g"`` or ``".{d}f"``) with the fewest digits, at
    least `least`, that tells an interval's ends apart.

    A well-determined mode's interval (a few 1e-5 Hz wide on the simulated
    rig) would print as one number twice at four digits.

    Parameters
    ----------
    pair : (float, float)
        The interval's ends.
    kind : {"g", "f"}
        Significant digits or digits after the point.
    least : int
        The fewest digits.

    Returns
    -------
    str
        A format specification for :func:`format`.
    """
    lo, hi = pair
    fmt = f".{least}{kind}"
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return fmt
    for d in range(least, least + 7):
        fmt = f".{d}{kind}"
        if format(lo, fmt) != format(hi, fmt):
            break
    return fmt


def _pct(value: float) -> str:
    return f"{100 * value:5.1f} %" if np.isfinite(value) else "    - "


def mode_table(
    a,
    b,
    ts: float,
    *,
    covariance=None,
    level: float = 0.95,
    factor=None,
    shares: bool = True,
) -> ModeTable:
    """The modes of ``B(q) / A(q)`` with intervals from the coefficients'
    covariance.

    Parameters
    ----------
    a : array_like, shape (n,)
        The denominator's coefficients ``a_1..a_n`` (``A = 1 + a_1 q^-1 +
        ...``), without any known integrator.
    b : array_like
        The numerator in ``q^-1``, leading delay zeros included.
    ts : float
        Sample time in seconds.
    covariance : array_like, shape (n, n), optional
        The covariance of ``a``; without it the standard errors are NaN and
        no flag is raised from an interval.
    level : float, default 0.95
        Confidence level of the intervals.
    factor : array_like, shape (k, n), optional
        A square-root factor ``R`` of `covariance` (``C = R^T R``): the
        variances are then ``|R g|^2``, which keep their precision where
        ``g^T C g`` on an ill-conditioned ``C`` rounds to zero.

    shares : bool, default True
        Compute each mode's share of the output (partial fractions, the
        table's slowest part at high orders); without them ``share`` is NaN
        and no mode is flagged for a small share (the estimation's own
        diagnosis, which acts on the interval and cancellation flags only).

    Returns
    -------
    ModeTable

    Examples
    --------
    >>> import numpy as np
    >>> wn, zeta, ts = 2 * np.pi * 5.0, 0.02, 0.01
    >>> p = np.exp((-zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)) * ts)
    >>> a = np.poly([p, p.conjugate()]).real[1:]
    >>> table = mode_table(a, [0.0, 1.0], ts, covariance=np.eye(2) * 1e-8)
    >>> round(float(table.frequency[0]), 6), round(float(table.damping[0]), 6)
    (5.0, 0.02)
    >>> bool(table.frequency_se[0] > 0)
    True
    """
    a = np.asarray(a, dtype=float).ravel()
    b = np.asarray(b, dtype=float).ravel()
    n = a.size
    den = np.r_[1.0, a]
    roots = np.roots(den) if n else np.zeros(0, complex)
    upper = roots[(roots.imag > _REAL_TOL) & (np.abs(roots) > _REAL_TOL)]
    upper = upper[np.argsort(np.abs(np.log(upper)))]
    s = np.log(upper) / ts
    wn = np.abs(s)
    frequency, damping = wn / (2 * np.pi), -s.real / wn

    nan = np.full(upper.size, np.nan)
    freq_se, damp_se, radius_se = nan.copy(), nan.copy(), nan.copy()
    if (covariance is not None or factor is not None) and upper.size:
        cov = (
            np.asarray(covariance, dtype=float)
            if factor is None
            else _Root(np.asarray(factor, dtype=float))
        )
        # dp/da_k = -p^(n-k) / A'(p), one row per pole.
        slope = np.polyval(np.polyder(den), upper)
        dp = -(upper[:, None] ** (n - np.arange(1, n + 1))) / slope[:, None]
        ds = dp / (upper[:, None] * ts)
        g_wn = np.real(np.conj(s)[:, None] * ds) / wn[:, None]
        g_zeta = -np.real(ds) / wn[:, None] + (s.real / wn**2)[:, None] * g_wn
        g_r = np.real(np.conj(upper)[:, None] * dp) / np.abs(upper)[:, None]
        freq_se = _spread(g_wn, cov) / (2 * np.pi)
        damp_se = _spread(g_zeta, cov)
        radius_se = _spread(g_r, cov)
        pole_se = np.sqrt(
            _spread(np.real(dp), cov) ** 2 + _spread(np.imag(dp), cov) ** 2
        )
    else:
        pole_se = nan.copy()

    z = float(stats.norm.ppf(0.5 + level / 2))
    reaches = np.abs(upper) + z * radius_se >= 1.0
    zeros = np.roots(np.trim_zeros(b, "f")) if np.count_nonzero(b) > 1 else []
    zeros = np.asarray(zeros, dtype=complex)
    if zeros.size and upper.size:
        gap = np.min(np.abs(upper[:, None] - zeros[None, :]), axis=1)
        cancelled = gap <= z * pole_se
    else:
        cancelled = np.zeros(upper.size, bool)
    share = _peak_shares(b, den, upper) if shares else np.full(upper.size, np.nan)
    spurious = (
        (share < SPURIOUS_SHARE)
        | (z * freq_se > SPURIOUS_WIDTH * frequency)
        | cancelled
        | reaches
    )
    return ModeTable(
        poles=upper,
        frequency=frequency,
        damping=damping,
        frequency_se=freq_se,
        damping_se=damp_se,
        radius_se=radius_se,
        share=share,
        reaches_unit_circle=reaches,
        cancelled=cancelled,
        spurious=spurious,
        level=level,
    )


class _Root:
    """A covariance given by its factor ``R`` (``C = R^T R``)."""

    def __init__(self, root: np.ndarray) -> None:
        self.root = root


def _spread(gradient: np.ndarray, cov) -> np.ndarray:
    """Delta-method standard deviations, one per row of `gradient`."""
    if isinstance(cov, _Root):
        return np.linalg.norm(cov.root @ gradient.T, axis=0)
    var = np.einsum("ik,kl,il->i", gradient, cov, gradient)
    return np.sqrt(np.maximum(var, 0.0))


def _peak_shares(b: np.ndarray, den: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Each mode's resonant peak ``|r| / (1 - |p|)`` over the sum of every
    pole's (a complex pair counted once)."""
    if not upper.size:
        return np.zeros(0)
    # The shares are ratios, whatever the output's unit; residuez is not:
    # its tolerances are absolute, so a numerator of order 1e-8 (an output
    # in small units) would move them. In the numerator's own scale it
    # sees every unit alike.
    scale = np.max(np.abs(b), initial=0.0)
    b = b / scale if scale > 0 else b
    with np.errstate(all="ignore"):
        residues, poles, _ = signal.residuez(b, den)
        peaks = np.abs(residues) / np.abs(1.0 - np.abs(poles))
    # A pole within 1e-2 of the origin decays within a sample: it is neither
    # a mode nor drift, and its residue (of order 1 / p when it nearly
    # cancels) would swamp every mode's share.
    once = (poles.imag >= -_REAL_TOL) & (np.abs(poles) > _ORIGIN)
    if not np.all(np.isfinite(peaks[once])):
        return np.full(upper.size, np.nan)
    total = peaks[once].sum()
    nearest = np.argmin(np.abs(upper[:, None] - poles[None, :]), axis=1)
    return peaks[nearest] / total
