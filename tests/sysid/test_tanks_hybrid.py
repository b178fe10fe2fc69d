"""The Cascaded Tanks grey box plus a learned correction
(spiralid.datasets.tanks_model.tanks_hybrid): no correction of an error the
grey box does not make, the hybrid's run against the grey box's plus a
correction filtered by SciPy, one rng one hybrid, bad input."""

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.datasets import cascaded_tanks
from spiralid.datasets.tanks_model import TanksHybrid, tanks_greybox, tanks_hybrid
from spiralid.sysid import ARX, IOData, NeuralStateSpace


@pytest.fixture(scope="module")
def fitted():
    """A quickly fitted grey box on the estimation record's first 300
    samples (a short polish: the tests need a fitted model, not a good
    one) and that record."""
    est = cascaded_tanks()[:300]
    return sid.identify(est, tanks_greybox(), method="oe", polish_nfev=3), est


def test_an_error_the_grey_box_does_not_make_is_not_corrected(fitted):
    box, est = fitted
    y_gb = np.ravel(box.simulate(est))
    # The record is the grey box's own run: its residual is zero.
    exact = IOData(est.u, y_gb, ts=est.ts)
    hybrid = tanks_hybrid(box, exact, ARX(2, 2, 0), with_input=True)
    assert hybrid.correction is None
    np.testing.assert_array_equal(hybrid.correct(est.u, y_gb), 0.0)
    np.testing.assert_array_equal(hybrid.simulate(est), np.minimum(y_gb, 10.0))
    # A constant error is corrected by its mean, whatever the input.
    shifted = IOData(est.u, y_gb - 0.25, ts=est.ts)
    hybrid = tanks_hybrid(box, shifted, NeuralStateSpace(1, hidden=(4,)))
    np.testing.assert_allclose(hybrid.simulate(est), y_gb - 0.25, atol=1e-12)


def test_the_hybrid_is_the_grey_box_plus_its_correction_by_hand(fitted):
    box, est = fitted
    hybrid = tanks_hybrid(box, est, ARX(2, 2, 0), rng=0)
    assert isinstance(hybrid, TanksHybrid) and not hybrid.with_input
    y_gb = np.ravel(box.simulate(est))
    # The correction's free run from rest, by SciPy's filter of its
    # polynomials over the centred grey-box run, plus the residual's mean.
    num, den = hybrid.correction.polynomials
    u_offset, y_offset = hybrid.offsets
    r_hat = lfilter(num, den, y_gb - u_offset) + y_offset
    expected = np.minimum(y_gb + r_hat, 10.0)
    np.testing.assert_allclose(hybrid.simulate(est), expected, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(hybrid.simulate(np.ravel(est.u)), expected, atol=1e-10)
    # The residual's mean and the grey box's run's mean are the offsets.
    assert y_offset == pytest.approx(np.mean(np.ravel(est.y) - y_gb), abs=1e-12)
    assert float(u_offset) == pytest.approx(np.mean(y_gb), abs=1e-12)
    # The correction learned something: it lowers the record's error.
    assert np.sqrt(np.mean((expected - np.ravel(est.y)) ** 2)) < np.sqrt(
        np.mean((np.minimum(y_gb, 10.0) - np.ravel(est.y)) ** 2)
    )


def test_one_rng_gives_one_hybrid(fitted):
    box, est = fitted
    structure = NeuralStateSpace(1, hidden=(4,))
    runs = [tanks_hybrid(box, est, structure, rng=3).simulate(est) for _ in "ab"]
    np.testing.assert_array_equal(runs[0], runs[1])
    assert np.all(np.isfinite(runs[0])) and np.max(runs[0]) <= 10.0
    two = tanks_hybrid(box, est, ARX(1, 1, 0), with_input=True, rng=3)
    assert np.asarray(two.offsets[0]).shape == (2,)


def test_bad_input_is_named(fitted):
    box, est = fitted
    with pytest.raises(TypeError, match="`data`"):
        tanks_hybrid(box, np.ravel(est.y), ARX(1, 1, 0))
    with pytest.raises(TypeError, match="`with_input`"):
        tanks_hybrid(box, est, ARX(1, 1, 0), with_input="yes")
    with pytest.raises(TypeError, match="`greybox`"):
        tanks_hybrid("box", est, ARX(1, 1, 0))
    two = IOData(np.column_stack([est.u, est.u]), est.y, ts=est.ts)
    with pytest.raises(ValueError, match=r"2 inputs .*tanks_hybrid takes one"):
        tanks_hybrid(box, two, ARX(1, 1, 0))
