"""NARX models: Jacobians, linear limit, training, persistence."""

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import (
    ARX,
    NARX,
    IOData,
    NARXModel,
    PolynomialNARX,
    fit_percent,
    identify,
    validate,
)
from spiralid.sysid.models.narx import Scaling


def _fd(f, p, eps=1e-6):
    return np.array(
        [(f(p + eps * e) - f(p - eps * e)) / (2 * eps) for e in np.eye(p.size)]
    ).T


@pytest.mark.parametrize("activation", ["tanh", "logistic", "linear"])
@pytest.mark.parametrize("linear", [True, False])
def test_exact_jacobians_match_finite_differences(activation, linear):
    rng = np.random.default_rng(3)
    st = NARX(3, 2, 1, hidden=(4,), activation=activation, linear=linear)
    p = 0.4 * rng.standard_normal(st.n_params)
    sc = Scaling(0.1, 1.3, -0.2, 0.7)
    u, y = rng.standard_normal(120), rng.standard_normal(120)
    phi, _ = st.regressors(u, y, sc)
    np.testing.assert_allclose(
        st.jacobian(p, phi), _fd(lambda q: st.evaluate(q, phi), p), atol=1e-7
    )
    ulag, hist = st.input_lags(u, sc), st.rest_history(sc)
    out, sens = st.free_run_jacobian(p, ulag, hist)
    np.testing.assert_array_equal(out, st.free_run_scaled(p, ulag, hist))
    np.testing.assert_allclose(
        sens, _fd(lambda q: st.free_run_scaled(q, ulag, hist), p), atol=1e-6
    )


def test_linear_network_free_run_is_the_arx_free_run():
    """A linear activation makes the whole map affine: the free run is
    lfilter of the equivalent ARX model plus the constant's response."""
    rng = np.random.default_rng(0)
    st = NARX(2, 3, 1, hidden=(4,), activation="linear")
    p = 0.3 * rng.standard_normal(st.n_params)
    sc = Scaling(0.3, 2.0, -0.5, 1.7)
    u = rng.standard_normal(300)
    y = NARXModel(p, st, sc, 0.01, method="ls").simulate(u)
    d = st.split(p)
    alpha = d["l"] + d["W"].T @ d["v"]
    gamma = d["v"] @ d["b"] + d["c"][0]
    ay, bu = alpha[:2], alpha[2:] * sc.y_scale / sc.u_scale
    a = np.r_[1.0, -ay]
    const = sc.y_shift * (1 - ay.sum()) - bu.sum() * sc.u_shift + gamma * sc.y_scale
    ref = lfilter(np.r_[0.0, bu], a, u) + lfilter([const], a, np.ones(u.size))
    np.testing.assert_allclose(y, ref, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("integrator", [False, True])
def test_bypass_from_arx_is_the_arx_model(integrator):
    rng = np.random.default_rng(1)
    u = rng.standard_normal(400)
    theta = np.array([-1.2, 0.5, 0.8, 0.3])
    arx = ARX(2, 2, 1)
    st = NARX(2, 2, 1, hidden=(3,), integrator=integrator)
    sc = Scaling(0.2, 1.5, 0.4, 2.0) if not integrator else Scaling(0.2, 1.5, 0, 2)
    model = NARXModel(st.from_arx(theta[:2], theta[2:], sc), st, sc, 0.01, method="ls")
    expected = arx.simulate(theta, u)
    if integrator:
        expected = np.cumsum(expected)
    np.testing.assert_allclose(model.simulate(u), expected, atol=1e-10)


def _hammerstein(n=1500, seed=0, noise=0.0):
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1.5, 1.5, n)
    y = lfilter([0.0, 0.6, 0.3], [1.0, -1.2, 0.5], np.tanh(2.0 * u))
    y = y + noise * rng.standard_normal(n)
    return IOData(u, y, ts=0.01)


def test_gradient_training_beats_arx_on_a_hammerstein_system():
    est, val = _hammerstein(noise=0.01).split(2 / 3)
    arx = identify(est, ARX(2, 2, 1), method="oe")
    fit_arx = validate(arx, val, warmup=est).fit_percent
    model = identify(est, NARX(2, 2, 1, hidden=(6,)), method="oe", rng=0)
    v = validate(model, val, warmup=est)
    assert fit_arx < 90.0
    assert v.fit_percent > fit_arx + 5.0
    # Same seed, same weights.
    again = identify(est, NARX(2, 2, 1, hidden=(6,)), method="oe", rng=0)
    np.testing.assert_array_equal(model.params, again.params)


def test_spiral_search_never_ends_above_its_gradient_start():
    est, _val = _hammerstein(n=900, noise=0.01).split(2 / 3)
    st = NARX(2, 2, 1, hidden=(4,))
    grad = identify(est, st, method="oe", rng=1)
    spiral = identify(est, st, method="spiral", rng=1, max_nfev=1500)
    assert spiral.result["holdout_cost"] <= grad.result["holdout_cost"] + 1e-9
    paper = identify(est, st, method="ebsda", rng=1, max_nfev=500)
    assert paper.result["nfev"] <= 500 and np.isfinite(paper.cost)


def test_frols_recovers_a_polynomial_narx():
    rng = np.random.default_rng(2)
    u = rng.uniform(-1, 1, 600)
    y = np.zeros(600)
    for t in range(1, 600):
        y[t] = 0.5 * y[t - 1] + u[t - 1] + 0.3 * u[t - 1] ** 2
    data = IOData(u, y, ts=1.0)
    model = identify(data, PolynomialNARX(2, 2, 1, degree=2, n_terms=None), "ls")
    names = set(model.structure.term_names())
    assert {"y(t-1)", "u(t-1)", "u(t-1)*u(t-1)"} <= names
    assert fit_percent(y, model.simulate(u)) > 99.99


def test_saved_model_predicts_identically(tmp_path):
    est, val = _hammerstein(n=600).split(2 / 3)
    for structure, seed in (
        (NARX(2, 2, 1, hidden=(3,)), dict(rng=0)),
        # Forward regression is deterministic: it takes no seed.
        (PolynomialNARX(2, 2, 1, degree=2, n_terms=6), {}),
    ):
        model = identify(est, structure, method="ls", **seed)
        back = NARXModel.from_dict(json.loads(json.dumps(model.to_dict())))
        np.testing.assert_array_equal(back.simulate(val.u), model.simulate(val.u))
        np.testing.assert_array_equal(back.predict(val), model.predict(val))


def test_bad_narx_arguments_are_one_line_errors():
    with pytest.raises(ValueError, match="`hidden` must be"):
        NARX(2, 2, 1, hidden=(3, 3))
    with pytest.raises(ValueError, match="`activation` must be"):
        NARX(2, 2, 1, activation="relu6")
    with pytest.raises(ValueError, match="`ny` must be"):
        NARX(0, 2)
    data = _hammerstein(n=300)
    with pytest.raises(ValueError, match="does not train NARX"):
        identify(data, NARX(2, 2, 1), method="de")
    with pytest.raises(ValueError, match="`refine` does not apply to method 'oe' for"):
        identify(data, NARX(2, 2, 1), method="oe", refine=True)
    with pytest.raises(ValueError, match="`holdout` must be"):
        identify(data, NARX(2, 2, 1), method="ls", holdout=0.7)
    with pytest.raises(ValueError, match="`decay` must be"):
        identify(data, NARX(2, 2, 1), method="ls", decay=-1.0)
    with pytest.raises(ValueError, match="too short"):
        identify(IOData(data.u[:20], data.y[:20], ts=0.01), NARX(2, 2, 1), "ls")
    with pytest.raises(ValueError, match="a NARX model must be"):
        NARXModel.from_dict({"model": "arx"})


@pytest.mark.parametrize("integrator", [False, True])
def test_free_run_from_measured_samples_continues_the_record(integrator):
    """A record the model itself produced, cut after 50 samples: the run
    started from its measured samples reproduces the rest exactly."""
    rng = np.random.default_rng(4)
    st = NARX(3, 2, 1, hidden=(4,), integrator=integrator)
    model = NARXModel(
        0.3 * rng.standard_normal(st.n_params),
        st,
        Scaling(0.1, 1.2, 0.2, 0.9),
        0.01,
        method="ls",
    )
    u = rng.standard_normal(300)
    y = model.simulate(u)
    tail = model.simulate(u[50:], y0=y[50:])
    np.testing.assert_array_equal(tail[: st.max_lag], y[50 : 50 + st.max_lag])
    np.testing.assert_allclose(tail, y[50:], rtol=1e-10, atol=1e-10)


@pytest.mark.parametrize("method", ["ls", "oe", "spiral"])
def test_training_never_ends_above_its_linear_start(method):
    """Guaranteed by the final check: the returned model's cost on the
    whole estimation record is at most its linear start's."""
    est, _ = _hammerstein(n=600, noise=0.05).split(2 / 3)
    opts = {"max_nfev": 400} if method == "spiral" else {}
    model = identify(est, NARX(2, 2, 1, hidden=(3,)), method=method, rng=0, **opts)
    res = model.result
    assert model.linear_params is not None
    if method == "ls":
        return  # its guarantee is on the one-step error it minimises
    assert res["fun"] <= res["linear_cost"] + 1e-9


def test_linear_start_is_the_default_methods_arx_with_its_integrators():
    rng = np.random.default_rng(5)
    u = rng.standard_normal(500)
    y = np.cumsum(np.cumsum(lfilter([0.0, 0.02], [1.0, -0.5], u)))
    est = IOData(u, y, ts=0.01)
    model = identify(est, NARX(2, 2, 1, hidden=(2,), integrator=2), "oe", rng=3)
    arx = identify(est, ARX(3, 2, 1), integrator=2, rng=3)
    np.testing.assert_allclose(
        model.linear_start.simulate(u), arx.simulate(u), rtol=1e-8, atol=1e-8
    )
    assert "integrator=2" in model.linear_model


def test_a_network_that_adds_nothing_is_reported_as_such():
    rng = np.random.default_rng(6)
    u = rng.standard_normal(600)
    data = IOData(u, lfilter([0.0, 0.5], [1.0, -0.7], u), ts=0.01)
    est, val = data.split(2 / 3)
    model = identify(est, NARX(1, 1, 1, hidden=(2,)), method="oe", rng=0)
    text = validate(model, val, warmup=est).summary()
    assert "network added nothing" in text or "points of fit" in text
    est, val = _hammerstein(n=900).split(2 / 3)
    model = identify(est, NARX(2, 2, 1), method="oe", rng=0)
    v = validate(model, val, warmup=est)
    assert v.fit_percent > v.nonlinear.linear_fit_percent + 1.0
    assert "points of fit" in v.summary()


def test_frols_uses_every_sample_and_the_default_method():
    est = _hammerstein(n=600, noise=0.01)
    st = PolynomialNARX(2, 2, 1, degree=2, n_terms=6)
    model = identify(est, st)  # the default method
    cut = IOData(est.u, np.r_[est.y[:500], 2.0 * est.y[500:]], ts=est.ts)
    other = identify(cut, st, method="ls")
    assert not np.array_equal(model.params, other.params)


def test_method_names_are_case_insensitive_for_narx():
    est = _hammerstein(n=400)
    a = identify(est, NARX(2, 2, 1, hidden=(2,)), method="OE", rng=0)
    b = identify(est, NARX(2, 2, 1, hidden=(2,)), method="oe", rng=0)
    np.testing.assert_array_equal(a.params, b.params)
    identify(est, PolynomialNARX(2, 2, 1, n_terms=4), method="LS")


def test_a_test_without_degrees_of_freedom_is_not_applicable():
    from spiralid.sysid import billings_voon

    rng = np.random.default_rng(0)
    u = np.sign(rng.standard_normal(800))  # binary: u^2 constant
    bv = billings_voon(u, rng.standard_normal(800))
    assert set(bv.not_applicable) == {"u2e", "u2e2"}
    assert "u2e" not in bv.passed and "n/a" in bv.verdicts()
    assert (
        "not applicable" in bv.summary()
        and "pass" not in bv.summary().split("phi_u2'e")[1].split("\n")[0]
    )


def test_narx_figures_carry_labels():
    import matplotlib

    matplotlib.use("Agg")
    est, val = _hammerstein(n=500).split(2 / 3)
    model = identify(est, NARX(2, 2, 1, hidden=(2,)), method="oe", rng=0)
    figs = validate(model, val, warmup=est).plot()
    # The figures of every validation, with the higher-order tests in place
    # of a linear model's pole-zero map.
    assert set(figs) == {"time", "residuals", "spectrum", "billings_voon"}
    top, bottom = figs["time"].axes[0], figs["time"].axes[-1]
    assert top.get_ylabel() and top.get_title()
    assert bottom.get_xlabel().startswith("time")
    assert figs["billings_voon"].axes[-1].get_xlabel() == "lag (samples)"
