"""Finite-element matrices and natural frequencies against analytic results."""

import numpy as np
import pytest
from scipy.optimize import brentq

from spiralid.fms import FlexibleManipulator
from spiralid.fms.beam import assemble, element_matrices

# The Sheffield rig's constants, typed in again here rather than read from the
# code, so a changed default cannot silently move the reference.
L, WIDTH, THICK, E, RHO, IH = 0.9, 19.008e-3, 3.2004e-3, 71e9, 2710.0, 5.86e-4
RHO_A = RHO * WIDTH * THICK
EI = E * WIDTH * THICK**3 / 12.0


def _hub_beam_payload_roots(ih, mp, n):
    """First n natural frequencies (Hz) of the continuous hub-beam-payload.

    Total displacement y(x) = x theta + w(x) obeys EI y'''' = rho A w^2 y with
    y(0) = 0, EI y''(0) + I_h w^2 y'(0) = 0 (hub), y''(L) = 0 and
    EI y'''(L) + m_p w^2 y(L) = 0 (tip mass).  Roots of the 4x4 determinant.
    """

    def det(b):
        w2 = b**4 * EI / RHO_A
        s, c, sh, ch = np.sin(b * L), np.cos(b * L), np.sinh(b * L), np.cosh(b * L)
        rows = [
            [0.0, 1.0, 0.0, 1.0],
            [ih * w2 * b, -EI * b * b, ih * w2 * b, EI * b * b],
            [-s, -c, sh, ch],
            [
                -EI * b**3 * c + mp * w2 * s,
                EI * b**3 * s + mp * w2 * c,
                EI * b**3 * ch + mp * w2 * sh,
                EI * b**3 * sh + mp * w2 * ch,
            ],
        ]
        return np.linalg.det(np.array(rows))

    return _roots(det, n)


def _issue_equation_roots(n):
    """Roots of the issue's hub-beam frequency equation (no payload), in Hz."""

    def f(b):
        bl = b * L
        return (IH * b**3 / RHO_A) * (1 + np.cos(bl) * np.cosh(bl)) + (
            np.sin(bl) * np.cosh(bl) - np.cos(bl) * np.sinh(bl)
        )

    return _roots(f, n)


def _roots(f, n):
    grid = np.linspace(0.2, 20.0, 4000)
    vals = np.array([f(b) for b in grid])
    betas = [
        brentq(f, grid[i], grid[i + 1])
        for i in range(grid.size - 1)
        if np.sign(vals[i]) != np.sign(vals[i + 1])
    ][:n]
    assert len(betas) == n
    return np.array(betas) ** 2 * np.sqrt(EI / RHO_A) / (2 * np.pi)


def test_element_matrices_match_the_textbook_closed_forms():
    le, ei, ra, x0 = 0.3, 2.5, 0.7, 0.45
    ke, me, ce = element_matrices(le, ei, ra, x0)
    # Consistent mass of a Hermite beam element (e.g. Petyt, eq. 3.89).
    me_ref = (ra * le / 420.0) * np.array(
        [
            [156, 22 * le, 54, -13 * le],
            [22 * le, 4 * le**2, 13 * le, -3 * le**2],
            [54, 13 * le, 156, -22 * le],
            [-13 * le, -3 * le**2, -22 * le, 4 * le**2],
        ]
    )
    np.testing.assert_allclose(me, me_ref, rtol=1e-13, atol=1e-15)
    # int rho A x N dx worked by hand: x = x0 + le xi.
    ce_ref = ra * (
        x0 * le * np.array([0.5, le / 12, 0.5, -le / 12])
        + le**2 * np.array([3 / 20, le / 30, 7 / 20, -le / 20])
    )
    np.testing.assert_allclose(ce, ce_ref, rtol=1e-13)
    # Stiffness: rigid-body motions (translation, rotation) store no energy.
    np.testing.assert_allclose(ke @ [1, 0, 1, 0], 0, atol=1e-12)
    np.testing.assert_allclose(ke @ [0, 1, le, 1], 0, atol=1e-12)
    assert ke[1, 1] == pytest.approx(4 * ei / le)


def test_assembled_mass_reproduces_rigid_body_kinetic_energy():
    # Rotating as a rigid body (w = 0) the kinetic energy is J theta'^2 / 2.
    mp, jp = 0.1, 2e-4
    M, K = assemble(7, L, EI, RHO_A, IH, mp, jp)
    J = IH + RHO_A * L**3 / 3 + mp * L**2 + jp
    assert M[0, 0] == pytest.approx(J, rel=1e-14)
    # Hub turning at theta' = 1 while the beam bends as w' = a x^2 (clamped,
    # and exact for cubic elements): 2 T = I_h + int rho A (x + a x^2)^2 dx
    # + m_p (L + a L^2)^2 + J_p (1 + 2 a L)^2.
    a = 0.37
    x = np.linspace(0, L, 8)[1:]
    q = np.zeros(M.shape[0])
    q[0] = 1.0
    q[1::2] = a * x**2
    q[2::2] = 2 * a * x
    two_t = (
        IH
        + RHO_A * (L**3 / 3 + a * L**4 / 2 + a**2 * L**5 / 5)
        + mp * (L + a * L**2) ** 2
        + jp * (1 + 2 * a * L) ** 2
    )
    assert q @ M @ q == pytest.approx(two_t, rel=1e-12)
    np.testing.assert_allclose(K[0], 0.0)
    assert np.allclose(M, M.T) and np.allclose(K, K.T)


def test_first_three_modes_match_the_hub_beam_frequency_equation():
    exact = _issue_equation_roots(3)
    fe = FlexibleManipulator().modes(3)
    np.testing.assert_allclose(fe, exact, rtol=5e-3)


def test_payload_modes_match_the_continuous_hub_beam_payload_solution():
    # The determinant reduces to the issue's equation without payload.
    np.testing.assert_allclose(
        _hub_beam_payload_roots(IH, 0.0, 3), _issue_equation_roots(3), rtol=1e-9
    )
    for mp in (0.02, 0.1):
        exact = _hub_beam_payload_roots(IH, mp, 3)
        fe = FlexibleManipulator(payload_mass=mp).modes(3)
        np.testing.assert_allclose(fe, exact, rtol=5e-3)


def test_modes_converge_from_10_to_20_elements():
    f10 = FlexibleManipulator(n_elements=10).modes(3)
    f20 = FlexibleManipulator(n_elements=20).modes(3)
    assert np.all(np.abs(f10 - f20) / f20 < 5e-3)
    # Consistent-mass FE frequencies approach the exact ones from above.
    exact = _issue_equation_roots(3)
    assert np.all(f10 >= f20) and np.all(f20 >= exact * (1 - 1e-9))


def test_modes_are_ascending_and_all_flexible():
    rig = FlexibleManipulator(n_elements=6)
    f = rig.modes()
    assert f.shape == (12,)
    assert np.all(np.diff(f) > 0) and f[0] > 1.0
    # Same spectrum from a generic generalised eigen-solve (rigid zero dropped).
    lam = np.linalg.eigvals(np.linalg.solve(rig.mass_matrix, rig.stiffness_matrix))
    ref = np.sort(np.sqrt(np.abs(lam.real)))[1:] / (2 * np.pi)
    np.testing.assert_allclose(f, ref, rtol=1e-7)


def test_bad_matrix_arguments_raise():
    # Used to fail with ZeroDivisionError or return NaN matrices.
    with pytest.raises(ValueError, match=r"^`n_elements` must be an integer >= 1"):
        assemble(0, L, EI, RHO_A, IH)
    with pytest.raises(ValueError, match=r"^`length` must be a finite number > 0"):
        assemble(3, np.nan, EI, RHO_A, IH)
    with pytest.raises(ValueError, match=r"^`payload_mass` must be a finite number"):
        assemble(3, L, EI, RHO_A, IH, payload_mass=-1.0)
    with pytest.raises(ValueError, match=r"^`le` must be a finite number > 0"):
        element_matrices(0.0, EI, RHO_A, 0.0)
    with pytest.raises(ValueError, match=r"^`x0` must be a finite number >= 0"):
        element_matrices(0.1, EI, RHO_A, -1.0)
