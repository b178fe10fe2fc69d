"""Output error with integrated noise (identify's ``noise="integrated"``):
the plant fitted on the differenced record, so a random-walk drift of the
output is not fitted by its poles."""

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.sysid import PaperCost

# A known plant: y = (q^-1 + 0.5 q^-2) / (1 - 1.5 q^-1 + 0.7 q^-2) u.
TRUE = np.array([-1.5, 0.7, 1.0, 0.5])
ARX = sid.ARX(2, 2, 1)


def _drifting(seed: int, n: int = 800) -> sid.IOData:
    """The plant's response to white noise plus a random walk of about
    the output's size: exactly the integrated-noise model's disturbance."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    return sid.IOData(u, y + np.cumsum(0.3 * rng.standard_normal(n)), ts=0.01)


@pytest.mark.parametrize("seed", range(5))
def test_integrated_noise_recovers_the_plant_under_a_random_walk(seed):
    data = _drifting(seed)
    white = sid.identify(data, ARX, method="oe")
    integrated = sid.identify(data, ARX, method="oe", noise="integrated")
    error = np.abs(integrated.theta - TRUE).max()
    assert error < 0.1
    # Output error with white noise spends the model on the drift.
    assert error < np.abs(white.theta - TRUE).max()


def test_its_cost_is_the_differenced_record_s_simulation_error():
    data = _drifting(0)
    model = sid.identify(data, ARX, method="oe", noise="integrated")
    diff = sid.IOData(np.diff(data.u), np.diff(data.y), ts=data.ts)
    assert model.cost == pytest.approx(PaperCost(ARX, diff)(model.theta), rel=1e-9)
    assert model.result.noise == "integrated"
    # The model is the plant on the record as given: its provenance is kept.
    assert model.ts == data.ts and model.input_name == data.input_name


def test_the_recommended_method_takes_it_too():
    model = sid.identify(_drifting(1), ARX, noise="integrated", rng=0)
    assert np.abs(model.theta - TRUE).max() < 0.1


def test_a_wrong_noise_model_is_refused_in_one_line():
    data = _drifting(0, 200)
    with pytest.raises(ValueError, match="`noise` must be one of"):
        sid.identify(data, ARX, method="oe", noise="pink")
    with pytest.raises(TypeError, match="`noise` must be a string"):
        sid.identify(data, ARX, method="oe", noise=1)
    with pytest.raises(ValueError, match="`noise` does not apply to method 'ls'"):
        sid.identify(data, ARX, method="ls", noise="integrated")
    # The default, passed by value, is never refused.
    sid.identify(data, ARX, method="ls", noise="white")
