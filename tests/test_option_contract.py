"""Options of the public entry points: a default passed explicitly is
accepted, a wrong one is refused by its own name (issue 29's first cases)."""

import numpy as np
import pytest
from scipy.signal import lfilter

import spiralid as sid
from spiralid.optim import minimize_pareto


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(0)
    u = rng.standard_normal(400)
    return sid.IOData(u, lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u), ts=0.01)


def _two_objectives(x):
    return np.c_[x[:, 0], 1.0 - x[:, 0]]


def test_a_default_passed_by_value_is_the_default(record):
    # Equal, not the same object: float("1e6") is penalty's default.
    model = sid.identify(record, sid.NARX(2, 2, 1), method="ls", penalty=float("1e6"))
    assert model.structure == sid.NARX(2, 2, 1)
    with pytest.raises(ValueError, match="`penalty` does not apply to method 'ls' for"):
        sid.identify(record, sid.NARX(2, 2, 1), method="ls", penalty=1e5)


def test_the_spiral_method_s_rule_is_named_as_its_own_option(record):
    with pytest.raises(ValueError, match="`rule` of method 'spiral' must be one of"):
        sid.identify(record, sid.ARX(2, 2, 1), method="spiral", rule="nope")


def test_minimize_pareto_offers_only_the_rules_it_accepts():
    with pytest.raises(ValueError) as refused:
        minimize_pareto(_two_objectives, [(0, 1)] * 2, method="periodic")
    message = str(refused.value)
    assert "learned-metric" in message
    assert "periodic" not in message.split("; got")[0]
    assert "convergent" not in message


def test_minimize_pareto_checks_vectorized_as_minimize_does():
    with pytest.raises(ValueError, match="`vectorized` must be True or False"):
        minimize_pareto(_two_objectives, [(0, 1)] * 2, vectorized="yes")
