"""Forward-regression orthogonal least squares (FROLS) of a polynomial NARX
(Billings, *Nonlinear System Identification*, Wiley, 2013, ch. 3): the
terms chosen one at a time by their error reduction ratio."""

from __future__ import annotations

import time

import numpy as np

from spiralid.optim.result import OptimiserResult

from ...models.narx import PolynomialNARX
from .problem import NARXProblem, narx_result

__all__ = ["frols"]


def frols(problem: NARXProblem) -> OptimiserResult:
    """Forward-regression orthogonal least squares of a polynomial NARX.

    Parameters
    ----------
    problem : NARXProblem
        With a :class:`PolynomialNARX` structure; the fitted structure (its
        chosen terms) replaces it.

    Returns
    -------
    OptimiserResult
        ``x`` the coefficients, ``err`` the chosen terms' error reduction
        ratios in order.
    """
    t0 = time.perf_counter()
    st = problem.structure
    cands = st.candidates()
    # Every sample: forward regression stops by its own rule, no early
    # stopping needs a held-back part.
    rows = slice(st.max_lag, problem.data.n)
    P = st.term_matrix(problem.phi[rows], cands)
    y = problem.target[rows]
    yy = float(y @ y) or 1.0
    Q = P.copy()
    chosen: list[int] = []
    errs: list[float] = []
    cap = min(st.n_terms or len(cands), len(cands), y.size - 1)
    while len(chosen) < cap:
        norms = np.einsum("ij,ij->j", Q, Q)
        g = (Q.T @ y) / np.where(norms > 0, norms, np.inf)
        err = g**2 * norms / yy
        err[chosen] = -1.0
        # Columns already spanned by the chosen ones (norm ~ 0) carry nothing.
        err[norms <= 1e-12 * np.einsum("ij,ij->j", P, P)] = -1.0
        j = int(np.argmax(err))
        if err[j] <= 0:
            break
        chosen.append(j)
        errs.append(float(err[j]))
        w = Q[:, j].copy()
        Q -= np.outer(w, (w @ Q) / (w @ w))
        if st.n_terms is None and 1.0 - sum(errs) < st.tolerance:
            break
    terms = tuple(cands[j] for j in chosen)
    coef, *_ = np.linalg.lstsq(P[:, chosen], y, rcond=None)
    fitted = PolynomialNARX(
        st.ny,
        st.nu,
        st.nk,
        degree=st.degree,
        n_terms=len(terms),
        tolerance=st.tolerance,
        integrator=st.integrator,
        terms=terms,
    )
    problem.structure = fitted
    return narx_result(
        problem,
        coef,
        t0,
        err=np.asarray(errs),
        message="Forward-regression orthogonal least squares (ERR order).",
    )
