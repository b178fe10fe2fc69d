"""One run of a study: a task, and the function a worker runs for it.

A :class:`Task` names one configuration (optimiser or baseline) on one
reading (record, predictor, parametrisation) with one seed; its :attr:`key`
is a hash of everything that decides the result, so a store can tell a
finished run from one still to do. :func:`run_task` is a plain module-level
function of picklable arguments: a worker needs nothing but spiralid.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass

import numpy as np

from .spec import BASELINES, PREDICTORS, StudySpec

__all__ = ["Task", "load_records", "reproducible_part", "run_task", "study_tasks"]


@dataclass(frozen=True)
class Task:
    """One run: a configuration on a reading with a seed.

    ``seed`` and ``parametrization`` are None for the deterministic
    baselines (least squares, output error), which search no parameters.

    Attributes
    ----------
    data : str
        The reading (record) name in the study specification.
    predictor, parametrization : str
        As for :func:`~spiralid.sysid.identify`.
    label : str
        The configuration's name in tables and figures.
    method : str
        The identification method.
    seed : int or None
        The search's seed.
    refine : bool
        Polish the search's best by a local method.
    gain_scale : float
        Factor on the reading's default cost gain (the gain sweep).
    safe_start : bool or None
        As for :func:`~spiralid.sysid.identify` (None: the method's own).
    options : tuple
        Further method options as ``(name, value)`` pairs.
    budget, points : int
        Evaluation budget and population size.
    arx : tuple of int
        ``(na, nb, nk)``.
    fraction : float
        Share of the record that estimates.
    data_digest : str
        Digest of the record's samples, so a store never mixes records.
    """

    data: str
    predictor: str
    parametrization: str | None
    label: str
    method: str
    seed: int | None
    refine: bool = False
    gain_scale: float = 1.0
    safe_start: bool | None = None
    options: tuple = ()
    budget: int = 20_000
    points: int = 50
    arx: tuple[int, int, int] = (8, 8, 0)
    fraction: float = 2 / 3
    data_digest: str = ""

    @property
    def key(self) -> str:
        """A hash of every field: equal keys mean the same computation."""
        text = json.dumps(asdict(self), sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:32]

    @property
    def reading(self) -> tuple[str, str, str | None]:
        return (self.data, self.predictor, self.parametrization)


def _digest(data) -> str:
    h = hashlib.sha256()
    for part in (data.u, data.y, np.array([data.ts])):
        h.update(np.ascontiguousarray(part, dtype=float).tobytes())
    return h.hexdigest()[:16]


def load_records(spec: StudySpec) -> dict:
    """Read every record of `spec` and check the ARX orders fit each.

    Returns a dict of record name to :class:`~spiralid.sysid.IOData`. Any
    failure is a one-line ValueError naming the record, raised before any
    run starts.
    """
    from spiralid.sysid import ARX

    arx = ARX(spec.na, spec.nb, spec.nk)
    records = {}
    for d in spec.data:
        try:
            data = d.load()
            est, _ = data.split(spec.fraction)
            arx.check_length(est, f"the estimation part of record {d.name!r}")
        except (ValueError, OSError, TypeError) as exc:
            # The names the reader's message gives are keys of the record's
            # [[data]] table (input, output, ts, path), quoted as the file
            # writes them, not arguments of ours.
            message = " ".join(str(exc).split()).replace("`", "'")
            raise ValueError(f"record {d.name!r} ({d.kind}): {message}") from None
        records[d.name] = data
    return records


def reading_tasks(
    data: str, predictor: str, baselines, runs, seeds, **common
) -> list[Task]:
    """The tasks of one reading: each baseline once, then every
    ``(parametrization, optimiser)`` of `runs` with every seed. An optimiser
    has ``label``, ``method``, ``refine``, ``gain_scale``, ``safe_start`` and
    optionally ``options`` (:class:`~spiralid.study.spec.OptimizerSpec`, or
    a configuration of ``spiralid reproduce``); `common` holds the other
    :class:`Task` fields."""
    tasks = [
        Task(data, predictor, None, BASELINES[method], method, None, **common)
        for method in baselines
    ]
    for par, opt in runs:
        for seed in seeds:
            tasks.append(
                Task(
                    data,
                    predictor,
                    par,
                    opt.label,
                    opt.method,
                    seed,
                    refine=opt.refine,
                    gain_scale=opt.gain_scale,
                    safe_start=opt.safe_start,
                    options=tuple(sorted(getattr(opt, "options", {}).items())),
                    **common,
                )
            )
    return tasks


def study_tasks(spec: StudySpec, records: dict) -> list[Task]:
    """Every run of `spec` on its `records` (name to IOData, from
    :func:`load_records`), baselines first, in a fixed order."""
    common = dict(
        budget=spec.budget,
        points=spec.points,
        arx=(spec.na, spec.nb, spec.nk),
        fraction=spec.fraction,
    )
    runs = [(par, opt) for par in spec.parametrizations for opt in spec.optimizers]
    tasks = []
    for d in spec.data:
        digest = _digest(records[d.name])
        for predictor in spec.predictors:
            tasks += reading_tasks(
                d.name,
                predictor,
                spec.baselines,
                runs,
                spec.seeds,
                data_digest=digest,
                **common,
            )
    return tasks


def run_task(task: Task, data, detail: bool = False) -> dict:
    """Run one `task` on its record `data` (an IOData) and return its row
    for the store.

    The row holds the estimation cost (the paper's eq. (2)-(3) on the
    estimation part at the reading's default gain, whatever gain the search
    used), the validation fit % of the free run from rest over the whole
    record scored on the validation part, the evaluations used, the wall
    time and the model as a dict (with its convergence history). With
    `detail`, also ``model_object`` (the
    :class:`~spiralid.sysid.IdentifiedModel` itself) and ``times`` (the wall
    time of every history entry, for Figure 6a), which a store does not keep.
    """
    from spiralid.sysid import ARX, PaperCost, fit_percent, identify
    from spiralid.sysid.estimation.spiral.population import search_options

    arx = ARX(*task.arx)
    est, _ = data.split(task.fraction)
    predictor, initial = PREDICTORS[task.predictor]
    scorer = PaperCost(arx, est, predictor=predictor, initial=initial)
    kwargs = dict(predictor=predictor, initial=initial)
    # (history entries so far, wall time) at every callback: a restart adds
    # a history entry between two callbacks, so entries are matched to the
    # first stamp that covers them, not counted one per call.
    stamps: list[tuple[int | None, float]] = []

    def clock(intermediate) -> bool:
        history = getattr(intermediate, "history", None)
        stamps.append((None if history is None else len(history), time.perf_counter()))
        return False

    if task.seed is not None:
        kwargs.update(
            parametrization=task.parametrization,
            refine=task.refine,
            safe_start=task.safe_start,
            gain=scorer.w * task.gain_scale,
            rng=task.seed,
            callback=clock,
            **search_options(
                {"n_points": task.points, "max_nfev": task.budget, **dict(task.options)}
            ),
        )
    start = time.perf_counter()
    model = identify(est, arx, method=task.method, **kwargs)
    seconds = time.perf_counter() - start
    y_sim = model.simulate(data.u)
    res = model.result
    row = {
        "key": task.key,
        "data": task.data,
        "predictor": task.predictor,
        "parametrization": task.parametrization,
        "label": task.label,
        "method": task.method,
        "seed": task.seed,
        "cost": float(scorer(model.theta)),
        "fit_val": float(fit_percent(data.y[est.n :], y_sim[est.n :])),
        "nfev": getattr(res, "nfev", None),
        "seconds": seconds,
        "stable": bool(model.is_stable),
        "model": model.to_dict(),
    }
    if detail:
        # Index 0 of the history (the initial population) is put at t = 0.
        row.update(model_object=model, times=_entry_times(model, stamps, start))
    return row


def _entry_times(model, stamps, start: float) -> np.ndarray | None:
    """The wall time of every entry of the model's search history (index 0,
    the initial population, at t = 0), from the callback's `stamps`."""
    history = getattr(model, "history", None)
    if not stamps or history is None:
        return None
    n = len(history)
    if any(count is None for count, _ in stamps):
        # A callback that does not see the history: one stamp per entry.
        return np.array([start, *(t for _, t in stamps)])[:n] - start
    times = np.full(n, stamps[-1][1])
    times[0] = start
    filled = 1
    for count, t in stamps:
        times[filled : min(count, n)] = t
        filled = max(filled, min(count, n))
    return times - start


def reproducible_part(row: dict) -> dict:
    """A store's `row` without its wall times: what the seed alone decides.

    Two runs of the same task agree on this part bit for bit, whatever the
    engine, the worker count or the order of completion.
    """
    out = dict(row, model=dict(row["model"]))
    out.pop("seconds")
    out["model"].pop("timings", None)
    return out
