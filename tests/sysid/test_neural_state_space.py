"""The neural state-space family: exact gradients against finite
differences, the linear start against SciPy's filter and the ARX it
realises, the encoder's exact state, never worse than the linear start on
the held-back samples, the model file, and bad input in one line."""

import json

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.sysid import NeuralStateSpace, NeuralStateSpaceModel
from spiralid.sysid.estimation.state_space.training import _hold_mask, _Problem

N = 500


def _wiener(n: int = N, seed: int = 0) -> sid.IOData:
    """A second-order linear system followed by a saturation, with a
    little output noise: a nonlinearity a linear model misses."""
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.standard_normal(n // 5), 5)
    x = lfilter([0.0, 0.3, 0.15], [1.0, -1.4, 0.6], u)
    y = np.tanh(1.5 * x) + 0.01 * rng.standard_normal(n)
    return sid.IOData(u, y, ts=0.1)


def test_the_linear_start_is_the_arx_realisation():
    st = NeuralStateSpace(3, hidden=(4,))
    a, b = np.array([-1.5, 0.7, -0.1]), np.array([0.5, 0.2, 0.1])
    u = np.random.default_rng(1).standard_normal(300)
    y = lfilter(np.r_[0.0, b], np.r_[1.0, a], u)
    p = st.from_linear(a, b)
    np.testing.assert_allclose(st.free_run(p, u), y, atol=1e-12)
    # The encoder's state from the 5 samples before t continues the run.
    t = 40
    x0 = st.split(p)["E"] @ st.regressors(y, u, [t])[0]
    np.testing.assert_allclose(st.free_run(p, u[t:], x0), y[t:], atol=1e-10)


def _assert_exact_gradient(problem, p):
    """The loss's gradient against central finite differences."""
    g = problem.loss(p)[1]
    eps = 1e-6
    numeric = np.array(
        [
            (problem.loss(p + eps * d)[0] - problem.loss(p - eps * d)[0]) / (2 * eps)
            for d in np.eye(p.size)
        ]
    )
    np.testing.assert_allclose(g, numeric, rtol=1e-5, atol=1e-8 * np.abs(g).max())


def test_the_gradient_is_exact():
    data = _wiener(200)
    st = NeuralStateSpace(2, hidden=(3,))
    problem = _Problem(st, data, 0.2, 1e-2)
    problem.batch(15)
    rng = np.random.default_rng(2)
    p = st.from_linear([-1.4, 0.6], [0.3, 0.15]) + 0.2 * rng.standard_normal(
        st.n_params
    )
    _assert_exact_gradient(problem, p)


def test_the_free_run_stage_is_the_free_run_from_rest():
    # Its loss is the held-back score's run (from rest, the whole record)
    # on the training samples, and its gradient is exact.
    data = _wiener(200)
    st = NeuralStateSpace(2, hidden=(3,))
    problem = _Problem(st, data, 0.2, 1e-2)
    problem.batch(None)
    rng = np.random.default_rng(3)
    p = st.from_linear([-1.4, 0.6], [0.3, 0.15]) + 0.1 * rng.standard_normal(
        st.n_params
    )
    e = st.free_run(p, problem.us) - problem.ys
    train = ~_hold_mask(data.n, 0.2)
    w = p[st.network_mask()]
    expected = np.mean(e[train] ** 2) + 1e-2 * np.mean(w**2)
    assert problem.loss(p)[0] == pytest.approx(expected, rel=1e-12)
    _assert_exact_gradient(problem, p)


def test_the_free_run_stage_never_ends_worse_on_the_held_back_samples():
    est = _wiener(300)
    model = sid.identify(
        est,
        NeuralStateSpace(2, hidden=(4,)),
        method="oe",
        rng=1,
        horizon=50,
        free_run=True,
    )
    stages = model.result["schedule"]
    # Three starts, each ending on the free run (horizon None).
    assert [s[0] for s in stages[1::2]] == [None] * 3
    for before, after in zip(stages[::2], stages[1::2], strict=True):
        assert after[2] <= before[2]
    held = _hold_mask(est.n, 0.2)
    rms = np.sqrt(np.mean((model.simulate(est.u) - est.y)[held] ** 2))
    assert rms == pytest.approx(model.cost, rel=1e-9)
    assert rms <= min(s[2] for s in stages[::2]) + 1e-12


@pytest.fixture(scope="module")
def fitted():
    data = _wiener()
    est, val = data.split(0.7)
    model = sid.identify(est, NeuralStateSpace(2, hidden=(6,)), method="oe", rng=0)
    return model, est, val


def test_the_start_is_the_output_error_arx(fitted):
    model, est, _ = fitted
    arx = sid.identify(est, sid.ARX(2, 2, 1), method="oe")
    np.testing.assert_allclose(
        model.linear_start.simulate(est.u), arx.simulate(est.u), atol=1e-9
    )


def test_never_worse_than_the_linear_start_on_the_held_back_samples(fitted):
    model, est, _ = fitted
    # Recomputed here from the free run and the held-back blocks.
    held = _hold_mask(est.n, 0.2)
    rms = {
        name: np.sqrt(np.mean((m.simulate(est.u) - est.y)[held] ** 2))
        for name, m in (("model", model), ("linear", model.linear_start))
    }
    assert rms["model"] <= rms["linear"] + 1e-12
    assert model.cost == pytest.approx(rms["model"], rel=1e-9)


def test_it_learns_what_the_linear_model_misses(fitted):
    model, est, val = fitted
    fit = sid.validate(model, val, warmup=est).fit_percent
    linear = sid.validate(model.linear_start, val, warmup=est).fit_percent
    assert not model.result["kept_linear"]
    assert fit > linear + 5.0


def test_a_linear_record_keeps_or_matches_its_linear_start():
    rng = np.random.default_rng(4)
    u = rng.standard_normal(400)
    y = lfilter([0.0, 0.5], [1.0, -0.8], u) + 0.05 * rng.standard_normal(400)
    model = sid.identify(sid.IOData(u, y, ts=1.0), NeuralStateSpace(1, hidden=(3,)),
                         method="oe", rng=0)  # fmt: skip
    assert model.cost <= model.result["linear_cost"]


def test_the_model_file_reads_back(fitted, tmp_path):
    model, _, val = fitted
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    back = sid.sysid.load_model(path)
    assert isinstance(back, NeuralStateSpaceModel)
    np.testing.assert_array_equal(back.params, model.params)
    np.testing.assert_array_equal(back.simulate(val.u), model.simulate(val.u))
    np.testing.assert_array_equal(
        back.simulate(val.u, y0=val.y), model.simulate(val.u, y0=val.y)
    )


def test_a_run_from_measured_samples_starts_at_the_encoder_state(fitted):
    model, _, val = fitted
    w = model.structure.window
    run = model.simulate(val.u, y0=val.y)
    np.testing.assert_array_equal(run[:w], val.y[:w])
    assert np.sqrt(np.mean((run - val.y) ** 2)) < np.std(val.y)


def test_the_same_seed_gives_the_same_model():
    est = _wiener(300)
    a = sid.identify(est, NeuralStateSpace(2, hidden=(3,)), method="ls", rng=5)
    b = sid.identify(est, NeuralStateSpace(2, hidden=(3,)), method="ls", rng=5)
    np.testing.assert_array_equal(a.params, b.params)


@pytest.mark.parametrize(
    "make",
    [
        lambda: NeuralStateSpace(0),
        lambda: NeuralStateSpace(2, hidden=(3, 3)),
        lambda: NeuralStateSpace(3, window=2),
    ],
)
def test_a_bad_structure_is_refused_in_one_line(make):
    with pytest.raises(ValueError) as refused:
        make()
    assert "\n" not in str(refused.value)


@pytest.mark.parametrize(
    "options, error, name",
    [
        ({"holdout": 0.7}, ValueError, "holdout"),
        ({"decay": -1.0}, ValueError, "decay"),
        ({"horizon": 1}, ValueError, "horizon"),
        ({"max_iter": 2.5}, TypeError, "max_iter"),
        ({"free_run": 1}, TypeError, "free_run"),
        ({"method": "sda"}, ValueError, "method"),
    ],
)
def test_bad_options_are_refused_in_one_line(options, error, name):
    options = {"method": "ls", **options}
    with pytest.raises(error) as refused:
        sid.identify(_wiener(200), NeuralStateSpace(2, hidden=(2,)), **options)
    message = str(refused.value)
    assert "\n" not in message and f"`{name}`" in message


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--na", "2"], "not to --model nss"),
        (["--method", "sda"], "does not fit --model nss: spiral, oe, ls"),
        (["--activation", "logistic"], "not to --model nss"),
    ],
)
def test_the_command_line_refuses_what_nss_does_not_take(tmp_path, argv, message):
    from clitools import run

    proc = run("identify", "rec.npz", "--model", "nss", *argv, "--out", "m",
               cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
