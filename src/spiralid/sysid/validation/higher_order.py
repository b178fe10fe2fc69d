"""The Billings-Voon correlation tests for nonlinear models.

A linear model's residual tests (:mod:`.correlation`) cannot see
nonlinear structure left in the residual: a residual that is white and
uncorrelated with the input can still depend on the input's square or on
products of past residuals and inputs. Billings and Voon ("Correlation
based model validity tests for non-linear models", *Int. J. Control* 44(1),
235-244, 1986; S. A. Billings, *Nonlinear System Identification*, Wiley,
2013, section 5.3) give five tests; the model is adequate when all hold:

========================  =============================================  ==========
name                      correlation                                    lags
========================  =============================================  ==========
``"ee"``                  ``phi_ee(k)``: residual autocorrelation        ``1..L``
``"ue"``                  ``phi_ue(k)``: input-residual                  ``-L..L``
``"e(eu)"``               ``phi_e(eu)(k) = E[e(t) e(t-k) u(t-k)]``       ``1..L``
``"u2e"``                 ``phi_u2'e(k)``: ``u^2 - mean(u^2)`` and e     ``-L..L``
``"u2e2"``                ``phi_u2'e2(k)``: ``u^2'`` and ``e^2``         ``-L..L``
========================  =============================================  ==========

(``phi_e(eu)`` at ``k = 1 + tau`` is Billings and Voon's
``phi_xi(xi u)(tau)``, ``tau >= 0``.) Each is the normalised correlation of
:func:`~.correlation.correlation` with the bands ``+-z / sqrt(N)`` drawn as
the papers draw them (95 %: ``1.96 / sqrt(N)``). The verdicts are joint
chi-square tests, as for the linear tests and for the same reason ("every
lag inside the band" rejects white noise 72 % of the time at 25 lags): the
Ljung-Box statistic for ``ee`` and ``e(eu)`` (under the null hypothesis the
product ``e(t-k) u(t-k)`` of a white residual and an independent input is
white and uncorrelated with ``e(t)``), Bartlett's covariance for the three
cross-correlations (:func:`~.correlation.independence_test`), so a coloured
input does not make them reject good models.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..signals import check_pair
from .correlation import (
    _DEFAULT_LEVELS,
    CorrelationTest,
    _check_levels,
    _finish,
    check_lags,
    correlation,
    independence_test,
    whiteness_test,
)

__all__ = ["BILLINGS_VOON", "BillingsVoon", "billings_voon", "correlation_dict"]

# The one list of the tests: name -> what the figure and tables call it.
BILLINGS_VOON = {
    "ee": "residual autocorrelation phi_ee",
    "ue": "input-residual phi_ue",
    "e(eu)": "phi_e(eu)",
    "u2e": "phi_u2'e",
    "u2e2": "phi_u2'e2",
}


@dataclass(frozen=True)
class BillingsVoon:
    """The five tests' outcomes.

    Attributes
    ----------
    tests : dict
        ``{name: CorrelationTest}`` for the names of :data:`BILLINGS_VOON`.
    level : float
        The level the verdicts of :attr:`passed` and :meth:`summary` use.
    """

    tests: dict[str, CorrelationTest]
    level: float = 0.95

    @property
    def not_applicable(self) -> tuple[str, ...]:
        """Tests with no degrees of freedom: nothing to test (a binary
        input's ``u^2`` is constant, so the two ``u^2'`` tests), reported as
        not applicable, never as passed."""
        return tuple(k for k, t in self.tests.items() if not t.applicable)

    @property
    def passed(self) -> dict[str, bool]:
        """``{name: verdict at level}`` of the applicable tests."""
        skip = self.not_applicable
        return {k: t.passed[self.level] for k, t in self.tests.items() if k not in skip}

    @property
    def n_passed(self) -> int:
        """How many of the five tests pass at :attr:`level` (a test that
        does not apply does not count)."""
        return int(sum(self.passed.values()))

    def verdicts(self) -> str:
        """Compact verdicts such as ``"ee+ ue+ e(eu)- u2e+ u2e2+"`` (``u2e
        n/a`` for a test that does not apply)."""
        passed = self.passed
        return " ".join(
            f"{k}{'+' if passed[k] else '-'}" if k in passed else f"{k} n/a"
            for k in self.tests
        )

    def summary(self) -> str:
        """A few lines: each test's statistic, p-value and verdict."""
        lines = [f"Billings-Voon tests at {self.level:.0%} (joint chi-square):"]
        for name, t in self.tests.items():
            if name in self.not_applicable:
                lines.append(
                    f"  {BILLINGS_VOON[name]:<34} not applicable: no degrees "
                    "of freedom (a constant u^2, as a binary input gives; use "
                    "a multilevel input)"
                )
                continue
            lines.append(
                f"  {BILLINGS_VOON[name]:<34} chi2={t.statistic:9.2f} "
                f"(dof {t.dof:3d}) p={t.p_value:.3g} "
                f"{'pass' if t.passed[self.level] else 'FAIL'}; "
                f"{t.n_outside[self.level]} of {t.lags.size} lags outside "
                f"+-{t.bands[self.level]:.3f}"
            )
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-safe dictionary."""
        return {
            "level": float(self.level),
            "passed": {k: bool(v) for k, v in self.passed.items()},
            "not_applicable": list(self.not_applicable),
            "tests": {k: correlation_dict(t) for k, t in self.tests.items()},
        }

    def plot(self):
        """The five correlations with their 95 % bands (a Figure)."""
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(len(self.tests), 1, figsize=(7, 9), sharex=False)
        for ax, (name, t) in zip(axes, self.tests.items(), strict=True):
            band = t.bands[self.level]
            ax.vlines(t.lags, 0.0, t.values, color="C0")
            ax.plot(t.lags, t.values, "o", color="C0", ms=3)
            ax.axhline(band, color="C3", ls="--", lw=1)
            ax.axhline(-band, color="C3", ls="--", lw=1)
            if t.applicable:
                verdict = "pass" if t.passed[self.level] else "FAIL"
                colour = "black"
            else:
                verdict = "n/a (no degrees of freedom)"
                colour = "tab:gray"
            ax.set_title(f"{BILLINGS_VOON[name]}: {verdict}", fontsize=9, color=colour)
            ax.set_ylim(-1.05, 1.05)
            ax.set_ylabel("correlation", fontsize=8)
        axes[-1].set_xlabel("lag (samples)")
        fig.suptitle(
            f"Billings-Voon correlation tests ({self.level:.0%} bands dashed)",
            fontsize=10,
        )
        fig.tight_layout()
        return fig


def correlation_dict(test: CorrelationTest) -> dict:
    """A test's JSON-safe dictionary with ``"applicable"``: a test with no
    degrees of freedom has nothing to test, so its verdicts are null rather
    than the ``true`` its statistic of zero would give (what
    :meth:`CorrelationTest.to_dict` itself writes; kept for its callers).

    Parameters
    ----------
    test : CorrelationTest
    """
    return test.to_dict()


def _product_test(e, u, lags, levels) -> CorrelationTest:
    """``phi_e(eu)(k)`` at ``k = 1..lags`` with a Ljung-Box verdict."""
    n = e.size
    r = correlation(e, e * u, lags)[lags + 1 :]
    k = np.arange(1, lags + 1)
    q = n * (n + 2) * np.sum(r**2 / (n - k))
    return _finish("e(eu)", k, r, n, levels, q, lags)


def _square_part(u: np.ndarray) -> np.ndarray:
    """``u^2 - mean(u^2)``, or zeros when it is an affine function of ``u``.

    Any function of a two-level input is affine in it (``u^2 = (a + b) u -
    a b`` for levels ``a``, ``b``), so the ``u^2'`` tests of a binary input
    repeat the ``u`` tests; with symmetric levels ``u^2`` is constant. An
    offset binary input (a PRBS between 0 and 5 V, or one detrended by
    another record's mean) is the same case: no degrees of freedom.
    """
    u2 = u**2 - np.mean(u**2)
    uc = u - np.mean(u)
    norm_u, norm_u2 = float(np.linalg.norm(uc)), float(np.linalg.norm(u2))
    if norm_u > 0.0 and norm_u2 > 0.0:
        # What of u2 is left after its projection on u' (relative).
        left = u2 - (np.dot(u2, uc) / norm_u**2) * uc
        if np.linalg.norm(left) <= 1e-9 * norm_u2:
            return np.zeros_like(u2)
    return u2


def billings_voon(u, e, lags: int = 25, levels=_DEFAULT_LEVELS) -> BillingsVoon:
    """The five Billings-Voon correlation tests of a residual.

    Parameters
    ----------
    u : array_like, shape (N,)
        Input signal.
    e : array_like, shape (N,)
        Residual (one-step prediction error, usually).
    lags : int, default 25
        Largest lag ``L``, ``1 <= L < N``.
    levels : sequence of float, default (0.95, 0.99)
        Confidence levels; the first is the verdicts' level.

    Returns
    -------
    BillingsVoon

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> u, e = rng.standard_normal(2000), rng.standard_normal(2000)
    >>> billings_voon(u, e).n_passed    # each test errs 5 % of the time
    5
    >>> billings_voon(u, e + 0.5 * (u**2 - 1)).passed["u2e"]
    False
    """
    u, e = check_pair(u, e, "u", "e")
    lags = check_lags(lags, e.size)
    levels = _check_levels(levels)
    u2 = _square_part(u)
    ec = e - np.mean(e)
    tests = {
        "ee": whiteness_test(e, lags, levels),
        "ue": independence_test(u, e, lags, levels),
        "e(eu)": _product_test(ec, u - np.mean(u), lags, levels),
        "u2e": independence_test(u2, e, lags, levels),
        "u2e2": independence_test(u2, ec**2, lags, levels),
    }
    return BillingsVoon(tests=tests, level=levels[0])
