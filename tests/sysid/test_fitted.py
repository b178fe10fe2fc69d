"""One fitted-model type: an ARX fit and a NARX fit share their provenance,
its JSON form and one reader, and validate dispatches on the structure."""

import dataclasses
import json

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import (
    ARX,
    NARX,
    FittedModel,
    IdentifiedModel,
    IOData,
    NARXModel,
    PolynomialNARX,
    SharedDenominatorModel,
    identify,
    load_model,
    validate,
)
from spiralid.sysid.models.fitted import Provenance
from spiralid.sysid.validation.validate import Validation


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(400)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    y = y + 0.3 * np.tanh(y) + 0.01 * rng.standard_normal(u.size)
    return IOData(u, y, ts=0.01, input_name="torque", output_name="angle")


@pytest.fixture(scope="module")
def fits(record):
    return {
        "arx": identify(record, ARX(2, 2, 1), method="ls"),
        "narx": identify(record, NARX(2, 2, 1, hidden=(3,)), method="ls", rng=0),
        "polynomial": identify(
            record, PolynomialNARX(2, 2, 1, degree=2, n_terms=5), method="ls"
        ),
    }


PROVENANCE = [f.name for f in dataclasses.fields(FittedModel)]


def test_every_fit_is_one_fitted_model_type(fits):
    for model in fits.values():
        assert isinstance(model, FittedModel)
        assert model.params.shape == (model.structure.n_params,)
        assert model.input_name == "torque" and model.output_name == "angle"
    assert isinstance(fits["arx"], IdentifiedModel)
    assert isinstance(fits["narx"], NARXModel)


def test_the_provenance_is_written_alike_by_every_model(fits):
    """The same provenance keys, with the same values for the same fields,
    whatever the structure (NARX once lacked `fraction`)."""
    for model in fits.values():
        model.fraction = 0.5
        d = model.to_dict()
        missing = [k for k in PROVENANCE if k not in d]
        assert not missing, (type(model).__name__, missing)
        assert d["fraction"] == 0.5 and d["method"] == "ls"
        assert d["input_name"] == "torque"


@pytest.mark.parametrize("kind", ["arx", "narx", "polynomial"])
def test_load_model_reads_back_every_kind(fits, record, kind):
    model = fits[kind]
    text = json.dumps(model.to_dict(timings=False))
    back = load_model(json.loads(text))
    assert type(back) is type(model)
    np.testing.assert_array_equal(back.params, model.params)
    np.testing.assert_array_equal(back.simulate(record.u), model.simulate(record.u))
    for name in PROVENANCE:
        if name not in ("result", "timings", "history"):
            assert getattr(back, name) == pytest.approx(getattr(model, name)), name


def test_load_model_reads_a_shared_denominator_model():
    model = SharedDenominatorModel(
        a=[-1.5, 0.7], b=[[1.0, 0.5], [0.2, 0.1]], arx=ARX(2, 2, 1), ts=0.01,
        output_names=("a", "b"),
    )  # fmt: skip
    back = load_model(json.loads(json.dumps(model.to_dict())))
    assert isinstance(back, SharedDenominatorModel)
    np.testing.assert_array_equal(back.b, model.b)


def _shared(**provenance):
    return SharedDenominatorModel(
        a=[-1.5, 0.7], b=[[1.0, 0.5], [0.2, 0.1]], arx=ARX(2, 2, 1), ts=0.01,
        output_names=("a", "b"), **provenance,
    )  # fmt: skip


def test_a_shared_denominator_model_writes_the_same_provenance():
    """The record-wide provenance of every fitted model, in the same keys;
    the estimator's wall time is not in the result summary, and the wall
    times leave the file on request, as a one-output model's."""
    model = _shared(
        method="oe", fraction=0.5, timings={"total": 1.5},
        result={"nfev": 12, "message": "done", "elapsed": 1.5},
    )  # fmt: skip
    d = json.loads(json.dumps(model.to_dict()))
    keys = [f.name for f in dataclasses.fields(Provenance)]
    assert not [k for k in keys if k not in d]
    assert d["result"] == {"nfev": 12, "message": "done"}
    assert d["fraction"] == 0.5 and d["timings"] == {"total": 1.5}
    assert d["predictor"] == "simulation" and d["gain"] is None
    assert "timings" not in model.to_dict(timings=False)
    back = load_model(d)
    for name in keys:
        if name != "result":
            expected = pytest.approx(getattr(model, name), nan_ok=True)
            assert getattr(back, name) == expected, name


def test_a_shared_denominator_file_written_before_the_shared_provenance_loads():
    """A file as the several-output model wrote it before: only its method,
    cost (null when NaN), input name, unit and offset of the provenance."""
    d = _shared(method="spiral", u_offset=0.25).to_dict()
    for key in ("predictor", "initial", "gain", "penalty", "history", "timings",
                "fraction", "result"):  # fmt: skip
        del d[key]
    d["cost"] = None
    back = load_model(json.loads(json.dumps(d)))
    assert isinstance(back, SharedDenominatorModel)
    assert back.method == "spiral" and back.u_offset == 0.25
    assert np.isnan(back.cost) and np.isnan(back.gain)
    assert (back.predictor, back.initial, back.penalty) == ("simulation", "rest", 0.0)
    assert back.fraction is None and back.timings == {}


@pytest.mark.parametrize(
    ("d", "named"),
    [
        ({"model": "tree"}, "field 'model' must be one of arx, narx"),
        ([1, 2], "a model must be a JSON object"),
    ],
)
def test_load_model_refuses_what_it_cannot_read(d, named):
    with pytest.raises(ValueError, match=named):
        load_model(d)


def test_validate_gives_one_type_whatever_the_structure(fits, record):
    """One Validation; the structure decides which part it fills in."""
    assert fits["arx"].is_linear and not fits["narx"].is_linear
    reports = {kind: validate(model, record) for kind, model in fits.items()}
    assert {type(v) for v in reports.values()} == {Validation}
    assert reports["arx"].is_linear and reports["arx"].nonlinear is None
    for kind in ("narx", "polynomial"):
        v = reports[kind]
        assert not v.is_linear and v.nonlinear is not None
        assert v.stable is None and v.realization is None and v.poles.size == 0


def test_the_linear_part(fits, record):
    """An ARX fit is its own linear part; a NARX's is its linear start,
    the ARX with the same lags (network output weights zero)."""
    assert fits["arx"].linear_part is fits["arx"]
    lin = fits["narx"].linear_part
    assert lin is not None and isinstance(lin, NARXModel)
    # Without an integrator the linear start is ARX(ny, nu, nk) by the
    # method's own linear estimate (least squares here).
    two = identify(record, ARX(2, 2, 1), method="ls")
    y_lin = lin.simulate(record.u)
    assert np.max(np.abs(y_lin - two.simulate(record.u))) < 1e-6 * np.ptp(record.y)


@pytest.mark.parametrize("tolerance", [0.0, 1.0, 100.0])
def test_choose_order_among_models_of_any_structure(record, tolerance):
    """The smallest model (by parameters) whose held-out fit is within
    `tolerance` of the best, worked out here from each model's own fit."""
    from spiralid.sysid import choose_order

    est, val = record.split(2 / 3)
    models = [
        identify(est, NARX(n, n, 1, hidden=(h,)), method="ls", rng=0)
        for n in (1, 2)
        for h in (2, 4)
    ]
    fits = [validate(m, val, warmup=est).fit_percent for m in models]
    ok = [i for i, f in enumerate(fits) if f >= max(fits) - tolerance]
    want = min(ok, key=lambda i: models[i].params.size)
    assert choose_order(models, val, warmup=est, tolerance=tolerance) == want


def test_choose_order_refuses_what_is_not_a_model(record):
    from spiralid.sysid import choose_order

    with pytest.raises(ValueError, match="non-empty list of fitted models"):
        choose_order([], record)
    with pytest.raises(ValueError, match="non-empty list of fitted models"):
        choose_order([ARX(2, 2, 1)], record)


@pytest.mark.parametrize(
    ("pair", "kind", "want"),
    [
        ((13.31049, 13.31061), "g", ".5g"),  # 13.31 twice at four, 13.311 at five
        ((13.310504, 13.310506), "g", ".7g"),
        ((13.2, 13.4), "g", ".4g"),
        ((0.019995, 0.020004), "f", ".5f"),  # 0.0200 at four, 0.02000 at five
        ((float("nan"), 1.0), "g", ".4g"),
    ],
)
def test_interval_format_tells_the_ends_apart(pair, kind, want):
    from spiralid.sysid.models.modes import interval_format

    fmt = interval_format(pair, kind)
    assert fmt == want
    if all(np.isfinite(pair)):
        assert format(pair[0], fmt) != format(pair[1], fmt)
