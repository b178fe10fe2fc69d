"""Levenberg-Marquardt with a projection, against SciPy and hand-worked cases."""

from pathlib import Path

import numpy as np
import pytest
from scipy import optimize

import spiralid
from spiralid.sysid.estimation.linear.levenberg import (
    STOPS,
    damped_descent,
    levenberg_marquardt,
)


def _exponential_fit():
    # y = 2.5 exp(-1.3 t) + 0.4 with noise: a classical nonlinear fit.
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 4.0, 60)
    y = 2.5 * np.exp(-1.3 * t) + 0.4 + 0.01 * rng.standard_normal(t.size)

    def residual(x):
        return x[0] * np.exp(-x[1] * t) + x[2] - y

    def jacobian(x):
        e = np.exp(-x[1] * t)
        return np.column_stack([e, -x[0] * t * e, np.ones_like(t)])

    return residual, jacobian


def test_same_minimum_as_scipy_least_squares():
    residual, jacobian = _exponential_fit()
    x0 = np.array([1.0, 0.5, 0.0])
    ours = levenberg_marquardt(residual, jacobian, x0)
    ref = optimize.least_squares(residual, x0, jac=jacobian, method="lm",
                                 xtol=1e-15, ftol=1e-15, gtol=1e-15)  # fmt: skip
    np.testing.assert_allclose(ours.x, ref.x, rtol=1e-8)
    np.testing.assert_allclose(ours.cost, ref.cost, rtol=1e-12)
    assert ours.stop in (1, 2, 3, 4) and ours.success and ours.status == 0
    assert ours.message == STOPS[ours.stop]
    # The gradient J' r vanishes at the end.
    assert ours.optimality == pytest.approx(np.max(np.abs(ours.jac.T @ ours.fun)))
    assert ours.optimality < 1e-8


def test_rosenbrock_valley():
    def residual(x):
        return np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])

    def jacobian(x):
        return np.array([[-20.0 * x[0], 10.0], [-1.0, 0.0]])

    res = levenberg_marquardt(residual, jacobian, np.array([-1.2, 1.0]))
    np.testing.assert_allclose(res.x, [1.0, 1.0], atol=1e-10)


def test_projection_keeps_every_point_feasible_and_ends_on_the_boundary():
    # min (x - 3)^2 + (y - 1)^2 over x <= 2: the constrained optimum (2, 1),
    # reached by projecting (clipping) every trial point.
    seen = []

    def residual(x):
        seen.append(x.copy())
        return np.array([x[0] - 3.0, x[1] - 1.0])

    def jacobian(x):
        return np.eye(2)

    res = levenberg_marquardt(
        residual,
        jacobian,
        np.array([0.0, 0.0]),
        project=lambda x: np.array([min(x[0], 2.0), x[1]]),
    )
    assert all(p[0] <= 2.0 for p in seen)
    np.testing.assert_allclose(res.x, [2.0, 1.0], atol=1e-9)


def test_cap_and_stall_are_reported():
    residual, jacobian = _exponential_fit()
    x0 = np.array([1.0, 0.5, 0.0])
    capped = levenberg_marquardt(residual, jacobian, x0, max_nfev=3)
    assert capped.status == 1 and capped.stop == 0 and not capped.success
    assert capped.nfev <= 3
    # A stall window whose required gain no step can bring.
    stalled = levenberg_marquardt(residual, jacobian, x0, stall=(2, 1.0))
    assert stalled.stop == 5 and stalled.status == 0
    assert "flat valley" in stalled.message


def test_damped_descent_with_normal_equations_reaches_the_same_minimum():
    # The variable-projection polish's way in: the step from normal
    # equations, the linearisation counted as an evaluation.
    residual, jacobian = _exponential_fit()

    def evaluate(x):
        r = residual(x)
        return float(r @ r), None

    def linearise(x, _cost, _state):
        r, jac = residual(x), jacobian(x)
        grad, hess = jac.T @ r, jac.T @ jac

        def step(lam):
            return -np.linalg.solve(hess + lam * np.diag(np.diag(hess)), grad)

        return float(r @ r), step, False

    out = damped_descent(
        evaluate,
        linearise,
        np.array([1.0, 0.5, 0.0]),
        max_nfev=200,
        linearising_counts=True,
        grow=4.0,
    )
    ref = levenberg_marquardt(residual, jacobian, np.array([1.0, 0.5, 0.0]))
    np.testing.assert_allclose(out["x"], ref.x, rtol=1e-6)
    assert (
        out["nfev"] <= 200
        and out["njev"] == 0
        and out["stop"] in ("cap", "no decrease")
    )


def test_damped_descent_stops_when_the_evaluations_run_out():
    residual, jacobian = _exponential_fit()

    def evaluate(x):
        r = residual(x)
        return float(r @ r), r

    def linearise(x, cost, r):
        jac = jacobian(x)
        return cost, (lambda lam: -np.linalg.lstsq(jac, r, rcond=None)[0]), False

    out = damped_descent(evaluate, linearise, np.array([1.0, 0.5, 0.0]), max_nfev=3)
    assert out["nfev"] == 3 and out["stop"] == "cap" and out["nit"] >= 1


def test_every_levenberg_marquardt_in_the_package_is_levenbergs():
    # One loop (issue 28): no estimator runs SciPy's LM or a damping loop
    # of its own.
    for path in Path(spiralid.__file__).parent.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        if path.name == "levenberg.py":
            continue
        assert 'method="lm"' not in text, path
        assert "lam *=" not in text, path
