"""The grey box's 95 % intervals against the exact ones of a model linear
in its parameters: ``B = (b1, b2)`` of a fixed ``A`` and ``C``, so the
record is ``y = b1 x1 + b2 x2 + e`` with ``x1``, ``x2`` SciPy's
zero-order-hold responses to the input, and least squares gives the
estimate and its covariance ``s^2 (X'X)^-1`` in closed form."""

import numpy as np
import pytest
from scipy import signal

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter
from spiralid.sysid.estimation.core.coloured import noise_ar
from spiralid.sysid.estimation.greybox.intervals import undetermined_directions
from spiralid.sysid.estimation.greybox.problem import GreyBoxProblem

TS = 0.1
TRUE = np.array([2.0, 0.5])
POLES = (1.0, 3.0)
Z95 = 1.959963984540054


def two_channels(p):
    b1, b2 = p
    a = np.diag([-POLES[0], -POLES[1]])
    return a, [[b1], [b2]], [[1.0, 1.0]], [[0.0]]


def regressors(u: np.ndarray) -> np.ndarray:
    """Each channel's response to `u` with a unit gain, by SciPy."""
    cols = []
    for pole in POLES:
        one = np.ones((1, 1))
        sys = signal.cont2discrete((-pole * one, one, one, 0 * one), TS, "zoh")
        _, x, _ = signal.dlsim(sys, u)
        cols.append(x.ravel())
    return np.column_stack(cols)


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(3)
    n = 400
    u = np.repeat(rng.standard_normal(n // 8), 8)
    x = regressors(u)
    y = x @ TRUE + 0.05 * rng.standard_normal(n)
    beta, rss, *_ = np.linalg.lstsq(x, y, rcond=None)
    s2 = float(rss[0]) / (n - 2)
    sd = np.sqrt(s2 * np.diag(np.linalg.inv(x.T @ x)))
    return sid.IOData(u, y, ts=TS), beta, sd


@pytest.mark.parametrize("log", [False, True])
def test_intervals_are_least_squares_exact_ones(record, log):
    rec, beta, sd = record
    params = [
        Parameter(f"b{i + 1}", 1.0, (0.1, 10.0), log=log) for i in range(TRUE.size)
    ]
    model = sid.identify(rec, GreyBox(params, ss=two_channels), method="oe")
    np.testing.assert_allclose(model.params, beta, rtol=1e-6)
    if log:
        # Symmetric in log: the delta method's sd of log(b) is sd / b,
        # exact here, as log(b) is a linear change of the Jacobian's columns.
        half = Z95 * sd / beta
        want = np.column_stack([beta * np.exp(-half), beta * np.exp(half)])
    else:
        want = np.column_stack([beta - Z95 * sd, beta + Z95 * sd])
    np.testing.assert_allclose(model.intervals, want, rtol=1e-5)


def test_coloured_noise_widens_the_intervals_to_the_exact_sandwich():
    # AR(1) noise: least squares' exact covariance is the sandwich
    # (X'X)^-1 X' R X (X'X)^-1 with R_ij = s^2 phi^|i-j| / (1 - phi^2).
    rng = np.random.default_rng(5)
    n, phi, s = 2000, 0.9, 0.02
    u = np.repeat(rng.standard_normal(n // 8), 8)
    x = regressors(u)
    noise = signal.lfilter([1.0], [1.0, -phi], s * rng.standard_normal(n))
    rec = sid.IOData(u, x @ TRUE + noise, ts=TS)
    params = [Parameter(f"b{i + 1}", 1.0, (0.1, 10.0)) for i in range(TRUE.size)]
    model = sid.identify(rec, GreyBox(params, ss=two_channels), method="oe")
    lag = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    r = s**2 * phi**lag / (1 - phi**2)
    inv = np.linalg.inv(x.T @ x)
    exact = np.sqrt(np.diag(inv @ x.T @ r @ x @ inv))
    half = np.diff(model.intervals, axis=1).ravel() / 2
    np.testing.assert_allclose(half, Z95 * exact, rtol=0.2)
    # The white formula would claim intervals about three times narrower.
    _, rss, *_ = np.linalg.lstsq(x, rec.y, rcond=None)
    white = np.sqrt(float(rss[0]) / (n - 2) * np.diag(inv))
    assert np.all(half > 2 * Z95 * white)


def weak_directions(data, ss) -> np.ndarray:
    """The directions the record cannot determine at the initial values of
    two gains with equal linear bounds."""
    params = [Parameter(name, 1.0, (0.0, 4.0)) for name in ("b1", "b2")]
    problem = GreyBoxProblem(data, GreyBox(params, ss=ss))
    z = problem.z0
    return undetermined_directions(problem, problem.residual(z), problem.jacobian(z))


def test_the_undetermined_directions_are_the_jacobians_null_space(record):
    # Both gains on the first channel: the record sees their sum only, so
    # (1, -1)/sqrt(2) in the unit box is undetermined; on two channels
    # every direction is determined.
    def one_channel(p):
        return two_channels((p[0] + p[1], 0.0))

    weak = weak_directions(record[0], one_channel)
    assert weak.shape == (1, 2)
    np.testing.assert_allclose(weak[0] * np.sign(weak[0, 0]), [2**-0.5, -(2**-0.5)])
    assert weak_directions(record[0], two_channels).shape == (0, 2)


def test_a_coloured_error_shorter_than_the_largest_order_is_modelled():
    # 25 samples of a slow drift fail the whiteness test; the autoregressive
    # model's order is at most a tenth of them: here 2 by Akaike's
    # criterion, its coefficients the Yule-Walker equations' solved by hand.
    noise = 0.01 * np.random.default_rng(0).standard_normal(25)
    e = np.sin(np.arange(25) / 6.0) + noise
    a, s2 = noise_ar(e)
    r = np.array([e[k:] @ e[: e.size - k] for k in range(3)]) / e.size
    coef = np.linalg.solve([[r[0], r[1]], [r[1], r[0]]], r[1:])
    np.testing.assert_allclose(a, [1.0, *-coef], rtol=1e-10)
    np.testing.assert_allclose(s2, r[0] - coef @ r[1:], rtol=1e-10)
