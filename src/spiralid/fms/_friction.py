"""Compiled time stepping of the rig with hub friction (Coulomb, Stribeck).

Friction makes the rig nonlinear, so the closed-form linear simulation of
:func:`spiralid.fms._zoh.simulate_discrete` does not apply. Each sample
is split into ``m`` sub-steps of the exact zero-order-hold model; on every
sub-step the friction torque is held constant and chosen implicitly: the
torque that would stop the hub at the end of the sub-step, clipped to the
friction law's magnitude at the present velocity. Sliding therefore costs
exactly the law's torque times the hub's travel, and a hub whose driving
torque stays below the breakaway torque stays at rest (no chattering
around zero velocity, which an explicit ``-F sign(v)`` would produce).
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["simulate_friction"]


@numba.njit(cache=True)
def _run(
    Ad, Bd, C, D, cv, u, x0, m, coulomb, static, v_stribeck, out, states
):  # pragma: no cover - compiled
    nx = Ad.shape[0]
    p = C.shape[0]
    x = x0.copy()
    xn = np.empty(nx)
    g = 0.0
    for i in range(nx):
        g += cv[i] * Bd[i]
    for k in range(u.size):
        for i in range(nx):
            states[k, i] = x[i]
        for sub in range(m):
            v = 0.0
            for i in range(nx):
                v += cv[i] * x[i]
            level = coulomb
            if static > coulomb:
                level = coulomb + (static - coulomb) * math.exp(
                    -((v / v_stribeck) ** 2)
                )
            v_free = 0.0
            for i in range(nx):
                s = Bd[i] * u[k]
                for j in range(nx):
                    s += Ad[i, j] * x[j]
                xn[i] = s
                v_free += cv[i] * s
            tf = -v_free / g
            if tf > level:
                tf = level
            elif tf < -level:
                tf = -level
            if sub == 0:
                # The output's feedthrough sees the net torque at the sample.
                for r in range(p):
                    s = D[r] * (u[k] + tf)
                    for i in range(nx):
                        s += C[r, i] * x[i]
                    out[k, r] = s
            for i in range(nx):
                x[i] = xn[i] + Bd[i] * tf


def simulate_friction(
    Ad: np.ndarray,
    Bd: np.ndarray,
    C: np.ndarray,
    D: np.ndarray,
    cv: np.ndarray,
    u: np.ndarray,
    x0: np.ndarray,
    m: int,
    coulomb: float,
    static: float,
    v_stribeck: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Run the sub-stepped model with hub friction.

    ``Ad, Bd`` are the exact ZOH matrices of one sub-step (``ts / m``),
    ``C, D`` the output rows, ``cv`` the row that reads the exact hub
    velocity from the state. The friction magnitude is
    ``coulomb + (static - coulomb) exp(-(v / v_stribeck)^2)`` (Stribeck;
    plain Coulomb when ``static <= coulomb``).

    Returns
    -------
    y : ndarray, shape (N, p)
        Outputs at the sample instants.
    x : ndarray, shape (N, nx)
        The state at each sample instant.
    """
    n = u.size
    out = np.empty((n, C.shape[0]))
    states = np.empty((n, Ad.shape[0]))
    _run(
        np.ascontiguousarray(Ad),
        np.ascontiguousarray(Bd),
        np.ascontiguousarray(C),
        np.ascontiguousarray(D),
        np.ascontiguousarray(cv),
        np.ascontiguousarray(u, dtype=float),
        np.ascontiguousarray(x0, dtype=float),
        int(m),
        float(coulomb),
        float(static),
        float(v_stribeck),
        out,
        states,
    )
    return out, states
