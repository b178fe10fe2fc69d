"""Variable projection against numpy.linalg.lstsq on the filtered regressors
and against the paper's cost."""

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import ARX, IOData, PaperCost, random_stable_polynomial
from spiralid.sysid.estimation.linear.modal import ModalParametrization
from spiralid.sysid.estimation.linear.varpro import ProjectedCost, gauss_newton_polish


def _record(n=400, seed=0, noise=0.1):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = lfilter([0.0, 0.8, -0.3, 0.2], [1.0, -1.6, 1.2, -0.4], u)
    return IOData(u, y + noise * rng.standard_normal(n), ts=0.01)


def _lstsq_numerator(a, data, arx):
    """Independent: filter u by 1/A (scipy), shift, and solve with lstsq."""
    v = lfilter([1.0], np.r_[1.0, a], data.u)
    cols = []
    for j in range(arx.nb):
        lag = arx.nk + j
        cols.append(np.r_[np.zeros(lag), v[: data.n - lag]])
    return np.linalg.lstsq(np.column_stack(cols), data.y, rcond=None)[0]


@pytest.mark.parametrize("na, nb, nk", [(3, 3, 1), (2, 4, 0), (4, 2, 2), (1, 1, 0)])
def test_projected_numerator_is_lstsq_on_filtered_regressors(na, nb, nk):
    data = _record()
    arx = ARX(na, nb, nk)
    cost = ProjectedCost(arx, data)
    a = random_stable_polynomial(na, size=20, rng=1) * 0.9
    b = cost.numerator(a)
    for row, got in zip(a, b, strict=True):
        want = _lstsq_numerator(row, data, arx)
        assert got == pytest.approx(want, rel=1e-9, abs=1e-9 * np.abs(want).max())


def test_value_is_the_paper_cost_at_the_projected_numerator():
    data = _record()
    arx = ARX(3, 3, 1)
    cost = ProjectedCost(arx, data)
    paper = PaperCost(arx, data)
    a = random_stable_polynomial(3, size=30, rng=2)
    f, b = cost.evaluate(a)
    theta = np.concatenate([a, b], axis=1)
    assert f == pytest.approx(paper(theta), rel=1e-12)
    # And never above the zero model (b = 0 is a candidate numerator).
    assert np.all(f <= paper(np.zeros(6)) + 1e-12)


def test_true_denominator_gives_the_true_numerator_without_noise():
    data = _record(noise=0.0)
    cost = ProjectedCost(ARX(3, 3, 1), data)
    theta = cost.theta([-1.6, 1.2, -0.4])
    assert theta == pytest.approx([-1.6, 1.2, -0.4, 0.8, -0.3, 0.2], abs=1e-9)
    assert cost([-1.6, 1.2, -0.4]) == pytest.approx(0.0, abs=1e-7)


def test_unstable_denominator_pays_the_penalty_at_the_one_step_numerator():
    data = _record()
    arx = ARX(2, 2, 1)
    cost = ProjectedCost(arx, data)
    a = np.array([-2.5, 1.5])  # a root at z = 1.5
    f, b = cost.evaluate(a[None, :])
    # Independent: minimise the one-step error over b with a fixed.
    t0 = arx.max_lag
    phi = arx.regressors(data)[t0:]
    target = data.y[t0:] - phi[:, :2] @ a
    want = np.linalg.lstsq(phi[:, 2:], target, rcond=None)[0]
    assert b[0] == pytest.approx(want, rel=1e-9)
    assert f[0] == pytest.approx(PaperCost(arx, data)(np.r_[a, want]), rel=1e-12)
    assert f[0] > 1e6


def test_residual_jacobian_matches_central_differences():
    data = _record()
    cost = ProjectedCost(ARX(3, 3, 1), data)
    a = np.array([-1.5, 1.1, -0.35])
    r, jac = cost.residual(a)
    h = 1e-6
    num = np.column_stack(
        [
            (cost.residual(a + h * e)[0] - cost.residual(a - h * e)[0]) / (2 * h)
            for e in np.eye(3)
        ]
    )
    assert np.abs(jac - num).max() <= 1e-6 * np.abs(num).max()
    assert (cost.w / cost.K) * np.linalg.norm(r) == pytest.approx(cost(a), rel=1e-9)


def test_polish_lowers_the_cost_within_its_budget_and_box():
    data = _record()
    arx = ARX(4, 3, 1)
    cost = ProjectedCost(arx, data)
    par = ModalParametrization(4, data.ts)
    x0 = par.initial_points(5, rng=3)
    for x in x0:
        start = cost(par.to_denominator(x))
        res = gauss_newton_polish(cost, par, x, max_nfev=12)
        assert res.nfev <= 12
        assert res.fun <= start
        assert np.all((res.x >= par.bounds[:, 0]) & (res.x <= par.bounds[:, 1]))
        assert res.fun == pytest.approx(cost(par.to_denominator(res.x)), rel=1e-12)


@pytest.mark.parametrize(
    "kwargs, match",
    [(dict(predictor="one-step"), "method='ls'"), (dict(initial="measured"), "'oe'")],
)
def test_unsupported_settings_are_refused_clearly(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ProjectedCost(ARX(2, 2, 1), _record(), **kwargs)


def test_bad_denominator_shape_is_named():
    cost = ProjectedCost(ARX(2, 2, 1), _record())
    with pytest.raises(ValueError, match="`a`"):
        cost([1.0, 2.0, 3.0])
