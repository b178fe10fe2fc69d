"""Statistics for comparing optimisers over seeds.

- :func:`rank_sum`: the Wilcoxon rank-sum test, computed as the equivalent
  Mann-Whitney U test (exact for small tie-free samples).
- :func:`a12`: the Vargha-Delaney effect size, the probability that a run
  of one method ends *lower* (better) than a run of the other.
- :func:`holm`: Holm's step-down adjustment of p-values tested together.
"""

from __future__ import annotations

import numpy as np

__all__ = ["a12", "holm", "rank_sum"]


def _sample(x, name: str) -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)):
        raise ValueError(f"`{name}` must be a non-empty 1-D sequence of finite numbers")
    return arr


def a12(x, y) -> float:
    """Vargha-Delaney A12: P(X < Y) + P(X = Y) / 2 for costs (lower wins).

    0.5 means no difference; 1.0 means every run of `x` beats every run of
    `y`. Vargha and Delaney call 0.56, 0.64 and 0.71 small, medium and large
    effects (and their mirror images below 0.5).

    Examples
    --------
    >>> a12([1, 2], [3, 4]), a12([3, 4], [1, 2]), a12([1, 3], [3, 1])
    (1.0, 0.0, 0.5)
    """
    x, y = _sample(x, "x"), _sample(y, "y")
    less = (x[:, None] < y[None, :]).sum()
    ties = (x[:, None] == y[None, :]).sum()
    return float((less + 0.5 * ties) / (x.size * y.size))


def holm(pvalues) -> np.ndarray:
    """Holm-adjusted `pvalues` (family-wise error control, any dependence).

    The k-th smallest of m p-values is multiplied by ``m - k + 1``, made
    non-decreasing in that order, and capped at 1.

    Examples
    --------
    >>> holm([0.01, 0.04, 0.03]).round(3).tolist()
    [0.03, 0.06, 0.06]
    """
    p = np.asarray(pvalues, dtype=float)
    if p.ndim != 1 or np.any((p < 0) | (p > 1)) or np.any(np.isnan(p)):
        raise ValueError("`pvalues` must be a 1-D sequence of numbers in [0, 1]")
    m = p.size
    order = np.argsort(p, kind="stable")
    scaled = np.minimum(1.0, np.maximum.accumulate((m - np.arange(m)) * p[order]))
    out = np.empty(m)
    out[order] = scaled
    return out


def rank_sum(x, y) -> dict:
    """Two-sided rank-sum test of `x` against `y`, with medians and A12.

    Returns a dict with ``u`` (the Mann-Whitney statistic of `x`),
    ``p_two_sided``, ``p_less`` (one-sided: `x` lower), ``a12`` (of `x`
    over `y`, lower cost winning) and both medians.
    """
    from scipy import stats

    x, y = _sample(x, "x"), _sample(y, "y")
    if np.ptp(np.concatenate([x, y])) == 0:
        # Every run ended at the same cost: no evidence of any difference
        # (SciPy would divide by a zero variance).
        u, p, p_less = x.size * y.size / 2.0, 1.0, 1.0
    else:
        res = stats.mannwhitneyu(x, y, alternative="two-sided")
        u, p = float(res.statistic), float(res.pvalue)
        p_less = float(stats.mannwhitneyu(x, y, alternative="less").pvalue)
    return {
        "u": u,
        "p_two_sided": p,
        "p_less": p_less,
        "a12": a12(x, y),
        "median_x": float(np.median(x)),
        "median_y": float(np.median(y)),
    }
