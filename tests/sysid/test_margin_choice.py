"""Keeping or lifting the default stability margin by the held-back end
(:mod:`spiralid.sysid.estimation.spiral.margin_choice`): a plant that needs a pole
slower than the record gets it back, a drift does not, and a time constant
the user gave is never lifted."""

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import ARX, IdentifiedModel, IOData, fit_percent, identify, validate
from spiralid.sysid.estimation.spiral.margin_choice import LIFT, slowest_time_constant

TS = 0.002


def _double_integrator(seed: int, n: int = 3000) -> IOData:
    """Torque to angle of a hub with a light viscous friction (a pole at
    0.99999, a time constant of 200 s) and one lightly damped mode, 1 %
    noise: told of one integrator only, the model needs the friction's pole,
    which is 50 times slower than the 4 s estimation record."""
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.choice([-1.0, 1.0], n // 25), 25)
    mode = 0.995 * np.exp(0.06j)
    a = np.poly([1.0, 0.99999, mode, np.conj(mode)]).real
    y = lfilter(np.array([0.0, 1.0, 0.5, 0.2]) * 1e-4, a, u)
    return IOData(u, y + 0.01 * np.std(y) * rng.standard_normal(n), ts=TS)


def _validation_fit(model, data: IOData, est: IOData) -> float:
    return fit_percent(data.y[est.n :], model.simulate(data.u)[est.n :])


def test_the_time_constant_of_a_pole_is_read_back():
    # A pole at exp(-ts / tau) has the time constant tau.
    a = np.poly([np.exp(-TS / 3.0), 0.5])[1:]
    assert slowest_time_constant(a, TS) == pytest.approx(3.0, rel=1e-9)
    assert slowest_time_constant(np.poly([1.0, 0.2])[1:], TS) == np.inf
    assert slowest_time_constant(np.array([]), TS) == 0.0


@pytest.mark.parametrize("method", ["oe", "spiral"])
@pytest.mark.parametrize("seed", [0, 2])
def test_a_missing_integrator_lifts_the_margin(method, seed):
    data = _double_integrator(seed)
    est, _ = data.split(2 / 3)
    kw = {"rng": 0} if method == "spiral" else {}
    fit = identify(est, ARX(4, 3, 1), method=method, integrator=True, **kw)
    # The same margin given explicitly is the user's and stays.
    kept = identify(
        est,
        ARX(4, 3, 1),
        method=method,
        integrator=True,
        max_time_constant=est.n * est.ts,
        **kw,
    )
    assert kept.margin is None
    assert fit.margin["lifted"]
    rms = fit.margin["held_back_rms"]
    assert rms["free"] < LIFT * rms["margin"]
    assert "integrator" in fit.margin["note"]
    # The friction's pole is back beyond the record's length...
    second = np.sort(np.abs(fit.poles))[-2]  # the largest is the integrator's
    assert second > np.exp(-1.0 / est.n)
    # ... and it is what the validation third needed.
    lifted_fit = _validation_fit(fit, data, est)
    assert lifted_fit > 95.0
    assert _validation_fit(kept, data, est) < lifted_fit - 10.0
    # Said where a user reads it.
    assert fit.margin["note"] in validate(fit, data[est.n :]).choice


def test_a_drift_keeps_the_margin():
    # The record of test_margin: a plant and a random walk, whose pole the
    # margin holds back; released, the drift's model gains too little.
    rng = np.random.default_rng(1)
    n = 600
    u = rng.standard_normal(n)
    y = lfilter([0, 0.5, 0.3], [1, -1.5, 0.7], u)
    noise = 0.02 * rng.standard_normal(n)
    walk = 0.05 * np.cumsum(rng.standard_normal(n)) / np.sqrt(n)
    data = IOData(u, y + np.std(y) * (noise + walk), ts=0.01)
    fit = identify(data, ARX(3, 3, 1), method="oe")
    assert fit.margin is not None and not fit.margin["lifted"]
    assert fit.max_pole_radius <= np.exp(-1.0 / n)


def test_the_margin_record_is_saved_and_read_back():
    data = _double_integrator(0)
    est, _ = data.split(2 / 3)
    fit = identify(est, ARX(4, 3, 1), method="oe", integrator=True)
    back = IdentifiedModel.from_dict(json.loads(json.dumps(fit.to_dict())))
    assert back.margin == fit.margin
    bad = {**fit.to_dict(), "margin": {"lifted": True}}
    with pytest.raises(ValueError, match="field 'margin' must be an object"):
        IdentifiedModel.from_dict(bad)
