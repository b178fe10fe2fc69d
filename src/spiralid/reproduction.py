"""The paper's experiment: SDA against Eb-SDA on an ARX(8, 8, 0) model.

:func:`reproduce` runs every configuration of the comparison over several
seeds with an equal budget of cost evaluations, adds the least-squares and
output-error baselines, and returns a :class:`Reproduction` holding every
model and every number. It computes only: figures are drawn by
:mod:`spiralid.report.figures` and files written by
:mod:`spiralid.report.output` and the command line. It sits above the study
(it runs the study's tasks with the study's runner) and below the report.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from spiralid._checks import is_default
from spiralid.study import modes as _modes
from spiralid.study.modes import (
    SharedModesFit,
    fit_every_sensor,
    modes_comparison,
    rig_record,
)
from spiralid.study.runner import execute
from spiralid.study.spec import BASELINES
from spiralid.study.tasks import reading_tasks
from spiralid.sysid import (
    ARX,
    IdentifiedModel,
    IOData,
    PaperCost,
    arx_least_squares,
    identify,
)
from spiralid.sysid.estimation.linear.parametrizations import DEFAULT_PARAMETRIZATION
from spiralid.sysid.estimation.spiral.population import search_options
from spiralid.sysid.validation.validate import Validation, validate

__all__ = [
    "CONFIGURATIONS",
    "HEADLINE_TEST",
    "MODE_WINDOW",
    "RIG_INTEGRATORS",
    "RIG_OUTPUTS",
    "SHARED_ARX",
    "Configuration",
    "Reproduction",
    "Run",
    "SharedModesFit",
    "default_data",
    "default_data_source",
    "reproduce",
]


# The fit of every sensor is spiralid.study.modes' (the study runs it too);
# its constants are named here too, where all_outputs documents them.

# Every sensor of the simulated rig's experiment (the outputs of
# all_outputs' shared fit).
RIG_OUTPUTS = _modes.RIG_OUTPUTS
# Each sensor's known integrators against the hub torque: the hub angle
# twice, the hub velocity once, outside the shared poles.
RIG_INTEGRATORS = _modes.RIG_INTEGRATORS
# The structure that identifies the shared modes from all four sensors: three
# modes, the anti-aliasing filter's pair and the fourth mode.
SHARED_ARX = _modes.SHARED_ARX
# A model's mode stands for a FEM mode when within this share of its
# frequency: a model that lacks a mode is not credited with a neighbour's.
MODE_WINDOW = _modes.MODE_WINDOW

# The one test behind the headline verdict, everywhere it is stated (the
# report, its summary, results.json): the same two-sided test the budget
# ladder and `spiralid study` make, so the three never disagree in kind.
HEADLINE_TEST = (
    "two-sided Wilcoxon rank-sum test (Mann-Whitney U) of the estimation costs "
    "over the seeds, Eb-SDA against SDA, at the 5 % level; the direction from "
    "A12 (the probability that an Eb-SDA run costs less than an SDA run)"
)
HEADLINE_ALPHA = 0.05
# The rank-sum pairs the report lists, one per parametrisation.
_PAIRS = (("Eb-SDA", "SDA"), ("Eb-SDA (reflection)", "SDA (reflection)"))


@dataclass(frozen=True)
class Configuration:
    """One arm of the comparison: an optimiser, what it searches, the gain.

    Attributes
    ----------
    label : str
        The name the figures, tables and ``results.json`` give the arm.
    method : str
        A method of :func:`spiralid.sysid.identify` (``"sda"``, ``"ebsda"``,
        ``"de"``, ``"spiral"`` ...).
    parametrization : str, default the package's default parametrisation
        What the search moves (``"coefficients"``, ``"reflection"``,
        ``"modal"``).
    gain_scale : float, default 1.0
        Factor on the paper's gain ``w`` in the search's cost.
    refine : bool, default False
        Polish the search's result locally.
    safe_start : bool or None, default None
        None takes the method's default (off for the paper's methods, see
        :mod:`spiralid.sysid.estimation.core.estimators`).
    """

    label: str
    method: str
    parametrization: str = DEFAULT_PARAMETRIZATION
    gain_scale: float = 1.0
    refine: bool = False
    safe_start: bool | None = None


# The paper's comparison first (raw coefficients with the stability penalty),
# then what we add: the stable-by-construction search, a local polish,
# Eb-SDA under a gain w scaled by 0.1 and 10 (the paper does not state w),
# SciPy's differential evolution at the same budget as another population
# metaheuristic beside the spiral ones, and the recommended method
# (modes, projected numerator, memetic polish; simulation from rest only,
# so reproduce leaves it out under initial="measured").
CONFIGURATIONS: tuple[Configuration, ...] = (
    Configuration("SDA", "sda"),
    Configuration("Eb-SDA", "ebsda"),
    Configuration("SDA (reflection)", "sda", "reflection"),
    Configuration("Eb-SDA (reflection)", "ebsda", "reflection"),
    Configuration("Eb-SDA + refine", "ebsda", refine=True),
    Configuration("Eb-SDA (w x 0.1)", "ebsda", gain_scale=0.1),
    Configuration("Eb-SDA (w x 10)", "ebsda", gain_scale=10.0),
    Configuration("DE", "de"),
    Configuration("DE (reflection)", "de", "reflection"),
    # The recommended spiral identification (identify's default method).
    Configuration("spiral (recommended)", "spiral", "modal"),
)


@dataclass
class Run:
    """One identification: a configuration (or baseline) and a seed.

    ``cost`` is the paper's eq. (2)-(3) on the estimation part at the default
    gain (``w`` auto), whatever gain the search used, so that runs compare on
    one scale; ``fit_val`` is the validation fit % of the free-run simulation
    over the whole record, scored on the validation part.

    Attributes
    ----------
    label : str
        The configuration's label, or ``"LS"``/``"OE"`` for a baseline.
    seed : int or None
        None for a baseline.
    model : IdentifiedModel
    cost, fit_val : float
    times : ndarray or None
        Wall seconds at each entry of the model's history.
    """

    label: str
    seed: int | None
    model: IdentifiedModel
    cost: float
    fit_val: float
    times: np.ndarray | None = None

    @property
    def history(self) -> np.ndarray | None:
        return self.model.history

    def to_dict(self) -> dict:
        res = self.model.result
        refined = self.model.refine_result
        return {
            "label": self.label,
            "seed": self.seed,
            "cost_estimation": self.cost,
            "fit_validation_percent": self.fit_val,
            "search_cost": self.model.cost,
            "gain": self.model.gain,
            "theta": self.model.theta.tolist(),
            "stable": bool(self.model.is_stable),
            "max_pole_radius": self.model.max_pole_radius,
            "status": getattr(res, "status", None),
            "refine_status": getattr(refined, "status", None),
            "nfev": getattr(res, "nfev", None),
            "nit": getattr(res, "nit", None),
            "message": getattr(res, "message", None),
            "refine_nfev": getattr(refined, "nfev", None),
            "seconds": self.model.timings.get("total"),
            "history": None if self.history is None else self.history.tolist(),
            "times": None if self.times is None else self.times.tolist(),
        }


@dataclass
class Reproduction:
    """Everything :func:`reproduce` computed.

    Attributes
    ----------
    data, estimation, validation : IOData
        The record and its 2/3-1/3 parts (the paper's split).
    arx : ARX
    seeds : list of int
    options : dict
        The optimiser settings every spiral run shared.
    configurations : tuple of Configuration
        The arms that ran.
    runs : dict of str to list of Run
        Per configuration label, one run per seed (in seed order).
    baselines : dict of str to Run
        ``"LS"`` and ``"OE"``.
    validations : dict of str to (Validation, Validation)
        For the best run of each configuration and each baseline: the
        estimation part and the validation part.
    source : dict
        How the record was obtained (see :func:`reproduce`).
    elapsed : float
        Wall time of the whole experiment in seconds.
    shared : SharedModesFit or None
        The rig's modes from every sensor (``reproduce(all_outputs=True)``);
        None otherwise.
    """

    data: IOData
    estimation: IOData
    validation: IOData
    arx: ARX
    seeds: list[int]
    options: dict
    configurations: tuple[Configuration, ...]
    runs: dict[str, list[Run]]
    baselines: dict[str, Run]
    validations: dict[str, tuple[Validation, Validation]] = field(repr=False)
    source: dict = field(default_factory=dict)
    elapsed: float = 0.0
    shared: SharedModesFit | None = None

    def best(self, label: str) -> Run:
        """The run of lowest estimation cost (ties: the first seed)."""
        if label in self.baselines:
            return self.baselines[label]
        runs = self.runs[label]
        return runs[int(np.argmin([r.cost for r in runs]))]

    def modes_comparison(self) -> list[dict]:
        """The FEM's modes beside those of every sensor's shared fit and of
        each single-output best model and baseline: for each model, the
        mode nearest each FEM frequency and its error in percent
        (:func:`spiralid.study.modes.modes_comparison`). Empty without
        :attr:`shared`."""
        if self.shared is None:
            return []
        return modes_comparison(
            self.shared,
            [
                (label, self.best(label).model, self.arx)
                for label in [*self.runs, *self.baselines]
            ],
        )

    def statistics(self, label: str) -> dict:
        """Mean, std, median, best and worst over seeds of cost and fit."""
        runs = self.runs[label]
        cost = np.array([r.cost for r in runs])
        fit = np.array([r.fit_val for r in runs])
        return {
            "n": len(runs),
            "cost_mean": float(cost.mean()),
            "cost_std": float(cost.std(ddof=1)) if cost.size > 1 else 0.0,
            "cost_median": float(np.median(cost)),
            "cost_best": float(cost.min()),
            "cost_worst": float(cost.max()),
            "fit_val_median": float(np.median(fit)),
            "fit_val_best": float(fit.max()),
            "fit_val_worst": float(fit.min()),
        }

    def ranksum(self, a: str, b: str) -> dict:
        """Wilcoxon rank-sum test of the estimation costs of `a` against `b`
        (:func:`spiralid.study.statistics.rank_sum`, the one implementation
        the study uses too): ``p_two_sided`` tests for any difference (the
        report's headline test), ``p_less`` for `a` lower; ``a12`` is the
        probability that a run of `a` costs less than one of `b`."""
        from spiralid.study.statistics import rank_sum

        test = rank_sum([r.cost for r in self.runs[a]], [r.cost for r in self.runs[b]])
        return {
            "a": a,
            "b": b,
            "u_statistic": test["u"],
            "p_two_sided": test["p_two_sided"],
            "p_less": test["p_less"],
            "a12": test["a12"],
        }

    def table2(self) -> list[dict]:
        """The paper's Table-2 for each method's best run and the baselines:
        best fitness and the error range in modelling and validation."""
        rows = []
        for label in [*self.runs, *self.baselines]:
            est_v, val_v = self.validations[label]
            rows.append(
                {
                    "label": label,
                    "best_fitness": self.best(label).cost,
                    "error_range_modelling": list(est_v.error_range),
                    "error_range_validation": list(val_v.error_range),
                    "fit_validation_percent": val_v.fit_percent,
                }
            )
        return rows

    def ranksums(self) -> list[dict]:
        """:meth:`ranksum` of Eb-SDA against SDA, per parametrisation present."""
        return [
            self.ranksum(a, b) for a, b in _PAIRS if a in self.runs and b in self.runs
        ]

    def headline(self, a: str = "Eb-SDA", b: str = "SDA") -> dict:
        """The headline test (:data:`HEADLINE_TEST`) of `a` against `b` and its
        verdict sentence; ``None`` numbers when the experiment lacks either."""
        out = {"test": HEADLINE_TEST, "alpha": HEADLINE_ALPHA, "a": a, "b": b}
        if a not in self.runs or b not in self.runs:
            sentence = (
                f"No {a} vs {b} comparison: the experiment ran neither or one of them."
            )
            return {**out, "outcome": None, "p_two_sided": None, "verdict": sentence}
        test = self.ranksum(a, b)
        p, effect = test["p_two_sided"], test["a12"]
        ma = self.statistics(a)["cost_median"]
        mb = self.statistics(b)["cost_median"]
        numbers = (
            f"median cost {ma:.4g} against {mb:.4g} over {len(self.seeds)} seeds "
            f"(two-sided Wilcoxon rank-sum p = {p:.3g}, A12 = {effect:.2f})"
        )
        outcome, sentence = _outcome(a, b, p, effect, numbers)
        return {
            **out,
            "outcome": outcome,
            "median_a": ma,
            "median_b": mb,
            "n_seeds": len(self.seeds),
            "u_statistic": test["u_statistic"],
            "p_two_sided": p,
            "a12": effect,
            "verdict": sentence,
        }

    def verdict(self, a: str = "Eb-SDA", b: str = "SDA") -> str:
        """One sentence: did `a` beat `b` on estimation cost over the seeds, by
        the headline test (:data:`HEADLINE_TEST`)?"""
        return self.headline(a, b)["verdict"]

    def budget_verdict(self, a: str = "Eb-SDA", b: str = "SDA") -> dict:
        """The claim at a ladder of budgets, from the runs' own histories
        (:func:`spiralid.study.anytime.budget_verdicts`, Holm over the
        budgets), with a sentence: the budget the verdict holds at and where
        it flips."""
        from spiralid.study.anytime import budget_verdicts

        if a not in self.runs or b not in self.runs:
            return {"rows": [], "sentence": ""}
        cells = {
            (("reproduce",), label): {
                "history": [r.model.history for r in self.runs[label]],
                "nfev": [r.model.result["nfev"] for r in self.runs[label]],
            }
            for label in (a, b)
        }
        out = budget_verdicts(
            cells,
            [("reproduce",)],
            (a, b),
            self.options["max_nfev"],
            self.options["n_points"],
        )
        rows = out["rows"]
        flips = out["crossovers"].get(("reproduce",), [])
        return {
            "budgets": out["budgets"],
            "holm_family": out["family"],
            "rows": [{k: v for k, v in r.items() if k != "reading"} for r in rows],
            "crossovers": flips,
            "sentence": _ladder_sentence(rows, flips, out["family"]),
        }


def _outcome(a: str, b: str, p: float, effect: float, numbers: str) -> tuple:
    """The headline's outcome and sentence from its p-value and A12."""
    if p < HEADLINE_ALPHA and effect > 0.5:
        return f"{a} better", f"{a} beat {b}: {numbers}."
    if p < HEADLINE_ALPHA:
        return f"{b} better", f"{a} did not beat {b}; {b} beat {a}: {numbers}."
    return (
        "no significant difference",
        f"{a} did not beat {b}: no significant difference, {numbers}.",
    )


def _ladder_sentence(rows: list[dict], flips: list[int], family: int) -> str:
    """The budget ladder in words: the verdict at the full budget, then
    where it flips along the way (or that it never does)."""
    full = rows[-1]
    sentence = f"At {full['budget']:,} evaluations: {full['verdict']}"
    if flips:
        verdict_at = {r["budget"]: r["verdict"] for r in rows}
        ladder = [r["budget"] for r in rows]
        steps = [
            f"{verdict_at[ladder[ladder.index(f) - 1]]} up to "
            f"{ladder[ladder.index(f) - 1]:,}, {verdict_at[f]} from {f:,}"
            for f in flips
        ]
        sentence += "; along the way: " + "; ".join(steps)
    else:
        sentence += f", the same at every budget from {rows[0]['budget']:,}"
    # The headline's test at each budget, Holm-adjusted over the ladder: at
    # the full budget it can say "no significant difference" where the
    # headline's unadjusted p is below 5 %.
    sentence += (
        f" (the headline's two-sided rank-sum test, Holm-adjusted over the "
        f"{family} budgets)"
    )
    return sentence + "."


def default_data(seed: int = 0) -> IOData:
    """The default record: the simulated rig's bang-bang experiment.

    End-point acceleration against hub torque, sampled at 500 Hz, from
    :func:`spiralid.fms.paper_experiment` on the default
    :class:`~spiralid.fms.FlexibleManipulator`, sensor noise seeded by `seed`.
    """
    return _rig_recording(seed).iodata("end_acceleration")


def _rig_recording(seed: int):
    """The simulated rig's bang-bang experiment, every sensor recorded."""
    from spiralid.fms import paper_experiment

    return paper_experiment().run(rng=seed)


def default_data_source(seed: int = 0) -> dict:
    """What :func:`default_data` simulates: every rig and experiment setting,
    with `seed` as the noise seed."""
    from dataclasses import asdict

    from spiralid.fms import FlexibleManipulator, paper_experiment

    return {
        "kind": "simulated rig",
        "rig": asdict(FlexibleManipulator()),
        "rig_modes_hz": FlexibleManipulator().modes(5).tolist(),
        "experiment": asdict(paper_experiment()),
        "noise_seed": seed,
    }


def _warm_up(est: IOData, arx: ARX, kinds, initial: str) -> None:
    """Compile (or load) every Numba kernel the runs use, before any is timed.

    Without it the first run in each process carries the JIT compilation
    (seconds) in its wall time and misleads the time panel of Figure 6a.
    One tiny search per (method, parametrisation); the results are dropped.
    On a first run every worker compiles: odd-numbered pool workers go
    through the kinds from the end, so two workers compile different
    kernels side by side and each loads from Numba's on-disk cache what the
    other has already saved, rather than both compiling everything (a fifth
    less wall time on 2 cores).
    """
    # A pickled IOData arrives with writable arrays, the tasks' split with
    # read-only ones, and Numba compiles a kernel once for each: rebuilt,
    # the record's arrays are read-only as the tasks' are.
    est = replace(est)
    # The pool's n-th worker process has _identity (n,); a main process ().
    if (multiprocessing.current_process()._identity or (0,))[0] % 2:
        kinds = list(kinds)[::-1]
    for method, parametrization in kinds:
        # The spiral method's Gauss-Newton polish (here after its one
        # iteration) compiles the kernels of its Jacobian, else the first
        # spiral run of each worker would.
        polish = {"polish_every": 1, "max_nfev": 100} if method == "spiral" else {}
        identify(
            est,
            arx,
            method=method,
            parametrization=parametrization,
            initial=initial,
            rng=0,
            n_points=5,
            max_iter=1,
            **{"max_nfev": 10, **polish},
        )


def reproduce(
    data: IOData | None = None,
    *,
    seeds: Sequence[int] | int = 6,
    max_nfev: int = 20_000,
    n_points: int = 50,
    arx: ARX | None = None,
    fraction: float = 2 / 3,
    initial: str = "rest",
    configurations: Sequence[Configuration] = CONFIGURATIONS,
    all_outputs: bool = False,
    source: dict | None = None,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Reproduction:
    """Run the paper's SDA vs Eb-SDA comparison with baselines and statistics.

    Parameters
    ----------
    data : IOData, optional
        The record; default :func:`default_data` (the simulated rig).
    seeds : int or sequence of int, default 6
        Seeds of the spiral runs (an int ``n`` means ``0..n-1``).
    max_nfev : int, default 20000
        Budget of cost evaluations of every search run, the same for all so
        that the algorithms compare at equal cost; no iteration cap stops a
        run first (:func:`spiralid.sysid.estimation.spiral.population.search_options`).
    n_points : int, default 50
        Search points ``m``.
    arx : ARX, default ARX(8, 8, 0)
        Eq. (6).
    fraction : float, default 2/3
        Estimation share of the record.
    initial : {"rest", "measured"}, default "rest"
        Initial condition of the simulation error in the cost (see
        :func:`spiralid.sysid.identify`): ``"rest"`` is the paper's free run
        from the input alone and suits records that start at rest (the rig);
        ``"measured"`` starts from the measured first samples, for records
        that start in motion (the real arm, a slice of a periodic sweep).
    configurations : sequence of Configuration
        Default :data:`CONFIGURATIONS`. With ``initial="measured"`` the
        ``"modal"`` ones (the recommended ``"spiral"``) are left out: they
        project the numerator of the simulation from rest only.
    all_outputs : bool, default False
        Also identify the rig's modes from all four sensors of the same
        simulated run (:class:`SharedModesFit`: hub angle, hub velocity,
        end-point acceleration and tip deflection with one denominator,
        :data:`SHARED_ARX` with known integrators :data:`RIG_INTEGRATORS`,
        seeded by the first of `seeds`), beside the paper's single-output
        model; the paper's runs are unchanged. Only for the simulated rig
        (`data` None): a record of one sensor has no others.
    source : dict, optional
        How `data` was obtained, recorded in the results (e.g. its path);
        default a description of the simulated rig when `data` is None.
    workers : int, optional
        Processes for the spiral runs; default the CPU count. ``1`` runs in
        this process.
    progress : callable, optional
        ``progress(done, total)`` after each finished run.

    Returns
    -------
    Reproduction
    """
    t0 = time.perf_counter()
    every_sensor = _all_outputs_record(data, all_outputs)
    if data is None:
        data, source = default_data(), default_data_source()
    source = {"kind": "user data"} if source is None else dict(source)
    seed_list = _checked_seeds(data, seeds, n_points, max_nfev)
    arx = ARX(8, 8, 0) if arx is None else arx
    est, val = data.split(fraction)
    _check_record(est, arx)
    if initial != "rest":
        # The modal parametrisation projects the numerator of the
        # simulation from rest only.
        configurations = [c for c in configurations if c.parametrization != "modal"]
    options = {
        **search_options({"n_points": n_points, "max_nfev": max_nfev}),
        "predictor": "simulation",
        "initial": initial,
        "gain": PaperCost(arx, est, predictor="simulation", initial=initial).w,
    }
    # The same tasks and runner as `spiralid study`: one execution path.
    tasks = reading_tasks(
        "record",
        f"simulation-{initial}",
        BASELINES,
        [(c.parametrization, c) for c in configurations],
        seed_list,
        budget=max_nfev,
        points=n_points,
        arx=(arx.na, arx.nb, arx.nk),
        fraction=fraction,
    )
    kinds = sorted({(c.method, c.parametrization) for c in configurations})
    results = _run_tasks(tasks, data, workers, (est, arx, kinds, initial), progress)
    rep = Reproduction(
        data=data,
        estimation=est,
        validation=val,
        arx=arx,
        seeds=seed_list,
        options=options,
        configurations=tuple(configurations),
        runs={
            c.label: [results[c.label, s] for s in seed_list] for c in configurations
        },
        baselines={label: results[label, None] for label in BASELINES.values()},
        validations={},
        source=source,
    )
    rep.validations = _validate_best(rep)
    if every_sensor is not None:
        rep.shared = fit_every_sensor(every_sensor, fraction, seed_list[0])
    rep.elapsed = time.perf_counter() - t0
    return rep


def _all_outputs_record(data, all_outputs) -> IOData | None:
    """The rig's record of every sensor when `all_outputs` asks for it
    (the same run as :func:`default_data`'s), after its checks."""
    if not isinstance(all_outputs, bool | np.bool_):
        raise TypeError(f"`all_outputs` must be True or False; got {all_outputs!r}")
    if is_default(all_outputs, False):
        return None
    if data is not None:
        raise ValueError(
            "`all_outputs` applies to the simulated rig (data=None) only: a "
            "record given as `data` has no other sensors; leave it False"
        )
    return rig_record(noise_seed=0)


def _checked_seeds(data, seeds, n_points, max_nfev) -> list[int]:
    """The seeds as a list, after :func:`reproduce`'s argument checks."""
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData or None; got {type(data)!r}")
    seed_list = list(range(seeds)) if isinstance(seeds, int) else list(seeds)
    if not seed_list:
        raise ValueError(f"`seeds` must give at least one seed; got {seeds!r}")
    if isinstance(n_points, bool) or not isinstance(n_points, int) or n_points < 2:
        raise ValueError(f"`n_points` must be an integer >= 2; got {n_points!r}")
    # Every search needs its initial population and one iteration.
    if (
        isinstance(max_nfev, bool)
        or not isinstance(max_nfev, int)
        or max_nfev < 2 * n_points
    ):
        raise ValueError(
            f"`max_nfev` must be an integer >= 2 * n_points = {2 * n_points}; "
            f"got {max_nfev!r}"
        )
    return seed_list


def _check_record(est: IOData, arx: ARX) -> None:
    """Refuse an estimation record the searches cannot start from."""
    arx.check_length(est, "data")
    # Every search scales its box from the least-squares estimate, and the
    # workers' warm-up runs searches: a record that least squares refuses (a
    # constant input, too little excitation) fails here, in this process,
    # rather than in the initializer of every worker of a pool.
    arx_least_squares(est, arx)


def _run_tasks(tasks, data: IOData, workers, warm_up: tuple, progress) -> dict:
    """Every task's :class:`Run`, by ``(label, seed)``, from the study's
    runner (processes unless `workers` is 1, each warmed up by
    :func:`_warm_up` with `warm_up`)."""
    n_workers = (os.cpu_count() or 1) if workers is None else int(workers)
    results = {}
    for task, row in execute(
        tasks,
        {"record": data},
        engine="processes" if n_workers > 1 else "local",
        workers=n_workers,
        detail=True,
        initializer=_warm_up,
        initargs=warm_up,
    ):
        if isinstance(row, Exception):
            raise row
        times = None if row["times"] is None else np.asarray(row["times"])
        results[task.label, task.seed] = Run(
            task.label,
            task.seed,
            row["model_object"],
            row["cost"],
            row["fit_val"],
            times,
        )
        if progress is not None:
            progress(len(results), len(tasks))
    return results


def _validate_best(rep: Reproduction) -> dict[str, tuple[Validation, Validation]]:
    """Each configuration's best run and each baseline validated on the
    estimation part and, run on from it, the validation part."""
    out = {}
    for label in [*rep.runs, *rep.baselines]:
        model = rep.best(label).model
        out[label] = (
            validate(model, rep.estimation, label=label),
            validate(model, rep.validation, warmup=rep.estimation, label=label),
        )
    return out
