"""Frequency-domain checks: Welch spectra, resonance peaks, modes from poles.

The paper judges its models in the frequency domain by the resonance modes of
the end-point acceleration (three modes within 0-100 Hz, found at 11.72,
39.06 and 66.41 Hz; those are bins 24, 80 and 136 of a 1024-point FFT at
500 Hz, so its resolution was about 0.49 Hz). Here the measured and modelled
outputs are compared by Welch power spectral densities and their peaks
(:func:`psd`, :func:`find_resonances`), and the model's own resonances are
read off its poles (:func:`modes_from_poles`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from spiralid._checks import integer, positive

from .signals import check_signal

__all__ = [
    "PSD",
    "Modes",
    "Peaks",
    "cross_spectra",
    "default_nperseg",
    "find_resonances",
    "modes_from_poles",
    "psd",
    "segment_length",
]


@dataclass(frozen=True)
class PSD:
    """A one-sided Welch power spectral density.

    Attributes
    ----------
    f : ndarray
        Frequencies in Hz (``0..fs/2``).
    p : ndarray
        Power spectral density (signal units squared per Hz).
    fs : float
        Sampling frequency in Hz.
    nperseg : int
        Welch segment length; the frequency resolution is ``fs / nperseg``.
    resolution : float
        ``fs / nperseg`` in Hz. Two peaks closer than about this merge.
    """

    f: np.ndarray
    p: np.ndarray
    fs: float
    nperseg: int
    resolution: float


@dataclass(frozen=True)
class Peaks:
    """Resonance peaks of a spectrum, sorted by frequency.

    Attributes
    ----------
    frequency : ndarray
        Peak frequencies in Hz (refined by a parabola through the peak bin and
        its neighbours on the dB scale).
    level_db : ndarray
        PSD at the peak bins, ``10 log10(p)``.
    prominence_db : ndarray
        How far each peak stands above its surroundings, in dB
        (:func:`scipy.signal.peak_prominences`).
    """

    frequency: np.ndarray
    level_db: np.ndarray
    prominence_db: np.ndarray


@dataclass(frozen=True)
class Modes:
    """Continuous-time equivalents of discrete poles, sorted by frequency.

    Attributes
    ----------
    poles : ndarray of complex
        One discrete pole per mode (the one with positive imaginary part for a
        complex pair).
    frequency : ndarray
        Natural frequency ``|s| / (2 pi)`` in Hz, with ``s = ln(z) / ts``.
    damping : ndarray
        Damping ratio ``-Re(s) / |s|`` (negative for an unstable pole).
    damped_frequency : ndarray
        ``Im(s) / (2 pi)`` in Hz, where a lightly damped mode peaks.
    """

    poles: np.ndarray
    frequency: np.ndarray
    damping: np.ndarray
    damped_frequency: np.ndarray

    def to_dict(self) -> dict:
        """JSON-safe dictionary (poles as ``[re, im]`` pairs)."""
        return {
            "poles": [[float(p.real), float(p.imag)] for p in self.poles],
            "frequency_hz": [float(x) for x in self.frequency],
            "damping": [float(x) for x in self.damping],
            "damped_frequency_hz": [float(x) for x in self.damped_frequency],
        }


def _check_fs(fs) -> float:
    return positive(fs, "fs")


def default_nperseg(n: int) -> int:
    """Welch segment length used when none is given.

    The largest power of two not above ``N / 4`` (so at least about seven
    half-overlapping segments are averaged and the PSD's scatter is tamed),
    but never below ``min(N, 256)``: shorter segments blur resonances that
    are only a few per cent of the sampling rate apart.

    Examples
    --------
    >>> default_nperseg(4096), default_nperseg(2700), default_nperseg(341)
    (1024, 512, 256)
    """
    if n < 1:
        raise ValueError(f"`n` must be a positive record length; got {n!r}")
    pow2 = 1 << max(int(np.floor(np.log2(max(n / 4.0, 1.0)))), 0)
    return int(min(n, max(pow2, 256)))


def segment_length(nperseg, n: int, minimum: int) -> int:
    """A Welch segment length checked against a record of `n` samples:
    :func:`default_nperseg` when `nperseg` is None, else an integer in
    ``[minimum, n]`` (one-line ValueError naming ``nperseg`` otherwise)."""
    if nperseg is None:
        return default_nperseg(n)
    if isinstance(nperseg, bool) or not isinstance(nperseg, int | np.integer):
        raise ValueError(f"`nperseg` must be an integer; got {nperseg!r}")
    if not minimum <= nperseg <= n:
        raise ValueError(
            f"`nperseg` must be in [{minimum}, N] = [{minimum}, {n}]; got {nperseg!r}"
        )
    return int(nperseg)


def _welch_options(fs: float, nperseg: int, nfft: int | None = None) -> dict:
    # The one windowing of every spectrum here: Hann, half overlap, each
    # segment's mean removed, densities per Hz.
    return dict(
        fs=fs,
        window="hann",
        nperseg=nperseg,
        noverlap=nperseg // 2,
        nfft=nfft,
        detrend="constant",
        scaling="density",
    )


def cross_spectra(u, y, fs: float, *, nperseg: int) -> tuple[np.ndarray, ...]:
    """Welch auto and cross spectra of an input and an output, as :func:`psd`
    averages them (without its zero padding).

    Parameters
    ----------
    u, y : ndarray, shape (N,)
        Input and output.
    fs : float
        Sampling frequency in Hz.
    nperseg : int
        Segment length (checked by the caller, e.g. :func:`segment_length`).

    Returns
    -------
    f, suu, syy, suy : ndarray
        Frequencies in Hz, the input's and output's PSDs and the cross
        spectrum ``conj(U) Y`` (so the H1 estimate is ``suy / suu``).
    """
    opts = _welch_options(_check_fs(fs), nperseg)
    f, suu = signal.welch(u, **opts)
    _, syy = signal.welch(y, **opts)
    _, suy = signal.csd(u, y, **opts)
    return f, suu, syy, suy


def psd(x, fs: float, *, nperseg: int | None = None) -> PSD:
    """Welch power spectral density (Hann window, 50 % overlap, mean removed).

    The FFT is zero-padded to four times the segment length so that peak
    frequencies can be located finer than a bin; zero padding does not
    improve the resolution, which stays ``fs / nperseg``.

    Parameters
    ----------
    x : array_like, shape (N,)
        Signal.
    fs : float
        Sampling frequency in Hz (``1 / ts``).
    nperseg : int, optional
        Segment length, ``2 <= nperseg <= N``; default :func:`default_nperseg`.

    Returns
    -------
    PSD

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(4096) / 500.0
    >>> s = psd(np.sin(2 * np.pi * 62.5 * t), fs=500.0)
    >>> s.resolution, round(float(s.f[np.argmax(s.p)]), 2)
    (0.48828125, 62.5)
    """
    x = check_signal(x, "x", min_size=2)
    fs = _check_fs(fs)
    nperseg = segment_length(nperseg, x.size, 2)
    f, p = signal.welch(x, **_welch_options(fs, nperseg, nfft=4 * nperseg))
    return PSD(f=f, p=p, fs=fs, nperseg=nperseg, resolution=fs / nperseg)


def find_resonances(
    spectrum: PSD,
    n_peaks: int = 3,
    *,
    min_prominence_db: float = 3.0,
    fmin: float | None = None,
    fmax: float | None = None,
) -> Peaks:
    """The ``n_peaks`` most prominent peaks of a spectrum, in Hz.

    Peaks are found on the dB scale by :func:`scipy.signal.find_peaks` with a
    prominence of at least ``min_prominence_db`` and a spacing of at least one
    resolution cell (``fs / nperseg``); the most prominent ``n_peaks`` are kept
    and returned in ascending frequency. Each frequency is refined by a
    parabola through the peak bin and its two neighbours.

    Parameters
    ----------
    spectrum : PSD
        From :func:`psd`.
    n_peaks : int, default 3
        How many peaks at most (the paper's arm has three modes in 0-100 Hz).
    min_prominence_db : float, default 3.0
        Smallest prominence accepted, in dB: half power above the valleys.
    fmin, fmax : float, optional
        Search band in Hz. ``fmin`` defaults to one resolution cell, which
        keeps the DC lobe (the rigid-body motion) out; ``fmax`` to ``fs/2``.

    Returns
    -------
    Peaks
        Possibly fewer than ``n_peaks`` if the spectrum has fewer peaks.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(4096) / 500.0
    >>> x = np.sin(2 * np.pi * 11.72 * t) + np.sin(2 * np.pi * 39.06 * t)
    >>> np.round(find_resonances(psd(x, 500.0), 2).frequency, 1).tolist()
    [11.7, 39.1]
    """
    n_peaks = integer(n_peaks, "n_peaks", 1)
    if not (np.isfinite(min_prominence_db) and min_prominence_db >= 0):
        raise ValueError(
            f"`min_prominence_db` must be a non-negative number; "
            f"got {min_prominence_db!r}"
        )
    f, p = spectrum.f, spectrum.p
    lo = spectrum.resolution if fmin is None else float(fmin)
    hi = spectrum.fs / 2.0 if fmax is None else float(fmax)
    if not lo < hi:
        raise ValueError(f"`fmin` must be below `fmax`; got fmin={lo}, fmax={hi}")
    tiny = np.finfo(float).tiny
    db = 10.0 * np.log10(np.maximum(p, tiny))
    df = f[1] - f[0] if f.size > 1 else 1.0
    distance = max(1, round(spectrum.resolution / df))
    idx, props = signal.find_peaks(db, prominence=min_prominence_db, distance=distance)
    in_band = (f[idx] >= lo) & (f[idx] <= hi)
    idx, prom = idx[in_band], props["prominences"][in_band]
    order = np.argsort(prom)[::-1][:n_peaks]
    idx, prom = idx[order], prom[order]
    freq = f[idx].astype(float)
    # Parabolic interpolation on the dB scale; find_peaks never returns an
    # end point, so both neighbours exist.
    left, mid, right = db[idx - 1], db[idx], db[idx + 1]
    denom = left - 2.0 * mid + right
    safe = np.where(denom < 0.0, denom, -1.0)
    shift = np.where(denom < 0.0, 0.5 * (left - right) / safe, 0.0)
    freq = freq + np.clip(shift, -0.5, 0.5) * df
    srt = np.argsort(freq)
    return Peaks(frequency=freq[srt], level_db=db[idx][srt], prominence_db=prom[srt])


def modes_from_poles(
    poles, ts: float, *, max_damping: float | None = None, tol: float = 1e-9
) -> Modes:
    """Resonances of a discrete model read from its poles.

    Each pole ``z`` is mapped to its continuous equivalent ``s = ln(z) / ts``
    (exact for a zero-order-hold discretisation), giving the natural frequency
    ``|s| / (2 pi)`` in Hz and the damping ratio ``-Re(s) / |s|``. Only complex
    pairs (``Im(z) > tol``) are modes of vibration; one pole per pair is
    reported. Real poles (including a negative real pole, which sits at the
    Nyquist frequency) and poles at the origin are left out.

    Parameters
    ----------
    poles : array_like of complex
        Discrete-time poles.
    ts : float
        Sample time in seconds.
    max_damping : float, optional
        Keep only modes with damping below this (lightly damped ones, e.g.
        0.3); default keeps all complex pairs.
    tol : float, default 1e-9
        Imaginary parts at or below this count as real.

    Returns
    -------
    Modes
        Sorted by natural frequency.

    Examples
    --------
    >>> import numpy as np
    >>> wn, zeta, ts = 2 * np.pi * 10.0, 0.05, 0.002
    >>> s = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)
    >>> m = modes_from_poles([np.exp(s * ts), np.exp(np.conj(s) * ts)], ts)
    >>> round(float(m.frequency[0]), 6), round(float(m.damping[0]), 6)
    (10.0, 0.05)
    """
    z = np.atleast_1d(np.asarray(poles, dtype=complex)).ravel()
    if not np.all(np.isfinite(z)):
        raise ValueError(f"`poles` must be finite; got {z!r}")
    ts = positive(ts, "ts")
    if max_damping is not None and not np.isfinite(max_damping):
        raise ValueError(f"`max_damping` must be a finite number; got {max_damping!r}")
    z = z[(z.imag > tol) & (np.abs(z) > tol)]
    s = np.log(z) / ts
    wn = np.abs(s)
    zeta = -s.real / wn
    keep = np.ones(z.size, bool) if max_damping is None else zeta < max_damping
    z, s, wn, zeta = z[keep], s[keep], wn[keep], zeta[keep]
    order = np.argsort(wn)
    return Modes(
        poles=z[order],
        frequency=wn[order] / (2 * np.pi),
        damping=zeta[order],
        damped_frequency=s.imag[order] / (2 * np.pi),
    )
