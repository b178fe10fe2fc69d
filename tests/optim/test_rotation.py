"""Rotation: checked against hand-built Givens products and linear algebra."""

import numpy as np
import pytest

from spiralid.optim import planes, rotate, rotation_matrix


def givens(n, i, j, theta):
    """R_ij (1-based) written out from its definition in Tamura & Yasuda."""
    g = np.eye(n)
    c, s = np.cos(theta), np.sin(theta)
    g[i - 1, i - 1] = c
    g[j - 1, j - 1] = c
    g[i - 1, j - 1] = -s
    g[j - 1, i - 1] = s
    return g


def tamura_product(n, theta):
    """prod_{i=1}^{n-1} prod_{j=1}^{i} R_{n-i, n+1-j}, left to right."""
    out = np.eye(n)
    for i in range(1, n):
        for j in range(1, i + 1):
            out = out @ givens(n, n - i, n + 1 - j, theta)
    return out


@pytest.mark.parametrize("theta", [0.3, np.pi / 4, -2.1, 3.0])
def test_n3_is_r23_r13_r12(theta):
    expected = givens(3, 2, 3, theta) @ givens(3, 1, 3, theta) @ givens(3, 1, 2, theta)
    np.testing.assert_allclose(rotation_matrix(3, theta), expected, atol=1e-15)


def test_n2_is_the_plane_rotation():
    t = 0.7
    c, s = np.cos(t), np.sin(t)
    np.testing.assert_allclose(rotation_matrix(2, t), [[c, -s], [s, c]], atol=1e-16)


def test_n4_order_written_out():
    t = 1.3
    g = [
        givens(4, i, j, t) for i, j in [(3, 4), (2, 4), (2, 3), (1, 4), (1, 3), (1, 2)]
    ]
    np.testing.assert_allclose(
        rotation_matrix(4, t), np.linalg.multi_dot(g), atol=1e-15
    )
    assert planes(4).tolist() == [[2, 3], [1, 3], [1, 2], [0, 3], [0, 2], [0, 1]]


@pytest.mark.parametrize("n", [1, 2, 5, 8, 13])
def test_matches_formula_product(n):
    np.testing.assert_allclose(
        rotation_matrix(n, 0.9), tamura_product(n, 0.9), atol=1e-14
    )


@pytest.mark.parametrize("n", range(1, 21))
def test_orthogonal_with_unit_determinant(n):
    theta = np.random.default_rng(n).uniform(-np.pi, np.pi)
    R = rotation_matrix(n, theta)
    np.testing.assert_allclose(R @ R.T, np.eye(n), atol=1e-13)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("n", [1, 2, 3, 7, 16, 20])
def test_rotate_matches_matrix_scalar_angle(n):
    rng = np.random.default_rng(n)
    v = rng.normal(size=(9, n))
    expected = v @ rotation_matrix(n, 0.61).T
    np.testing.assert_allclose(rotate(v, 0.61), expected, rtol=0, atol=1e-13)


@pytest.mark.parametrize("n", [2, 3, 7, 16, 20])
def test_rotate_matches_matrix_per_point_angles(n):
    rng = np.random.default_rng(100 + n)
    v = rng.normal(size=(11, n))
    theta = rng.uniform(-3, 3, size=11)
    out = rotate(v, theta)
    for i in range(11):
        expected = rotation_matrix(n, theta[i]) @ v[i]
        np.testing.assert_allclose(out[i], expected, rtol=0, atol=1e-13)
    # Norms are preserved (independent of the matrix).
    np.testing.assert_allclose(
        np.linalg.norm(out, axis=1), np.linalg.norm(v, axis=1), rtol=1e-13
    )


def test_rotate_leaves_input_alone_and_accepts_1d():
    v = np.array([1.0, 2.0, 3.0])
    out = rotate(v, 0.5)
    assert out.shape == (3,)
    np.testing.assert_array_equal(v, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(out, rotation_matrix(3, 0.5) @ v, atol=1e-15)


def test_rotate_accepts_non_contiguous_and_integer_input():
    v = np.arange(24).reshape(4, 6)[:, ::2]
    np.testing.assert_allclose(
        rotate(v, 1.0), v @ rotation_matrix(3, 1.0).T, atol=1e-12
    )


@pytest.mark.parametrize(
    ("n", "error"),
    [
        (0, ValueError),
        (-1, ValueError),
        (2.0, TypeError),
        (True, TypeError),
        ("3", TypeError),
    ],
)
def test_bad_n(n, error):
    with pytest.raises(error, match=r"^`n` must be an integer >= 1; got"):
        rotation_matrix(n, 0.1)


@pytest.mark.parametrize(
    ("theta", "error"),
    [(np.nan, ValueError), (np.inf, ValueError), ("x", TypeError), (None, TypeError)],
)
def test_bad_theta(theta, error):
    with pytest.raises(error, match=r"^`theta` must be a finite number"):
        rotation_matrix(3, theta)


def test_rotate_bad_shapes():
    with pytest.raises(ValueError, match=r"^`v` must have shape \(m, n\).*\(2, 2, 2\)"):
        rotate(np.zeros((2, 2, 2)), 0.1)
    with pytest.raises(
        ValueError, match=r"^`theta` must be a scalar or have shape \(3,\)"
    ):
        rotate(np.zeros((3, 2)), np.zeros(2))
    with pytest.raises(ValueError, match=r"^`theta` must be a scalar or have shape"):
        rotate(np.zeros(3), np.zeros(1))
    with pytest.raises(ValueError, match=r"^`theta` must be finite"):
        rotate(np.zeros((2, 2)), [0.0, np.nan])


def test_rotate_rejects_non_finite_and_non_real_input():
    # NaN would otherwise come back as NaN rows without a word.
    with pytest.raises(ValueError, match=r"^`v` must be finite"):
        rotate([[np.nan, 1.0]], 0.1)
    with pytest.raises(ValueError, match=r"^`v` must be finite"):
        rotate([1.0, np.inf], 0.1)
    with pytest.raises(TypeError, match=r"^`v` must be an array of real numbers"):
        rotate("ab", 0.1)
    with pytest.raises(TypeError, match=r"^`v` must be an array of real numbers"):
        rotate(np.ones((2, 3)) + 1j, 0.1)
    with pytest.raises(TypeError, match=r"^`theta` must be an array of real numbers"):
        rotate(np.zeros((2, 3)), "a")
