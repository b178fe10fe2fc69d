"""The polynomial NARX structure: monomials of the regressors, whose terms
forward regression chooses (see :mod:`.narx`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._narx_kernels import _poly_free_run
from .narx_lags import _integrators, _Lags, _order

__all__ = ["PolynomialNARX"]


@dataclass(frozen=True)
class PolynomialNARX(_Lags):
    """Polynomial NARX structure: monomials of the regressors up to `degree`.

    Parameters
    ----------
    ny, nu, nk : int
        Lags as for :class:`NARX` (``nk`` defaults to 1, as there, where
        :class:`ARX`'s is 0).
    degree : int
        Largest total degree of a term (1..3).
    n_terms : int or None
        Terms to keep (forward regression stops there); None: stop when the
        error reduction ratios left sum below `tolerance`.
    tolerance : float
        ``1 - sum(ERR)`` at which forward regression stops.
    integrator : bool
        Predict the increment (see the module docstring).
    terms : tuple of tuple of int, optional
        The chosen terms (indices of the regressors multiplied together),
        set by estimation; None before.

    Examples
    --------
    >>> PolynomialNARX(2, 2, 1, degree=2).n_candidates   # 1 + 4 + 10
    15
    """

    ny: int
    nu: int
    nk: int = 1
    degree: int = 2
    n_terms: int | None = 10
    tolerance: float = 1e-4
    integrator: bool = False
    terms: tuple[tuple[int, ...], ...] | None = field(default=None, compare=True)

    def __post_init__(self) -> None:
        object.__setattr__(self, "ny", _order(self.ny, "ny", 1))
        object.__setattr__(self, "nu", _order(self.nu, "nu", 1))
        object.__setattr__(self, "nk", _order(self.nk, "nk", 0))
        deg = _order(self.degree, "degree", 1)
        if deg > 3:
            raise ValueError(f"`degree` must be an integer in [1, 3]; got {deg!r}")
        object.__setattr__(self, "degree", deg)
        object.__setattr__(self, "integrator", _integrators(self.integrator))
        if self.n_terms is not None:
            object.__setattr__(self, "n_terms", _order(self.n_terms, "n_terms", 1))
        tol = self.tolerance
        if not (isinstance(tol, float | int) and 0.0 < tol < 1.0):
            raise ValueError(f"`tolerance` must be in (0, 1); got {tol!r}")
        if self.terms is not None:
            terms = tuple(tuple(int(i) for i in t) for t in self.terms)
            if any(
                len(t) != deg or min(t) < 0 or max(t) > self.n_regressors for t in terms
            ):
                raise ValueError(
                    f"`terms` must be tuples of {deg} indices in "
                    f"[0, {self.n_regressors}]; got {self.terms!r}"
                )
            object.__setattr__(self, "terms", terms)

    def candidates(self) -> list[tuple[int, ...]]:
        """Every monomial up to `degree` as sorted regressor indices (0: the
        constant 1, ``i``: regressor ``i - 1``)."""
        from itertools import combinations_with_replacement

        return list(
            combinations_with_replacement(range(self.n_regressors + 1), self.degree)
        )

    @property
    def n_candidates(self) -> int:
        """Number of candidate terms."""
        return len(self.candidates())

    #: Validated as a nonlinear model (higher-order tests, no poles), even at
    #: ``degree=1``: its fitted model holds monomials, not polynomials in q.
    is_linear = False

    #: The estimator table's family (a record of one output only).
    family = "polynomial-narx"
    outputs_family = None

    @property
    def n_params(self) -> int:
        """Number of coefficients (the chosen terms, or the cap)."""
        if self.terms is not None:
            return len(self.terms)
        return self.n_terms or self.n_candidates

    def term_matrix(self, phi: np.ndarray, terms=None) -> np.ndarray:
        """Columns of the given terms (default the chosen, else all) over ``phi``.

        Parameters
        ----------
        phi : ndarray, shape (N, ny + nu)
        terms : sequence of tuple, optional
        """
        terms = self.terms if terms is None else terms
        if terms is None:
            terms = self.candidates()
        ext = np.hstack([np.ones((phi.shape[0], 1)), phi])
        return np.prod(ext[:, np.asarray(terms)], axis=2)

    def evaluate(self, params, phi: np.ndarray) -> np.ndarray:
        """The map ``F(phi)`` (scaled).

        Parameters
        ----------
        params : array_like, shape (n_terms,)
        phi : ndarray, shape (N, ny + nu)
        """
        return self.term_matrix(phi) @ np.asarray(params, dtype=float)

    def free_run_scaled(self, params, ulag, hist) -> np.ndarray:
        """Compiled free run (scaled map outputs), one per row of `params`.

        Parameters
        ----------
        params : array_like, shape (n_terms,) or (m, n_terms)
        ulag : ndarray, shape (N, nu)
        hist : ndarray, shape (ny,)
        """
        P = np.atleast_2d(np.asarray(params, dtype=float))
        out = np.empty((P.shape[0], ulag.shape[0]))
        terms = np.asarray(self.terms, dtype=np.int64).reshape(-1, self.degree)
        for j in range(P.shape[0]):
            _poly_free_run(
                np.ascontiguousarray(P[j]),
                terms,
                np.ascontiguousarray(ulag),
                np.ascontiguousarray(hist, dtype=float),
                self.ny,
                out[j],
            )
        return out[0] if np.ndim(params) == 1 else out

    def term_names(self) -> list[str]:
        """Readable names such as ``y(t-1)*u(t-2)``."""
        out = []
        ylab = "dy" if self.integrator else "y"
        for t in self.terms or ():
            parts = []
            for i in t:
                if i == 0:
                    continue
                if i <= self.ny:
                    parts.append(f"{ylab}(t-{i})")
                else:
                    parts.append(f"u(t-{self.nk + i - 1 - self.ny})")
            out.append("*".join(parts) or "1")
        return out

    def __str__(self) -> str:
        n = len(self.terms) if self.terms is not None else self.n_terms
        return (
            f"PolynomialNARX({self.ny}, {self.nu}, {self.nk}, degree={self.degree}, "
            f"terms={n})"
        )
