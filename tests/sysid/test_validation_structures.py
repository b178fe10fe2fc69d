"""One validation type for every structure: an ARX model and a NARX model
validate to the same Validation, the NARX model's with its higher-order
tests, and a NARX model whose network outputs are zero scores exactly as
the ARX model it equals."""

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest
from scipy import signal

from spiralid.sysid import (
    ARX,
    NARX,
    IdentifiedModel,
    IOData,
    NARXModel,
    Validation,
    identify,
    validate,
)
from spiralid.sysid.models.narx import Scaling

TS = 0.01
A = np.array([-1.5, 0.7])  # poles 0.75 +- 0.37j, a mode at 7.8 Hz
B = np.array([1.0, 0.5])  # b_0, b_1 with one sample of delay


def _record(u, seed=0, noise=0.05):
    """An ARX(2, 2, 1) system with equation noise, by SciPy's lfilter."""
    rng = np.random.default_rng(seed)
    e = noise * rng.standard_normal(u.size)
    y = signal.lfilter(np.r_[0.0, B], np.r_[1.0, A], u)
    y = y + signal.lfilter([1.0], np.r_[1.0, A], e)
    return IOData(u, y, ts=TS, output_name="angle", output_unit="rad")


@pytest.fixture(scope="module")
def data():
    # A mean and a scale away from 0 and 1, so the NARX scaling matters.
    u = 0.4 + 1.3 * np.random.default_rng(1).standard_normal(900)
    return _record(u)


def _arx(theta, method="ls"):
    return IdentifiedModel(theta=np.asarray(theta), arx=ARX(2, 2, 1), ts=TS,
                           method=method)  # fmt: skip


def _narx_with_zero_outputs(theta, method="ls", hidden=3, seed=2):
    """NARX(2, 2, 1) whose bypass is the ARX model `theta` and whose hidden
    layer is random but whose output weights are zero: a nonlinear
    structure that computes a linear model. Its linear start is the same."""
    st = NARX(2, 2, 1, hidden=(hidden,))
    scaling = Scaling(u_shift=0.3, u_scale=1.4, y_shift=-0.2, y_scale=2.5)
    p = st.from_arx(theta[:2], theta[2:], scaling)
    p[: st.h * (st.n_regressors + 1)] = np.random.default_rng(seed).standard_normal(
        st.h * (st.n_regressors + 1)
    )  # W and b; v stays zero
    assert np.all(st.split(p)["v"] == 0.0)
    return NARXModel(p, st, scaling, TS, method=method, linear_params=p.copy())


# The fields every structure shares, scalars and arrays.
SHARED_SCALARS = (
    "fit_percent", "fit_percent_one_step", "rmse", "rmse_one_step", "cost",
    "fit_percent_measured",
)  # fmt: skip
SHARED_ARRAYS = ("y_sim", "y_pred", "t", "error_range", "error_range_one_step")


@pytest.mark.parametrize("method", ["ls", "oe"])
@pytest.mark.parametrize("warm", [False, True])
def test_a_narx_with_zero_network_outputs_scores_as_its_arx_model(data, method, warm):
    theta = np.r_[A, B] * np.array([1.0, 1.0, 1.1, 0.9])  # a slightly wrong model
    arx, narx = _arx(theta, method), _narx_with_zero_outputs(theta, method)
    est, val = data.split(2 / 3)
    kw = {"warmup": est} if warm else {}
    va = validate(arx, val, **kw)
    for model in (narx, narx.linear_start):
        vn = validate(model, val, **kw)
        assert type(vn) is type(va) is Validation
        for name in SHARED_SCALARS:
            assert getattr(vn, name) == pytest.approx(
                getattr(va, name), rel=1e-9, abs=1e-9
            ), name
        for name in SHARED_ARRAYS:
            np.testing.assert_allclose(
                getattr(vn, name), getattr(va, name), rtol=1e-9, atol=1e-9,
                err_msg=name,
            )  # fmt: skip
        assert (vn.residuals, vn.cost_predictor, vn.output_error) == (
            va.residuals, va.cost_predictor, va.output_error,
        )  # fmt: skip
        for test in ("whiteness", "independence"):
            a, n = getattr(va, test), getattr(vn, test)
            np.testing.assert_allclose(n.values, a.values, atol=1e-9)
            assert n.statistic == pytest.approx(a.statistic, rel=1e-9)
        np.testing.assert_allclose(
            vn.psd_model.p, va.psd_model.p, rtol=1e-9, atol=1e-12
        )
        np.testing.assert_allclose(
            vn.peaks_model.frequency, va.peaks_model.frequency, rtol=1e-9
        )
    # And the ARX validation itself against SciPy: its free run is lfilter's.
    u = np.r_[est.u, val.u] if warm else val.u
    y_ref = signal.lfilter(np.r_[0.0, theta[2:]], np.r_[1.0, theta[:2]], u)
    np.testing.assert_allclose(va.y_sim, y_ref[u.size - val.n :], rtol=1e-12)


def test_the_network_that_outputs_zero_added_nothing(data):
    theta = np.r_[A, B]
    narx = _narx_with_zero_outputs(theta)
    v = validate(narx, data)
    assert v.nonlinear.linear_fit_percent == pytest.approx(v.fit_percent, abs=1e-9)
    assert v.nonlinear.network_gain(v.fit_percent) == pytest.approx(0.0, abs=1e-9)
    assert "the network added nothing" in v.summary()


def test_higher_order_tests_only_for_the_nonlinear_model(data):
    theta = np.r_[A, B]
    va = validate(_arx(theta), data)
    vn = validate(_narx_with_zero_outputs(theta), data)
    assert va.nonlinear is None and va.is_linear
    assert vn.nonlinear is not None and not vn.is_linear
    assert set(vn.nonlinear.billings_voon.tests) == {"ee", "ue", "e(eu)", "u2e", "u2e2"}
    assert "Billings-Voon" not in va.summary() and "Billings-Voon" in vn.summary()
    assert "billings_voon" in vn.plot() and "billings_voon" not in va.plot()
    # The higher-order tests examine the residual the shared tests do: their
    # ee and ue are the shared whiteness and independence tests.
    bv = vn.nonlinear.billings_voon.tests
    np.testing.assert_array_equal(bv["ee"].values, vn.whiteness.values)
    np.testing.assert_array_equal(bv["ue"].values, vn.independence.values)


def test_linear_fields_are_empty_for_the_nonlinear_model_and_say_so(data):
    theta = np.r_[A, B]
    va = validate(_arx(theta), data)
    vn = validate(_narx_with_zero_outputs(theta), data)
    # The ARX model's mode: 1 - 1.5 z^-1 + 0.7 z^-2 at 100 Hz sampling.
    s = np.log(np.roots(np.r_[1.0, A])) / TS
    assert va.modes.frequency == pytest.approx(np.abs(s[0]) / (2 * np.pi), rel=1e-9)
    assert va.stable is True and va.realization.minimal
    assert vn.stable is None and vn.max_pole_radius is None
    assert vn.realization is None and vn.mode_table is None
    assert vn.poles.size == vn.zeros.size == vn.modes.frequency.size == 0
    assert vn.order_advice is None
    text = vn.summary()
    assert "not applicable: a nonlinear model has no poles" in text
    assert "judged by the free run" in text
    assert "controllable / observable" not in text
    assert set(vn.plot()) == {"time", "residuals", "spectrum", "billings_voon"}
    assert set(va.plot()) == {"time", "residuals", "spectrum", "pole_zero"}


def test_the_json_has_one_shape(data):
    theta = np.r_[A, B]
    da = json.loads(json.dumps(validate(_arx(theta), data).to_dict()))
    dn = json.loads(
        json.dumps(validate(_narx_with_zero_outputs(theta), data).to_dict())
    )
    assert set(da) == set(dn)
    assert da["nonlinear"] is None and da["is_linear"] is True
    assert dn["is_linear"] is False
    for key in ("poles", "zeros", "modes", "stable", "max_pole_radius", "realization"):
        assert da[key] is not None and dn[key] is None, key
    nl = dn["nonlinear"]
    assert set(nl["billings_voon"]["tests"]) == {"ee", "ue", "e(eu)", "u2e", "u2e2"}
    assert nl["network_gain_points"] == pytest.approx(0.0, abs=1e-9)
    assert nl["linear_fit_percent"] == pytest.approx(dn["fit_percent"], abs=1e-9)


def test_a_higher_order_test_without_degrees_of_freedom_is_not_applicable():
    """A binary input makes u^2 constant: the two u^2' tests have nothing
    to test and read "not applicable", never "pass", in every form."""
    u = np.sign(np.random.default_rng(4).standard_normal(900))
    rec = _record(u, seed=5)
    model = identify(rec, NARX(2, 2, 1, hidden=(2,)), method="ls", rng=0)
    v = validate(model, rec)
    bv = v.nonlinear.billings_voon
    assert set(bv.not_applicable) == {"u2e", "u2e2"}
    assert set(bv.passed) == {"ee", "ue", "e(eu)"}
    text = v.summary()
    for line in text.splitlines():
        if "phi_u2'e" in line:
            assert "not applicable" in line and "pass" not in line, line
    assert "u2e n/a" in text and "u2e2 n/a" in text
    assert "of 3 applicable" in text
    d = json.loads(json.dumps(v.to_dict()))["nonlinear"]["billings_voon"]
    assert set(d["passed"]) == {"ee", "ue", "e(eu)"}
    for name in ("u2e", "u2e2"):
        assert d["tests"][name]["applicable"] is False
        assert set(d["tests"][name]["passed"].values()) == {None}
    assert d["tests"]["ee"]["applicable"] is True
    for name in ("u2e", "u2e2"):
        t = bv.tests[name]
        assert not t.applicable and set(t.passed.values()) == {None}
    # The figure: "n/a" in grey for the two, a verdict for the others.
    figures = v.plot()
    plt.close(figures["billings_voon"])  # drawn with pyplot, which keeps it
    axes = figures["billings_voon"].axes
    titles = {name: ax.title for name, ax in zip(bv.tests, axes, strict=True)}
    for name in ("u2e", "u2e2"):
        text = titles[name].get_text()
        assert _verdict_words(text) == {"n/a"} and _grey(titles[name]), text
    for name in ("ee", "ue", "e(eu)"):
        text = titles[name].get_text()
        want = "pass" if bv.passed[name] else "FAIL"
        assert text.endswith(f": {want}") and not _grey(titles[name]), text
    # Its residual figure: the input is not constant, so both tests apply
    # and read pass or fail as before.
    residual_axes = figures["residuals"].axes
    for ax, t in zip(residual_axes, (v.whiteness, v.independence), strict=True):
        assert t.applicable and _verdict_words(ax.get_title()) <= {"pass", "fail"}


def _grey(title) -> bool:
    """Whether a title is drawn in matplotlib's grey (tab:gray)."""
    from matplotlib.colors import same_color

    return same_color(title.get_color(), "tab:gray")


def _verdict_words(text: str) -> set[str]:
    return {w for w in ("pass", "fail", "n/a") if w in text.lower()}


def test_a_shared_test_without_degrees_of_freedom_is_not_applicable():
    """A constant input leaves the input-residual test nothing to test."""
    rec = _record(np.ones(600), seed=6)
    v = validate(_arx(np.r_[A, B]), rec)
    assert v.independence.dof == 0 and not v.independence.applicable
    assert set(v.independence.passed.values()) == {None}
    row = next(r for r in v.summary().splitlines() if r.startswith("independence"))
    assert "not applicable" in row and "pass" not in row
    d = v.to_dict()["independence"]
    assert d["applicable"] is False and set(d["passed"].values()) == {None}
    # The residual figure: whiteness keeps its verdict, independence reads
    # "n/a" in grey and never "pass".
    axes = v.plot()["residuals"].axes
    white, indep = axes[0].title, axes[1].title
    assert _verdict_words(indep.get_text()) == {"n/a"} and _grey(indep)
    assert "p =" not in indep.get_text()
    assert "n/a" not in white.get_text() and not _grey(white)
    words = {"pass" if v.whiteness.passed[lv] else "fail" for lv in v.whiteness.levels}
    assert _verdict_words(white.get_text()) == words
