"""Variable projection: the paper's cost as a function of the denominator alone.

The simulation error from rest is linear in the numerator: with ``v`` the
input filtered by ``1 / A`` from rest,

    yhat(t) = B(q) / A(q) u(t) = sum_j b_j v(t - nk - j),   j = 0..nb-1,

so for every candidate denominator ``A`` the best numerator is the exact
least-squares solution ``b(A) = argmin_b ||y - V(A) b||`` over the filtered,
shifted regressors ``V(A)``. Searching ``A`` alone (``na`` parameters, not
``na + nb``) with ``b`` projected out is the variable-projection method of
Golub and Pereyra (SIAM J. Numer. Anal. 10(2), 1973). The value reported is
the paper's cost, eq. (2)-(3), exactly as :class:`~spiralid.sysid.PaperCost`
computes it (same gain ``w``, same ``K = N``) at ``theta = [a, b(A)]``.

Choices where the method is silent:

- Only ``predictor="simulation"`` with ``initial="rest"``. The one-step
  error is convex and least squares is its exact minimiser (``method="ls"``);
  from the measured past the initial state depends on ``b`` through the
  past inputs, a different projection we do not offer (a clear error says so).
- An unstable candidate (a coefficient search can propose one) is not
  simulated, as in :class:`PaperCost`: its numerator minimises the one-step
  error for that denominator (from the Gram matrix, O(p^2)) and its value is
  PaperCost's there, penalty included.
- Since ``b = 0`` is always available, the projected cost of a stable
  denominator never exceeds the zero model's (100 at ``gain="auto"``).
"""

from __future__ import annotations

import numpy as np

from spiralid.optim.result import OptimiserResult

from ...data import IOData
from ...models.arx import ARX
from ...models.polynomials import is_stable_polynomial
from ..core.cost import PaperCost
from .levenberg import damped_descent

__all__ = ["ProjectedCost", "gauss_newton_polish"]

_kernels = None


def _kernel():
    """The compiled kernel, imported (and compiled or loaded) on first use."""
    global _kernels
    if _kernels is None:
        from . import _varpro_kernels

        _kernels = _varpro_kernels
    return _kernels.projected_sse


class ProjectedCost:
    """Eq. (2)-(3) over denominators, the numerator projected out.

    Parameters
    ----------
    arx : ARX
        Model structure; the search is over its ``na`` denominator
        coefficients.
    data : IOData
        Estimation record.
    gain, penalty
        As in :class:`~spiralid.sysid.PaperCost`.
    predictor : {"simulation"}
        Only the simulation error is projected (see the module docstring).
    initial : {"rest"}
        Only the simulation from rest is projected.

    Attributes
    ----------
    paper : PaperCost
        The paper's cost on the same record; ``paper(theta(a))`` equals
        ``self(a)``.
    w, K : float, int
        The gain and number of samples of :attr:`paper`.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> from spiralid.sysid import ARX, IOData
    >>> u = np.random.default_rng(0).standard_normal(300)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> cost = ProjectedCost(ARX(2, 2, 1), IOData(u, y, ts=1.0))
    >>> cost.theta([-1.5, 0.7]).round(9)      # the true numerator comes out
    array([-1.5,  0.7,  1. ,  0.5])
    >>> round(float(cost([-1.5, 0.7])), 9)
    0.0
    """

    def __init__(
        self,
        arx: ARX,
        data: IOData,
        gain: str | float = "auto",
        penalty: float = 1e6,
        predictor: str = "simulation",
        initial: str = "rest",
    ) -> None:
        if predictor != "simulation":
            raise ValueError(
                "`predictor` must be 'simulation' for variable projection; got "
                f"{predictor!r} (the one-step error is convex: method='ls' is its "
                "exact minimiser)"
            )
        if initial != "rest":
            raise ValueError(
                "`initial` must be 'rest' for variable projection; got "
                f"{initial!r} (from the measured past the initial state depends on "
                "the numerator; use method='oe' for initial='measured')"
            )
        self.paper = PaperCost(arx, data, gain=gain, penalty=penalty, initial=initial)
        self.arx = arx
        self.data = data
        self.w = self.paper.w
        self.K = self.paper.K
        self._u = np.ascontiguousarray(data.u)
        self._y = np.ascontiguousarray(data.y)

    def __repr__(self) -> str:
        return f"ProjectedCost({self.arx}, K={self.K}, w={self.w:.6g})"

    @property
    def n_params(self) -> int:
        """Searched parameters: the ``na`` denominator coefficients."""
        return self.arx.na

    def _denominators(self, a) -> tuple[np.ndarray, bool]:
        arr = np.asarray(a, dtype=float)
        na = self.arx.na
        if arr.ndim not in (1, 2) or arr.shape[-1] != na:
            raise ValueError(
                f"`a` must have shape ({na},) or (m, {na}); got shape {arr.shape}"
            )
        return np.atleast_2d(arr), arr.ndim == 1

    def evaluate(self, a) -> tuple[np.ndarray, np.ndarray]:
        """Costs and projected numerators of a population of denominators.

        Parameters
        ----------
        a : array_like, shape (m, na)

        Returns
        -------
        f : ndarray, shape (m,)
            Eq. (2)-(3) at ``[a, b]``.
        b : ndarray, shape (m, nb)
        """
        aa, _ = self._denominators(a)
        m = aa.shape[0]
        arx = self.arx
        f = np.empty(m)
        b = np.empty((m, arx.nb))
        stable = is_stable_polynomial(aa) if arx.na else np.ones(m, bool)
        idx = np.flatnonzero(stable)
        if idx.size:
            sub = aa[idx]
            bt = np.empty((arx.nb, idx.size))
            sse = np.empty(idx.size)
            _kernel()(self._u, self._y, np.ascontiguousarray(sub.T), arx.nk, bt, sse)
            b[idx] = bt.T
            f[idx] = (self.w / self.K) * np.sqrt(sse)
        bad = np.flatnonzero(~stable)
        if bad.size:
            b[bad] = self._one_step_numerator(aa[bad])
            f[bad] = self.paper(np.concatenate([aa[bad], b[bad]], axis=1))
        return f, b

    def _one_step_numerator(self, a: np.ndarray) -> np.ndarray:
        """``argmin_b`` of the one-step error for fixed denominators (Gram)."""
        na = self.arx.na
        gram, phity = self.paper.gram, self.paper.phity
        rhs = phity[na:][None, :] - a @ gram[:na, na:]
        return np.linalg.lstsq(gram[na:, na:], rhs.T, rcond=None)[0].T

    def __call__(self, a) -> np.ndarray | float:
        """Eq. (2)-(3) at the projected numerator; float for one denominator."""
        aa, single = self._denominators(a)
        f, _ = self.evaluate(aa)
        return float(f[0]) if single else f

    def numerator(self, a) -> np.ndarray:
        """The projected numerator ``b(A)``, shape (nb,) or (m, nb)."""
        aa, single = self._denominators(a)
        _, b = self.evaluate(aa)
        return b[0] if single else b

    def theta(self, a) -> np.ndarray:
        """ARX theta ``[a, b(A)]``, shape (p,) or (m, p)."""
        aa, single = self._denominators(a)
        th = np.concatenate([aa, self.evaluate(aa)[1]], axis=1)
        return th[0] if single else th

    # -- residual and Jacobian of one candidate (for Gauss-Newton) -------------

    def sse(self, a) -> float:
        """``||y - V b(A)||^2`` of one stable denominator (what the
        Gauss-Newton polish lowers)."""
        a = np.ascontiguousarray(np.asarray(a, dtype=float)[:, None])
        b = np.empty((self.arx.nb, 1))
        out = np.empty(1)
        _kernel()(self._u, self._y, a, self.arx.nk, b, out)
        return float(out[0])

    def normal_equations(self, a) -> tuple[float, np.ndarray, np.ndarray]:
        """``(sse, J'r, J'J)`` of the projected residual at one denominator
        (:meth:`residual`'s ``J``), reduced in compiled loops."""
        _kernel()
        a = np.ascontiguousarray(a, dtype=float)
        return _kernels.normal_equations(self._u, self._y, a, self.arx.nb, self.arx.nk)

    def fun_of_sse(self, sse: float) -> float:
        """The cost, eq. (2), of a projected squared error."""
        return self.w / self.K * np.sqrt(sse)

    def residual(self, a) -> tuple[np.ndarray, np.ndarray]:
        """``(r, J)``: the projected residual ``y - V b(A)`` of one stable
        denominator and its exact Jacobian ``d r / d a`` (Golub-Pereyra).

        With ``G = V'V`` and ``D_i = d(V b)/d a_i`` at fixed
        ``b`` (``-1/A`` applied to ``yhat`` delayed by ``i``):
        ``d r / d a_i = -D_i + V G^-1 (V' D_i - (dV/da_i)' r)``.
        """
        a = np.ascontiguousarray(a, dtype=float)
        _kernel()  # load the module
        r, jac = _kernels.residual_jacobian(
            self._u, self._y, a, self.arx.nb, self.arx.nk
        )
        return r, jac


def gauss_newton_polish(
    cost: ProjectedCost,
    parametrization,
    x0,
    max_nfev: int = 10,
) -> OptimiserResult:
    """A few Levenberg-Marquardt steps of the projected problem.

    Minimises ``||y - V(A(x)) b(A(x))||^2`` over the searched denominator
    coordinates ``x``, inside the parametrisation's box (a step leaving it
    is clipped back). Exact Jacobian of the projected residual
    (:meth:`ProjectedCost.residual`) chained with the parametrisation's
    ``jacobian``; the damping ``lambda`` of ``(J'J + lambda diag(J'J))``
    shrinks after a successful step and grows after a failed one (Marquardt,
    1963), in the one Levenberg-Marquardt loop
    (:func:`~spiralid.sysid.estimation.linear.levenberg.damped_descent`). The
    normal equations are formed in compiled loops: on a shared machine a
    threaded BLAS on these thin matrices is several times slower.

    Parameters
    ----------
    cost : ProjectedCost
        Or any cost with ``sse(a)``, ``normal_equations(a)`` and
        ``fun_of_sse(sse)`` (the shared denominator's,
        :class:`~spiralid.sysid.estimation.shared.denominator.SharedProjectedCost`).
    parametrization
        Has ``bounds`` (na, 2), ``to_denominator(x)`` and ``jacobian(x)``
        (``d a / d x``), e.g. :class:`~spiralid.sysid.ModalParametrization`.
    x0 : array_like, shape (na,)
        Start, inside the box (a stable denominator).
    max_nfev : int
        Budget in evaluations: a Jacobian and a trial point count one each.

    Returns
    -------
    OptimiserResult
        ``x`` (coordinates, never worse than `x0`), ``fun`` (the paper's cost
        there), ``nfev``, ``nit`` (accepted steps), ``status`` (a key of
        :data:`~spiralid.optim.result.STATUS`: 1 when the budget ended it, 0
        at a step below the tolerance or no decrease), ``message``.
    """
    box = parametrization.bounds
    lo, hi = box[:, 0], box[:, 1]

    def evaluate(pt):
        return cost.sse(parametrization.to_denominator(pt)), None

    def linearise(x, _sse, _state):
        s0, g_a, h_a = cost.normal_equations(parametrization.to_denominator(x))
        m = parametrization.jacobian(x)
        grad = m.T @ g_a
        hess = m.T @ h_a @ m
        diag = np.maximum(np.diag(hess), 1e-300)
        # Coordinates on a bound whose descent direction leaves the box
        # stay there; the step is solved for the others.
        free = ~(((x <= lo) & (grad > 0)) | ((x >= hi) & (grad < 0)))

        def step(lam):
            out = np.zeros_like(x)
            sub = hess[np.ix_(free, free)] + lam * np.diag(diag[free])
            try:
                out[free] = -np.linalg.solve(sub, grad[free])
            except np.linalg.LinAlgError:
                return None
            return out

        return s0, step, False

    def converged(before, x, _sse_before, _sse, _nfev):
        small = np.all(np.abs(x - before) <= 1e-10 * (hi - lo))
        return "small" if small else None

    # The one Levenberg-Marquardt loop (levenberg.py) with this problem's
    # normal equations, the box as its projection, and the damping growing
    # fourfold after a rejected point as this polish always has.
    out = damped_descent(
        evaluate,
        linearise,
        np.clip(np.asarray(x0, dtype=float), lo, hi),
        max_nfev=max_nfev,
        project=lambda pt: np.clip(pt, lo, hi),
        converged=converged,
        linearising_counts=True,
        grow=4.0,
        lam_max=1e12,
    )
    x, sse, stop = out["x"], out["cost"], out["stop"]
    if stop == "small":
        status, message = 0, "Step below tolerance."
    elif stop == "no decrease" and out["nfev"] < max_nfev:
        status, message = 0, "No decrease along the damped step."
    else:
        status, message = 1, "Evaluation budget used."
    return OptimiserResult(
        x=x,
        fun=cost.fun_of_sse(sse)
        if sse is not None
        else cost(parametrization.to_denominator(x)),
        nfev=out["nfev"],
        nit=out["nit"],
        status=status,
        message=message,
        success=True,
        n_restarts=0,
        history=None,
    )
