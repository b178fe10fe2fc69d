"""Finite-element matrices of the hub-beam-payload system.

The link is an Euler-Bernoulli beam clamped to a rigid hub that turns in the
horizontal plane.  Its transverse displacement is measured in the frame that
rotates with the hub, so a point at distance ``x`` from the axis moves by
``x theta + w(x, t)``; the hub-angle coupling terms of the mass matrix come
from the rigid-body part ``x theta`` (a linear, small-deflection model:
centrifugal stiffening and gravity are neglected, as the rig moves in the
horizontal plane).

Generalised coordinates, in this order::

    q = [theta, w_1, w_1', w_2, w_2', ..., w_n, w_n']

``theta`` the hub angle and ``w_j, w_j'`` the deflection and slope at node
``j`` (node 0 at the hub is clamped: ``w = w' = 0``).  Each element uses
Hermite cubic shape functions with the consistent mass matrix.
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import integer, nonneg, positive

__all__ = ["assemble", "element_matrices"]

# 4-point Gauss-Legendre is exact for polynomials up to degree 7; the
# integrands below (products of cubics, x times a cubic) are at most degree 6.
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_XI = 0.5 * (_GAUSS_X + 1.0)
_WXI = 0.5 * _GAUSS_W


def _hermite(xi: np.ndarray, le: float) -> np.ndarray:
    """Hermite cubic shape functions at local coordinates ``xi`` in [0, 1]."""
    return np.stack(
        [
            1 - 3 * xi**2 + 2 * xi**3,
            le * (xi - 2 * xi**2 + xi**3),
            3 * xi**2 - 2 * xi**3,
            le * (-(xi**2) + xi**3),
        ]
    )


def element_matrices(
    le: float, ei: float, rho_a: float, x0: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness, consistent mass and hub-coupling of one beam element.

    Parameters
    ----------
    le : float
        Element length (m).
    ei : float
        Flexural rigidity ``E I`` (N m^2).
    rho_a : float
        Mass per unit length ``rho A`` (kg/m).
    x0 : float
        Distance of the element's first node from the hub axis (m).

    Returns
    -------
    ke, me : ndarray, shape (4, 4)
        ``int EI N'' N''^T dx`` and ``int rho A N N^T dx`` over the element.
    ce : ndarray, shape (4,)
        ``int rho A x N dx``: the kinetic-energy coupling between the hub
        angle and the element's nodal coordinates.

    Examples
    --------
    >>> ke, me, ce = element_matrices(1.0, 1.0, 1.0, 0.0)
    >>> round(float(me[::2, ::2].sum()), 12), float(ke[0, 0])  # rho A le, 12 EI/le^3
    (1.0, 12.0)
    """
    le, ei, rho_a = (
        positive(v, k) for k, v in (("le", le), ("ei", ei), ("rho_a", rho_a))
    )
    x0 = nonneg(x0, "x0")
    n = _hermite(_XI, le)
    me = rho_a * le * (n * _WXI) @ n.T
    ce = rho_a * le * (n * _WXI) @ (x0 + le * _XI)
    l2 = le * le
    ke = (ei / le**3) * np.array(
        [
            [12.0, 6 * le, -12.0, 6 * le],
            [6 * le, 4 * l2, -6 * le, 2 * l2],
            [-12.0, -6 * le, 12.0, -6 * le],
            [6 * le, 2 * l2, -6 * le, 4 * l2],
        ]
    )
    return ke, me, ce


def assemble(
    n_elements: int,
    length: float,
    ei: float,
    rho_a: float,
    hub_inertia: float,
    payload_mass: float = 0.0,
    payload_inertia: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Global mass and stiffness matrices of the hub-beam-payload system.

    Parameters
    ----------
    n_elements : int
        Number of equal beam elements.
    length : float
        Beam length ``L`` (m).
    ei, rho_a : float
        Flexural rigidity (N m^2) and mass per unit length (kg/m).
    hub_inertia : float
        Hub moment of inertia ``I_h`` about the axis (kg m^2).
    payload_mass, payload_inertia : float
        Tip payload: point mass ``m_p`` at distance ``L`` (contributes
        ``m_p L^2`` to the hub inertia and couples to the tip deflection) and
        its own moment of inertia ``J_p`` (turns with ``theta + w'(L)``).

    Returns
    -------
    M, K : ndarray, shape (2 n + 1, 2 n + 1)
        Symmetric mass (positive definite) and stiffness (positive
        semi-definite, zero row and column for ``theta``) matrices.

    Examples
    --------
    >>> M, K = assemble(4, 1.0, 1.0, 3.0, 0.5)
    >>> M.shape, round(float(M[0, 0]), 12)   # I_h + rho A L^3 / 3
    ((9, 9), 1.5)
    """
    n = integer(n_elements, "n_elements", 1)
    length = positive(length, "length")
    hub_inertia = positive(hub_inertia, "hub_inertia")
    payload_mass = nonneg(payload_mass, "payload_mass")
    payload_inertia = nonneg(payload_inertia, "payload_inertia")
    ndof = 2 * n + 1
    # Work on the unconstrained node set (node 0 included), then drop node 0's
    # two coordinates: that is the clamp at the hub.
    nfull = 2 * (n + 1)
    mww = np.zeros((nfull, nfull))
    kww = np.zeros((nfull, nfull))
    cw = np.zeros(nfull)
    le = length / n
    for e in range(n):
        ke, me, ce = element_matrices(le, ei, rho_a, e * le)
        sl = slice(2 * e, 2 * e + 4)
        kww[sl, sl] += ke
        mww[sl, sl] += me
        cw[sl] += ce
    M = np.zeros((ndof, ndof))
    K = np.zeros((ndof, ndof))
    M[1:, 1:] = mww[2:, 2:]
    K[1:, 1:] = kww[2:, 2:]
    M[0, 1:] = M[1:, 0] = cw[2:]
    M[0, 0] = hub_inertia + rho_a * length**3 / 3.0
    tip_w, tip_s = ndof - 2, ndof - 1
    # Payload kinetic energy: m_p (L theta' + w_L')^2 / 2 + J_p (theta' + s_L')^2 / 2.
    M[0, 0] += payload_mass * length**2 + payload_inertia
    M[tip_w, tip_w] += payload_mass
    M[0, tip_w] += payload_mass * length
    M[tip_w, 0] += payload_mass * length
    M[tip_s, tip_s] += payload_inertia
    M[0, tip_s] += payload_inertia
    M[tip_s, 0] += payload_inertia
    return M, K
