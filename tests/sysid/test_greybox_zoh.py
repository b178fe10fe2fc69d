"""The linear grey box's compiled zero-order hold and run against SciPy:
the matrix exponential against ``scipy.linalg.expm`` (stiff, defective,
zero and large-norm matrices), the discretisation against
``scipy.signal.cont2discrete``, the run against ``scipy.signal.dlsim``, on
a system of several inputs and outputs, and a blown-up run left NaN."""

import numpy as np
import pytest
from scipy import linalg, signal

from spiralid.sysid import GreyBox, Parameter
from spiralid.sysid.models.greybox_run import expm_small, lti_run, zoh


def _close(a, b, tol=1e-12):
    scale = max(np.abs(b).max(), 1.0)
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


@pytest.mark.parametrize("scale", [1e-3, 0.3, 1.0, 30.0, 500.0])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_expm_is_scipys_on_random_matrices(scale, seed):
    # Random matrices of decaying exponentials (eigenvalues left of the
    # axis), as a physical model's A times ts is.
    rng = np.random.default_rng(seed)
    n = 3 + seed
    m = rng.standard_normal((n, n)) - 2 * np.eye(n)
    m *= scale / np.abs(m).sum(axis=0).max()
    # Relative to the largest entry: both lose digits when squaring.
    _close(expm_small(m), linalg.expm(m), tol=1e-13 * max(scale, 1.0))


def test_expm_of_defective_zero_and_rigid_matrices():
    jordan = np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -1.0]])
    # A rigid body: a double zero eigenvalue, exp is I + m exactly.
    rigid = np.array([[0.0, 1.0], [0.0, 0.0]])
    for m in (jordan * 2.5, rigid * 7.0, np.zeros((4, 4))):
        _close(expm_small(m), linalg.expm(m))
    np.testing.assert_array_equal(expm_small(np.zeros((3, 3))), np.eye(3))
    np.testing.assert_allclose(expm_small(rigid * 7.0), [[1.0, 7.0], [0.0, 1.0]])


def test_expm_of_a_non_finite_matrix_is_nan():
    m = np.eye(2)
    m[0, 1] = np.inf
    assert np.all(np.isnan(expm_small(m)))


def _mimo(rng):
    # A lightly damped pair of modes, two inputs and two outputs.
    a = np.array(
        [
            [0.0, 1.0, 0.0, 0.0],
            [-40.0, -0.4, 10.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [5.0, 0.0, -90.0, -1.0],
        ]
    )
    b = rng.standard_normal((4, 2))
    c = rng.standard_normal((2, 4))
    d = rng.standard_normal((2, 2))
    return a, b, c, d


@pytest.mark.parametrize("ts", [1e-3, 0.05, 0.5])
def test_zoh_is_cont2discrete(ts):
    a, b, c, d = _mimo(np.random.default_rng(3))
    ad, bd = zoh(a, b, ts)
    ref = signal.cont2discrete((a, b, c, d), ts, "zoh")
    _close(ad, ref[0])
    _close(bd, ref[1])


def test_run_is_dlsim_with_several_inputs_and_outputs():
    rng = np.random.default_rng(4)
    a, b, c, d = _mimo(rng)
    ts = 0.02
    ad, bd = zoh(a, b, ts)
    u = rng.standard_normal((500, 2))
    x0 = rng.standard_normal(4)
    _, y_ref, _ = signal.dlsim((ad, bd, c, d, ts), u, x0=x0)
    _close(lti_run(ad, bd, c, d, x0, u), y_ref)


def test_a_blown_up_run_is_nan_from_where_it_left_the_range():
    ad = np.array([[1e200]])
    bd, c, d = np.ones((1, 1)), np.ones((1, 1)), np.zeros((1, 1))
    y = lti_run(ad, bd, c, d, np.ones(1), np.zeros((5, 1)))[:, 0]
    np.testing.assert_array_equal(y[:2], [1.0, 1e200])
    assert np.all(np.isnan(y[2:]))


def _chain(p):
    # Two masses in a chain from a wall, a force on the first, its
    # position measured.
    m1, m2, k1, k2, c1, c2 = p
    a = np.array(
        [
            [0, 0, 1, 0],
            [0, 0, 0, 1],
            [-(k1 + k2) / m1, k2 / m1, -(c1 + c2) / m1, c2 / m1],
            [k2 / m2, -k2 / m2, c2 / m2, -c2 / m2],
        ]
    )
    return a, [[0], [0], [1 / m1], [0]], [[1, 0, 0, 0]], [[0]]


def test_a_linear_grey_box_simulates_as_scipy():
    names = ["m1", "m2", "k1", "k2", "c1", "c2"]
    values = [1.0, 0.5, 200.0, 150.0, 1.0, 0.6]
    box = GreyBox(
        [Parameter(n, v, (v / 10, v * 10)) for n, v in zip(names, values, strict=True)],
        ss=_chain,
    )
    u = np.random.default_rng(5).standard_normal(800)
    ts = 0.01
    matrices = tuple(np.asarray(m, dtype=float) for m in _chain(values))
    sys_d = signal.cont2discrete(matrices, ts, "zoh")
    _, y_ref, _ = signal.dlsim(sys_d, u)
    _close(box.simulate(values, u, ts), y_ref[:, 0])
