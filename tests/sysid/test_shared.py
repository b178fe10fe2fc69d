"""One denominator for several outputs (issue 30): the shared-denominator
cost, estimate and model (`sysid/estimation/shared/denominator.py`,
`sysid/models/shared.py`)."""

import numpy as np
import pytest
from scipy import signal
from two_modes import MODES, TS, A, B, record

from spiralid.sysid import ARX, IOData, PaperCost, identify, validate
from spiralid.sysid.estimation.shared.denominator import SharedProjectedCost
from spiralid.sysid.models.shared import SharedDenominatorModel


def test_the_shared_cost_of_one_output_is_the_papers_cost():
    data = record().output(0)
    arx = ARX(4, 4, 1)
    shared = SharedProjectedCost(arx, data)
    a = A[1:] * 0.99 ** np.arange(1, 5)
    theta = np.r_[a, shared.numerators(a)[0]]
    # With one output and the default weight, 100 sqrt(sse / sum y^2) is
    # eq. (2) at gain "auto" for the projected numerator.
    assert shared(a) == pytest.approx(float(PaperCost(arx, data)(theta)), rel=1e-10)


def test_two_outputs_give_one_denominator_with_intervals_that_hold_the_truth():
    data = record(1)
    fit = identify(data, ARX(4, 4, 1), rng=0, max_nfev=3000)
    assert isinstance(fit, SharedDenominatorModel) and fit.n_outputs == 2
    np.testing.assert_allclose(fit.a, A[1:], atol=2e-3)
    np.testing.assert_allclose(fit.b, B[:, 1:], atol=2e-3)
    modes = fit.modes
    lo, hi = modes.table.frequency_interval.T
    truth = np.array([f for f, _ in MODES])
    assert np.all((lo <= truth) & (truth <= hi))
    assert modes.share.shape == (2, 2)
    # Each output's transfer function validates on its own output.
    for k, name in enumerate(data.output_names):
        v = validate(fit.output_model(name), data.output(k))
        assert v.fit_percent > 90


def test_noise_weights_come_from_the_first_fit():
    data = record(2, noise=(0.0005, 0.02))
    fit = identify(data, ARX(4, 4, 1), rng=0, max_nfev=2000)
    # 1 / sigma^2: the quiet sensor weighs about (0.02 / 0.0005)^2 more.
    ratio = fit.weights[0] / fit.weights[1]
    assert 400 < ratio < 4000
    given = identify(data, ARX(4, 4, 1), rng=0, max_nfev=2000, weights=[1.0, 1.0])
    np.testing.assert_array_equal(given.weights, [1.0, 1.0])


def test_the_model_round_trips_through_json_and_refuses_bad_input():
    fit = identify(record(3), ARX(4, 4, 1), rng=0, max_nfev=1000)
    again = SharedDenominatorModel.from_dict(fit.to_dict())
    np.testing.assert_array_equal(again.a, fit.a)
    np.testing.assert_array_equal(again.b, fit.b)
    assert again.output_names == ("near", "far")
    np.testing.assert_array_equal(again.simulate(np.ones(5)), fit.simulate(np.ones(5)))
    with pytest.raises(ValueError, match="`weights` must be 2 finite numbers"):
        identify(record(3), ARX(4, 4, 1), weights=[1.0, -1.0])
    with pytest.raises(ValueError, match="`method` 'sda' takes one output"):
        identify(record(3), ARX(4, 4, 1), method="sda")
    with pytest.raises(ValueError, match="`max_nfev` does not apply to method 'oe'"):
        identify(record(3), ARX(4, 4, 1), method="oe", max_nfev=100)
    with pytest.raises(ValueError, match="`refine` does not apply to method 'spiral'"):
        identify(record(3), ARX(4, 4, 1), refine=True)


def test_to_control_is_a_simo_system():
    control = pytest.importorskip("control")
    fit = identify(record(4), ARX(4, 4, 1), rng=0, max_nfev=1000)
    sys = fit.to_control()
    assert (sys.noutputs, sys.ninputs) == (2, 1) and sys.dt == TS
    _, y = control.forced_response(sys, U=np.r_[1.0, np.zeros(49)])
    np.testing.assert_allclose(y.T, fit.simulate(np.r_[1.0, np.zeros(49)]), atol=1e-9)


def test_each_output_is_validated_and_the_joint_fit_combines_them():
    from spiralid.sysid import joint_fit

    est, val = record(5).split(2 / 3)
    fit = identify(est, ARX(4, 4, 1), rng=0, max_nfev=1000)
    report = validate(fit, val, warmup=est)
    fits = [v.fit_percent for v in report.outputs.values()]
    assert list(report.outputs) == ["near", "far"] and min(fits) > 90
    # By hand: the normalised RMS error over the outputs.
    miss = 1 - np.array(fits) / 100
    assert report.fit_percent == pytest.approx(100 * (1 - np.sqrt(np.mean(miss**2))))
    assert joint_fit([fits[0]]) == pytest.approx(fits[0])
    one = validate(fit.output_model("far"), val.output("far"), warmup=est.output("far"))
    assert report.outputs["far"].fit_percent == pytest.approx(one.fit_percent)
    assert "joint fit %" in report.summary() and "far" in report.summary()
    assert type(report) is type(one) and one.outputs is None
    with pytest.raises(ValueError, match="`data` must hold the model's outputs"):
        validate(fit, val.output("far"))


def test_output_error_and_least_squares_for_the_same_structure():
    data = record(6)
    oe = identify(data, ARX(4, 4, 1), method="oe")
    spiral = identify(data, ARX(4, 4, 1), rng=0, max_nfev=2000)
    ls = identify(data, ARX(4, 4, 1), method="ls")
    assert (oe.method, ls.method) == ("oe", "ls")
    # One minimum on this record: the search and output error agree.
    np.testing.assert_allclose(oe.a, spiral.a, atol=1e-6)
    np.testing.assert_allclose(oe.a, A[1:], atol=2e-3)
    # Least squares of the joint equation error, by hand: stacked rows.
    rows, rhs = [], []
    for i in range(2):
        one = data.output(i)
        phi = ARX(4, 4, 1).regressors(one)[4:]
        block = np.zeros((phi.shape[0], 12))
        block[:, :4] = phi[:, :4]
        block[:, 4 + 4 * i : 8 + 4 * i] = phi[:, 4:]
        w = np.sqrt(ls.weights[i])
        rows.append(w * block)
        rhs.append(w * one.y[4:])
    theta = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
    np.testing.assert_allclose(np.r_[ls.a, ls.b.ravel()], theta, rtol=1e-9)


def test_each_output_has_its_own_known_integrators():
    from spiralid.sysid.models.polynomials import with_integrator

    rng = np.random.default_rng(7)
    u = rng.standard_normal(1500)
    # Output 1 integrates the modes once (a velocity to an angle), output 2
    # does not: one A, a numerator each, and (1 - z^-1) for output 1 only.
    y = np.column_stack(
        [
            signal.lfilter(B[0], np.r_[1.0, with_integrator(A[1:])], u),
            signal.lfilter(B[1], A, u),
        ]
    )
    y += 0.002 * rng.standard_normal(y.shape)
    data = IOData(u, y, ts=TS, output_name=("angle", "rate"))
    fit = identify(data, ARX(4, 4, 1), rng=0, max_nfev=2000, integrator=(1, 0))
    assert fit.integrators == (1, 0)
    np.testing.assert_allclose(fit.a, A[1:], atol=2e-3)
    angle = fit.output_model("angle")
    assert angle.integrator == 1 and angle.arx == ARX(5, 4, 1)
    np.testing.assert_allclose(angle.free_denominator, A[1:], atol=2e-3)
    # The free run holds the ramp: fit above 95 % on both outputs.
    for k, name in enumerate(data.output_names):
        assert validate(fit.output_model(name), data.output(k)).fit_percent > 95
    again = SharedDenominatorModel.from_dict(fit.to_dict())
    assert again.integrators == (1, 0)
    control = pytest.importorskip("control")
    impulse = np.r_[1.0, np.zeros(49)]
    _, response = control.forced_response(fit.to_control(), U=impulse)
    np.testing.assert_allclose(response.T, fit.simulate(impulse), atol=1e-9)
    np.testing.assert_allclose(again.simulate(u[:50]), fit.simulate(u[:50]))
    with pytest.raises(ValueError, match="`integrator` must be one count or one per"):
        identify(data, ARX(4, 4, 1), integrator=(1, 0, 0))


def test_the_stabilisation_diagram_keeps_the_true_modes_and_flags_the_rest():
    from spiralid.sysid import stabilisation
    from spiralid.sysid.validation.stabilisation import _classify

    # The rule by hand: 1 % in frequency, 5 % in damping.
    prev_f, prev_z = np.array([10.0, 30.0]), np.array([0.02, 0.05])
    assert _classify(prev_f, prev_z, 10.05, 0.0205, 0.01, 0.05) == "stable"
    assert _classify(prev_f, prev_z, 10.05, 0.03, 0.01, 0.05) == "frequency"
    assert _classify(prev_f, prev_z, 20.0, 0.02, 0.01, 0.05) == "new"
    diagram = stabilisation(record(8), [4, 6, 8], nk=1, rng=0, max_nfev=1500)
    assert diagram.orders == (4, 6, 8)
    stable = diagram.stable_modes(min_orders=3)
    np.testing.assert_allclose(stable, [f for f, _ in MODES], rtol=1e-3)
    first = diagram.status[diagram.order == 4]
    assert set(first) == {"new"}  # nothing below the first order
    assert diagram.to_dict()["modes"][0]["order"] == 4
    with pytest.raises(ValueError, match="`orders` must be"):
        stabilisation(record(8), [0, 2])


def test_the_stabilisation_figure_draws_every_mode():
    from spiralid.sysid import plots, stabilisation

    data = record(9)
    diagram = stabilisation(data, [4, 6], nk=1, rng=0, max_nfev=800)
    fig = plots.plot_stabilisation(diagram, data)
    ax = fig.axes[0]
    drawn = sum(len(line.get_xdata()) for line in ax.lines)
    assert drawn == diagram.frequency.size
    assert ax.get_xlabel() == "frequency (Hz)" and ax.get_title()
    # The markers and their legend are drawn above the spectra's twin axes.
    spectra = fig.axes[1]
    assert ax.get_zorder() > spectra.get_zorder() and not ax.patch.get_visible()


def test_the_search_never_ends_above_output_error():
    # The spiral's best is polished beside output error's starts, and the
    # lowest cost kept (before the noise weights, which both then share).
    for seed in range(3):
        data = record(20 + seed, noise=(0.01, 0.004))
        spiral = identify(data, ARX(4, 4, 1), rng=seed, max_nfev=300, weights=[1, 1])
        oe = identify(data, ARX(4, 4, 1), method="oe", weights=[1, 1])
        assert spiral.cost <= oe.cost * (1 + 1e-12)


def test_a_sensor_at_a_node_of_a_mode_still_gets_that_mode_from_the_others():
    # Sensor "node" sits at a node of the 11 Hz mode: its numerator holds
    # that mode's pole pair (a zero pair on it), so its own response barely
    # shows the mode; sensor "near" sees both.
    poles = np.roots(A)
    upper = poles[poles.imag > 0]
    eleven = upper[np.argmax(np.abs(np.angle(upper)))]
    zeros = np.poly([eleven, np.conj(eleven)]).real
    node = np.convolve([0.0, 0.02, 0.01], zeros)
    rng = np.random.default_rng(11)
    u = rng.standard_normal(1500)
    y = np.column_stack([signal.lfilter(B[0], A, u), signal.lfilter(node, A, u)])
    y += rng.standard_normal(y.shape) * np.array([0.004, 0.001])
    data = IOData(u, y, ts=TS, output_name=("near", "node"))
    shared = identify(data, ARX(4, 4, 1), rng=0, max_nfev=2000)
    alone = identify(data.output("node"), ARX(4, 4, 1), rng=0, max_nfev=2000)

    def error_at_11_hz(table):
        return np.min(np.abs(table.frequency - 11.0)) / 11.0 if len(table) else 1.0

    assert error_at_11_hz(shared.modes.table) < 0.005
    share = shared.modes.share[np.argmin(np.abs(shared.modes.table.frequency - 11))]
    assert share[1] < share[0] / 10  # the node sensor barely sees it
    assert error_at_11_hz(alone.modes) > 0.005


def test_the_subspace_poles_are_the_true_ones_and_a_short_record_is_refused():
    from spiralid.sysid import subspace_denominator

    data = record(30, noise=(0.0005, 0.0005))
    a = subspace_denominator(data, 4)
    np.testing.assert_allclose(np.sort_complex(np.roots(np.r_[1.0, a])),
                               np.sort_complex(np.roots(A)), atol=5e-3)  # fmt: skip
    with pytest.raises(ValueError, match="`n` = 4 needs a longer record"):
        subspace_denominator(data[:40], 4)


def test_output_error_starts_from_the_subspace_poles_too():
    from spiralid.sysid.estimation.linear.modal import ModalParametrization
    from spiralid.sysid.estimation.shared.denominator import (
        SharedProjectedCost,
        _subspace_start,
    )

    data = record(31)
    par = ModalParametrization(4, TS)
    start = _subspace_start(SharedProjectedCost(ARX(4, 4, 1), data), par)
    # The subspace poles, as modal coordinates, are the true modes.
    np.testing.assert_allclose(
        np.sort_complex(np.roots(np.r_[1.0, par.to_denominator(start)])),
        np.sort_complex(np.roots(A)),
        atol=5e-3,
    )
    # Outputs with different integrators have different inputs: no start.
    mixed = SharedProjectedCost(ARX(4, 4, 1), data, integrators=(1, 0))
    assert _subspace_start(mixed, par) is None
    assert "subspace" in identify(data, ARX(4, 4, 1), method="oe").result["message"]


def test_an_accelerometer_at_a_node_of_the_rig_gets_that_mode_from_the_other():
    # On the simulated rig: a second accelerometer at the outer node of
    # mode 2 (where the FEM's mode shape, in the inertial frame, is zero)
    # barely sees 35.1 Hz; with the end-point accelerometer beside it the
    # shared denominator still holds that mode.
    from dataclasses import replace

    from spiralid.fms import FlexibleManipulator, paper_experiment

    rig = FlexibleManipulator()
    node = rig.mode_nodes(2, frame="inertial")[-1]
    exp = replace(paper_experiment(), acceleration_at=(node,))
    (name,) = exp.sensors().positional_names
    est = exp.run(rig, rng=0).iodata(["end_acceleration", name]).split(2 / 3)[0]
    arx = ARX(12, 12, 1)  # the acceleration's true order (mode_intervals.py)
    shared = identify(est, arx, rng=0)
    alone = identify(est.output(name), arx, rng=0)
    mode2 = rig.modes(3)[1]

    def error(table):
        return np.min(np.abs(table.frequency - mode2)) / mode2 if len(table) else 1.0

    assert error(shared.modes.table) < 0.005
    assert error(alone.modes) > 0.005
    k = np.argmin(np.abs(shared.modes.table.frequency - mode2))
    share = shared.modes.share[k]
    assert share[1] < share[0] / 10  # the node accelerometer barely sees it


def test_the_covariance_is_s2_over_the_stacked_jacobian_with_its_factor():
    # By hand: finite differences of every output's weighted projected
    # residual, stacked, and s^2 = the weighted squared error per degree of
    # freedom; the factor R (C = R^T R) gives the same standard errors.
    from spiralid.sysid.models.modes import mode_table

    data = record(12)
    arx = ARX(4, 4, 1)
    fit = identify(data, arx, method="oe")
    cost = SharedProjectedCost(arx, data, fit.weights)

    def residual(a):
        return np.concatenate(
            [
                np.sqrt(w) * part.residual(a)[0]
                for w, part in zip(fit.weights, cost.parts, strict=True)
            ]
        )

    r = residual(fit.a)
    h = 1e-7
    jac = np.column_stack(
        [
            (residual(fit.a + h * e) - residual(fit.a - h * e)) / (2 * h)
            for e in np.eye(4)
        ]
    )
    s2 = r @ r / (2 * data.n - 4 - 2 * 4)
    expected = s2 * np.linalg.inv(jac.T @ jac)
    np.testing.assert_allclose(fit.covariance, expected, rtol=1e-4)
    root = fit.covariance_factor
    np.testing.assert_allclose(root.T @ root, fit.covariance, rtol=1e-10)
    plain = mode_table(fit.a, [0.0, *fit.b[0]], TS, covariance=expected)
    np.testing.assert_allclose(
        fit.modes.table.frequency_se, plain.frequency_se, rtol=1e-3
    )
