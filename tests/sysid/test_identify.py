"""identify(): a known ARX(2, 2, 1), the real flexible arm, serialisation, bad input."""

import json

import numpy as np
import pytest
from scipy import signal

from spiralid.datasets import robot_arm
from spiralid.sysid import ARX, IdentifiedModel, IOData, identify, step_up
from spiralid.sysid.estimation.core.identify import (
    default_bounds,
    feasible_initial_points,
    steiglitz_mcbride,
)

TRUE = np.array([-1.5, 0.7, 1.0, 0.5])


def _fit(y, yhat):
    """MATLAB compare's NRMSE fit in percent."""
    return 100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y - np.mean(y)))


@pytest.fixture(scope="module")
def known():
    u = np.random.default_rng(11).standard_normal(600)
    y = signal.lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    return IOData(u, y, ts=0.01)


def _validation_fit(model, data):
    est, val = data.split()
    return _fit(val.y, model.simulate(data.u)[est.n :])


def test_ls_recovers_theta(known):
    est, _ = known.split()
    fit = identify(est, ARX(2, 2, 1), method="ls")
    np.testing.assert_allclose(fit.theta, TRUE, rtol=0, atol=1e-9)
    assert fit.is_stable and fit.cost < 1e-6 and fit.result.status == 0


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(method="oe"),
        dict(method="oe", initial="measured"),
        dict(method="ebsda", refine=True, rng=0),
        dict(method="ebsda", refine=True, rng=0, initial="measured"),
        dict(method="ebsda", refine=True, rng=1, parametrization="reflection"),
        dict(method="de", refine=True, rng=0, max_nfev=5000),
    ],
)
def test_oe_and_refined_ebsda_fit_the_known_system(known, kwargs):
    est, _ = known.split()
    fit = identify(est, ARX(2, 2, 1), **kwargs)
    assert _validation_fit(fit, known) >= 99.9
    assert fit.is_stable


def test_spiral_search_result_and_history(known):
    est, _ = known.split()
    fit = identify(est, ARX(2, 2, 1), method="sda", rng=3, n_points=20, max_iter=50)
    assert fit.history.shape == (fit.result.nit + 1,)
    assert np.all(np.diff(fit.history) <= 0)  # the best never gets worse
    assert fit.cost == pytest.approx(fit.history[-1])
    assert fit.bounds.shape == (4, 2)
    # Default box: |a_i| <= binom(2, i).
    np.testing.assert_array_equal(fit.bounds[:2], [[-2, 2], [-1, 1]])


def test_initial_points_are_stable_and_reflection_never_penalised(known):
    est, _ = known.split()
    arx = ARX(8, 8, 0)
    noisy = IOData(
        est.u, est.y + 0.01 * np.random.default_rng(0).standard_normal(est.n), 1
    )
    box = default_bounds(noisy, arx)
    np.testing.assert_array_equal(box[:8, 1], [8, 28, 56, 70, 56, 28, 8, 1])
    x0 = feasible_initial_points(box, arx, 500, rng=4)
    assert np.all((x0 >= box[:, 0]) & (x0 <= box[:, 1]))
    assert all(np.abs(np.roots(np.r_[1.0, row[:8]])).max() < 1 for row in x0)
    refl = identify(
        est,
        ARX(2, 2, 1),
        method="sda",
        parametrization="reflection",
        rng=5,
        n_points=10,
        max_iter=30,
    )
    assert np.all(refl.history < 1e6)
    assert refl.is_stable


def test_same_seed_same_result_bit_for_bit(known):
    est, _ = known.split()
    kw = dict(method="ebsda", rng=7, n_points=15, max_iter=40)
    a = identify(est, ARX(2, 2, 1), **kw)
    b = identify(est, ARX(2, 2, 1), **kw)
    np.testing.assert_array_equal(a.theta, b.theta)
    np.testing.assert_array_equal(a.history, b.history)


def test_to_dlti_and_dict_round_trip(known):
    est, _ = known.split()
    fit = identify(est, ARX(2, 2, 1), method="sda", rng=0, n_points=10, max_iter=20)
    _, (h,) = fit.to_dlti().impulse(n=30)
    impulse = np.zeros(h.shape[0])
    impulse[0] = 1.0
    np.testing.assert_allclose(h[:, 0], fit.simulate(impulse), atol=1e-12)
    d = json.loads(json.dumps(fit.to_dict()))
    back = IdentifiedModel.from_dict(d)
    np.testing.assert_array_equal(back.theta, fit.theta)
    np.testing.assert_array_equal(back.history, fit.history)
    assert back.arx == fit.arx and back.ts == 0.01 and back.method == "sda"
    assert back.cost == fit.cost and back.initial == fit.initial == "rest"
    np.testing.assert_array_equal(back.predict(est), fit.predict(est))
    for method in ("ls", "oe"):  # no history, no bounds
        for initial in ("rest", "measured"):
            other = identify(est, ARX(2, 2, 1), method=method, initial=initial)
            back = IdentifiedModel.from_dict(json.loads(json.dumps(other.to_dict())))
            np.testing.assert_array_equal(back.theta, other.theta)
            assert back.method == method and back.history is None
            assert back.bounds is None and back.initial == initial
            assert back.cost == other.cost and back.gain == other.gain
    # A dict saved before `initial` existed was made by the measured-past rule.
    old = fit.to_dict()
    del old["initial"]
    assert IdentifiedModel.from_dict(old).initial == "measured"
    with pytest.raises(ValueError, match=r"`initial` must be one of .*; got 'zero'"):
        IdentifiedModel.from_dict({**old, "initial": "zero"})


@pytest.fixture(scope="module")
def arm():
    return robot_arm()


@pytest.fixture(scope="module")
def arm_ls(arm):
    est, _ = arm.split()
    return identify(est, ARX(8, 8, 0), method="ls")


def test_real_arm_least_squares_about_95(arm, arm_ls):
    assert arm_ls.is_stable
    assert abs(_validation_fit(arm_ls, arm) - 95.0) <= 1.0


def test_real_arm_output_error(arm):
    est, _ = arm.split()
    # The arm record is a slice of a periodic sine sweep: it starts in
    # motion, so the simulation must start from the measured past outputs
    # (initial="measured"). From rest (the default, right for records that
    # start at rest) OE validates at only ~89.7 % here: the start-up
    # transient of a lightly damped model is not in the data.
    oe = identify(est, ARX(8, 8, 0), method="oe", initial="measured")
    ls = identify(est, ARX(8, 8, 0), method="ls", initial="measured")
    assert oe.is_stable and oe.initial == "measured"
    # OE minimises the simulation cost, so it must not lose to LS there...
    assert oe.cost <= ls.cost
    # ...and it validates within a point of 95 % too. Issue 4 asks for at
    # least the LS fit (95.36); OE reaches 95.21: its lowest simulation cost
    # puts a pole pair at the stability limit (12.9 Hz, nearly cancelled by
    # a zero) that only the measured initial state excites, which a
    # validation run from rest cannot use. Not selectable on estimation
    # data without looking at validation, so the bar stays "within 1 point".
    assert abs(_validation_fit(oe, arm) - 95.0) <= 1.0
    assert oe.result.start in ("ls", "steiglitz-mcbride")


def test_steiglitz_mcbride_removes_the_output_noise_bias():
    # Output (not equation) noise biases least squares; the Steiglitz-
    # McBride fixed point is the output-error estimate, close to the truth.
    rng = np.random.default_rng(3)
    u = rng.standard_normal(2000)
    clean = signal.lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    data = IOData(u, clean + 1.0 * rng.standard_normal(u.size), ts=1.0)
    arx = ARX(2, 2, 1)
    ls = identify(data, arx, method="ls").theta
    sm = steiglitz_mcbride(data, arx)
    assert np.linalg.norm(sm - TRUE) < 0.3 * np.linalg.norm(ls - TRUE)
    # Without noise the first iteration already lands on the truth.
    exact = steiglitz_mcbride(IOData(u, clean, ts=1.0), arx, n_iter=1)
    np.testing.assert_allclose(exact, TRUE, atol=1e-9)
    with pytest.raises(ValueError, match=r"`theta0` must be a finite vector of sh"):
        steiglitz_mcbride(data, arx, theta0=[1.0, 2.0])
    with pytest.raises(ValueError, match="`n_iter` must be an integer >= 0; got -1"):
        steiglitz_mcbride(data, arx, n_iter=-1)


@pytest.mark.parametrize("initial", ["rest", "measured"])
def test_oe_keeps_the_start_with_the_lower_cost(initial):
    from spiralid.sysid.estimation.core.cost import PaperCost
    from spiralid.sysid.estimation.linear.outputerror import local_polish

    rng = np.random.default_rng(4)
    u = rng.standard_normal(400)
    y = signal.lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    data = IOData(u, y + 0.5 * rng.standard_normal(u.size), ts=1.0)
    arx = ARX(2, 2, 1)
    cost = PaperCost(arx, data, initial=initial)
    ls = identify(data, arx, method="ls").theta
    polished = [
        cost(local_polish(s, arx, data, "simulation", initial)[0])
        for s in (ls, steiglitz_mcbride(data, arx))
    ]
    oe = identify(data, arx, method="oe", initial=initial)
    assert oe.cost == pytest.approx(min(polished), rel=1e-12)
    # The saved summary holds scalars, not least_squares' residual vector.
    summary = json.loads(json.dumps(oe.to_dict()))["result"]
    assert summary["fun"] == oe.cost and summary["start"] == oe.result.start
    assert summary["nfev"] == oe.result.nfev


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(method="ga"), "`method` must be one of .*; got 'ga'"),
        (
            dict(parametrization="poles"),
            "`parametrization` must be one of .*; got 'poles'",
        ),
        (
            dict(method="ls", n_points=5),
            "`n_points` does not apply to method 'ls'; the options that do: ",
        ),
        (
            dict(method="de", target=1.0),
            r"`target` does not apply to method 'de'; the options that do: .*max_nfev",
        ),
        (dict(predictor="two-step"), "`predictor` must be one of .*; got 'two-step'"),
        (dict(method="oe", initial="zero"), "`initial` must be one of .*; got 'zero'"),
        (
            dict(method="ebsda", bounds=np.zeros((3, 2))),
            r"`bounds` must have 4 \(low, high\) pairs; got 3 pairs",
        ),
    ],
)
def test_bad_arguments(known, kwargs, match):
    with pytest.raises(ValueError, match=match):
        identify(known, ARX(2, 2, 1), **kwargs)


def test_constant_input_is_rejected():
    d = IOData(np.ones(50), np.random.default_rng(0).standard_normal(50), ts=1.0)
    with pytest.raises(ValueError, match="does not excite the system"):
        identify(d, ARX(2, 2, 1), method="oe")


def test_one_step_refine_reaches_least_squares(known):
    # With noise the one-step optimum is not the truth; least squares is it.
    rng = np.random.default_rng(12)
    est, _ = known.split()
    noisy = IOData(est.u, est.y + 0.3 * rng.standard_normal(est.n), ts=est.ts)
    ls = identify(noisy, ARX(2, 2, 1), method="ls", predictor="one-step")
    fit = identify(
        noisy,
        ARX(2, 2, 1),
        method="sda",
        predictor="one-step",
        refine=True,
        rng=0,
        n_points=20,
        max_iter=100,
    )
    assert fit.cost == pytest.approx(ls.cost, rel=1e-9)
    np.testing.assert_allclose(fit.theta, ls.theta, rtol=1e-6)
    assert fit.cost <= fit.history[-1]


def test_user_bounds_are_the_search_box(known):
    est, _ = known.split()
    box = [[-2, 2], [-1, 1], [0.5, 1.5], [0.0, 1.0]]
    fit = identify(est, ARX(2, 2, 1), method="sda", bounds=box, rng=0, max_iter=5)
    np.testing.assert_array_equal(fit.bounds, box)
    with pytest.raises(
        ValueError, match="`bounds` must have low < high in every dimension"
    ):
        identify(est, ARX(2, 2, 1), method="sda", bounds=[[0, 0]] * 4)


def test_unstable_start_is_reflected_inside():
    from spiralid.sysid.estimation.linear.parametrizations import stabilise

    arx = ARX(3, 1, 0)
    roots = np.array([1.25, 0.5 + 0.6j, 0.5 - 0.6j])  # |0.5 +- 0.6j| = 0.78
    theta = np.r_[np.real(np.poly(roots))[1:], 2.0]
    k_b = stabilise(theta, arx)
    assert np.all(np.abs(k_b[:3]) < 1) and k_b[3] == 2.0
    a = step_up(k_b[:3])
    expected = np.sort_complex(np.r_[1 / 1.25, roots[1:]])
    np.testing.assert_allclose(np.sort_complex(np.roots(np.r_[1.0, a])), expected)


def test_oe_from_rest_is_a_prediction_error_method():
    # Output (not equation) noise on a known ARX(2, 2, 1) record that starts
    # at rest. At the OE optimum the Jacobian least_squares used (analytic,
    # sensitivities filtered from rest) equals central finite differences of
    # the residual written out here with scipy.signal.lfilter from rest over
    # all N samples, and the gradient J' r of the criterion vanishes.
    rng = np.random.default_rng(21)
    u = rng.standard_normal(500)
    clean = signal.lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    data = IOData(u, clean + 0.5 * rng.standard_normal(u.size), ts=1.0)
    arx = ARX(2, 2, 1)
    oe = identify(data, arx, method="oe")
    assert oe.initial == "rest" and oe.result.success

    def residual(x):
        return signal.lfilter([0.0, *x[2:]], np.r_[1.0, x[:2]], u) - data.y

    raw = oe.result.raw  # least_squares' own result (coordinates: theta)
    x = raw.x
    r = residual(x)
    np.testing.assert_allclose(r, raw.fun, rtol=1e-9, atol=1e-12)
    h = 1e-6
    fd = np.column_stack(
        [(residual(x + h * e) - residual(x - h * e)) / (2 * h) for e in np.eye(x.size)]
    )
    np.testing.assert_allclose(raw.jac, fd, rtol=1e-5, atol=1e-6)
    assert np.linalg.norm(fd.T @ r) <= 1e-6 * np.linalg.norm(fd) * np.linalg.norm(r)
    # Output noise biases least squares; OE from rest lands near the truth.
    ls = identify(data, arx, method="ls").theta
    assert np.linalg.norm(oe.theta - TRUE) < 0.5 * np.linalg.norm(ls - TRUE)


def test_rig_rest_criterion_validates_better_than_measured():
    # The simulated rig's record starts at rest and its accelerometer is
    # noisy. The measured-past start maps the noise of the 8 measured past
    # outputs into the initial state (gain up to ~1e4 for these lightly
    # damped models), so its optimum validates worse than the from-rest one.
    # Both polished from the Steiglitz-McBride start, the start "oe" keeps
    # for either rule on this record (identify itself also polishes the
    # least-squares start, ~3 s more from rest); identify's figures are in
    # the benchmarks. Validation: free run from rest over the whole record.
    from spiralid.reproduction import default_data
    from spiralid.sysid import validate
    from spiralid.sysid.estimation.linear.outputerror import local_polish

    est, val = default_data().split()
    arx = ARX(8, 8, 0)
    start = steiglitz_mcbride(est, arx)
    fits = {}
    for initial in ("rest", "measured"):
        theta, _ = local_polish(start, arx, est, "simulation", initial)
        model = IdentifiedModel(theta, arx, est.ts, method="oe", initial=initial)
        fits[initial] = validate(model, val, warmup=est).fit_percent
    # Measured: rest 95.85 %, measured 92.55 %.
    assert fits["rest"] > fits["measured"] + 2.0
    assert fits["rest"] > 95.0


def test_differential_evolution_shares_the_spiral_methods_start(known):
    est, _ = known.split()
    fit = identify(est, ARX(2, 2, 1), method="de", rng=4, n_points=20, max_nfev=2000)
    # Same cost, box and stable initial points as the spiral methods: the
    # history starts at the best of those points and never rises.
    assert fit.result.nfev <= 2000
    assert fit.history.size == fit.result.nit + 1
    assert np.all(np.diff(fit.history) <= 0)
    assert fit.cost == pytest.approx(fit.history[-1])
    assert fit.is_stable


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"refine": "yes"}, "`refine` must be True or False; got 'yes'"),
        ({"rng": "abc"}, "`rng` must be None, a non-negative integer"),
        ({"rng": 1.5}, "`rng` must be None"),
    ],
)
def test_bad_refine_and_rng_are_refused_by_name(known, kwargs, match):
    with pytest.raises(TypeError, match=match):
        identify(known, ARX(2, 2, 1), method="ebsda", **kwargs)


def test_search_on_constant_input_does_not_blame_least_squares():
    d = IOData(np.ones(50), np.random.default_rng(0).standard_normal(50), ts=1.0)
    with pytest.raises(ValueError) as info:
        identify(d, ARX(2, 2, 1), method="ebsda", rng=0)
    assert "least squares" not in str(info.value)
    assert "constant input" in str(info.value)


def test_to_control_matches_scipy_and_keeps_the_sample_time(known):
    control = pytest.importorskip("control", reason="python-control not installed")
    model = identify(known, ARX(2, 2, 1), method="ls")
    tf = model.to_control()
    assert isinstance(tf, control.TransferFunction) and tf.dt == known.ts
    w = np.array([0.1, 1.0, 10.0, 100.0])  # rad/s, below Nyquist (314 rad/s)
    _, h_scipy = model.to_dlti().freqresp(w * known.ts)
    np.testing.assert_allclose(tf(np.exp(1j * w * known.ts)), h_scipy, rtol=1e-10)
    # The same through a saved model file.
    again = IdentifiedModel.from_dict(json.loads(json.dumps(model.to_dict())))
    np.testing.assert_array_equal(again.to_control().num[0][0], tf.num[0][0])
