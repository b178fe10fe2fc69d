"""The frequency objective against hand-worked cases."""

import numpy as np
import pytest
from scipy.signal import freqz, lfilter

from spiralid.sysid import ARX, IOData
from spiralid.sysid.estimation.linear.frequency import FrequencyError, h1_estimate

A = [1.0, -1.5, 0.7]
B = [0.0, 1.0, 0.5]
THETA = np.array([-1.5, 0.7, 1.0, 0.5])


@pytest.fixture(scope="module")
def record():
    u = np.random.default_rng(0).standard_normal(8192)
    return IOData(u, lfilter(B, A, u), ts=0.01)


def test_h1_matches_the_true_response_on_noise_free_data(record):
    est = h1_estimate(record)
    _, g = freqz(B, A, worN=est.f, fs=100.0)
    db_error = 20 * np.log10(np.abs(est.h) / np.abs(g))
    assert np.max(np.abs(db_error)) < 0.5
    assert est.coherence.min() > 0.99
    assert est.band == (100.0 / est.nperseg, 40.0)
    assert est.f.min() >= est.band[0] and est.f.max() <= 40.0
    assert np.isclose(est.weight.sum(), 1.0)


def test_the_true_model_scores_near_zero_and_its_response_is_freqz(record):
    err = FrequencyError(ARX(2, 2, 1), h1_estimate(record))
    _, g = freqz(B, A, worN=err.estimate.f, fs=100.0)
    assert np.allclose(err.response(THETA), g)
    assert err(THETA) < 0.1


@pytest.mark.parametrize("c", [0.1, 0.5, 3.0])
def test_a_scaled_gain_scores_the_log_ratio(record, c):
    err = FrequencyError(ARX(2, 2, 1), h1_estimate(record))
    scaled = THETA * [1, 1, c, c]
    shift = err.residual(scaled) - err.residual(THETA)
    assert np.allclose(shift, 20 * np.log10(c))
    # Against the model's own exact response the score is |20 log10 c|.
    assert err(scaled) == pytest.approx(abs(20 * np.log10(c)), abs=0.1)


def test_weights_are_the_coherence_and_low_coherence_bins_drop_out():
    rng = np.random.default_rng(1)
    u = rng.standard_normal(8192)
    y = lfilter(B, A, u) + 5.0 * rng.standard_normal(8192)
    est = h1_estimate(IOData(u, y, ts=0.01), min_coherence=0.3)
    assert est.coherence.min() >= 0.3
    assert np.allclose(est.weight, est.coherence / est.coherence.sum())
    assert est.f.size < h1_estimate(IOData(u, y, ts=0.01), min_coherence=0.0).f.size


def test_a_population_scores_row_by_row(record):
    err = FrequencyError(ARX(2, 2, 1), h1_estimate(record))
    pop = np.array([THETA, THETA * [1, 1, 2, 2], [0.0, 0.0, 0.0, 0.0]])
    scores = err(pop)
    assert scores.shape == (3,)
    assert scores[1] == pytest.approx(err(pop[1]))
    assert np.all(np.isfinite(scores))  # the zero model's -inf dB is capped


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"fmax": 60.0}, "fmax"),
        ({"fmin": -1.0}, "fmin"),
        ({"fmin": 30.0, "fmax": 20.0}, "fmin"),
        ({"nperseg": 4}, "nperseg"),
        ({"nperseg": 2.5}, "nperseg"),
        ({"min_coherence": 1.0}, "min_coherence"),
        ({"min_coherence": 0.999999}, "coherence"),
    ],
)
def test_bad_arguments_are_named(kwargs, match):
    rng = np.random.default_rng(2)
    u = rng.standard_normal(2048)
    y = lfilter(B, A, u) + 5.0 * rng.standard_normal(2048)
    with pytest.raises(ValueError, match=match):
        h1_estimate(IOData(u, y, ts=0.01), **kwargs)


def test_bad_inputs_of_the_error_are_named(record):
    est = h1_estimate(record)
    with pytest.raises(TypeError, match="`arx`"):
        FrequencyError("ARX(2, 2, 1)", est)
    with pytest.raises(TypeError, match="`estimate`"):
        FrequencyError(ARX(2, 2, 1), None)
    with pytest.raises(ValueError, match="`thetas`"):
        FrequencyError(ARX(2, 2, 1), est)([1.0, 2.0])
    with pytest.raises(TypeError, match="`data`"):
        h1_estimate(np.zeros(10))
