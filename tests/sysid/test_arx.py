"""ARX structure against hand-built regressions, scipy.signal.lfilter and numpy."""

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import ARX, IOData, arx_least_squares

STRUCTURES = [(2, 2, 1), (8, 8, 0), (3, 1, 2), (1, 4, 0), (0, 3, 1)]


def _hand_regressors(u, y, na, nb, nk):
    """Row t: [-y(t-1)..-y(t-na), u(t-nk)..u(t-nk-nb+1)], zero before t = 0."""
    n = len(u)
    phi = np.zeros((n, na + nb))
    for t in range(n):
        for i in range(1, na + 1):
            phi[t, i - 1] = -y[t - i] if t - i >= 0 else 0.0
        for j in range(nb):
            phi[t, na + j] = u[t - nk - j] if t - nk - j >= 0 else 0.0
    return phi


def _data(n=120, seed=0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = lfilter([0.0, 0.8, -0.3], [1.0, -1.2, 0.5], u) + 0.05 * rng.standard_normal(n)
    return IOData(u, y, ts=0.01)


@pytest.mark.parametrize("orders", STRUCTURES)
def test_regressors_and_predict_match_hand_built(orders):
    d = _data()
    arx = ARX(*orders)
    phi = _hand_regressors(d.u, d.y, *orders)
    np.testing.assert_array_equal(arx.regressors(d), phi)
    theta = np.random.default_rng(1).standard_normal(arx.n_params)
    np.testing.assert_allclose(arx.predict(theta, d), phi @ theta, rtol=1e-13)
    thetas = np.random.default_rng(2).standard_normal((4, arx.n_params))
    np.testing.assert_allclose(arx.predict(thetas, d), thetas @ phi.T, rtol=1e-13)


@pytest.mark.parametrize("orders", STRUCTURES)
def test_simulate_matches_lfilter(orders):
    na, nb, nk = orders
    arx = ARX(*orders)
    rng = np.random.default_rng(3)
    u = rng.standard_normal(300)
    thetas = np.c_[
        0.3 * rng.uniform(-1, 1, (5, na)) / max(na, 1), rng.standard_normal((5, nb))
    ]
    batched = arx.simulate(thetas, u)
    for row, th in zip(batched, thetas, strict=True):
        num = np.r_[np.zeros(nk), th[na:]]
        den = np.r_[1.0, th[:na]]
        expected = lfilter(num, den, u)
        np.testing.assert_allclose(
            arx.simulate(th, u), expected, rtol=1e-12, atol=1e-12
        )
        np.testing.assert_allclose(row, expected, rtol=1e-12, atol=1e-12)


def test_polynomials_poles_zeros_against_numpy():
    arx = ARX(2, 2, 1)
    theta = np.array([-1.5, 0.7, 1.0, 0.5])
    num, den = arx.polynomials(theta)
    np.testing.assert_array_equal(num, [0.0, 1.0, 0.5])
    np.testing.assert_array_equal(den, [1.0, -1.5, 0.7])
    np.testing.assert_allclose(
        np.sort_complex(arx.poles(theta)), np.sort_complex(np.roots(den))
    )
    np.testing.assert_allclose(arx.zeros(theta), [-0.5])
    assert arx.is_stable(theta)
    # eq. (6): b0 multiplies z^8, so z = 0 is a zero of ARX(8, 8, 0).
    a8 = ARX(8, 8, 0)
    r = 0.9 * np.exp(1j * np.linspace(0.2, 2.8, 4))
    th8 = np.r_[np.real(np.poly(np.r_[r, np.conj(r)]))[1:], np.ones(8)]
    assert np.min(np.abs(a8.zeros(th8))) < 1e-12
    poles = a8.poles(np.vstack([th8, th8]))
    assert poles.shape == (2, 8)
    np.testing.assert_allclose(np.abs(poles), 0.9, rtol=1e-9)
    # More numerator lags than poles: extra poles at the origin.
    p = ARX(1, 3, 0).poles([0.5, 1.0, 1.0, 1.0])
    np.testing.assert_allclose(np.sort(np.abs(p)), [0.0, 0.5], atol=1e-15)


def test_is_stable_batched_matches_roots():
    arx = ARX(2, 1, 0)
    thetas = np.array(
        [[-1.5, 0.7, 1.0], [-2.0, 1.0, 1.0], [0.5, -1.2, 1.0], [0.0, 0.0, 1.0]]
    )
    expected = [np.abs(np.roots(np.r_[1.0, t[:2]])).max() < 1 - 1e-9 for t in thetas]
    np.testing.assert_array_equal(arx.is_stable(thetas), expected)


def test_tf_string_reproduces_eq_10():
    b = [0.00101, 0.00059, 0.00344, 0.000385, 0.000261, 0.000846, 0.00694, 0.00556]
    a = [2.492, 1.805, 0.5301, 1.094, 0.145, 0.0393, 0.268, 0.1533]
    text = ARX(8, 8, 1).tf_string(np.r_[a, b])
    assert text == (
        "(0.00101 z^7 + 0.00059 z^6 + 0.00344 z^5 + 0.000385 z^4 + 0.000261 z^3 "
        "+ 0.000846 z^2 + 0.00694 z + 0.00556) / (z^8 + 2.492 z^7 + 1.805 z^6 "
        "+ 0.5301 z^5 + 1.094 z^4 + 0.145 z^3 + 0.0393 z^2 + 0.268 z + 0.1533)"
    )


@pytest.mark.parametrize("orders", [(2, 2, 1), (8, 8, 0), (3, 2, 4)])
def test_least_squares_equals_lstsq_on_hand_built_matrix(orders):
    d = _data(n=400, seed=5)
    arx = ARX(*orders)
    t0 = max(arx.na, arx.nk + arx.nb - 1)
    phi = _hand_regressors(d.u, d.y, *orders)[t0:]
    expected = np.linalg.lstsq(phi, d.y[t0:], rcond=None)[0]
    np.testing.assert_allclose(arx_least_squares(d, arx), expected, rtol=1e-10)


def test_least_squares_recovers_noise_free_system():
    u = np.random.default_rng(6).standard_normal(500)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    theta = arx_least_squares(IOData(u, y, ts=1.0), ARX(2, 2, 1))
    np.testing.assert_allclose(theta, [-1.5, 0.7, 1.0, 0.5], rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(na=-1, nb=2, nk=0), "`na` must be an integer >= 0; got -1"),
        (dict(na=2, nb=0, nk=0), "`nb` must be an integer >= 1; got 0"),
        (dict(na=2, nb=2, nk=-3), "`nk` must be an integer >= 0; got -3"),
        (dict(na=2.5, nb=2, nk=0), "`na` must be an integer >= 0; got 2.5"),
    ],
)
def test_bad_orders(kwargs, match):
    # 2.5 orders is a wrong type (TypeError), -1 a wrong value (ValueError).
    with pytest.raises((TypeError, ValueError), match=match):
        ARX(**kwargs)


def test_bad_theta_short_record_constant_input():
    arx = ARX(8, 8, 0)
    with pytest.raises(
        ValueError, match=r"`theta` must have shape \(16,\) or \(m, 16\)"
    ):
        arx.simulate(np.zeros(5), np.ones(10))
    with pytest.raises(ValueError, match="`u` must be finite; got nan at sample 2"):
        arx.simulate(np.zeros(16), [0.0, 1.0, np.nan])
    with pytest.raises(TypeError, match="`data` must be an IOData; got tuple"):
        arx.predict(np.zeros(16), (np.ones(30), np.ones(30)))
    short = IOData(np.arange(20.0), np.arange(20.0), ts=1.0)
    with pytest.raises(
        ValueError, match=r"`data` is too short for ARX\(8, 8, 0\): needs at least 25"
    ):
        arx_least_squares(short, arx)
    const = IOData(
        np.full(100, 2.0), np.random.default_rng(0).standard_normal(100), ts=1.0
    )
    with pytest.raises(
        ValueError, match=r"`data` has a constant input .*does not excite the system"
    ):
        arx_least_squares(const, ARX(2, 2, 1))
