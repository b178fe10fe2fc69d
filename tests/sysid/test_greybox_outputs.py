"""A grey box of several outputs against independent references: a
mass-spring-damper whose position is measured well and whose velocity is
measured badly (noise of known standard deviations added to SciPy's exact
zero-order-hold run). The noise variances the fit estimates are the ones
added; the well-measured output is not drowned by the noisy one (the fit of
both is as good as the position's alone, and better than weighting the
outputs by their RMS only); each output's fit is ``validate``'s; the JSON
form reads back; a record and a model of different output counts are
refused in one line."""

import json

import numpy as np
import pytest
from scipy import signal

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter
from spiralid.sysid.estimation.greybox import fit as greybox_fit

TRUE = np.array([4.0, 0.6, 1.5])  # k (N/m), c (N s/m), m (kg)
TS = 0.05
NAMES = ("position", "velocity")
# Noise of each output, in shares of its standard deviation: a good
# position sensor, a velocity as noisy as it is large.
NOISE = np.array([0.01, 1.0])


def msd2(p):
    """The mass-spring-damper with position and velocity measured."""
    k, c, m = p
    a = [[0.0, 1.0], [-k / m, -c / m]]
    return a, [[0.0], [1.0 / m]], np.eye(2), np.zeros((2, 1))


def msd2_f(t, x, u, p):
    k, c, m = p
    return np.array([x[1], (u[0] - k * x[0] - c * x[1]) / m])


def msd2_g(x, u, p):
    return np.array([x[0], x[1]])


def msd3_g(x, u, p):
    return np.array([x[0], x[1], x[0] + x[1]])


def parameters():
    return [
        Parameter("k", 2.0, (0.1, 20.0), "N/m"),
        Parameter("c", 1.0, (0.01, 10.0), "N s/m"),
        Parameter("m", 1.0, (0.1, 10.0), "kg"),
    ]


def exact(n=600, seed=1):
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.standard_normal(n // 10), 10)
    a, b, c, d = (np.asarray(x, dtype=float) for x in msd2(TRUE))
    _, y, _ = signal.dlsim(signal.cont2discrete((a, b, c, d), TS, "zoh"), u)
    return u, y


def record(seed=1):
    u, y = exact(seed=seed)
    sd = NOISE * y.std(axis=0)
    noisy = y + sd * np.random.default_rng(seed + 100).standard_normal(y.shape)
    return sid.IOData(u, noisy, ts=TS, output_name=NAMES), sd


def error(model):
    return float(np.linalg.norm(model.values / TRUE - 1.0))


@pytest.fixture(scope="module")
def fits():
    rec, sd = record()
    both = sid.identify(rec, GreyBox(parameters(), ss=msd2), method="oe")
    position = sid.identify(
        rec.output("position"), GreyBox(parameters(), ss=_position), method="oe"
    )
    return rec, sd, both, position


def _position(p):
    a, b, c, d = msd2(p)
    return a, b, c[:1], d[:1]


def test_the_weights_are_the_noise_variances_added(fits):
    _, sd, both, _ = fits
    assert both.output_names == NAMES
    np.testing.assert_allclose(both.weights, 1.0 / sd**2, rtol=0.15)
    assert "noise sd" in both.summary()


def test_the_well_measured_output_is_not_drowned_by_the_noisy_one(fits, monkeypatch):
    rec, _, both, position = fits
    # The position alone is the best one can do here (the velocity adds
    # little); both together must be as good, within a share.
    assert error(both) <= 1.2 * error(position)
    # Weighting by the outputs' RMS only (no reweighting) lets the noisy
    # velocity pull the parameters.
    monkeypatch.setattr(greybox_fit, "_REWEIGHTS", 0)
    rms_only = sid.identify(rec, GreyBox(parameters(), ss=msd2), method="oe")
    assert error(both) < 0.5 * error(rms_only)
    # The intervals of the weighted fit cover the truth, and are about as
    # narrow as the position's alone.
    low, high = both.intervals.T
    assert np.all((low <= TRUE) & (TRUE <= high)), (both.intervals, TRUE)
    width, alone = high - low, np.diff(position.intervals, axis=1).ravel()
    assert np.all(width <= 1.1 * alone), (width, alone)


def test_each_outputs_fit_is_validates(fits):
    rec, _, both, _ = fits
    v = sid.validate(both, rec)
    for name in NAMES:
        assert v.outputs[name].fit_percent == pytest.approx(
            both.output_fits[name], abs=1e-9
        )
        np.testing.assert_array_equal(
            both.output_model(name).simulate(rec),
            both.simulate(rec)[:, NAMES.index(name)],
        )
    assert both.output_fits["position"] > 95 > both.output_fits["velocity"]


def test_the_nonlinear_kind_gives_the_linear_kinds_outputs():
    rec, _ = record()
    lin = GreyBox(parameters(), ss=msd2)
    non = GreyBox(parameters(), f=msd2_f, g=msd2_g, n_states=2)
    assert non.n_outputs == 2
    y_lin, y_non = lin.simulate(TRUE, rec.u, TS), non.simulate(TRUE, rec.u, TS)
    assert y_non.shape == (rec.n, 2)
    np.testing.assert_allclose(y_non, y_lin, atol=1e-7 * np.max(np.abs(y_lin)))


def test_the_json_form_reads_back(fits, tmp_path):
    rec, _, both, _ = fits
    path = tmp_path / "model.json"
    path.write_text(json.dumps(both.to_dict()))
    back = sid.sysid.load_model(path)
    assert type(back) is type(both) and back.output_names == NAMES
    np.testing.assert_array_equal(back.simulate(rec), both.simulate(rec))
    np.testing.assert_array_equal(back.weights, both.weights)
    assert back.output_fits == both.output_fits
    one = back.output_model("velocity")
    assert one.output_names == ("velocity",) and one.poles.size == 2


@pytest.mark.parametrize(
    ("g", "data", "message"),
    [
        (msd3_g, "two", r"`g` \(msd3_g\) gives 3 output\(s\) but `data` holds 2"),
        (msd2_g, "one", r"`g` \(msd2_g\) gives 2 output\(s\) but `data` holds 1"),
    ],
)
def test_a_record_of_other_outputs_is_refused_in_one_line(g, data, message):
    rec, _ = record()
    rec = rec.output("position") if data == "one" else rec
    box = GreyBox(parameters(), f=msd2_f, g=g, n_states=2)
    with pytest.raises(ValueError, match=message) as refused:
        sid.identify(rec, box, method="oe")
    assert "\n" not in str(refused.value)


def test_a_linear_models_outputs_are_checked_against_the_record():
    rec, _ = record()
    with pytest.raises(ValueError, match=r"`ss` \(_position\) gives 1 output"):
        sid.identify(rec, GreyBox(parameters(), ss=_position), method="oe")
