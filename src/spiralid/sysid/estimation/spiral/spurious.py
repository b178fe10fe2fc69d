"""Acting on the modes table's diagnosis: flagged poles removed and refitted.

The modes table (:class:`~spiralid.sysid.models.modes.ModeTable`) flags a
mode whose pole's 95 % radius interval reaches ``|z| = 1`` (the record does
not show it decay: it is indistinguishable from a drift or an offset) or
that a zero cancels within the pole's interval (it barely reaches the
output). On real records the recommended method returned such modes and
said so without acting on it (a heat-exchanger record whose every mode
was flagged validated 15 points below output error). After
``"spiral"`` (``cancel=True``, its default) each flagged pole is therefore
a candidate for removal, as a near pole-zero cancellation is
(:mod:`~spiralid.sysid.estimation.spiral.cancellation`):

- a complex pair flagged in the table (``reaches_unit_circle`` or
  ``cancelled``), and a real pole whose radius interval reaches ``|z| = 1``
  (the table lists pairs only; a real pole that slow is the same drift,
  and the stability margin's time constant alone does not bound it:
  on the exchanger the drift's pole sat at 0.99962, inside the margin);
- removed with the zero (or pair of zeros) nearest to it: both polynomials
  are deflated (:func:`~spiralid.sysid.estimation.spiral.cancellation.deflate`,
  the remainder of the numerator's division dropped), the reduced model
  ``ARX(na - k, nb - k, nk)`` is polished by output error with the same
  stability margin, and its estimation cost is judged.

The statistical tolerance: the likelihood-ratio test of the nested models
at the 5 % level. Removing ``k`` poles and ``k`` zeros fixes ``d = 2k``
parameters; with Gaussian errors ``N_eff ln(V_reduced / V)`` is ``chi2(d)``
when the reduced model holds, so the removal is kept while

    V_reduced <= V exp(chi2_0.95(d) / N_eff).

``N`` samples of a white error would give ``N_eff = N``; the simulation
error of a model on a record with drift is far from white, and its
correlated samples carry less evidence: ``N_eff = N / tau`` with ``tau =
1 + 2 sum_k rho_k`` the error's integrated autocorrelation time (its
autocorrelations ``rho_k`` summed up to the first that is not positive,
:func:`effective_samples`). On a white error this is the textbook test; on
a drifting one the tolerance widens as far as the drift leaves the data
unable to tell the models apart. ``d`` and the rise are counted from the
estimate before any removal, so removals cannot creep past the tolerance
one by one.

A flagged pole whose removal costs more than the tolerance is kept, and the
model says which and why (``IdentifiedModel.diagnosis``, the validation
summary's "estimate chosen by" row): the record then holds evidence for it
that the interval does not show. Candidates are tried slowest first, again
after each removal; the flags are recomputed at the reduced order.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from ...data import IOData
from ...models.arx import ARX
from ...models.modes import mode_table
from ..core.uncertainty import parameter_covariance
from .cancellation import Candidate, pad

__all__ = [
    "LEVEL",
    "Diagnosis",
    "Flagged",
    "effective_samples",
    "flagged_poles",
    "remove_flagged",
    "tolerance",
]

#: The likelihood-ratio test's size: a removal is refused when the rise of
#: the cost is significant at this level.
LEVEL = 0.05

# A root with |imag| below this (relative to its size) is real.
_REAL = 1e-8


@dataclass(frozen=True)
class Flagged:
    """A pole (the upper member of a pair) the diagnosis flags, and why."""

    pole: complex
    reasons: tuple[str, ...]

    @property
    def size(self) -> int:
        return 2 if abs(self.pole.imag) > 0.0 else 1


@dataclass
class Diagnosis:
    """What acting on the diagnosis did (``IdentifiedModel.diagnosis``):
    the poles removed and the flagged poles kept, with the test's
    tolerance, the effective samples it used and the cost each kept pole's
    removal would have taken; ``untried`` counts the flagged poles left
    when the polishes' budget was spent; ``flagged`` counts the poles the
    table flagged on the estimate before any removal."""

    n_samples: int
    n_effective: float
    flagged: int = 0
    removed: list[dict] = field(default_factory=list)
    kept: list[dict] = field(default_factory=list)
    untried: int = 0

    def to_dict(self) -> dict:
        return {
            "n_samples": int(self.n_samples),
            "n_effective": float(self.n_effective),
            "removed": [dict(r) for r in self.removed],
            "kept": [dict(k) for k in self.kept],
            "untried": int(self.untried),
            "flagged": int(self.flagged),
            "note": self.sentence(),
        }

    def sentence(self) -> str:
        """One line for a summary."""
        parts = []
        if self.removed:
            where = ", ".join(_pole_text(r["pole"]) for r in self.removed)
            rise = self.removed[-1]["cost_increase"]
            parts.append(
                f"{len(self.removed)} flagged pole(s) removed (z = {where}: "
                f"{'; '.join(sorted({x for r in self.removed for x in r['reasons']}))}"
                f"), estimation cost {100 * rise:+.2g} %, within the "
                f"likelihood-ratio test's tolerance at {100 * LEVEL:g} % "
                f"({self.n_effective:.0f} effective samples of {self.n_samples})"
            )
        for k in self.kept:
            parts.append(
                f"the flagged pole at z = {_pole_text(k['pole'])} "
                f"({'; '.join(k['reasons'])}) was kept: removing it raised the "
                f"estimation cost {100 * k['cost_increase']:+.3g} %, more than "
                f"the tolerance {100 * k['tolerance']:.3g} % (likelihood-ratio "
                f"test at {100 * LEVEL:g} %, {self.n_effective:.0f} effective "
                "samples): the record holds evidence for it"
            )
        if self.untried:
            parts.append(
                f"{self.untried} flagged pole(s) left untried: the removal's "
                "evaluation budget (tied to output error's work) was spent"
            )
        return "; ".join(parts)


def _pole_text(pole) -> str:
    re, im = pole
    return f"{re:.5g}" if im == 0 else f"{re:.5g} +- {abs(im):.3g}j"


def effective_samples(error) -> float:
    """``N / tau``: the samples of a correlated error worth as many
    independent ones, ``tau = 1 + 2 sum_k rho_k`` its integrated
    autocorrelation time, the sum over the lags up to the first
    non-positive autocorrelation (at most ``N / 4``).

    Examples
    --------
    >>> import numpy as np
    >>> e = np.random.default_rng(0).standard_normal(4000)
    >>> 3500 < effective_samples(e) <= 4000
    True
    >>> from scipy.signal import lfilter
    >>> ar = lfilter([1.0], [1.0, -0.9], e)   # tau = (1 + 0.9) / (1 - 0.9) = 19
    >>> 100 < effective_samples(ar) < 400
    True
    """
    e = np.asarray(error, dtype=float)
    e = e - e.mean()
    n = e.size
    var = float(e @ e)
    if n < 4 or var == 0.0:
        return float(n)
    m = 1 << int(np.ceil(np.log2(2 * n)))
    spec = np.fft.rfft(e, m)
    acf = np.fft.irfft(spec * np.conj(spec), m)[: n // 4 + 1] / var
    below = np.flatnonzero(acf[1:] <= 0.0)
    last = int(below[0]) if below.size else acf.size - 1
    tau = 1.0 + 2.0 * float(acf[1 : last + 1].sum())
    return float(n / max(tau, 1.0))


def tolerance(n_fixed: int, n_effective: float, level: float = LEVEL) -> float:
    """The largest relative rise of the cost the test accepts for `n_fixed`
    parameters removed: ``exp(chi2_(1 - level)(d) / N_eff) - 1``.

    Examples
    --------
    >>> round(tolerance(2, 1000.0), 5)          # chi2_0.95(2) = 5.99
    0.00601
    """
    return float(np.expm1(stats.chi2.ppf(1.0 - level, n_fixed) / n_effective))


def _real_pole_reaches(a: np.ndarray, cov, root, z: float):
    """Real poles of ``1 + a_1 z^-1 + ...`` whose radius interval (delta
    method, ``dp/da_k = -p^(n-k) / A'(p)``, from the factor `root` or else
    the covariance `cov`) reaches ``|z| = 1``; an undetermined one (an
    infinite variance) does."""
    n = a.size
    den = np.r_[1.0, a]
    poles = np.roots(den) if n else np.zeros(0)
    real = poles[np.abs(poles.imag) <= _REAL * np.maximum(1.0, np.abs(poles))].real
    if not real.size:
        return []
    slope = np.polyval(np.polyder(den), real)
    with np.errstate(all="ignore"):
        dp = -(real[:, None] ** (n - np.arange(1, n + 1))) / slope[:, None]
        if root is not None:
            se = np.linalg.norm(root @ dp.T, axis=0)
        else:
            se = np.sqrt(np.abs(np.einsum("ik,kl,il->i", dp, cov, dp)))
    reach = ~np.isfinite(se) | (np.abs(real) + z * se >= 1.0)
    return [float(p) for p in real[reach]]


def flagged_poles(theta, arx: ARX, data: IOData, initial: str) -> list[Flagged]:
    """The poles of `theta` (at structure `arx`) the diagnosis flags, the
    slowest first: the mode table's pairs whose interval reaches ``|z| =
    1`` or that a zero cancels, and real poles whose interval reaches it.
    Empty where the covariance is not available."""
    theta = np.asarray(theta, dtype=float)
    cov, _, root = parameter_covariance(
        theta, arx, data, "simulation", initial, factor=True
    )
    na = arx.na
    if na == 0:
        return []
    # As IdentifiedModel.modes reads them: the factor where every direction
    # is determined, else the covariance with its infinite variances.
    cov_a = cov[:na, :na]
    root_a = None if root is None else root[:, :na]
    b = np.r_[np.zeros(arx.nk), theta[na:]]
    table = mode_table(
        theta[:na], b, data.ts, covariance=cov_a, factor=root_a, shares=False
    )
    out = []
    for i in range(len(table)):
        reasons = tuple(
            text
            for flag, text in (
                (table.reaches_unit_circle[i], "interval reaches |z| = 1"),
                (table.cancelled[i], "cancelled by a zero"),
            )
            if flag
        )
        if reasons:
            out.append(Flagged(complex(table.poles[i]), reasons))
    z = float(stats.norm.ppf(0.5 + table.level / 2))
    for p in _real_pole_reaches(theta[:na], cov_a, root_a, z):
        out.append(Flagged(complex(p, 0.0), ("interval reaches |z| = 1",)))
    out.sort(key=lambda f: -abs(f.pole))
    return out


def _partner(flag: Flagged, b: np.ndarray) -> complex | None:
    """The zero (upper member of a pair for a complex pole) removed with
    `flag`'s pole: the nearest of the same kind; None if there is none."""
    if np.count_nonzero(b) < 2:
        return None
    zeros = np.roots(np.trim_zeros(b, "f"))
    real = np.abs(zeros.imag) <= _REAL * np.maximum(1.0, np.abs(zeros))
    pool = zeros[~real & (zeros.imag > 0)] if flag.size == 2 else zeros[real].real
    if not pool.size:
        return None
    return complex(pool[int(np.argmin(np.abs(pool - flag.pole)))])


def remove_flagged(
    theta,
    arx: ARX,
    data: IOData,
    initial: str,
    cost: Callable[[np.ndarray], float],
    polish: Callable[[np.ndarray, ARX], np.ndarray],
    error: Callable[[np.ndarray], np.ndarray],
    level: float = LEVEL,
) -> tuple[np.ndarray, ARX, Diagnosis]:
    """Remove the flagged poles the likelihood-ratio test allows.

    Parameters
    ----------
    theta : array_like
        The estimate at structure `arx` (its effective order: no padding).
    arx : ARX
    data : IOData
        The estimation record.
    initial : str
        The simulation's initial condition.
    cost : callable
        The estimation cost of a theta in `arx`'s layout.
    polish : callable
        ``polish(start, reduced) -> theta`` at the reduced structure, or
        None when its budget is spent (that pole is then left untried).
    error : callable
        The simulation error of a theta in `arx`'s layout (its effective
        samples set the test's tolerance).
    level : float
        The test's size.

    Returns
    -------
    theta : ndarray
        The reduced estimate in `arx`'s layout (padded with zeros), or
        `theta` itself when nothing was removed.
    reduced : ARX
        Its effective structure.
    diagnosis : Diagnosis
    """
    from .cancellation import deflate

    theta = np.asarray(theta, dtype=float)
    base = float(cost(theta))
    n_eff = effective_samples(error(theta))
    diagnosis = Diagnosis(data.n, n_eff)
    if not np.isfinite(base) or base <= 0.0:
        return theta, arx, diagnosis
    current, structure, fixed = theta, arx, 0
    while True:
        # Every flag of the current model is tried, slowest first; the
        # first removal the test allows starts the next pass at the reduced
        # order. A pass without one ends: its refusals are what was kept.
        kept, acted, untried = [], False, 0
        flags = flagged_poles(current, structure, data, initial)
        if not fixed:
            # The estimate as it came, before any removal.
            diagnosis.flagged = sum(f.size for f in flags)
        for flag in flags:
            zero = _partner(flag, current[structure.na :])
            if zero is None:
                continue
            candidate = Candidate(flag.pole, zero, abs(flag.pole - zero))
            start, reduced = deflate(current, structure, candidate)
            if reduced.nb < 1 or not np.all(np.isfinite(start)):
                continue
            polished = polish(start, reduced)
            if polished is None:
                # The polishes' budget is spent: this pole stays untried.
                untried += 1
                continue
            polished = np.asarray(polished, dtype=float)
            value = float(cost(pad(polished, reduced, arx)))
            rise = value / base - 1.0
            allowed = tolerance(fixed + 2 * flag.size, n_eff, level)
            entry = {**candidate.to_dict(allowed, rise), "reasons": list(flag.reasons)}
            if np.isfinite(value) and rise <= allowed:
                diagnosis.removed.append(entry)
                current, structure = polished, reduced
                fixed += 2 * flag.size
                acted = True
                break
            kept.append(entry)
        if not acted:
            diagnosis.kept, diagnosis.untried = kept, untried
            break
    if not diagnosis.removed:
        return theta, arx, diagnosis
    return pad(current, structure, arx), structure, diagnosis
