"""The u^2' Billings-Voon tests of a binary input that is not symmetric
about zero: they repeat the input tests, so they do not apply."""

import numpy as np

from spiralid.sysid import billings_voon


def _binary(offset: float, seed: int = 0, n: int = 900) -> np.ndarray:
    return offset + np.sign(np.random.default_rng(seed).standard_normal(n))


def test_an_offset_binary_input_has_no_square_tests():
    u = _binary(0.3)  # levels -0.7 and 1.3
    # The premise, by hand: u^2 = (a + b) u - a b on the two levels.
    assert np.allclose(u**2, (1.3 - 0.7) * u + 0.7 * 1.3)
    e = np.random.default_rng(1).standard_normal(u.size)
    bv = billings_voon(u, e)
    assert set(bv.not_applicable) == {"u2e", "u2e2"}
    assert set(bv.passed) == {"ee", "ue", "e(eu)"}


def test_a_detrended_binary_input_is_the_same_case():
    """A PRBS shifted by another record's mean (``detrend(like=est)``)."""
    u = _binary(0.0, seed=2)
    u = u - np.mean(u[:300])
    e = np.random.default_rng(3).standard_normal(u.size)
    assert set(billings_voon(u, e).not_applicable) == {"u2e", "u2e2"}


def test_a_multilevel_offset_input_keeps_its_square_tests():
    """Three levels: u^2 is no affine function of u, and a residual made of
    the input's square fails the u2e test."""
    rng = np.random.default_rng(4)
    u = 0.5 + rng.choice([-1.0, 0.0, 1.0], size=2000)
    e = rng.standard_normal(u.size) + 2.0 * ((u - 0.5) ** 2 - 2 / 3)
    bv = billings_voon(u, e)
    assert bv.not_applicable == ()
    assert bv.passed["u2e"] is False
