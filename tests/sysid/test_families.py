"""The common test over every family of the estimator table, after
scikit-learn's ``check_estimator``: each family fits a small record,
simulates, predicts, validates, goes through its JSON form and back, goes
through the command line (identify, then validate), and refuses an option
that does not apply and a bad input, each in one line.

A new family is tested by adding its case to :data:`CASES`; the first test
fails until every family of the table has one."""

import json

import numpy as np
import pytest
from clitools import run
from scipy.signal import lfilter

import spiralid as sid
from spiralid.sysid.estimation.core.families import ESTIMATORS, family_of
from spiralid.sysid.models.protocol import is_fitted

N = 400


def _record(outputs: int = 1) -> sid.IOData:
    """A noisy second-order record (of two outputs sharing the poles)."""
    rng = np.random.default_rng(3)
    u = rng.standard_normal(N)
    a = [1.0, -1.5, 0.7]
    ys = [lfilter([0.0, 1.0, 0.5], a, u), lfilter([0.0, 0.4, -0.2], a, u)][:outputs]
    ys = [y + 0.01 * np.std(y) * rng.standard_normal(N) for y in ys]
    y = ys[0] if outputs == 1 else np.column_stack(ys)
    names = "y" if outputs == 1 else ("near", "far")
    return sid.IOData(u, y, ts=0.01, output_name=names)


def second_order(p):
    """A continuous second-order system near the record's poles (a grey box
    of two parameters, at module level so that its model.json can name it)."""
    wn, zeta = p
    a = [[0.0, 1.0], [-(wn**2), -2.0 * zeta * wn]]
    return a, [[0.0], [7.5 * wn**2]], [[1.0, 0.0]], [[0.0]]


GREYBOX = sid.sysid.GreyBox(
    [
        sid.sysid.Parameter("wn", 45.0, (10.0, 100.0), "rad/s"),
        sid.sysid.Parameter("zeta", 0.4, (0.05, 1.0)),
    ],
    ss=second_order,
)

# family: (structure, outputs of the record, the CLI's structure flags: None
# where the command line cannot build the structure from flags), and the
# family's quickest method where it has no least squares.
CASES = {
    "arx": (sid.ARX(2, 2, 1), 1, ["--na", "2", "--nb", "2", "--nk", "1"]),
    "narx": (
        sid.NARX(2, 2, 1, hidden=(2,)),
        1,
        ["--model", "narx", "--na", "2", "--nb", "2", "--nk", "1", "--hidden", "2"],
    ),
    "polynomial-narx": (
        sid.PolynomialNARX(2, 2, 1, degree=2, n_terms=4),
        1,
        ["--model", "polynomial", "--na", "2", "--nb", "2", "--nk", "1"],
    ),
    "shared-denominator": (
        sid.ARX(2, 2, 1),
        2,
        ["--na", "2", "--nb", "2", "--nk", "1", "--output", "near,far"],
    ),
    "greybox": (GREYBOX, 1, None),
    "neural-state-space": (
        sid.sysid.NeuralStateSpace(2, hidden=(3,)),
        1,
        ["--model", "nss", "--order", "2", "--hidden", "3"],
    ),
}
QUICKEST = {"greybox": "oe", "neural-state-space": "oe"}
FAMILIES = sorted(CASES)


def test_every_family_of_the_table_has_a_case():
    assert {family for family, _ in ESTIMATORS} == set(CASES)


@pytest.fixture(scope="module")
def fitted():
    """Each family's model by least squares (every family has it), with
    its estimation and validation parts."""
    out = {}
    for family, (structure, outputs, _) in CASES.items():
        est, val = _record(outputs).split(0.6)
        out[family] = identify_ls(est, structure), est, val
    return out


def identify_ls(data, structure):
    return sid.identify(data, structure, method=_quickest(structure), rng=0)


def _quickest(structure) -> str:
    """Least squares, or the family's quickest method without it."""
    return QUICKEST.get(structure.family, "ls")


@pytest.mark.parametrize("family", FAMILIES)
def test_the_fit_implements_the_protocol(fitted, family):
    model = fitted[family][0]
    assert is_fitted(model)
    assert family_of(model.structure, len(model.output_names)) == family
    assert model.params.ndim == 1 and np.all(np.isfinite(model.params))
    assert isinstance(model.summary(), str) and model.summary()
    assert hasattr(model, "modes") is model.is_linear
    assert hasattr(model, "is_stable") is model.is_linear


@pytest.mark.parametrize("family", FAMILIES)
def test_simulate_and_predict_have_the_record_shape(fitted, family):
    model, est, _ = fitted[family]
    shape = est.y.shape
    sim, pred = model.simulate(est.u), model.predict(est)
    assert sim.shape == shape and pred.shape == shape
    assert np.all(np.isfinite(sim)) and np.all(np.isfinite(pred))


@pytest.mark.parametrize("family", FAMILIES)
def test_validate_gives_one_type(fitted, family):
    model, est, val = fitted[family]
    v = sid.validate(model, val, warmup=est)
    assert type(v) is sid.Validation and v.fit_percent > 50
    several = len(model.output_names) > 1
    assert (v.outputs is not None) is several
    json.dumps(v.to_dict())
    assert v.summary()


@pytest.mark.parametrize("family", FAMILIES)
def test_the_json_form_reads_back(fitted, family, tmp_path):
    model, est, _ = fitted[family]
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    for back in (
        sid.sysid.load_model(json.loads(path.read_text())),
        sid.sysid.load_model(path),
    ):
        assert type(back) is type(model)
        np.testing.assert_array_equal(back.params, model.params)
        np.testing.assert_allclose(back.simulate(est.u), model.simulate(est.u))


@pytest.mark.parametrize("family", FAMILIES)
def test_an_option_that_does_not_apply_is_refused_in_one_line(family):
    structure, outputs, _ = CASES[family]
    with pytest.raises(ValueError) as refused:
        sid.identify(
            _record(outputs), structure, method=_quickest(structure), n_points=5
        )
    message = str(refused.value)
    assert "\n" not in message and "`n_points`" in message


@pytest.mark.parametrize("family", FAMILIES)
def test_bad_input_is_refused_in_one_line(fitted, family):
    # A wrong type is a TypeError, a wrong value a ValueError (as SciPy),
    # each one line that names the argument.
    structure, outputs, _ = CASES[family]
    model = fitted[family][0]
    for call in (
        lambda: sid.identify("data.csv", structure, method=_quickest(structure)),
        lambda: sid.validate(model, "data.csv"),
    ):
        with pytest.raises(TypeError) as refused:
            call()
        message = str(refused.value)
        assert "\n" not in message and "`data`" in message
    rec = _record(outputs)
    too_short = sid.IOData(rec.u[:3], rec.y[:3], ts=rec.ts, output_name=rec.output_name)
    with pytest.raises(ValueError) as refused:
        sid.identify(too_short, structure, method=_quickest(structure))
    assert "\n" not in str(refused.value)


@pytest.mark.parametrize("family", FAMILIES)
def test_the_command_line_identifies_then_validates(family, tmp_path):
    _, outputs, flags = CASES[family]
    if flags is None:
        pytest.skip(f"the command line cannot build a {family} structure from flags")
    rec = _record(outputs)
    columns = (
        {"y": rec.y}
        if outputs == 1
        else dict(zip(rec.output_names, rec.y.T, strict=True))
    )
    np.savez(tmp_path / "rec.npz", u=rec.u, ts=rec.ts, **columns)
    out = run("identify", "rec.npz", "--method", "ls", *flags, "--out", "m",
              "--quiet", cwd=tmp_path)  # fmt: skip
    assert out.returncode == 0, out.stderr
    # The summary prints the model's cost under what it is for the family
    # (eq. 2 by default; a shared fit's joint cost says so itself).
    model = sid.sysid.load_model(tmp_path / "m" / "model.json")
    summary = (tmp_path / "m" / "summary.txt").read_text()
    assert f"{model.cost:.6g}" in summary
    if hasattr(model, "cost_label"):
        assert f"{model.cost_label}: {model.cost:.6g}" in summary
        assert "eq. 2" not in summary.split("\n\n")[1]
    out = run("validate", "m/model.json", "rec.npz", "--quiet", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
