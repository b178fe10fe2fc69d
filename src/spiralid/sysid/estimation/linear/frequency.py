"""A frequency-domain objective: a model's gain against the measured one.

The measured frequency response is the H1 estimate of the record,

    H1(f) = S_uy(f) / S_uu(f),

with the cross and auto spectra averaged over Welch segments
(:func:`~spiralid.sysid.spectra.cross_spectra`, the Welch averaging of
:func:`~spiralid.sysid.spectra.psd`: Hann window, half overlap, means
removed), i.e. the empirical transfer-function estimate averaged over
segments. Its magnitude-squared coherence

    gamma^2(f) = |S_uy|^2 / (S_uu S_yy)

says how much of the output at ``f`` the input explains linearly (1 for
noise-free linear data). A model ``B(q) / A(q)`` is scored by the
coherence-weighted RMS of its log-magnitude error in decibels over a band,

    e = sqrt( sum_f w(f) (20 log10 |G(f)| - 20 log10 |H1(f)|)^2 ),
    w = gamma^2 / sum gamma^2,

where ``G(f) = B(e^{-j 2 pi f ts}) / A(e^{-j 2 pi f ts})``. The band is
``[fmin, fmax]`` (default: from one resolution cell ``fs / nperseg``, which
leaves DC out, to ``0.8`` of the Nyquist frequency) and only bins with
coherence of at least ``min_coherence`` count. A model whose gain is ``c``
times the measured one everywhere scores ``|20 log10 c|`` dB exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spiralid._checks import positive

from ...data import IOData, single_output_record
from ...models.arx import ARX, check_arx
from ...spectra import cross_spectra, segment_length

__all__ = ["FrequencyError", "FrequencyEstimate", "h1_estimate"]

# Default top of the band, as a share of the Nyquist frequency: the last
# fifth is where anti-aliasing and a zero-order hold bend a record's gain.
DEFAULT_FMAX_SHARE = 0.8
DEFAULT_MIN_COHERENCE = 0.5
# Bins needed for a meaningful score.
_MIN_BINS = 3


@dataclass(frozen=True)
class FrequencyEstimate:
    """The measured frequency response over the scored band.

    Attributes
    ----------
    f : ndarray, shape (L,)
        Frequencies in Hz of the scored bins.
    h : ndarray of complex, shape (L,)
        The H1 estimate ``S_uy / S_uu`` there (output units per input unit).
    coherence : ndarray, shape (L,)
        Magnitude-squared coherence there, in [0, 1].
    weight : ndarray, shape (L,)
        ``coherence / sum(coherence)``: the weights of the score.
    ts : float
        Sample time in seconds.
    nperseg : int
        Welch segment length (the resolution is ``1 / (nperseg ts)`` Hz).
    band : (float, float)
        The band asked for, in Hz.
    """

    f: np.ndarray
    h: np.ndarray
    coherence: np.ndarray
    weight: np.ndarray
    ts: float
    nperseg: int
    band: tuple[float, float]

    @property
    def magnitude_db(self) -> np.ndarray:
        """``20 log10 |H1|`` of the scored bins."""
        return _db(self.h)


def _db(h: np.ndarray) -> np.ndarray:
    # A zero gain is -6000 dB, not -inf: the score stays finite (and huge).
    return 20.0 * np.log10(np.maximum(np.abs(h), 1e-300))


def h1_estimate(
    data: IOData,
    *,
    nperseg: int | None = None,
    fmin: float | None = None,
    fmax: float | None = None,
    min_coherence: float = DEFAULT_MIN_COHERENCE,
) -> FrequencyEstimate:
    """The H1 estimate of a record's frequency response over a band.

    Parameters
    ----------
    data : IOData
        The record (its first 2/3 when it estimates a model).
    nperseg : int, optional
        Welch segment length, ``8 <= nperseg <= N``; default
        :func:`~spiralid.sysid.spectra.default_nperseg` of the record length.
    fmin : float, optional
        Lowest frequency scored, in Hz; default one resolution cell,
        ``1 / (nperseg ts)`` (DC left out).
    fmax : float, optional
        Highest frequency scored, in Hz, at most the Nyquist frequency;
        default 0.8 of it.
    min_coherence : float, default 0.5
        Bins whose coherence is below this are left out; in [0, 1).

    Returns
    -------
    FrequencyEstimate

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(4096)
    >>> y = lfilter([0.0, 0.5], [1.0, -0.9], u)        # low-pass, DC gain 5
    >>> est = h1_estimate(IOData(u, y, ts=0.01))
    >>> round(float(est.magnitude_db[0]), 1), bool(est.coherence.min() > 0.99)
    (13.9, True)
    """
    single_output_record(data, "the H1 estimate")
    nperseg = segment_length(nperseg, data.n, 8)
    fs = 1.0 / data.ts
    nyquist = fs / 2.0
    lo = fs / nperseg if fmin is None else _frequency(fmin, "fmin", nyquist)
    hi = (
        DEFAULT_FMAX_SHARE * nyquist
        if fmax is None
        else _frequency(fmax, "fmax", nyquist)
    )
    if not lo < hi:
        raise ValueError(f"`fmin` must be below `fmax`; got fmin={lo:g}, fmax={hi:g}")
    if not (
        isinstance(min_coherence, int | float | np.number)
        and 0.0 <= float(min_coherence) < 1.0
    ):
        raise ValueError(
            f"`min_coherence` must be a number in [0, 1); got {min_coherence!r}"
        )
    f, suu, syy, suy = cross_spectra(data.u, data.y, fs, nperseg=nperseg)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = suy / suu
        coh = np.abs(suy) ** 2 / (suu * syy)
    coh = np.nan_to_num(coh, nan=0.0, posinf=0.0)
    keep = (
        (f >= lo)
        & (f <= hi)
        & (coh >= min_coherence)
        & (coh > 0.0)
        & np.isfinite(h)
        & (suu > 0.0)
    )
    if int(keep.sum()) < _MIN_BINS:
        raise ValueError(
            f"`data` has {int(keep.sum())} frequency bins in [{lo:g}, {hi:g}] Hz "
            f"with coherence >= {min_coherence:g}; at least {_MIN_BINS} are "
            "needed (widen the band, lower `min_coherence` or use a richer input)"
        )
    coh = np.minimum(coh[keep], 1.0)
    return FrequencyEstimate(
        f=f[keep],
        h=h[keep],
        coherence=coh,
        weight=coh / coh.sum(),
        ts=data.ts,
        nperseg=nperseg,
        band=(float(lo), float(hi)),
    )


def _frequency(value, name: str, nyquist: float) -> float:
    v = positive(value, name)
    if v > nyquist:
        raise ValueError(
            f"`{name}` must be at most the Nyquist frequency {nyquist:g} Hz; "
            f"got {value!r}"
        )
    return v


class FrequencyError:
    """Coherence-weighted RMS log-magnitude error of ARX models, in dB.

    Parameters
    ----------
    arx : ARX
        Model structure of the parameter vectors scored.
    estimate : FrequencyEstimate
        The measured response, from :func:`h1_estimate`.

    Examples
    --------
    A model scores about 0 dB on its own noise-free data; twice its gain
    scores ``20 log10 2 = 6.02`` dB more in every bin.

    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(4096)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> err = FrequencyError(ARX(2, 2, 1), h1_estimate(IOData(u, y, ts=0.01)))
    >>> theta = np.array([-1.5, 0.7, 1.0, 0.5])
    >>> bool(err(theta) < 0.1)
    True
    >>> shift = err.residual(theta * [1, 1, 2, 2]) - err.residual(theta)
    >>> bool(np.allclose(shift, 20 * np.log10(2)))
    True
    """

    def __init__(self, arx: ARX, estimate: FrequencyEstimate) -> None:
        check_arx(arx)
        if not isinstance(estimate, FrequencyEstimate):
            raise TypeError(
                f"`estimate` must be a FrequencyEstimate; got {type(estimate).__name__}"
            )
        self.arx = arx
        self.estimate = estimate
        w = 2.0 * np.pi * estimate.f * estimate.ts
        lags = np.arange(max(arx.na, arx.nk + arx.nb - 1, 0) + 1)
        # powers[k, i] = z^-k at bin i.
        self._powers = np.exp(-1j * np.outer(lags, w))
        self._target_db = estimate.magnitude_db
        self._sqrt_weight = np.sqrt(estimate.weight)

    def __repr__(self) -> str:
        lo, hi = self.estimate.band
        return (
            f"FrequencyError({self.arx}, {self.estimate.f.size} bins in "
            f"[{lo:g}, {hi:g}] Hz)"
        )

    def response(self, thetas) -> np.ndarray:
        """Frequency responses ``G`` at the scored bins, shape (L,) or (m, L).

        Parameters
        ----------
        thetas : array_like, shape (p,) or (m, p)
            ARX parameter vectors ``[a_1..a_na, b_0..b_(nb-1)]``.
        """
        arx = self.arx
        arr = np.asarray(thetas, dtype=float)
        if arr.ndim not in (1, 2) or arr.shape[-1] != arx.n_params:
            raise ValueError(
                f"`thetas` must have shape ({arx.n_params},) or "
                f"(m, {arx.n_params}); got shape {arr.shape}"
            )
        th = np.atleast_2d(arr)
        na, nb, nk = arx.na, arx.nb, arx.nk
        den = 1.0 + th[:, :na] @ self._powers[1 : na + 1]
        num = th[:, na:] @ self._powers[nk : nk + nb]
        with np.errstate(divide="ignore", invalid="ignore"):
            g = num / den
        g = np.where(np.isfinite(g), g, np.inf)
        return g[0] if arr.ndim == 1 else g

    def residual(self, thetas) -> np.ndarray:
        """``20 log10 |G| - 20 log10 |H1|`` per bin, shape (L,) or (m, L).

        Parameters
        ----------
        thetas : array_like, shape (p,) or (m, p)
            ARX parameter vectors.
        """
        return _db(self.response(thetas)) - self._target_db

    def __call__(self, thetas) -> np.ndarray | float:
        """The score in dB: float for one vector, shape (m,) for a population.

        Parameters
        ----------
        thetas : array_like, shape (p,) or (m, p)
            ARX parameter vectors.
        """
        r = self.residual(thetas)
        # A pole on the unit circle at a scored bin: an infinite gain, scored
        # as the largest finite error instead of inf.
        r = np.nan_to_num(r, nan=6000.0, posinf=6000.0, neginf=-6000.0)
        e = np.sqrt(np.sum((r * self._sqrt_weight) ** 2, axis=-1))
        return float(e) if np.ndim(e) == 0 else e
