"""Where does the paper's claim hold? The statistics of a study's store.

:func:`analyse` turns a store's rows into a :class:`StudyResults`: per
reading (record, predictor, parametrisation) and configuration the costs,
fits and wall times over seeds; the baselines of each record and predictor;
and, per reading, the claim's test (Eb-SDA against SDA by default): the
rank-sum p-value, the Vargha-Delaney A12 effect size and the Holm-adjusted
p-value over all readings tested together, with a verdict; and, for a rig
record with ``all_outputs``, its modes from every sensor beside the FEM's
and the single-output models' (:mod:`~spiralid.study.modes`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .anytime import budget_verdicts, verdict
from .spec import StudySpec
from .statistics import holm, rank_sum

if TYPE_CHECKING:  # the modes module loads the identification (SciPy, Numba)
    from .modes import SharedModesFit

__all__ = ["CLAIM", "StudyResults", "analyse"]

# The paper's claim: Eb-SDA (first) ends at a lower cost than SDA (second).
CLAIM = ("Eb-SDA", "SDA")

Reading = tuple[str, str, str]


@dataclass
class StudyResults:
    """A study's numbers, ready for tables and figures.

    Attributes
    ----------
    readings : list of (data, predictor, parametrization)
    labels : list of str
        Search configurations.
    cells : dict of (reading, label) to dict
        ``cost``, ``fit_val``, ``seconds``, ``seeds`` arrays over seeds (seed
        order), ``history``, the runs' convergence histories, and
        ``best_model``, the model dict of the run of lowest cost.
    baselines : dict of (data, predictor) to dict of label to row
    claims : list of dict
        Per reading where both labels of `claim` ran: the medians, ``n``,
        ``p_two_sided``, ``p_holm``, ``a12`` and ``verdict``.
    anytime : dict
        The claim at a ladder of budgets, from the stored histories
        (:func:`~spiralid.study.anytime.budget_verdicts`); empty without the
        specification.
    claim : (str, str)
    alpha : float
    stored_runs : int
        Rows analysed, baselines included.
    expected_runs : int or None
        Runs of the specification (None without it); more than
        `stored_runs` when the study stopped early or runs failed.
    modes : dict of str to SharedModesFit
        Per rig record with ``all_outputs``, its modes from every sensor
        (empty without).
    missing_modes : tuple of str
        Rig records with ``all_outputs`` whose modes from every sensor the
        store does not hold (the study stopped before their fit).
    """

    readings: list[Reading]
    labels: list[str]
    cells: dict
    baselines: dict
    claims: list[dict] = field(default_factory=list)
    claim: tuple[str, str] = CLAIM
    alpha: float = 0.05
    anytime: dict = field(default_factory=dict)
    stored_runs: int = 0
    expected_runs: int | None = None
    modes: dict[str, SharedModesFit] = field(default_factory=dict)
    missing_modes: tuple[str, ...] = ()

    @property
    def missing_runs(self) -> int:
        """Runs of the specification that the store does not hold."""
        if self.expected_runs is None:
            return 0
        return max(self.expected_runs - self.stored_runs, 0)

    def modes_comparison(self, record: str) -> list[dict]:
        """The FEM's modes beside those of `record`'s fit from every sensor
        and of each single-output model identified on it: the best run of
        each configuration on each reading of the record, then each
        baseline per predictor (:func:`~spiralid.study.modes.modes_comparison`).

        Parameters
        ----------
        record : str
            A key of :attr:`modes`.
        """
        from spiralid.sysid import IdentifiedModel

        from .modes import modes_comparison

        models = []
        for rd in self.readings:
            if rd[0] != record:
                continue
            for label in self.labels:
                cell = self.cells.get((rd, label))
                if cell is not None:
                    models.append((f"{label} ({rd[1]}, {rd[2]})", cell["best_model"]))
        for (data, predictor), rows in self.baselines.items():
            if data == record:
                models += [
                    (f"{label} ({predictor})", row["model"])
                    for label, row in rows.items()
                ]
        built = [(label, IdentifiedModel.from_dict(d)) for label, d in models]
        return modes_comparison(
            self.modes[record], [(label, m, m.arx) for label, m in built]
        )

    def statistics(self, reading: Reading, label: str) -> dict:
        """Median, best, worst and quartiles of cost; median fit and time."""
        c = self.cells[reading, label]
        cost = c["cost"]
        return {
            "n": int(cost.size),
            "cost_median": float(np.median(cost)),
            "cost_q1": float(np.percentile(cost, 25)),
            "cost_q3": float(np.percentile(cost, 75)),
            "cost_best": float(cost.min()),
            "cost_worst": float(cost.max()),
            "fit_val_median": float(np.median(c["fit_val"])),
            "seconds_median": float(np.median(c["seconds"])),
        }


def _orders(spec: StudySpec | None) -> tuple[dict, dict]:
    """Rank of each reading and label in the specification (its own order)."""
    if spec is None:
        return {}, {}
    readings = [
        (d.name, p, par)
        for d in spec.data
        for p in spec.predictors
        for par in spec.parametrizations
    ]
    return (
        {r: i for i, r in enumerate(readings)},
        {o.label: i for i, o in enumerate(spec.optimizers)},
    )


def analyse(
    rows: list[dict],
    spec: StudySpec | None = None,
    claim=CLAIM,
    alpha: float = 0.05,
    modes: dict | None = None,
) -> StudyResults:
    """Group a store's rows and test the claim per reading.

    Parameters
    ----------
    rows : list of dict
        :meth:`~spiralid.study.ResultStore.rows`.
    spec : StudySpec, optional
        The study's specification: readings and configurations are listed in
        its order (else sorted by name).
    claim : (str, str)
        Labels of the configuration claimed better and its reference.
    alpha : float
        Family-wise significance level of the Holm-adjusted tests.
    modes : dict of str to dict, optional
        The store's modes from every sensor
        (:meth:`~spiralid.study.ResultStore.modes`), read into
        :attr:`StudyResults.modes`.
    """
    if not 0 < alpha < 1:
        raise ValueError(f"`alpha` must be in (0, 1); got {alpha!r}")
    grouped = _group(rows)
    readings, labels = _in_order(grouped, spec)
    cells = {key: _cell(group) for key, group in grouped.items()}
    res = StudyResults(
        readings,
        labels,
        cells,
        _baselines(rows),
        claim=tuple(claim),
        alpha=alpha,
        stored_runs=len(rows),
        expected_runs=None if spec is None else spec.n_runs,
        modes=_shared_modes(modes),
        missing_modes=tuple(
            d.name
            for d in ([] if spec is None else spec.data)
            if d.all_outputs and d.name not in (modes or {})
        ),
    )
    tested = [
        rd for rd in readings if (rd, claim[0]) in cells and (rd, claim[1]) in cells
    ]
    res.claims = _claims(cells, tested, claim, alpha)
    if spec is not None and tested:
        res.anytime = budget_verdicts(
            cells, tested, tuple(claim), spec.budget, spec.points, alpha=alpha
        )
    return res


def _shared_modes(modes: dict | None) -> dict:
    """The store's modes from every sensor, each read back as a
    SharedModesFit (the identification is loaded only when there are any)."""
    if not modes:
        return {}
    from .modes import SharedModesFit

    return {record: SharedModesFit.from_dict(d) for record, d in modes.items()}


def _group(rows: list[dict]) -> dict:
    """The seeded rows by (reading, label), each group in seed order."""
    grouped: dict = {}
    for r in sorted(
        (r for r in rows if r["seed"] is not None), key=lambda r: r["seed"]
    ):
        reading = (r["data"], r["predictor"], r["parametrization"])
        grouped.setdefault((reading, r["label"]), []).append(r)
    return grouped


def _in_order(grouped: dict, spec: StudySpec | None) -> tuple[list, list]:
    """The readings and labels present, in the specification's order (the
    rest after them, by name)."""
    reading_rank, label_rank = _orders(spec)
    readings = sorted(
        {rd for rd, _ in grouped}, key=lambda rd: (reading_rank.get(rd, 1 << 30), rd)
    )
    labels = sorted(
        {label for _, label in grouped},
        key=lambda label: (label_rank.get(label, 1 << 30), label),
    )
    return readings, labels


def _cell(group: list[dict]) -> dict:
    """One configuration's runs on one reading as arrays over seeds."""
    return {
        "seeds": np.array([r["seed"] for r in group]),
        "cost": np.array([r["cost"] for r in group]),
        "fit_val": np.array([r["fit_val"] for r in group]),
        "seconds": np.array([r["seconds"] for r in group]),
        "history": [r["model"]["history"] for r in group],
        "nfev": [r["nfev"] for r in group],
        "best_model": min(group, key=lambda r: r["cost"])["model"],
    }


def _baselines(rows: list[dict]) -> dict:
    """The unseeded rows (baselines) by (data, predictor), then label."""
    baselines: dict = {}
    for r in rows:
        if r["seed"] is None:
            baselines.setdefault((r["data"], r["predictor"]), {})[r["label"]] = r
    return baselines


def _claims(cells: dict, tested: list, claim, alpha: float) -> list[dict]:
    """The claim's rank-sum test per reading tested, Holm-adjusted over
    them all."""
    tests = [
        rank_sum(cells[rd, claim[0]]["cost"], cells[rd, claim[1]]["cost"])
        for rd in tested
    ]
    adjusted = holm([t["p_two_sided"] for t in tests]) if tests else []
    return [
        {
            "data": rd[0],
            "predictor": rd[1],
            "parametrization": rd[2],
            "n": [int(cells[rd, c]["cost"].size) for c in claim],
            f"median {claim[0]}": t["median_x"],
            f"median {claim[1]}": t["median_y"],
            "p_two_sided": t["p_two_sided"],
            "p_holm": float(p_adj),
            "a12": t["a12"],
            "verdict": verdict(float(p_adj), t["a12"], claim, alpha),
        }
        for rd, t, p_adj in zip(tested, tests, adjusted, strict=True)
    ]
