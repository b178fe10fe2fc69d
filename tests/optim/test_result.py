"""Every optimiser returns the one result type, its status saying how it
stopped (spiralid.optim.result.STATUS)."""

import numpy as np
import pytest

from spiralid.optim import (
    RULES,
    STATUS,
    OptimiserResult,
    differential_evolution,
    minimize,
)
from spiralid.sysid import ARX, IOData, identify
from spiralid.sysid.estimation.linear.levenberg import levenberg_marquardt

KEYS = ("x", "fun", "status", "success", "message", "nit", "nfev", "n_restarts")
BOX = [(-5.0, 5.0)] * 3


def sphere(x):
    return np.sum(np.asarray(x) ** 2, axis=-1)


def _check(res):
    assert isinstance(res, OptimiserResult)
    for key in KEYS:
        assert key in res, key
    assert "history" in res
    assert res.status in STATUS


@pytest.mark.parametrize("rule", list(RULES))
def test_every_rule_reports_each_stop(rule):
    kw = dict(n_points=10, rng=0, vectorized=True)
    by_nfev = minimize(sphere, BOX, rule, max_iter=1000, max_nfev=100, **kw)
    _check(by_nfev)
    assert by_nfev.status == 1 and by_nfev.nfev <= 100
    by_iter = minimize(sphere, BOX, rule, max_iter=5, **kw)
    assert by_iter.status == 2 and by_iter.nit == 5
    by_target = minimize(
        sphere, BOX, rule, max_iter=1000, options={"target": 1e6}, **kw
    )
    assert by_target.status == 0 and by_target.nit == 0
    by_callback = minimize(sphere, BOX, rule, callback=lambda r: r.nit >= 3, **kw)
    assert by_callback.status == 0 and by_callback.nit == 3
    restarted = minimize(sphere, BOX, rule, max_nfev=3000, restarts=True, **kw)
    _check(restarted)
    assert restarted.history.size == restarted.nit + restarted.n_restarts + 1


def test_differential_evolution_reports_each_stop():
    by_nfev = differential_evolution(sphere, BOX, max_nfev=200, rng=0)
    _check(by_nfev)
    assert by_nfev.status == 1 and by_nfev.nfev <= 200
    by_iter = differential_evolution(sphere, BOX, max_iter=3, rng=0)
    assert by_iter.status == 2 and by_iter.nit == 3
    by_callback = differential_evolution(sphere, BOX, rng=0, callback=lambda r: True)
    assert by_callback.status == 0


def test_levenberg_marquardt_reports_its_cap():
    t = np.linspace(0.0, 1.0, 20)
    y = 2.0 * np.exp(-3.0 * t)

    def residual(x):
        return x[0] * np.exp(-x[1] * t) - y

    def jacobian(x):
        e = np.exp(-x[1] * t)
        return np.column_stack([e, -x[0] * t * e])

    converged = levenberg_marquardt(residual, jacobian, np.array([1.0, 1.0]))
    _check(converged)
    assert converged.status == 0 and converged.success
    capped = levenberg_marquardt(residual, jacobian, np.array([1.0, 1.0]), max_nfev=2)
    assert capped.status == 1 and not capped.success


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(0)
    u = rng.standard_normal(300)
    y = np.convolve(u, [0.0, 0.5, 0.3], mode="full")[:300]
    return IOData(u, y + 0.01 * rng.standard_normal(300), ts=0.01)


@pytest.mark.parametrize("method", ["ls", "oe", "de", "spiral", *RULES])
def test_every_estimator_returns_the_one_type(record, method):
    kw = {} if method in ("ls", "oe") else dict(rng=0, max_nfev=400, n_points=10)
    res = identify(record, ARX(2, 2, 1), method=method, **kw).result
    _check(res)
    if method not in ("ls", "oe", "spiral"):
        assert res.status == 1  # the budget ended it
