"""Test functions against hand-worked values, SciPy and their stated optima."""

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar, rosen

from spiralid.optim import testfunctions as tf

PROBLEMS = list(tf.PROBLEMS.values())


def test_hand_values():
    assert tf.sphere([1.0, 2.0, 3.0]) == 14.0
    # 2 * 10 + (1 - 10 cos 2pi) + (0.25 - 10 cos pi)
    assert tf.rastrigin([1.0, 0.5]) == pytest.approx(21.25, abs=1e-12)
    assert tf.rosenbrock([-1.0, 1.0]) == 4.0
    assert tf.rosenbrock([0.0, 0.0]) == 1.0
    assert tf.ackley([1.0, 1.0]) == pytest.approx(20 - 20 * math.exp(-0.2), rel=1e-14)
    expected = 20 * (1 - math.exp(-0.1)) + math.e - math.exp(-1.0)
    assert tf.ackley([0.5]) == pytest.approx(expected, rel=1e-14)
    # cos(0) cos(sqrt(2) pi / sqrt(2)) = -1: 1 + 2 pi^2 / 4000 + 1
    val = tf.griewank([0.0, math.sqrt(2) * math.pi])
    assert val == pytest.approx(2 + math.pi**2 / 2000, rel=1e-14)
    assert tf.schwefel(np.zeros(3)) == pytest.approx(3 * 418.9828872724, rel=1e-12)


def test_rosenbrock_matches_scipy():
    x = np.random.default_rng(0).uniform(-5, 10, size=(20, 7))
    np.testing.assert_allclose(tf.rosenbrock(x), [rosen(r) for r in x], rtol=1e-14)


def test_schwefel_optimum_located_independently():
    res = minimize_scalar(
        lambda t: -t * math.sin(math.sqrt(t)),
        bounds=(400, 450),
        method="bounded",
        options=dict(xatol=1e-9),
    )
    assert tf.PROBLEMS["schwefel"].x_opt == pytest.approx(res.x, abs=1e-4)
    assert tf.schwefel(tf.PROBLEMS["schwefel"].optimum(10)) == pytest.approx(
        0.0, abs=1e-10
    )


@pytest.mark.parametrize("p", PROBLEMS, ids=lambda p: p.name)
@pytest.mark.parametrize("n", [2, 5, 10])
def test_stated_optimum(p, n):
    xo = p.optimum(n)
    b = p.bounds(n)
    assert b.shape == (n, 2)
    assert np.all((b[:, 0] <= xo) & (xo <= b[:, 1]))
    assert p(xo) == pytest.approx(p.f_opt, abs=1e-12)
    # Small random moves all cost more: a strict local minimum.
    moves = np.random.default_rng(n).normal(size=(200, n)) * 1e-3
    assert np.all(p(xo + moves) > p(xo))


@pytest.mark.parametrize("p", PROBLEMS, ids=lambda p: p.name)
def test_vectorised_equals_per_point(p):
    x = np.random.default_rng(1).uniform(p.low, p.high, size=(30, 6))
    batch = p(x)
    assert batch.shape == (30,)
    np.testing.assert_allclose(batch, [float(p(r)) for r in x], rtol=1e-13)
    assert np.ndim(p(x[0])) == 0


def test_bad_input():
    with pytest.raises(ValueError, match=r"^`x` must have shape \(n,\) or \(m, n\)"):
        tf.sphere(np.zeros((2, 2, 2)))
    with pytest.raises(ValueError, match=r"^`x` must .*n >= 2 for rosenbrock"):
        tf.rosenbrock([1.0])
    with pytest.raises(ValueError, match=r"^`n` must be an integer >= 2 for rosen"):
        tf.PROBLEMS["rosenbrock"].bounds(1)
    with pytest.raises(ValueError, match=r"^`n` must be an integer >= 1 for sphere"):
        tf.PROBLEMS["sphere"].optimum(2.0)


@pytest.mark.parametrize("p", PROBLEMS, ids=lambda p: p.name)
def test_bad_values_are_named(p):
    with pytest.raises(ValueError, match=rf"^`x` must be finite for {p.name}"):
        p.fun([1.0, np.nan])
    with pytest.raises(ValueError, match=rf"^`x` must be finite for {p.name}"):
        p.fun(np.full((2, 3), np.inf))
    with pytest.raises(TypeError, match=r"^`x` must be an array of real numbers"):
        p.fun("ab")
    with pytest.raises(ValueError, match=r"^`x` must be an array of real numbers"):
        p.fun([[1.0, 2.0], [3.0]])
