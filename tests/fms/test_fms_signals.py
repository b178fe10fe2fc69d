"""Torque signals and the anti-aliasing filter model."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from spiralid.fms import (
    Experiment,
    Sensors,
    bang_bang,
    chirp,
    paper_experiment,
    prbs,
)
from spiralid.fms.sensors import butterworth_ss, quantise


@settings(max_examples=30, deadline=None)
@given(
    amp=st.floats(-5, 5, allow_nan=False),
    w=st.integers(1, 40),
    i0=st.integers(0, 50),
    extra=st.integers(0, 30),
)
def test_bang_bang_is_two_opposite_pulses(amp, w, i0, extra):
    fs = 200.0
    n = i0 + 2 * w + extra
    u = bang_bang(amp, w / fs, i0 / fs, n / fs, fs)
    ref = np.zeros(n)
    ref[i0 : i0 + w] = amp
    ref[i0 + w : i0 + 2 * w] = -amp
    np.testing.assert_array_equal(u, ref)
    # Zero net impulse: a rigid hub ends at rest.
    assert abs(u.sum()) <= 1e-12 * max(1.0, abs(amp)) * n


def test_prbs_is_a_maximum_length_sequence():
    u = prbs(0.5, 2 * 1023 / 100.0, 100.0, n_bits=10)
    assert set(np.unique(u)) == {-0.5, 0.5}
    one = u[:1023]
    np.testing.assert_array_equal(u[1023:], one)  # period 2^10 - 1
    # m-sequence: one more +1 than -1, and a two-valued circular autocorrelation.
    assert (one > 0).sum() == 512
    s = np.sign(one)
    acf = np.array([s @ np.roll(s, k) for k in range(1, 1023)])
    np.testing.assert_array_equal(acf, -1.0)
    held = prbs(1.0, 0.3, 100.0, n_bits=4, hold=3)
    np.testing.assert_array_equal(held, np.repeat(held[::3], 3)[: held.size])


def test_chirp_matches_scipy_and_sweeps_frequency():
    fs, dur = 1000.0, 2.0
    u = chirp(0.4, 1.0, 50.0, dur, fs)
    t = np.arange(round(dur * fs)) / fs
    # Instantaneous frequency f0 + (f1 - f0) t / T, phase written out by hand.
    phase = 2 * np.pi * (1.0 * t + (50.0 - 1.0) * t**2 / (2 * dur))
    np.testing.assert_allclose(u, 0.4 * np.cos(phase), atol=1e-12)


@pytest.mark.parametrize("order", [1, 2, 3, 4, 5, 6])
def test_butterworth_state_space_matches_scipy_butter(order):
    fc = 37.0
    A, B, C = butterworth_ss(order, fc)
    b, a = signal.butter(order, 2 * np.pi * fc, analog=True)
    w = 2 * np.pi * np.logspace(0, 3, 40)
    _, h_ref = signal.freqs(b, a, worN=w)
    h = np.array([C @ np.linalg.solve(1j * wk * np.eye(order) - A, B) for wk in w])
    np.testing.assert_allclose(h, h_ref, rtol=1e-10, atol=1e-14)


def test_quantise_rounds_to_nearest_count():
    np.testing.assert_allclose(quantise([0.149, 0.151, -0.149], 0.1), [0.1, 0.2, -0.1])
    x = np.array([0.123])
    assert quantise(x, None) is not x and quantise(x, None)[0] == 0.123


def test_paper_experiment_defaults_are_consistent():
    exp = paper_experiment()
    u = exp.torque()
    assert u.size == round(exp.duration * exp.fs)
    pulses = np.flatnonzero(np.diff(np.concatenate([[0.0], u])) != 0)
    assert pulses[0] == round(exp.start * exp.fs)
    assert exp.sensors() == Sensors(accel_noise=1.0, tach_noise=0.01)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: bang_bang(np.nan, 0.1, 0, 1, 100), "`amplitude` must be a finite"),
        (lambda: bang_bang(1, 0.0, 0, 1, 100), "`width` must be a finite number > 0"),
        (lambda: bang_bang(1, 0.001, 0, 1, 100), "`width` must be at least one sample"),
        (lambda: bang_bang(1, 0.1, -1, 1, 100), "`start` must be >= 0"),
        (lambda: bang_bang(1, 0.4, 0.3, 1, 100), "`duration` must hold both pulses"),
        (lambda: bang_bang(1, 0.1, 0, 1, 0.0), "`fs` must be a finite number > 0"),
        (lambda: bang_bang(1, 0.1, 0, -1, 100), "`duration` must be a finite"),
        (
            lambda: prbs(1, 1, 100, n_bits=1),
            r"`n_bits` must be an integer in \[2, 32\]",
        ),
        (lambda: prbs(1, 1, 100, hold=0), "`hold` must be an integer >= 1"),
        (lambda: prbs(np.inf, 1, 100), "`amplitude` must be a finite"),
        (lambda: prbs(1, 1, -100), "`fs` must be"),
        (lambda: chirp(1, 0, 80, 1, 100), r"`f1` must be in \[0, fs/2 = 50\] Hz"),
        (lambda: chirp(1, -1, 10, 1, 100), "`f0` must be in"),
        (lambda: chirp(1, 1, 10, 1, 100, method="cubic"), "`method` must be one of"),
        (
            lambda: chirp(1, 1, 10, 1, 100, method=np.array(["linear", "linear"])),
            r"^`method` must be one of",
        ),
        (lambda: chirp(1, 0, 10, 1, 100, "logarithmic"), "`f0` and `f1` must be > 0"),
        (lambda: paper_experiment().__class__(n_pulses=0), "`n_pulses` must be"),
        (lambda: paper_experiment().__class__(period=0.01), "`period` must be"),
        (lambda: bang_bang("a", 0.1, 0, 1, 100), r"^`amplitude` must be a finite"),
        (lambda: bang_bang("1", 0.1, 0, 1, 100), r"^`amplitude` must be a finite"),
        (lambda: chirp(1, "a", 10, 1, 100), r"^`f0` must be a finite number"),
        (lambda: prbs(1, 1, 10, n_bits=5.0), r"^`n_bits` must be an integer"),
        # These used to fail inside arithmetic (TypeError, round(nan)).
        (lambda: Experiment(period=None), r"^`period` must be a finite number > 0"),
        (lambda: Experiment(width="a"), r"^`width` must be a finite number > 0"),
        (lambda: Experiment(fs=np.nan), r"^`fs` must be a finite number > 0"),
        (
            lambda: Experiment().run(rig="x"),
            r"^`rig` must be a FlexibleManipulator or None",
        ),
    ],
)
def test_bad_signal_arguments_raise(call, match):
    with pytest.raises((TypeError, ValueError), match=match):
        call()
