"""Welch spectra, resonance peaks and modes from poles on known answers."""

import numpy as np
import pytest
from scipy import signal

from spiralid.sysid.spectra import (
    default_nperseg,
    find_resonances,
    modes_from_poles,
    psd,
)

PAPER_MODES = (11.72, 39.06, 66.41)  # the paper's Figure 7c, Hz


def test_psd_is_scipy_welch_with_documented_settings():
    x = np.random.default_rng(0).standard_normal(3000)
    s = psd(x, 200.0)
    f, p = signal.welch(
        x, fs=200.0, window="hann", nperseg=512, noverlap=256, nfft=2048
    )
    np.testing.assert_allclose(s.f, f)
    np.testing.assert_allclose(s.p, p, rtol=1e-12)
    assert s.nperseg == 512 and s.resolution == pytest.approx(200.0 / 512)


def test_psd_integrates_to_the_power_of_a_sinusoid():
    t = np.arange(8192) / 500.0
    s = psd(3.0 * np.sin(2 * np.pi * 40.0 * t), 500.0)
    power = np.sum(s.p) * (s.f[1] - s.f[0])
    assert power == pytest.approx(3.0**2 / 2, rel=0.02)


def test_default_segment_lengths():
    assert default_nperseg(4096) == 1024
    assert default_nperseg(1000) == 256
    assert default_nperseg(100) == 100
    assert default_nperseg(100_000) == 16384


def test_peaks_of_a_sum_of_sinusoids_at_the_paper_modes():
    fs, n = 500.0, 4096
    t = np.arange(n) / fs
    rng = np.random.default_rng(0)
    x = sum(
        a * np.sin(2 * np.pi * f * t)
        for a, f in zip((1.0, 0.3, 0.1), PAPER_MODES, strict=True)
    )
    x = x + 0.05 * rng.standard_normal(n)
    s = psd(x, fs)
    pk = find_resonances(s, 3)
    assert pk.frequency.size == 3
    np.testing.assert_allclose(pk.frequency, PAPER_MODES, atol=s.resolution)
    assert np.all(np.diff(pk.frequency) > 0)
    assert np.all(pk.prominence_db > 10)


def test_peaks_keep_the_most_prominent_and_respect_the_band():
    fs, n = 500.0, 4096
    t = np.arange(n) / fs
    x = sum(np.sin(2 * np.pi * f * t) for f in PAPER_MODES)
    x = x + 0.01 * np.sin(2 * np.pi * 150.0 * t)
    s = psd(x, fs)
    assert find_resonances(s, 1, fmin=30.0, fmax=50.0).frequency == pytest.approx(
        [39.06], abs=s.resolution
    )
    # a white spectrum has no 20 dB peaks
    w = psd(np.random.default_rng(0).standard_normal(n), fs)
    assert find_resonances(w, 3, min_prominence_db=20.0).frequency.size == 0


def test_resonance_of_a_lightly_damped_system_driven_by_noise():
    fs, fn, zeta = 500.0, 39.06, 0.02
    wn = 2 * np.pi * fn
    num, den, _ = signal.cont2discrete(([wn**2], [1, 2 * zeta * wn, wn**2]), 1 / fs)
    y = signal.lfilter(
        num.ravel(), den, np.random.default_rng(4).standard_normal(20000)
    )
    s = psd(y, fs)
    (peak,) = find_resonances(s, 1).frequency
    # The resonance is 2 zeta fn = 1.6 Hz wide at half power, far wider than
    # the resolution, and the averaged PSD still scatters by ~1 dB per bin:
    # the peak is located within half that half-power width.
    assert peak == pytest.approx(fn * np.sqrt(1 - 2 * zeta**2), abs=zeta * fn)


@pytest.mark.parametrize("ts", [0.001, 0.002])
def test_modes_from_poles_recover_wn_and_zeta(ts):
    modes = [(11.72, 0.01), (39.06, 0.05), (66.41, 0.2)]
    den = np.array([1.0])
    for fn, z in modes:
        wn = 2 * np.pi * fn
        den = np.polymul(den, [1.0, 2 * z * wn, wn**2])
    sysd = signal.cont2discrete(([1.0], den), ts, method="zoh")
    poles = np.roots(sysd[1])
    m = modes_from_poles(poles, ts)
    np.testing.assert_allclose(m.frequency, [f for f, _ in modes], rtol=1e-7)
    np.testing.assert_allclose(m.damping, [z for _, z in modes], rtol=1e-6)
    np.testing.assert_allclose(
        m.damped_frequency, [f * np.sqrt(1 - z**2) for f, z in modes], rtol=1e-7
    )
    light = modes_from_poles(poles, ts, max_damping=0.1)
    np.testing.assert_allclose(light.frequency, [11.72, 39.06], rtol=1e-7)


def test_modes_skip_real_and_origin_poles():
    m = modes_from_poles(
        [0.5, -0.3, 0.0, 0.9 * np.exp(0.3j), 0.9 * np.exp(-0.3j)], 0.01
    )
    assert m.poles.size == 1 and m.poles[0].imag > 0
    assert m.to_dict()["frequency_hz"] == [
        pytest.approx(abs(np.log(m.poles[0])) / 0.01 / 2 / np.pi)
    ]


def test_bad_inputs():
    with pytest.raises(ValueError, match="`fs` must be a finite number > 0"):
        psd(np.zeros(100), -1.0)
    with pytest.raises(ValueError, match=r"`nperseg` must be in \[2, N\]"):
        psd(np.zeros(100), 1.0, nperseg=200)
    with pytest.raises(ValueError, match="`x` must be finite; got inf at sample 2"):
        psd([0.0, 1.0, np.inf, 2.0], 1.0)
    s = psd(np.random.default_rng(0).standard_normal(100), 1.0)
    with pytest.raises(ValueError, match="`n_peaks` must be an integer >= 1"):
        find_resonances(s, 0)
    with pytest.raises(ValueError, match="`fmin` must be below `fmax`"):
        find_resonances(s, 1, fmin=0.4, fmax=0.1)
    with pytest.raises(ValueError, match="`ts` must be a finite number > 0"):
        modes_from_poles([0.5j, -0.5j], 0.0)
