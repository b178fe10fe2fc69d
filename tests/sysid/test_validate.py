"""validate(), fit %, RMSE and realisation tests against hand-worked answers."""

import json

import numpy as np
import pytest
from scipy import signal

from spiralid.sysid import ARX, IdentifiedModel, IOData, PaperCost, identify
from spiralid.sysid.validation.correlation import independence_test, whiteness_test
from spiralid.sysid.validation.validate import (
    fit_percent,
    realization_tests,
    rmse,
    validate,
)

TS = 0.002
FN, ZETA = 11.72, 0.05  # the paper's first mode


def second_order_theta():
    """ARX(2, 2, 1) theta of the ZOH discretisation of wn^2/(s^2+2 zeta wn s+wn^2)."""
    wn = 2 * np.pi * FN
    num, den, _ = signal.cont2discrete(([wn**2], [1, 2 * ZETA * wn, wn**2]), TS)
    num = num.ravel()
    assert abs(num[0]) < 1e-15  # one sample of delay: nk = 1
    return np.r_[den[1:], num[1:]], num, den


def model(theta, method="ls", **kw):
    # The records below are ARX (equation-error) systems, whose true model is
    # what least squares estimates: its residual tests use the one-step error.
    return IdentifiedModel(theta=theta, arx=ARX(2, 2, 1), ts=TS, method=method, **kw)


def record(n=3000, noise=0.0, seed=0):
    _, num, den = second_order_theta()
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    e = noise * rng.standard_normal(n)
    # ARX noise enters through 1/A, so the one-step residual of the true
    # model is exactly e.
    y = signal.lfilter(num, den, u) + signal.lfilter([1.0], den, e)
    return IOData(u, y, ts=TS), e


# -- fit % and RMSE -------------------------------------------------------------


def test_fit_percent_hand_cases():
    y = np.array([1.0, 3.0, 2.0, 6.0])
    assert fit_percent(y, y) == 100.0
    assert fit_percent(y, np.full(4, y.mean())) == pytest.approx(0.0, abs=1e-12)
    # mean 3: ||y - mean|| = sqrt(4 + 0 + 1 + 9) = sqrt(14); error (0, 0, 0, -1)
    assert fit_percent(y, [1.0, 3.0, 2.0, 7.0]) == pytest.approx(
        100 * (1 - 1 / np.sqrt(14.0)), rel=1e-14
    )
    assert fit_percent(y, -y) < 0
    assert fit_percent(np.c_[y], np.c_[y + 1e-3]) == fit_percent(y, y + 1e-3)


def test_rmse_hand_case():
    assert rmse([1.0, 2.0, 3.0, 4.0], [1.0, 2.0, 3.0, 0.0]) == pytest.approx(2.0)


def test_fit_and_rmse_bad_input():
    with pytest.raises(ValueError, match="`y` and `yhat` must have the same length"):
        fit_percent([1.0, 2.0], [1.0])
    with pytest.raises(ValueError, match="`y` must not be constant"):
        fit_percent([2.0, 2.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="`yhat` must be finite; got nan at sample 1"):
        rmse([1.0, 2.0], [1.0, np.nan])


# -- controllability / observability ---------------------------------------------


def test_minimal_realisation_passes():
    # (z - 0.2) / ((z - 0.5)(z - 0.7))
    r = realization_tests([1.0, -0.2], np.polymul([1, -0.5], [1, -0.7]))
    assert (r.order, r.ctrb_rank, r.obsv_rank) == (2, 2, 2)
    assert r.controllable and r.observable and r.minimal
    assert r.min_pole_zero_distance == pytest.approx(0.3)


def test_exact_pole_zero_cancellation_is_flagged():
    # (z - 0.5)(z + 0.3) / ((z - 0.5)(z - 0.7)(z + 0.9)): the 0.5 cancels
    num = np.polymul([1.0, -0.5], [1.0, 0.3])
    den = np.polymul(np.polymul([1.0, -0.5], [1.0, -0.7]), [1.0, 0.9])
    r = realization_tests(num, den)
    # controller canonical form: controllable by construction, so the
    # cancellation appears as lost observability
    assert r.controllable and not r.observable and not r.minimal
    assert r.obsv_rank == 2
    assert r.min_pole_zero_distance < 1e-12
    # the same cancellation seen from the transposed (observer) form
    a, _, c, _ = signal.tf2ss(num, den)
    ctrb_t = np.column_stack([np.linalg.matrix_power(a.T, k) @ c.T for k in range(3)])
    assert np.linalg.matrix_rank(ctrb_t) == 2


def test_realisation_bad_input():
    with pytest.raises(ValueError, match="`den` must have a non-zero leading"):
        realization_tests([1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="`num` must not be longer than `den`"):
        realization_tests([1.0, 2.0, 3.0], [1.0, 0.5])


# -- validate ------------------------------------------------------------------------


def test_true_model_validates_perfectly():
    data, _ = record()
    theta, _, _ = second_order_theta()
    v = validate(model(theta), data)
    assert v.fit_percent == pytest.approx(100.0, abs=1e-8)
    assert v.fit_percent_one_step == pytest.approx(100.0, abs=1e-8)
    assert v.rmse < 1e-10 and max(map(abs, v.error_range)) < 1e-9
    assert v.cost == pytest.approx(0.0, abs=1e-8)
    assert v.stable and v.max_pole_radius < 1
    assert v.realization.minimal and v.realization.order == 2
    # the model's own mode is the continuous system's
    np.testing.assert_allclose(v.modes.frequency, [FN], rtol=1e-9)
    np.testing.assert_allclose(v.modes.frequency, [FN], rtol=1e-9)
    np.testing.assert_allclose(v.modes.damping, [ZETA], rtol=1e-8)
    # and the measured spectrum peaks at its resonance
    (peak,) = v.peaks_measured.frequency[:1]
    assert peak == pytest.approx(FN * np.sqrt(1 - 2 * ZETA**2), abs=ZETA * FN)
    np.testing.assert_allclose(v.peaks_model.frequency, v.peaks_measured.frequency)


def test_biased_model_scores_match_hand_computation():
    data, _ = record()
    theta, _, _ = second_order_theta()
    wrong = theta * np.array([1.0, 1.0, 1.1, 0.9])
    v = validate(model(wrong), data)
    y_sim = signal.lfilter(np.r_[0.0, wrong[2:]], np.r_[1.0, wrong[:2]], data.u)
    e = data.y - y_sim
    assert v.fit_percent == pytest.approx(
        100 * (1 - np.linalg.norm(e) / np.linalg.norm(data.y - data.y.mean())),
        rel=1e-10,
    )
    assert v.rmse == pytest.approx(np.sqrt(np.mean(e**2)), rel=1e-10)
    assert v.error_range == pytest.approx((e.min(), e.max()), rel=1e-10)
    # paper cost, eq. (2), gain "auto", simulation predictor: 100 rms(e)/rms(y);
    # exactly PaperCost from rest (the default), which runs the same free
    # run; the measured-past start agrees only up to the start-up transient
    rms = np.sqrt(np.mean(e**2)) / np.sqrt(np.mean(data.y**2))
    assert v.cost == pytest.approx(100 * rms, rel=1e-10)
    cost = PaperCost(ARX(2, 2, 1), data, predictor="simulation", gain="auto")
    assert v.cost == pytest.approx(cost(wrong), rel=1e-12)
    measured = PaperCost(ARX(2, 2, 1), data, gain="auto", initial="measured")
    assert v.cost == pytest.approx(measured(wrong), rel=1e-2)
    assert v.cost_predictor == "simulation"
    # a one-step model is costed on its one-step error
    v1 = validate(model(wrong, predictor="one-step"), data, gain=2.0)
    assert v1.cost_predictor == "one-step"
    assert v1.cost == pytest.approx(2.0 * np.linalg.norm(data.y - v.y_pred) / data.n)
    assert v.cost_predictor == "simulation"
    # one-step prediction by hand: y(t) = -a1 y(t-1) - a2 y(t-2) + b u(t-1) + ...
    y, u = data.y, data.u
    yp = np.zeros_like(y)
    yp[1:] += -wrong[0] * y[:-1] + wrong[2] * u[:-1]
    yp[2:] += -wrong[1] * y[:-2] + wrong[3] * u[:-2]
    assert v.rmse_one_step == pytest.approx(np.sqrt(np.mean((y - yp) ** 2)), rel=1e-10)


def test_gain_model_reuses_the_model_gain():
    data, _ = record(n=1000)
    theta, _, _ = second_order_theta()
    wrong = theta * np.array([1.0, 1.0, 1.05, 1.0])
    v = validate(model(wrong, gain=3.0), data, gain="model")
    e = data.y - signal.lfilter(np.r_[0.0, wrong[2:]], np.r_[1.0, wrong[:2]], data.u)
    assert v.cost == pytest.approx(3.0 * np.sqrt(np.sum(e**2)) / data.n, rel=1e-12)
    with pytest.raises(ValueError, match="`gain` 'model' needs a model with a finite"):
        validate(model(wrong), data, gain="model")  # IdentifiedModel's gain is NaN


def test_unstable_model_is_reported_and_penalised():
    data, _ = record(n=500)
    with pytest.warns(UserWarning, match="free run diverges"):
        v = validate(model([-2.0, 1.1, 1.0, 0.0]), data)  # poles 1 +- 0.32j
    assert not v.stable and v.max_pole_radius == pytest.approx(np.sqrt(1.1))
    assert v.cost >= 1e6
    # On a long record its free run overflows: validation still reports it,
    # with a fit that says it diverged and one warning, never a NaN or an
    # error.
    long, _ = record(n=20000)
    with pytest.warns(UserWarning, match=r"free run diverges .*max \|pole\| = 1.04"):
        v = validate(model([-2.0, 1.1, 1.0, 0.0]), long)
    assert v.diverged and v.fit_percent < -1e6
    assert np.all(np.isfinite(v.y_sim)) and "diverged" in v.summary()


def test_residual_tests_use_the_one_step_error_of_an_arx_model():
    data, e = record(noise=0.05, seed=1)
    theta, _, _ = second_order_theta()
    v = validate(model(theta), data, lags=20)
    # the true ARX model's one-step residual is the noise itself
    np.testing.assert_allclose(data.y - v.y_pred, e, atol=1e-12)
    ref = whiteness_test(e, 20)
    np.testing.assert_allclose(v.whiteness.values, ref.values, atol=1e-9)
    assert v.whiteness.passed[0.99] and v.independence.passed[0.99]
    assert v.independence.statistic == pytest.approx(
        independence_test(data.u, e, 20).statistic, rel=1e-6
    )
    # the simulation error of the same model is the noise through 1/A: coloured
    vs = validate(model(theta), data, lags=20, residuals="simulation")
    assert vs.residuals == "simulation" and not vs.whiteness.passed[0.95]


def test_missing_dynamics_fail_the_cross_correlation_test():
    data, _ = record(noise=0.05, seed=2)
    theta, _, _ = second_order_theta()
    v = validate(model(theta * np.array([1.0, 1.0, 1.3, 0.6])), data)
    assert not v.independence.passed[0.99]


def test_warmup_scores_the_tail_of_a_whole_record_simulation():
    data, _ = record(n=1200)
    theta, _, _ = second_order_theta()
    wrong = theta * np.array([1.0, 1.0, 1.1, 1.0])
    est, val = data.split(2 / 3)
    v = validate(model(wrong), val, warmup=est)
    whole = signal.lfilter(np.r_[0.0, wrong[2:]], np.r_[1.0, wrong[:2]], data.u)
    assert v.fit_percent == pytest.approx(fit_percent(val.y, whole[est.n :]), rel=1e-10)
    cold = validate(model(wrong), val)
    assert cold.fit_percent != pytest.approx(v.fit_percent, rel=1e-6)


def test_summary_and_json():
    data, _ = record(n=800, noise=0.01)
    theta, _, _ = second_order_theta()
    v = validate(model(theta), data, label="true model")
    text = v.summary()
    assert text.startswith("Validation of true model")
    for key in (
        "fit % (simulation, from rest)",
        "fit % (simulation, from measured samples)",
        "fit % (one-step)",
        "error range",
        "whiteness",
    ):
        assert key in text
    assert str(v) == text
    d = json.loads(json.dumps(v.to_dict()))
    assert d["fit_percent"] == pytest.approx(v.fit_percent)
    assert d["realization"]["minimal"] is True
    assert "y_sim" not in d
    assert len(json.loads(json.dumps(v.to_dict(signals=True)))["y_sim"]) == 800


def test_validate_bad_input():
    data, _ = record(n=100)
    theta, _, _ = second_order_theta()
    m = model(theta)
    with pytest.raises(ValueError, match=r"`lags` must be in \[1, N - 1\]"):
        validate(m, data, lags=0)
    with pytest.raises(ValueError, match=r"`lags` must be in \[1, N - 1\]"):
        validate(m, data, lags=100)
    with pytest.raises(ValueError, match="`data` sample time must match the model's"):
        validate(m, IOData(data.u, data.y, ts=0.01))
    with pytest.raises(ValueError, match="`residuals` must be 'auto' or one of"):
        validate(m, data, residuals="two-step")
    with pytest.raises(
        ValueError, match="`gain` must be 'auto', 'model' or a finite number > 0"
    ):
        validate(m, data, gain="big")
    for bad in (0.0, -1.0, np.nan, "2"):
        with pytest.raises(ValueError, match="`gain` must be 'auto', 'model' or a"):
            validate(m, data, gain=bad)
    with pytest.raises(ValueError, match="`warmup` sample time must match"):
        validate(m, data, warmup=IOData(data.u, data.y, ts=0.5))
    with pytest.raises(TypeError, match="`data` must be an IOData"):
        validate(m, (data.u, data.y))
    with pytest.raises(TypeError, match="`warmup` must be an IOData"):
        validate(m, data, warmup=(data.u, data.y))


@pytest.mark.parametrize("bad", [None, "model.json", np.zeros(4)])
def test_validate_names_a_model_that_is_not_one(bad):
    with pytest.raises(TypeError, match="`model` must be a fitted model"):
        validate(bad, record(200))


def test_an_output_error_model_is_judged_by_the_tests_output_error_promises():
    # An output-error plant (white noise added to the output, not through
    # 1/A): OE at the true order makes the simulation error white noise
    # independent of the input, while its one-step residual is coloured.
    # "auto" tests the simulation error and calls whiteness not applicable.
    _, num, den = second_order_theta()
    rng = np.random.default_rng(7)
    u = rng.standard_normal(3000)
    y = signal.lfilter(num, den, u) + 0.05 * rng.standard_normal(3000)
    est, val = IOData(u, y, ts=TS).split(2 / 3)
    fit = identify(est, ARX(2, 2, 1), method="oe")
    v = validate(fit, val)
    assert v.residuals == "simulation" and v.output_error
    assert v.independence.passed[0.99]
    assert not validate(fit, val, residuals="one-step").whiteness.passed[0.99]
    text = v.summary()
    assert "not applicable: an output-error model" in text
    assert "fit % (one-step)" not in text and "not shown" in text
    ls = validate(identify(est, ARX(2, 2, 1), method="ls"), val)
    assert ls.residuals == "one-step" and not ls.output_error


def test_the_free_run_from_measured_samples_is_scored_beside_the_run_from_rest():
    # The measured start is the simulation of PaperCost(initial="measured"):
    # its fit is computed on the samples after the first max_lag.
    data, _ = record(n=600, noise=0.02, seed=3)
    theta, _, _ = second_order_theta()
    wrong = theta * np.array([1.0, 1.0, 1.2, 1.0])
    v = validate(model(wrong), data)
    a, b = np.r_[1.0, wrong[:2]], np.r_[0.0, wrong[2:]]
    zi = signal.lfiltic(b, a, data.y[1::-1], data.u[1::-1])
    y_meas = signal.lfilter(b, a, data.u[2:], zi=zi)[0]
    expected = fit_percent(data.y[2:], y_meas)
    assert v.initial == "rest"
    assert v.fit_percent_measured == pytest.approx(expected, rel=1e-9)
    assert v.to_dict()["fit_percent_measured"] == pytest.approx(expected, rel=1e-9)
