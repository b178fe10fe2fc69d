"""Several inputs, one denominator: the projected cost of every
input-output pair.

With ``m`` inputs each output is a sum over the inputs,

    y_i(t) = sum_j B_ij(q) / A(q) u_j(t),

and for a given ``A`` it is still linear in its numerators: the regressors
are every input filtered by ``1 / A`` from rest and delayed by ``nk .. nk +
nb - 1`` (an (N, m nb) matrix ``V(A)``, the same for every output that has
the same known integrators), and ``[b_i1, .., b_im]`` is the least-squares
solution of ``y_i ~ V b``, one QR factorisation of ``V`` for all of them.
The numerators come from the Gram matrix ``G = V'V`` (scaled to a unit
diagonal, Cholesky) and one step of iterative refinement from the
residual, as the compiled single-input kernel computes them: a QR
factorisation of ``V`` for every candidate was six times slower. The
Jacobian of the projected residual is Golub and Pereyra's, the kernel's:
with ``yhat = V b``, ``S_k = q^-k yhat / A`` and ``z_k = (q^-k V / A)' r``,

    d r / d a_k = S_k - V G^-1 (V' S_k + z_k).

One input is not computed here: the single-input path (the compiled
:class:`~spiralid.sysid.estimation.linear.varpro.ProjectedCost`) is kept
as it is, so a record of one input gives the same estimate bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.signal import lfilter

from ...data import IOData
from ...models.arx import ARX
from ...models.polynomials import is_stable_polynomial
from ...models.shared import MOST_INTEGRATORS
from ..core.cost import auto_gain

__all__ = ["SharedInputsCost", "WeightedOutputs", "equation_regressors"]


def shared_integrators(integrators, p: int) -> tuple[int, ...]:
    """Each output's count of known integrators: one count for all, or one
    per output; a one-line ValueError otherwise."""
    from ...models.polynomials import integrator_count

    if integrators is None:
        return (0,) * p
    values = (
        list(integrators)
        if isinstance(integrators, list | tuple)
        else [integrators] * p
    )
    if len(values) != p:
        raise ValueError(
            f"`integrator` must be one count or one per output ({p}); got "
            f"{integrators!r}"
        )
    # Checked against the most a shared fit takes, not against a
    # denominator's order: the shared A holds none of them.
    counts = tuple(integrator_count(v, math.inf) for v in values)
    if max(counts) > MOST_INTEGRATORS:
        raise ValueError(
            f"`integrator` must be at most {MOST_INTEGRATORS} known integrators per "
            f"output; got {integrators!r}"
        )
    return counts


def summed(one: IOData, count: int) -> IOData:
    """`one` with its inputs summed `count` times (the known integrators)."""
    u = one.u
    for _ in range(count):
        u = np.cumsum(u, axis=0)
    return replace(one, u=u) if count else one


def _lagged(v: np.ndarray, nb: int, nk: int) -> np.ndarray:
    """``[v_j(t - nk - k)]``: column ``j nb + k`` is input `j` delayed by
    ``nk + k`` (zero before the record), shape (N, m nb)."""
    n, m = v.shape
    pad = np.zeros((n + nk + nb - 1, m))
    pad[nk + nb - 1 :] = v
    # windows[t, j, i] = pad[t + i, j], and v(t - nk - k) = pad[t + nb - 1 - k].
    windows = np.lib.stride_tricks.sliding_window_view(pad, nb, axis=0)[:n]
    return np.ascontiguousarray(windows[:, :, ::-1]).reshape(n, m * nb)


def _shifted(x: np.ndarray, count: int) -> np.ndarray:
    """``[x(t - 1), .., x(t - count)]``, zero before the record, (N, count)."""
    n = x.shape[0]
    out = np.zeros((n, count))
    for k in range(1, count + 1):
        if k < n:
            out[k:, k - 1] = x[: n - k]
    return out


def equation_regressors(one: IOData, arx: ARX) -> np.ndarray:
    """The equation-error regressors of one output of a record of several
    inputs, ``[-y(t-1) .. -y(t-na), u_j(t-nk) .. u_j(t-nk-nb+1) for each
    j]``, rows from ``max_lag`` on (the ARX regressors, input by input)."""
    phi = np.hstack([-_shifted(one.y, arx.na), _lagged(one.inputs, arx.nb, arx.nk)])
    return phi[arx.max_lag :]


def _gram_solver(big: np.ndarray):
    """``rhs -> G^-1 rhs`` with ``G = V' V`` of the regressors `big`,
    scaled to a unit diagonal first (filtering by a lightly damped ``1 /
    A`` spreads their scales); None when ``G`` is singular even with the
    ridge."""
    gram = big.T @ big
    d = np.sqrt(np.diag(gram))
    if not np.all(d > 0):
        return None
    scaled = gram / np.outer(d, d)
    factor = None
    # Regressors collinear to rounding give a non-positive pivot: a ridge
    # of 1e-13 on the unit diagonal, as the compiled kernel adds.
    for ridge in (0.0, 1e-13):
        try:
            factor = np.linalg.cholesky(scaled + ridge * np.eye(d.size))
            break
        except np.linalg.LinAlgError:
            continue
    if factor is None:
        return None

    def solve(rhs):
        rhs = rhs / (d if rhs.ndim == 1 else d[:, None])
        x = np.linalg.solve(factor.T, np.linalg.solve(factor, rhs))
        return x / (d if rhs.ndim == 1 else d[:, None])

    return solve


class _Projection:
    """The outputs that share one set of (summed) inputs: ``V(A)``, its QR
    factors and every output's numerators and residual, for the last
    denominator asked (the search asks each part in turn)."""

    def __init__(self, arx: ARX, inputs: np.ndarray, outputs: np.ndarray) -> None:
        self.arx = arx
        self.u = inputs
        self.y = outputs
        self._key = None
        self._at = None

    def at(self, a: np.ndarray) -> dict | None:
        """``V``, its Gram solver, numerators (m nb, q) and residuals (N, q)
        at a stable `a`; None for an unstable one (not simulated)."""
        a = np.asarray(a, dtype=float)
        key = a.tobytes()
        if key == self._key:
            return self._at
        out = None
        if is_stable_polynomial(a):
            den = np.r_[1.0, a]
            v = lfilter([1.0], den, self.u, axis=0)
            big = _lagged(v, self.arx.nb, self.arx.nk)
            solve = _gram_solver(big)
            if solve is None:
                # Collinear regressors (an input that is zero): the
                # minimum-norm numerators.
                coef = np.linalg.lstsq(big, self.y, rcond=None)[0]
                solve = np.linalg.pinv(big.T @ big).__matmul__
            else:
                coef = solve(big.T @ self.y)
                # One step of iterative refinement from the residual itself
                # (the seminormal equations, as the compiled kernel does):
                # the Gram matrix squares the regressors' conditioning.
                coef += solve(big.T @ (self.y - big @ coef))
            out = dict(a=a, den=den, v=v, V=big, solve=solve, coef=coef)
            out["resid"] = self.y - big @ coef
        self._key, self._at = key, out
        return out

    def residual(self, a, c: int) -> tuple[np.ndarray, np.ndarray]:
        """Output column `c`'s projected residual and its Jacobian (module
        docstring), shape (N,) and (N, na)."""
        at = self.at(a)
        if at is None:
            raise ValueError("`a` must be a stable denominator")
        na, nb, nk = self.arx.na, self.arx.nb, self.arx.nk
        r = at["resid"][:, c]
        yhat = self.y[:, c] - r
        s = _shifted(lfilter([1.0], at["den"], yhat), na)
        w_big = _lagged(lfilter([1.0], at["den"], at["v"], axis=0), nb, nk)
        n = r.size
        z = np.empty((w_big.shape[1], na))
        for k in range(na):
            z[:, k] = -w_big[: n - k - 1].T @ r[k + 1 :]
        big = at["V"]
        jac = s - big @ at["solve"](big.T @ s + z)
        return r, jac


class _Part:
    """One output of :class:`SharedInputsCost`, with the interface of a
    single-input :class:`~spiralid.sysid.estimation.linear.varpro.ProjectedCost`
    that the shared fit uses: ``data``, ``sse``, ``residual``,
    ``numerator`` and the paper's cost."""

    def __init__(self, group: _Projection, column: int, data: IOData) -> None:
        self.group, self.column, self.data = group, column, data
        self.K = data.n
        self.w = auto_gain(data.y)

    def sse(self, a) -> float:
        at = self.group.at(a)
        if at is None:
            return math.inf
        r = at["resid"][:, self.column]
        return float(r @ r)

    def __call__(self, a) -> float:
        """The output's own paper cost, eq. (2), at `a`."""
        return self.w / self.K * math.sqrt(self.sse(a))

    def numerator(self, a) -> np.ndarray:
        """``[b_i1, .., b_im]`` (m nb,) at `a` (NaN where unstable)."""
        at = self.group.at(a)
        if at is None:
            return np.full(self.group.u.shape[1] * self.group.arx.nb, np.nan)
        return at["coef"][:, self.column].copy()

    def residual(self, a) -> tuple[np.ndarray, np.ndarray]:
        return self.group.residual(a, self.column)


class WeightedOutputs:
    """What the shared costs of one and of several inputs have in common:
    each output's part (``parts``, each with its ``data`` and ``sse``)
    weighted by ``lambda_i`` (``weights``), and the percent RMS error the
    cost reports."""

    def _weigh(self, weights) -> None:
        """Set ``weights`` (default ``1 / mean(y_i^2)``), checked, and the
        norm the reported percent divides by."""
        energy = np.array([float(np.sum(part.data.y**2)) for part in self.parts])
        if weights is None:
            weights = self.data.n / np.maximum(energy, np.finfo(float).tiny)
        weights = np.asarray(weights, dtype=float).ravel()
        if weights.shape != (len(self.parts),) or not np.all(
            np.isfinite(weights) & (weights > 0)
        ):
            raise ValueError(
                f"`weights` must be {len(self.parts)} finite numbers > 0 (one per "
                f"output); got {weights!r}"
            )
        self.weights = weights
        self._norm = float(weights @ energy)

    def reweighted(self, weights):
        """The same cost with other weights."""
        return type(self)(self.arx, self.data, weights, self.integrators)

    def fun_of_sse(self, sse: float) -> float:
        """The reported percent RMS error of the weighted sum `sse`."""
        return 100.0 * float(np.sqrt(max(sse, 0.0) / self._norm))

    def sse(self, a) -> float:
        """The weighted sum of the outputs' squared errors at `a`."""
        return float(
            sum(
                w * part.sse(a)
                for w, part in zip(self.weights, self.parts, strict=True)
            )
        )


class SharedInputsCost(WeightedOutputs):
    """``J(A)`` over denominators for a record of several inputs, every
    input-output numerator projected out (module docstring): the interface
    of :class:`~spiralid.sysid.estimation.shared.denominator.SharedProjectedCost`.

    Parameters
    ----------
    arx : ARX
        Each input-output pair's structure, without known integrators.
    data : IOData
        A record of ``m >= 2`` inputs and ``p >= 1`` outputs.
    weights : array_like, shape (p,), optional
        ``lambda_i``; default ``1 / mean(y_i^2)``.
    integrators : sequence of int, optional
        Each output's known integrators (every input summed for it).

    Examples
    --------
    Two inputs through one pole pair, numerators exact:

    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal((400, 2))
    >>> a = [1.0, -1.5, 0.7]
    >>> y = lfilter([0, 1.0], a, u[:, 0]) + lfilter([0, 0.5, 0.2], a, u[:, 1])
    >>> cost = SharedInputsCost(ARX(2, 2, 1), IOData(u, y, ts=1.0))
    >>> float(cost([-1.5, 0.7])) < 1e-9
    True
    >>> cost.numerators([-1.5, 0.7]).round(9) + 0.0
    array([[1. , 0. , 0.5, 0.2]])
    """

    def __init__(self, arx: ARX, data: IOData, weights=None, integrators=None) -> None:
        self.arx = arx
        self.data = data
        self.integrators = shared_integrators(integrators, data.n_outputs)
        groups = {}
        for k in sorted(set(self.integrators)):
            cols = [i for i, c in enumerate(self.integrators) if c == k]
            u = summed(data, k).inputs
            groups[k] = _Projection(arx, u, data.outputs[:, cols])
        self.parts = []
        for i, k in enumerate(self.integrators):
            one = summed(data.output(i), k)
            column = [j for j, c in enumerate(self.integrators) if c == k].index(i)
            self.parts.append(_Part(groups[k], column, one))
        self._weigh(weights)

    def normal_equations(self, a):
        total_s, total_g, total_h = 0.0, 0.0, 0.0
        for w, part in zip(self.weights, self.parts, strict=True):
            r, jac = part.residual(a)
            total_s += w * float(r @ r)
            total_g = total_g + w * (jac.T @ r)
            total_h = total_h + w * (jac.T @ jac)
        return total_s, total_g, total_h

    def evaluate(self, a) -> tuple[np.ndarray, np.ndarray]:
        """Costs and numerators ``[b_1, .., b_p]`` of a population."""
        aa = np.atleast_2d(np.asarray(a, dtype=float))
        f = np.array([self.fun_of_sse(self.sse(row)) for row in aa])
        b = np.array([self.numerators(row).ravel() for row in aa])
        return f, b

    def __call__(self, a):
        aa = np.asarray(a, dtype=float)
        if aa.ndim == 1:
            return self.fun_of_sse(self.sse(aa))
        return np.array([self.fun_of_sse(self.sse(row)) for row in aa])

    def per_output(self, a) -> np.ndarray:
        """Each output's own paper cost, eq. (2), at denominator `a`."""
        return np.array([float(part(a)) for part in self.parts])

    def numerators(self, a) -> np.ndarray:
        """``[b_i1, .., b_im]`` of each output, shape (p, m nb)."""
        return np.array([part.numerator(a) for part in self.parts])
