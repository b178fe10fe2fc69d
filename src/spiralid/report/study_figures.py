"""Figures of a study: convergence bands per reading, the claim's effect sizes.

Each function takes a :class:`~spiralid.study.StudyResults` and returns a
matplotlib ``Figure``.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from spiralid.study import StudyResults

__all__ = ["anytime_ecdf", "claim_effects", "convergence_bands", "study_figures"]


def _band(histories: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    # Runs of one budget have histories of one length; a shorter one (a run
    # stopped early) counts up to where it ends.
    n = min(len(h) for h in histories)
    arr = np.array([h[:n] for h in histories], dtype=float)
    return np.percentile(arr, [25, 50, 75], axis=0)


def convergence_bands(res: StudyResults) -> Figure:
    """Best cost against iteration, median and interquartile band over seeds.

    One panel per record and predictor (rows) and parametrisation (columns),
    each with the two configurations of the claim.
    """
    rows = sorted({(d, p) for d, p, _ in res.readings})
    cols = sorted({par for _, _, par in res.readings})
    fig = Figure(figsize=(4.2 * len(cols), 2.6 * len(rows)), layout="constrained")
    axes = fig.subplots(len(rows), len(cols), squeeze=False, sharex=True)
    for i, (data, pred) in enumerate(rows):
        for j, par in enumerate(cols):
            ax = axes[i, j]
            for label, color in zip(res.claim, ("C1", "C0"), strict=True):
                cell = res.cells.get(((data, pred, par), label))
                hists = [h for h in (cell or {}).get("history", []) if h]
                if not hists:
                    continue
                lo, med, hi = _band(hists)
                k = np.arange(med.size)
                ax.plot(k, med, color=color, label=f"{label} (n = {len(hists)})")
                ax.fill_between(k, lo, hi, color=color, alpha=0.25, linewidth=0)
            ax.set_yscale("log")
            ax.set_title(f"{data}, {pred}, {par}", fontsize=9)
            if ax.get_legend_handles_labels()[0]:  # empty in a partial study
                ax.legend(fontsize=7, loc="upper right")
            if j == 0:
                ax.set_ylabel("best cost (% RMS error)")
            if i == len(rows) - 1:
                ax.set_xlabel("iteration")
    return fig


def anytime_ecdf(res: StudyResults) -> Figure:
    """Fraction of runs below a cost target against evaluations, per reading
    (an empirical runtime distribution, as COCO draws them).

    The target of a reading is the larger of the two configurations' median
    final costs, so that at least half the runs of one of them reach it;
    the budgets where the claim's verdict changes are marked.
    """
    from spiralid.study.anytime import evaluations

    readings = [
        rd for rd in res.readings if all((rd, c) in res.cells for c in res.claim)
    ]
    cols = min(3, max(len(readings), 1))
    rows = -(-max(len(readings), 1) // cols)
    fig = Figure(figsize=(4.2 * cols, 2.6 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    n_points = res.anytime.get("n_points", 50)
    for ax, rd in zip(axes, readings, strict=False):
        target = max(float(np.median(res.cells[rd, c]["cost"])) for c in res.claim)
        for label, color in zip(res.claim, ("C1", "C0"), strict=True):
            cell = res.cells[rd, label]
            hit = []
            for h, nfev in zip(cell["history"], cell["nfev"], strict=True):
                counts = evaluations(n_points, int(nfev), len(h))
                below = np.flatnonzero(np.asarray(h, dtype=float) <= target)
                hit.append(counts[below[0]] if below.size else np.inf)
            hit = np.sort(hit)
            grid = np.unique(np.r_[hit[np.isfinite(hit)], max(cell["nfev"])])
            frac = [np.mean(hit <= g) for g in grid]
            ax.step(grid, frac, where="post", color=color, label=label)
        for b in res.anytime.get("crossovers", {}).get(rd, []):
            ax.axvline(b, color="0.3", linestyle=":", linewidth=1)
        ax.set_xscale("log")
        ax.set_ylim(0, 1.02)
        ax.set_title(f"{', '.join(map(str, rd))}\ntarget {target:.4g}", fontsize=8)
        ax.set_xlabel("evaluations")
        ax.set_ylabel("fraction of runs below target")
        ax.legend(fontsize=7, loc="lower right")
    for ax in axes[len(readings) :]:
        ax.set_visible(False)
    return fig


def claim_effects(res: StudyResults) -> Figure:
    """A12 of the claim per reading; filled where Holm-adjusted p < alpha."""
    claims = res.claims
    fig = Figure(figsize=(7.0, 0.8 + 0.32 * max(len(claims), 1)), layout="constrained")
    ax = fig.subplots()
    y = np.arange(len(claims))
    a12 = [c["a12"] for c in claims]
    sig = [c["p_holm"] < res.alpha for c in claims]
    for yi, a, s in zip(y, a12, sig, strict=True):
        ax.plot(a, yi, "o", color="C3" if s else "0.4", mfc="C3" if s else "none", ms=7)
    ax.axvline(0.5, color="0.5", linestyle="--", linewidth=1)
    ax.set_yticks(
        y, [f"{c['data']}, {c['predictor']}, {c['parametrization']}" for c in claims]
    )
    ax.set_xlim(0, 1)
    ax.invert_yaxis()
    a, b = res.claim
    ax.set_xlabel(
        f"A12 = P({a} ends below {b})   (filled: Holm-adjusted p < {res.alpha:g})"
    )
    return fig


def study_figures(res: StudyResults) -> dict[str, Figure]:
    """Every study figure by file stem; those of a partly run study without
    anything to draw (no search run yet, no reading with both labels of the
    claim) are left out."""
    figures = {}
    if res.readings:
        figures["study_convergence"] = convergence_bands(res)
    if res.claims:
        figures["study_claim_a12"] = claim_effects(res)
    if res.anytime.get("rows"):
        figures["study_anytime"] = anytime_ecdf(res)
    return figures
