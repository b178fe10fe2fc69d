"""Torque inputs for the rig: bang-bang, PRBS, chirp and multilevel, sampled at
``fs``.

Sample ``k`` is the torque held on ``[k / fs, (k + 1) / fs)``.
"""

from __future__ import annotations

import numpy as np
from scipy import signal as _signal

from spiralid._checks import generator, integer, is_integer, one_of, positive, real

__all__ = ["bang_bang", "chirp", "multilevel", "prbs"]


# A record holds the torque, three outputs and the time: five float64
# signals of this many samples is 400 MB, as much as a record should need.
MAX_SAMPLES = 10_000_000


def _nsamples(duration: float, fs: float) -> int:
    duration = positive(duration, "duration")
    fs = positive(fs, "fs")
    n = round(duration * fs)
    if n > MAX_SAMPLES:
        raise ValueError(
            f"`duration` x `fs` asks for {n:.3g} samples ({duration:g} s at "
            f"{fs:g} Hz); at most {MAX_SAMPLES:,} (memory): shorten `duration` "
            "or lower `fs`"
        )
    if n < 1:
        raise ValueError(
            f"`duration` must span at least one sample at fs={fs}; got {duration!r}"
        )
    return n


def bang_bang(
    amplitude: float, width: float, start: float, duration: float, fs: float
) -> np.ndarray:
    """Bang-bang torque: ``+amplitude`` for ``width`` s, then ``-amplitude``.

    The paper's rig is usually excited this way: the first pulse accelerates
    the hub, the second brakes it, so a rigid hub would come to rest at
    ``amplitude width^2 / J``.  Edges fall on the nearest samples.

    Parameters
    ----------
    amplitude : float
        Torque of the first pulse (N m); negative turns the other way.
    width : float
        Width of each pulse (s); at least one sample.
    start : float
        Time of the first edge (s), >= 0.
    duration : float
        Length of the record (s); must contain both pulses.
    fs : float
        Sample rate (Hz).

    Examples
    --------
    >>> bang_bang(1.0, 0.2, 0.1, 0.6, 10.0)
    array([ 0.,  1.,  1., -1., -1.,  0.])
    """
    amplitude = real(amplitude, "amplitude")
    width = positive(width, "width")
    start = real(start, "start")
    if start < 0.0:
        raise ValueError(f"`start` must be >= 0; got {start!r}")
    n = _nsamples(duration, fs)
    w = round(width * fs)
    if w < 1:
        raise ValueError(
            f"`width` must be at least one sample (1/fs = {1 / fs:g} s); got {width!r}"
        )
    i0 = round(start * fs)
    if i0 + 2 * w > n:
        raise ValueError(
            f"`duration` must hold both pulses ({(i0 + 2 * w) / fs:g} s); "
            f"got {duration!r}"
        )
    u = np.zeros(n)
    u[i0 : i0 + w] = amplitude
    u[i0 + w : i0 + 2 * w] = -amplitude
    return u


def prbs(
    amplitude: float,
    duration: float,
    fs: float,
    n_bits: int = 10,
    hold: int = 1,
) -> np.ndarray:
    """Pseudo-random binary torque from a maximum-length shift register.

    Each bit of ``scipy.signal.max_len_seq(n_bits)`` (period ``2^n_bits -
    1`` bits) becomes ``+-amplitude`` held for ``hold`` samples; the sequence
    repeats to fill ``duration``.  Deterministic: the register starts from
    all ones.  Note the free hub integrates a PRBS's mean and drift.

    Parameters
    ----------
    amplitude : float
        Torque level (N m).
    duration : float
        Length (s).
    fs : float
        Sampling rate (Hz).
    n_bits : int
        Register length, 2..32.
    hold : int
        Samples each bit is held.

    Examples
    --------
    >>> prbs(2.0, 0.7, 10.0, n_bits=3)
    array([ 2.,  2.,  2., -2.,  2., -2., -2.])
    """
    amplitude = real(amplitude, "amplitude")
    n = _nsamples(duration, fs)
    if not is_integer(n_bits) or not 2 <= n_bits <= 32:
        raise ValueError(f"`n_bits` must be an integer in [2, 32]; got {n_bits!r}")
    hold = integer(hold, "hold", 1)
    nbits_needed = -(-n // hold)
    period = 2**n_bits - 1
    seq, _ = _signal.max_len_seq(int(n_bits), length=min(period, nbits_needed))
    bits = np.resize(seq, nbits_needed)
    return amplitude * (2.0 * np.repeat(bits, hold)[:n] - 1.0)


def chirp(
    amplitude: float,
    f0: float,
    f1: float,
    duration: float,
    fs: float,
    method: str = "linear",
) -> np.ndarray:
    """Swept-sine torque from ``f0`` to ``f1`` Hz over ``duration``.

    ``amplitude * scipy.signal.chirp(t, f0, duration, f1, method)``, with
    both frequencies at most the Nyquist frequency ``fs / 2``.

    Parameters
    ----------
    amplitude : float
        Torque amplitude (N m).
    f0, f1 : float
        Start and end frequencies (Hz).
    duration, fs : float
        Length (s) and sampling rate (Hz).
    method : str
        The sweep, as in ``scipy.signal.chirp``: ``"linear"``,
        ``"quadratic"``, ``"logarithmic"`` or ``"hyperbolic"``.

    Examples
    --------
    >>> chirp(1.0, 0.0, 1.0, 1.0, 4.0).round(3)
    array([ 1.   ,  0.981,  0.707, -0.195])
    """
    amplitude = real(amplitude, "amplitude")
    n = _nsamples(duration, fs)
    fs = float(fs)
    nyq = 0.5 * fs
    for name, f in (("f0", f0), ("f1", f1)):
        v = real(f, name)
        if not 0.0 <= v <= nyq:
            raise ValueError(f"`{name}` must be in [0, fs/2 = {nyq:g}] Hz; got {f!r}")
    methods = ("linear", "quadratic", "logarithmic", "hyperbolic")
    one_of(method, "method", methods)
    if method in ("logarithmic", "hyperbolic") and (float(f0) <= 0 or float(f1) <= 0):
        raise ValueError(
            f"`f0` and `f1` must be > 0 for method={method!r}; got {f0!r}, {f1!r}"
        )
    t = np.arange(n) / fs
    return amplitude * _signal.chirp(t, float(f0), float(duration), float(f1), method)


def multilevel(
    amplitude: float,
    duration: float,
    fs: float,
    min_hold: float = 0.02,
    max_hold: float = 0.2,
    rng=None,
) -> np.ndarray:
    """Random multilevel torque (an amplitude-modulated PRBS, APRBS).

    Levels uniform in ``[-amplitude, amplitude]``, each held for a time
    uniform in ``[min_hold, max_hold]`` s: unlike a binary signal it visits
    small torques (where friction holds the hub) and large ones (where an
    amplifier saturates), which a nonlinear model needs to see.

    Parameters
    ----------
    amplitude : float
        Largest level (N m).
    duration : float
        Length (s).
    fs : float
        Sample rate (Hz).
    min_hold, max_hold : float
        Range of the hold times (s), ``0 < min_hold <= max_hold``.
    rng : None, int or numpy.random.Generator
        Seed of the levels and hold times.

    Returns
    -------
    ndarray

    Examples
    --------
    >>> u = multilevel(0.4, 2.0, 500.0, rng=0)
    >>> u.size, bool(abs(u).max() <= 0.4)
    (1000, True)
    """
    amplitude = real(amplitude, "amplitude")
    n = _nsamples(duration, fs)
    lo = positive(min_hold, "min_hold")
    hi = positive(max_hold, "max_hold")
    if hi < lo:
        raise ValueError(f"`max_hold` must be >= `min_hold` = {lo!r}; got {max_hold!r}")
    gen = generator(rng)
    out = np.empty(n)
    k = 0
    while k < n:
        hold = max(1, round(gen.uniform(lo, hi) * float(fs)))
        out[k : k + hold] = gen.uniform(-amplitude, amplitude)
        k += hold
    return out
