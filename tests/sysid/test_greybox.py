"""The grey-box family against independent references: a mass-spring-damper
``(A, B, C, D)(k, c, m)`` simulated by SciPy, its parameters recovered from
a noisy record within their intervals, the nonlinear kind against the
linear kind on a linear ``f``, bad input refused in one line, and the JSON
form read back."""

import json
import os

import numpy as np
import pytest
from clitools import cli_env, run
from scipy import signal

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter

TRUE = np.array([4.0, 0.6, 1.5])  # k (N/m), c (N s/m), m (kg)
TS = 0.05


def msd(p):
    k, c, m = p
    return [[0.0, 1.0], [-k / m, -c / m]], [[0.0], [1.0 / m]], [[1.0, 0.0]], [[0.0]]


def msd_f(t, x, u, p):
    k, c, m = p
    return np.array([x[1], (u[0] - k * x[0] - c * x[1]) / m])


def msd_g(x, u, p):
    return x[0]


def parameters(values=(2.0, 1.0, 1.0), free=(True, True, True)):
    return [
        Parameter("k", values[0], (0.1, 20.0), "N/m", free=free[0]),
        Parameter("c", values[1], (0.01, 10.0), "N s/m", free=free[1]),
        Parameter("m", values[2], (0.1, 10.0), "kg", free=free[2]),
    ]


def record(n=600, noise=0.02, seed=1):
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.standard_normal(n // 10), 10)
    a, b, c, d = (np.asarray(m, dtype=float) for m in msd(TRUE))
    _, y, _ = signal.dlsim(signal.cont2discrete((a, b, c, d), TS, "zoh"), u)
    y = y.ravel()
    return sid.IOData(u, y + noise * np.std(y) * rng.standard_normal(n), ts=TS)


def test_the_linear_kind_is_scipys_zero_order_hold():
    rec = record(noise=0.0)
    box = GreyBox(parameters(TRUE), ss=msd)
    y = box.simulate(TRUE, rec.u, TS)
    np.testing.assert_allclose(y, rec.y, rtol=1e-10, atol=1e-12)
    t = np.arange(rec.u.size) * TS
    a, b, c, d = (np.asarray(m, dtype=float) for m in msd(TRUE))
    # lsim interpolates linearly between samples; a held input is exact at
    # the samples only with the hold's own steps, so compare to a fine grid.
    fine = np.arange(rec.u.size * 20) * TS / 20
    _, y_fine, _ = signal.lsim((a, b, c, d), np.repeat(rec.u, 20), fine, interp=False)
    np.testing.assert_allclose(y, y_fine[::20], atol=1e-9 * np.max(np.abs(y)))
    assert t.size == y.size


def test_the_nonlinear_kind_on_a_linear_f_is_the_linear_kind():
    rec = record(noise=0.0)
    lin = GreyBox(parameters(TRUE), ss=msd)
    non = GreyBox(parameters(TRUE), f=msd_f, g=msd_g, n_states=2, substeps=10)
    y_lin, y_non = lin.simulate(TRUE, rec.u, TS), non.simulate(TRUE, rec.u, TS)
    assert np.max(np.abs(y_non - y_lin)) < 1e-7 * np.max(np.abs(y_lin))


@pytest.fixture(scope="module")
def fitted():
    rec = record()
    return sid.identify(rec, GreyBox(parameters(), ss=msd), rng=0), rec


def test_the_spiral_recovers_the_parameters_within_their_intervals(fitted):
    model, rec = fitted
    assert isinstance(model, sid.sysid.LinearGreyBoxModel)
    assert model.method == "spiral" and not model.undetermined
    low, high = model.intervals.T
    assert np.all(low < TRUE) and np.all(TRUE < high), model.summary()
    np.testing.assert_allclose(model.params, TRUE, rtol=0.05)
    # Intervals are honest, not tiny: a few percent at 2 % noise.
    assert np.all((high - low) / TRUE > 1e-3)
    assert sid.validate(model, rec).fit_percent > 95
    assert model.is_stable and model.modes.frequency.size == 1


def test_local_and_paper_methods_by_name():
    rec = record()
    oe = sid.identify(rec, GreyBox(parameters(), ss=msd), method="oe")
    np.testing.assert_allclose(oe.params, TRUE, rtol=0.05)
    for method in ("sda", "ebsda"):
        model = sid.identify(
            rec, GreyBox(parameters(), ss=msd), method=method, rng=0, max_nfev=300
        )
        assert model.method == method and model.cost < 100


def test_a_parameter_the_record_cannot_determine_has_no_interval():
    # Scaling k, c and m together changes nothing but the gain; with the
    # output's gain through a free C, only the ratios are determined.
    rec = record()
    params = [*parameters(), Parameter("gain", 1.0, (0.1, 10.0))]
    model = sid.identify(rec, GreyBox(params, ss=scaled_ss), method="oe")
    assert model.undetermined, model.summary()
    assert np.all(np.isnan(model.intervals))
    assert "not determined" in model.summary()


def scaled_ss(p):
    k, c, m, gain = p
    a, b, _, d = msd((k, c, m))
    return a, b, [[gain, 0.0]], d


def test_fixed_parameters_stay_and_have_no_interval():
    rec = record()
    box = GreyBox(parameters(TRUE, free=(True, True, False)), ss=msd)
    model = sid.identify(rec, box, method="oe")
    assert model.values[2] == TRUE[2] and model.params.size == 2
    assert np.all(np.isnan(model.intervals[2])) and "fixed" in model.summary()


def _one_state(a):
    return lambda p: ([[a]], [[1.0]], [[1.0]], [[0.0]])


BAD = [
    (lambda: Parameter("k", 1.0, (0.0, np.inf)), "'k'"),
    (lambda: Parameter("k", 1.0, (5.0, 2.0)), "low < high"),
    (lambda: Parameter("k", 9.0, (1.0, 2.0)), "outside its bounds"),
    (lambda: Parameter("k", 1.0, (-1.0, 2.0), log=True), "log scale"),
    (lambda: GreyBox(parameters(), ss=lambda p: msd(p)[:3]), "`ss`"),
    (lambda: GreyBox(parameters(), ss=_one_state(np.nan)), "non-finite A"),
    (
        lambda: GreyBox(parameters(), f=lambda t, x, u, p: x[:1], g=msd_g, n_states=2),
        "`f`",
    ),
    (
        lambda: GreyBox(parameters(), f=msd_f, g=lambda x, u, p: np.nan, n_states=2),
        "`g`",
    ),
]


@pytest.mark.parametrize("make, words", BAD)
def test_bad_input_is_refused_in_one_line(make, words):
    with pytest.raises(ValueError) as refused:
        make()
    message = str(refused.value)
    assert "\n" not in message and words in message, message


def test_a_run_that_blows_up_costs_the_penalty_and_the_search_goes_on():
    def unstable(p):
        (a,) = p
        return [[a]], [[1.0]], [[1.0]], [[0.0]]

    box = GreyBox([Parameter("a", -1.0, (-2.0, 400.0))], ss=unstable)
    u = np.ones(400)
    y = box.simulate([400.0], u, 1.0)
    assert not np.all(np.isfinite(y))
    rec = sid.IOData(u, box.simulate([-1.0], u, 1.0) + 0.01, ts=1.0)
    model = sid.identify(rec, box, method="ebsda", rng=0, max_nfev=200)
    assert model.cost < 100


def test_the_json_form_reads_back_and_a_lambda_says_it_cannot_be_saved(
    fitted, tmp_path
):
    model, rec = fitted
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    back = sid.sysid.load_model(path)
    assert type(back) is type(model)
    np.testing.assert_array_equal(back.intervals, model.intervals)
    np.testing.assert_array_equal(back.simulate(rec), model.simulate(rec))
    anonymous = sid.identify(
        rec, GreyBox(parameters(), ss=lambda p: msd(p)), method="oe", polish_nfev=5
    )
    assert anonymous.summary() and sid.validate(anonymous, rec).fit_percent > 0
    with pytest.raises(ValueError) as refused:
        anonymous.to_dict()
    assert "\n" not in str(refused.value) and "lambda" in str(refused.value)


def test_the_nonlinear_kind_fits_by_oe():
    rec = record(n=300)
    box = GreyBox(parameters(), f=msd_f, g=msd_g, n_states=2, substeps=4)
    model = sid.identify(rec, box, method="oe", polish_nfev=60)
    assert type(model) is sid.sysid.GreyBoxModel and not model.is_linear
    assert model.linear_part is None
    np.testing.assert_allclose(model.params, TRUE, rtol=0.05)


def test_the_command_line_validates_a_saved_grey_box(tmp_path, monkeypatch):
    # The functions must be importable where the command runs: a module of
    # the user's, on its path.
    (tmp_path / "user_msd.py").write_text(
        "def msd(p):\n"
        "    k, c, m = p\n"
        "    return [[0, 1], [-k / m, -c / m]], [[0], [1 / m]], [[1, 0]], [[0]]\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    from user_msd import msd as user_ss

    rec = record(n=300)
    model = sid.identify(rec, GreyBox(parameters(), ss=user_ss), method="oe")
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "model.json").write_text(json.dumps(model.to_dict()))
    np.savez(tmp_path / "rec.npz", u=rec.u, y=rec.y, ts=rec.ts)
    path = os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])
    out = run("validate", "m/model.json", "rec.npz", "--quiet", cwd=tmp_path,
              env=cli_env(PYTHONPATH=path))  # fmt: skip
    assert out.returncode == 0, out.stderr
    # export writes ARX coefficients: a grey box is refused in one line.
    out = run("export", "m/model.json", cwd=tmp_path, env=cli_env(PYTHONPATH=path))
    assert out.returncode == 2
    assert out.stderr.strip().endswith(
        "'m/model.json' is a greybox model, not an ARX one (export takes the "
        "single-output ARX models of spiralid identify and spiralid pareto)"
    )
    assert "\n" not in out.stderr.strip()
