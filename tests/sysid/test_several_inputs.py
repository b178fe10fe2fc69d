"""Records of several inputs: IOData, the readers, the one-line refusals of
every function that takes one input, and the shared denominator over every
input-output pair (its cost, estimate, model and validation)."""

import numpy as np
import pytest
from scipy import signal
from scipy.signal import lfilter

from spiralid.sysid import (
    ARX,
    NARX,
    IOData,
    PaperCost,
    PolynomialNARX,
    ProjectedCost,
    SharedDenominatorModel,
    arx_least_squares,
    identify,
    identify_pareto,
    mac,
    steiglitz_mcbride,
    subspace_denominator,
    validate,
)
from spiralid.sysid.estimation.linear.frequency import h1_estimate
from spiralid.sysid.estimation.shared.denominator import SharedProjectedCost
from spiralid.sysid.estimation.shared.inputs import SharedInputsCost
from spiralid.sysid.models.shapes import normalise_shapes

A = np.poly(
    [0.95 * np.exp(0.4j), 0.95 * np.exp(-0.4j), 0.9 * np.exp(1.2j), 0.9 * np.exp(-1.2j)]
).real
# B[i][j]: output i from input j, delay 1.
B = [[[1.0, 0.3], [0.5, 0.1]], [[0.2, -0.5], [-0.4, 0.6]]]


def _record(n=1500, noise=0.0, seed=1):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, 2))
    y = np.column_stack(
        [sum(lfilter([0.0, *B[i][j]], A, u[:, j]) for j in range(2)) for i in range(2)]
    )
    y += noise * rng.standard_normal(y.shape)
    return IOData(u, y, ts=0.01, input_name=("f1", "f2"), output_name=("p", "q"))


# -- IOData ----------------------------------------------------------------------


def test_several_inputs_hold_a_name_unit_and_offset_each():
    d = IOData(np.ones((4, 3)), np.arange(4.0), ts=1.0, input_unit="N")
    assert d.u.shape == (4, 3) and d.n == 4 and d.n_inputs == 3
    assert d.input_names == ("u1", "u2", "u3")
    assert d.input_units == ("N",) * 3 and d.u_offsets == (0.0,) * 3
    one = IOData(np.ones(4), np.arange(4.0), ts=1.0)
    assert one.u.shape == (4,) and one.input_name == "u" and one.inputs.shape == (4, 1)
    assert "('u1', 'u2', 'u3')" in repr(d)
    with pytest.raises(ValueError, match="`input_unit` must have one entry per input"):
        IOData(np.ones((4, 2)), np.arange(4.0), ts=1.0, input_unit=("a", "b", "c"))
    with pytest.raises(ValueError, match="`input_name` must name each input once"):
        IOData(np.ones((4, 2)), np.arange(4.0), ts=1.0, input_name=("a", "a"))
    with pytest.raises(ValueError, match=r"`u\[:, 1\]` must be finite"):
        IOData([[0.0, 1.0], [0.0, np.nan]], [1.0, 2.0], ts=1.0)


def test_input_selection_slicing_and_detrend_keep_each_input():
    rng = np.random.default_rng(0)
    u = rng.standard_normal((10, 2)) + np.array([3.0, -1.0])
    d = IOData(u, rng.standard_normal(10), ts=0.5, input_name=("a", "b"))
    second = d.input("b")
    assert second.u.shape == (10,) and second.input_name == "b"
    np.testing.assert_array_equal(second.u, u[:, 1])
    est, val = d.split(0.6)
    assert est.u.shape == (6, 2) and val.input_names == ("a", "b")
    flat = d.detrend(like=est)
    np.testing.assert_allclose(flat.u, u - u[:6].mean(axis=0))
    np.testing.assert_allclose(flat.u_offsets, u[:6].mean(axis=0))
    with pytest.raises(ValueError, match="`like` must have the record's 2 input"):
        d.detrend(like=IOData(np.ones(3), np.ones(3), ts=0.5))


def test_readers_take_a_list_of_inputs(tmp_path):
    path = tmp_path / "two.csv"
    path.write_text("f1 [N],f2 [N],acc [m/s^2]\n1,2,3\n4,5,6\n7,8,9\n")
    d = IOData.from_csv(path, input=["f1", "f2"], output="acc", ts=0.1)
    assert d.input_names == ("f1", "f2") and d.input_units == ("N", "N")
    np.testing.assert_array_equal(d.u, [[1, 2], [4, 5], [7, 8]])
    npz = tmp_path / "two.npz"
    np.savez(npz, a=np.arange(5.0), b=np.ones(5), y=np.zeros(5), ts=0.2)
    n = IOData.from_npz(npz, input=["a", "b"], output="y")
    assert n.input_names == ("a", "b") and n.u.shape == (5, 2) and n.ts == 0.2
    np.savez(tmp_path / "bad.npz", a=np.arange(5.0), b=np.ones(4), y=np.zeros(5))
    with pytest.raises(ValueError, match="`input` variables must have the same len"):
        IOData.from_npz(tmp_path / "bad.npz", input=["a", "b"], output="y", ts=1.0)


# -- what takes one input refuses several, in one line -----------------------------

_TWO = _record(200)
_ONE_OUT = _TWO.output("p")

REFUSALS = [
    ("arx_least_squares", lambda: arx_least_squares(_ONE_OUT, ARX(2, 2, 1))),
    ("the ARX regressors", lambda: ARX(2, 2, 1).regressors(_ONE_OUT)),
    ("PaperCost", lambda: PaperCost(ARX(2, 2, 1), _ONE_OUT)),
    ("PaperCost", lambda: ProjectedCost(ARX(2, 2, 1), _ONE_OUT)),
    ("steiglitz_mcbride", lambda: steiglitz_mcbride(_ONE_OUT, ARX(2, 2, 1))),
    ("identify_pareto", lambda: identify_pareto(_ONE_OUT, [ARX(2, 2, 1)])),
    ("identify", lambda: identify(_ONE_OUT, NARX(2, 2, 1))),
    ("identify", lambda: identify(_ONE_OUT, PolynomialNARX(2, 2, 1))),
    ("the H1 estimate", lambda: h1_estimate(_ONE_OUT)),
    ("validate", lambda: validate(identify(_TWO.input(0).output(0), ARX(2, 2, 1),
                                           method="ls"), _ONE_OUT)),
]  # fmt: skip


@pytest.mark.parametrize(
    "what,call", REFUSALS, ids=[f"{i}" for i in range(len(REFUSALS))]
)
def test_functions_of_one_input_refuse_several_in_one_line(what, call):
    with pytest.raises(ValueError) as err:
        call()
    message = str(err.value)
    assert "\n" not in message and "has 2 inputs ('f1', 'f2')" in message
    assert what in message


def test_a_one_input_method_on_several_inputs_names_the_shared_ones():
    with pytest.raises(ValueError, match="`method` 'sda' takes one output \\(and one"):
        identify(_TWO, ARX(2, 2, 1), method="sda")


# -- the shared denominator over every pair ---------------------------------------


def test_the_inputs_cost_of_one_input_is_the_compiled_one():
    # The NumPy projection (QR, Golub-Pereyra Jacobian) against the
    # compiled single-input kernels, on a record of one input.
    d = _record(600, noise=0.05).input(0)
    arx = ARX(4, 2, 1)
    mine, ref = SharedInputsCost(arx, d), SharedProjectedCost(arx, d)
    a = A[1:] + 0.01
    assert mine(a) == pytest.approx(ref(a), rel=1e-10)
    np.testing.assert_allclose(mine.numerators(a), ref.numerators(a), rtol=1e-8)
    s1, g1, h1 = mine.normal_equations(a)
    s2, g2, h2 = ref.normal_equations(a)
    assert s1 == pytest.approx(s2, rel=1e-10)
    np.testing.assert_allclose(g1, g2, rtol=1e-6, atol=1e-9 * np.abs(g2).max())
    np.testing.assert_allclose(h1, h2, rtol=1e-6, atol=1e-9 * np.abs(h2).max())


def test_the_jacobian_of_several_inputs_is_the_residual_s_derivative():
    d = _record(400, noise=0.1)
    cost = SharedInputsCost(ARX(4, 2, 1), d)
    a = A[1:] + 0.02
    _, jac = cost.parts[1].residual(a)
    step = 1e-6
    for k in range(4):
        da = np.zeros(4)
        da[k] = step
        plus = cost.parts[1].residual(a + da)[0]
        minus = cost.parts[1].residual(a - da)[0]
        np.testing.assert_allclose(
            jac[:, k], (plus - minus) / (2 * step), atol=1e-5 * np.abs(jac).max()
        )


@pytest.mark.parametrize("method", ["oe", "spiral"])
def test_a_noise_free_record_of_two_inputs_gives_its_system(method):
    d = _record()
    kw = {"max_nfev": 600} if method == "spiral" else {}
    fit = identify(d, ARX(4, 2, 1), method=method, rng=0, **kw)
    assert isinstance(fit, SharedDenominatorModel) and fit.n_inputs == 2
    np.testing.assert_allclose(fit.a, A[1:], atol=1e-7)
    for i in range(2):
        for j in range(2):
            np.testing.assert_allclose(fit.numerator(i, j), B[i][j], atol=1e-6)
    assert fit.input_names == ("f1", "f2")


def test_least_squares_of_two_inputs_is_exact_without_noise():
    fit = identify(_record(), ARX(4, 2, 1), method="ls")
    np.testing.assert_allclose(fit.a, A[1:], atol=1e-8)
    np.testing.assert_allclose(fit.b[1], [*B[1][0], *B[1][1]], atol=1e-8)


def test_the_subspace_poles_of_two_inputs_are_the_system_s():
    got = subspace_denominator(_record(800), 4)
    np.testing.assert_allclose(got, A[1:], atol=1e-8)


def test_the_model_of_two_inputs_runs_predicts_and_is_saved():
    d = _record(500, noise=0.02)
    fit = identify(d, ARX(4, 2, 1), method="oe")
    # The free run is the sum of each pair's filter (SciPy's, independently).
    expect = np.column_stack(
        [
            sum(
                lfilter([0.0, *fit.numerator(i, j)], [1.0, *fit.a], d.u[:, j])
                for j in range(2)
            )
            for i in range(2)
        ]
    )  # fmt: skip
    np.testing.assert_allclose(fit.simulate(d), expect, atol=1e-10)
    _, y_ss, _ = signal.dlsim(fit.to_dlti(), d.u)
    np.testing.assert_allclose(y_ss, expect, atol=1e-8)
    # One step ahead: y - (A y - sum_j B_j u_j), by hand for the first output.
    a_y = lfilter([1.0, *fit.a], [1.0], d.y[:, 0])
    b_u = sum(lfilter([0.0, *fit.numerator(0, j)], [1.0], d.u[:, j]) for j in range(2))
    np.testing.assert_allclose(fit.predict(d)[:, 0], d.y[:, 0] - a_y + b_u, atol=1e-12)
    back = SharedDenominatorModel.from_dict(fit.to_dict())
    np.testing.assert_array_equal(back.b, fit.b)
    assert back.input_names == ("f1", "f2") and back.n_inputs == 2
    assert len(fit.modes) == 2 and fit.modes.share.shape == (2, 2)
    with pytest.raises(ValueError, match="`input` must name one of the model's inputs"):
        fit.output_model("p")
    assert fit.output_model("p", "f2").input_name == "f2"


def test_validation_of_two_inputs_fits_each_output_from_both():
    d = _record(900, noise=0.05, seed=4)
    est, val = d.split()
    fit = identify(est, ARX(4, 2, 1), method="oe")
    v = validate(fit, val, warmup=est)
    for i, name in enumerate(("p", "q")):
        one = v.outputs[name]
        y = val.y[:, i]
        whole = fit.simulate(d)[est.n :, i]
        expect = 100 * (1 - np.linalg.norm(y - whole) / np.linalg.norm(y - y.mean()))
        assert one.fit_percent == pytest.approx(expect, rel=1e-9)
        assert one.fit_percent > 95
    assert v.fit_percent > 95 and "joint fit" in str(v)
    with pytest.raises(ValueError, match="`data` must hold the model's 2 inputs"):
        validate(fit, val.input(0))


def test_the_command_fits_and_validates_two_inputs(tmp_path):
    """`identify --input f1,f2` fits one denominator over every pair and
    `validate` reads the model's inputs back by name; a command of one
    input refuses two in one line."""
    from clitools import run

    d = _record(900, noise=0.02)
    table = np.column_stack([d.t, d.u, d.y])
    np.savetxt(tmp_path / "two.csv", table, delimiter=",", comments="",
               header="time_s,f1 [N],f2 [N],p [m],q [m]")  # fmt: skip
    out = run("identify", "two.csv", "--input", "f1,f2", "--output", "p,q",
              "--na", "4", "--nb", "2", "--nk", "1", "--method", "oe",
              "--out", "m", cwd=tmp_path)  # fmt: skip
    assert out.returncode == 0, out.stderr
    model = SharedDenominatorModel.from_dict(
        __import__("json").loads((tmp_path / "m" / "model.json").read_text())
    )
    assert model.input_names == ("f1", "f2") and model.input_units == ("N", "N")
    np.testing.assert_allclose(model.a, A[1:], atol=1e-3)
    out = run("validate", "m/model.json", "two.csv", "--out", "v", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "fit % of q" in (tmp_path / "v" / "summary.txt").read_text()
    out = run("pareto", "two.csv", "--input", "f1,f2", "--output", "p", "--out", "x",
              cwd=tmp_path)  # fmt: skip
    assert out.returncode == 2 and "this command takes one input" in out.stderr


def test_each_input_s_shapes_are_scipys_residues_of_its_pairs():
    """A model of two inputs has shapes per input: each output's residue of
    ``B_ij / A`` at each mode's pole (SciPy's ``residuez``), normalised;
    ``shapes`` alone asks which input, in one line."""
    fit = identify(_record(), ARX(4, 2, 1), method="ls")
    with pytest.raises(ValueError, match=r"input_shapes\(input\)"):
        _ = fit.shapes
    for j, name in enumerate(("f1", "f2")):
        got = fit.input_shapes(name)
        poles = fit.modes.table.poles
        want = np.empty((len(poles), 2), dtype=complex)
        for i in range(2):
            r, p, _ = signal.residuez(np.r_[0.0, B[i][j]], A)
            want[:, i] = [r[np.argmin(np.abs(p - pole))] for pole in poles]
        np.testing.assert_allclose(
            np.abs(mac(got.shapes, want).diagonal()), 1.0, rtol=1e-9
        )
        np.testing.assert_allclose(got.shapes, normalise_shapes(want), atol=1e-7)


def test_the_covariance_of_two_inputs_is_the_finite_difference_one():
    """The shapes' factor of a fit of two inputs: ``R' R`` equals ``s^2
    (J' J)^-1`` of the weighted simulation error of every output, ``J`` by
    finite differences of SciPy's ``lfilter`` runs of every pair."""
    data = _record(600, noise=0.05, seed=4)
    fit = identify(data, ARX(4, 2, 1), method="oe")
    na, nb = 4, 2

    def residual(theta):
        a, b = theta[:na], theta[na:].reshape(2, 2 * nb)
        den = np.r_[1.0, a]
        out = []
        for i, w in enumerate(np.sqrt(fit.weights)):
            sim = sum(
                lfilter([0.0, *b[i, j * nb : (j + 1) * nb]], den, data.u[:, j])
                for j in range(2)
            )
            out.append(w * (sim - data.y[:, i]))
        return np.concatenate(out)

    theta = np.r_[fit.a, fit.b.ravel()]
    r0, h = residual(theta), 1e-7
    jac = np.column_stack(
        [(residual(theta + h * e) - r0) / h for e in np.eye(theta.size)]
    )
    s2 = r0 @ r0 / (r0.size - theta.size)
    want = s2 * np.linalg.inv(jac.T @ jac)
    got = fit.shape_factor.T @ fit.shape_factor
    np.testing.assert_allclose(got, want, rtol=1e-3, atol=1e-12)
    shapes = fit.input_shapes("f2")
    assert np.all(np.isfinite(shapes.real_interval))
