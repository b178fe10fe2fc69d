"""PaperCost against eq. (2)-(3) written out by hand."""

import numpy as np
import pytest
from scipy.signal import lfilter, lfiltic

from spiralid.sysid import ARX, IOData, PaperCost, step_up

PENALTY = 1e6


def _by_hand(
    theta, data, arx, predictor, gain="auto", penalty=PENALTY, initial="measured"
):
    """Eq. (2)-(3) as the docs define it, with plain loops and numpy.roots."""
    na, nb, nk = arx.na, arx.nb, arx.nk
    u, y = data.u, data.y
    t0 = max(na, nk + nb - 1)
    a, b = theta[:na], theta[na:]
    stable = na == 0 or np.all(np.abs(np.roots(np.r_[1.0, a])) < 1.0)
    yhat = y.copy()  # the first t0 samples are the (measured) initial state
    for t in range(t0, len(y)):
        past = yhat if (predictor == "simulation" and stable) else y
        yhat[t] = sum(b[j] * u[t - nk - j] for j in range(nb)) - sum(
            a[i - 1] * past[t - i] for i in range(1, na + 1)
        )
    e = y[t0:] - yhat[t0:]
    if predictor == "simulation" and initial == "rest":
        # All N samples from zero initial conditions; an unstable candidate
        # keeps the one-step error term (over t >= t0) but K is N.
        if stable:
            sim = np.zeros(len(y))
            for t in range(len(y)):
                sim[t] = sum(b[j] * u[t - nk - j] for j in range(nb) if t - nk - j >= 0)
                sim[t] -= sum(a[i - 1] * sim[t - i] for i in range(1, na + 1) if t >= i)
            e = y - sim
        K, y_k = len(y), y
    else:
        K, y_k = len(e), y[t0:]
    w = 100 * np.sqrt(K) / np.sqrt(np.mean(y_k**2)) if gain == "auto" else gain
    f = w * np.sqrt(np.sum(e**2)) / K
    return f if stable else f + penalty


def _population(arx, m, rng):
    """Stable denominators (step-up) with a third scaled out of the unit circle."""
    a = step_up(rng.uniform(-0.95, 0.95, size=(m, arx.na)))
    a[: m // 3] *= 1.6 ** np.arange(1, arx.na + 1)
    b = 0.5 * rng.standard_normal((m, arx.nb))
    return np.c_[a, b]


def _data(n=150, seed=0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = lfilter([0.0, 0.8, -0.3], [1.0, -1.2, 0.5], u) + 0.1 * rng.standard_normal(n)
    return IOData(u, y + 0.2, ts=0.01)


@pytest.mark.parametrize("initial", ["rest", "measured"])
@pytest.mark.parametrize("predictor", ["simulation", "one-step"])
@pytest.mark.parametrize("orders", [(2, 2, 1), (4, 3, 0), (1, 2, 2), (0, 3, 1)])
def test_matches_eq_2_3_single_and_batched(predictor, orders, initial):
    arx = ARX(*orders)
    d = _data()
    cost = PaperCost(arx, d, predictor=predictor, initial=initial)
    thetas = _population(arx, 12, np.random.default_rng(1))
    expected = np.array(
        [_by_hand(th, d, arx, predictor, initial=initial) for th in thetas]
    )
    np.testing.assert_allclose(cost(thetas), expected, rtol=1e-9)
    for th, f in zip(thetas, expected, strict=True):
        out = cost(th)
        assert isinstance(out, float)
        np.testing.assert_allclose(out, f, rtol=1e-9)


@pytest.mark.parametrize("initial", ["rest", "measured"])
def test_penalty_exactly_when_a_pole_is_outside(initial):
    arx = ARX(4, 3, 0)
    cost = PaperCost(arx, _data(), predictor="simulation", initial=initial)
    thetas = _population(arx, 300, np.random.default_rng(2))
    outside = np.array([np.abs(np.roots(np.r_[1.0, t[:4]])).max() >= 1 for t in thetas])
    assert 50 < outside.sum() < 250
    f = cost(thetas)
    assert np.all(np.isfinite(f))
    np.testing.assert_array_equal(f >= PENALTY, outside)
    # Unstable candidates carry the penalty plus the (finite) one-step term.
    one_step_term = cost.w * np.sqrt(cost.sse_one_step(thetas[outside])) / cost.K
    np.testing.assert_allclose(f[outside], PENALTY + one_step_term, rtol=1e-12)


@pytest.mark.parametrize("initial", ["rest", "measured"])
def test_poles_on_the_unit_circle_are_penalised(initial):
    arx = ARX(2, 1, 0)
    cost = PaperCost(arx, _data(), predictor="simulation", initial=initial)
    w = 0.4
    f = cost([[-2 * np.cos(w), 1.0, 0.3], [-1.0, 0.0, 0.3], [-0.5, 0.0, 0.3]])
    np.testing.assert_array_equal(f >= PENALTY, [True, True, False])


def test_gram_form_equals_explicit_residuals():
    arx = ARX(8, 8, 0)
    d = _data(n=600, seed=3)
    cost = PaperCost(arx, d, predictor="one-step")
    thetas = _population(arx, 50, np.random.default_rng(4))
    t0 = arx.max_lag
    resid = d.y[t0:] - arx.predict(thetas, d)[:, t0:]
    np.testing.assert_allclose(
        cost.sse_one_step(thetas), np.sum(resid**2, axis=1), rtol=1e-9
    )


@pytest.mark.parametrize("initial", ["rest", "measured"])
def test_gain_auto_is_percent_rms_and_numeric_gain_scales(initial):
    arx = ARX(2, 2, 1)
    d = _data()
    zero = PaperCost(arx, d, initial=initial)(np.zeros(4))
    assert zero == pytest.approx(100.0, rel=1e-12)
    theta = np.array([-1.2, 0.5, 0.8, -0.3])
    f5 = PaperCost(arx, d, gain=5.0, initial=initial)(theta)
    assert f5 == pytest.approx(
        _by_hand(theta, d, arx, "simulation", gain=5.0, initial=initial), rel=1e-12
    )


@pytest.mark.parametrize("initial", ["rest", "measured"])
def test_simulate_helper_is_the_compared_output(initial):
    arx = ARX(2, 2, 1)
    d = _data()
    cost = PaperCost(arx, d, initial=initial)
    theta = np.array([-1.2, 0.5, 0.8, -0.3])
    e = d.y[cost.t0 :] - cost.simulate(theta)
    assert cost(theta) == pytest.approx(cost.w * np.linalg.norm(e) / cost.K, rel=1e-12)


def _outside(thetas, na):
    return np.array([np.abs(np.roots(np.r_[1.0, t[:na]])).max() >= 1 for t in thetas])


@pytest.mark.parametrize("orders", [(2, 2, 1), (8, 8, 0), (3, 2, 3)])
def test_rest_is_eq_2_lfilter_from_rest_over_all_samples(orders):
    # DESIGN item 3: e = y - lfilter(b, a, u) from zero initial conditions
    # over all N samples, K = N, w = 100 sqrt(N) / rms(y); the penalty
    # exactly when numpy.roots puts a pole on or outside the unit circle.
    arx = ARX(*orders)
    d = _data(n=400, seed=5)
    cost = PaperCost(arx, d)  # the default is from rest
    assert cost.initial == "rest" and cost.t0 == 0 and cost.K == d.n
    thetas = _population(arx, 30, np.random.default_rng(6))
    outside = _outside(thetas, arx.na)
    assert 0 < outside.sum() < len(thetas)
    n = d.n
    w = 100.0 * np.sqrt(n) / np.sqrt(np.mean(d.y**2))
    f = cost(thetas)
    for th, fi, out in zip(thetas, f, outside, strict=True):
        if out:
            assert fi >= PENALTY and np.isfinite(fi)
            continue
        num = np.r_[np.zeros(arx.nk), th[arx.na :]]
        e = d.y - lfilter(num, np.r_[1.0, th[: arx.na]], d.u)
        expected = w * np.sqrt(np.sum(e**2)) / n
        assert fi < PENALTY
        np.testing.assert_allclose(fi, expected, rtol=1e-9)
        np.testing.assert_allclose(cost(th), expected, rtol=1e-9)


def test_measured_is_lfilter_with_lfiltic_on_the_measured_past():
    arx = ARX(8, 8, 0)
    d = _data(n=400, seed=7)
    cost = PaperCost(arx, d, initial="measured")
    t0 = arx.max_lag
    assert cost.t0 == t0 and cost.K == d.n - t0
    thetas = _population(arx, 30, np.random.default_rng(8))
    outside = _outside(thetas, arx.na)
    w = 100.0 * np.sqrt(d.n - t0) / np.sqrt(np.mean(d.y[t0:] ** 2))
    f = cost(thetas)
    np.testing.assert_array_equal(f >= PENALTY, outside)
    for th, fi in zip(thetas[~outside], f[~outside], strict=True):
        den = np.r_[1.0, th[:8]]
        x = lfilter(th[8:], [1.0], d.u)[t0:]  # the input part, all inputs measured
        zi = lfiltic([1.0], den, d.y[:t0][::-1])
        e = d.y[t0:] - lfilter([1.0], den, x, zi=zi)[0]
        np.testing.assert_allclose(
            fi, w * np.sqrt(np.sum(e**2)) / (d.n - t0), rtol=1e-9
        )


def test_one_step_ignores_initial():
    arx = ARX(4, 3, 0)
    d = _data()
    thetas = _population(arx, 20, np.random.default_rng(9))
    rest = PaperCost(arx, d, predictor="one-step", initial="rest")
    measured = PaperCost(arx, d, predictor="one-step", initial="measured")
    np.testing.assert_array_equal(rest(thetas), measured(thetas))
    assert rest.K == measured.K == d.n - arx.max_lag


def test_bad_arguments():
    arx = ARX(2, 2, 1)
    d = _data()
    with pytest.raises(ValueError, match=r"`predictor` must be one of .*; got 'free'"):
        PaperCost(arx, d, predictor="free")
    with pytest.raises(
        ValueError, match="`gain` must be 'auto' or a finite number > 0; got -1"
    ):
        PaperCost(arx, d, gain=-1)
    with pytest.raises(
        ValueError, match="`penalty` must be a finite number >= 0; got inf"
    ):
        PaperCost(arx, d, penalty=np.inf)
    with pytest.raises(
        ValueError, match=r"`thetas` must have shape \(4,\) or \(m, 4\)"
    ):
        PaperCost(arx, d)(np.zeros((3, 5)))
    with pytest.raises(ValueError, match="`data` has an all-zero output"):
        PaperCost(arx, IOData(d.u, np.zeros(d.n), ts=1.0))
    with pytest.raises(
        ValueError, match=r"`initial` must be one of \('rest', 'measured'\); got 'zero'"
    ):
        PaperCost(arx, d, initial="zero")
