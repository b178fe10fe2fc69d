"""identify_pareto(): a Pareto front of ARX models, and choosing one from it.

The spiral search of :func:`spiralid.optim.minimize_pareto` (SDA, Eb-SDA or
the learned-metric poll, by Tchebycheff decomposition) runs over the same
coordinates and box as ``identify``'s search methods (default ``"modal"``:
the denominator's modes in natural frequency and log damping ratio, the
numerator projected out by least squares on the simulation error, every
candidate stable), against two or three of these objectives, all minimised:

``"cost"``
    The paper's cost, eq. (2)-(3): the free-run simulation error as a
    percentage of the output's RMS, plus the penalty for an unstable pole
    (:class:`~spiralid.sysid.PaperCost`).
``"frequency"``
    The coherence-weighted RMS error of the model's log gain against the
    record's H1 estimate, in dB
    (:class:`~spiralid.sysid.estimation.linear.frequency.FrequencyError`); an
    unstable candidate pays the same penalty.
``"one-step"``
    The paper's cost with the one-step prediction error.
``"order"``
    The number of parameters ``na + nb``. Given several orders the search
    runs once per order over the other (two) objectives and the fronts are
    merged by :func:`~spiralid.optim.pareto.non_dominated` with the order as
    a third objective; it is added by itself then.

With the modal parametrisation the numerator of every candidate is the one
that minimises the simulation error for its denominator, so the front is
the trade-off over denominators (poles) at that numerator; the ``"cost"``
end is where output error is. ``parametrization="coefficients"`` or
``"reflection"`` search the numerator too (larger, slower searches).

Seeding (``seed_estimates=True``, the default) puts the stabilised
least-squares, Steiglitz-McBride and output-error (``identify(method="oe")``)
estimates of each order into the first population, mapped into the searched
coordinates, and keeps them among the final candidates, so the front's
``"cost"`` end is never above output error's (where the parametrisation
represents its denominator) and a weak search cannot lose it. The search's
candidates are the non-dominated set of every iteration's incumbents (an
incumbent that a neighbour replaced can still be on the front). Then each
searched objective's best candidate is polished on that objective alone by
L-BFGS-B in the box (``extremes_nfev`` evaluations each, 0 for none) and
joins the candidates. Which candidate each front model came from is its
``result.start`` (``"search"``, ``"polish"``, ``"ls"``,
``"steiglitz-mcbride"`` or ``"oe"``); every evaluation counts in ``nfev``.

Choosing a model
----------------
The front's :attr:`~ParetoIdentification.knee` is its knee point
(:func:`spiralid.optim.knee_point`, geometry of the front alone). The
rules for choosing a model from the front, the knee among them, are in one
module, :mod:`spiralid.sysid.validation.selection`: :func:`~spiralid.sysid.choose`
(the lowest value of one objective under bounds on the others) and
:func:`~spiralid.sysid.choose_order` (the lowest order that validates as
well on held-out data), which validates and so sits above estimation.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np

from spiralid._checks import generator, integer
from spiralid.choices import DEFAULT_PARETO_METHOD, OBJECTIVES
from spiralid.optim.front import knee_point
from spiralid.optim.pareto import non_dominated

from ...data import IOData, single_output_record
from ...models.arx import ARX
from ...models.identified import IdentifiedModel
from ..core.cost import PaperCost
from ..core.problem import EstimatorResult
from ..linear.frequency import FrequencyError, FrequencyEstimate, h1_estimate
from .options import (
    _FREQUENCY_DEFAULTS,
    _SEARCH_DEFAULTS,
    _pareto_settings,
    pareto_options,
    refused_pareto_options,
)
from .search import _Progress, _search_structure, _StructureRun

__all__ = [
    "OBJECTIVES",
    "ParetoIdentification",
    "identify_pareto",
    "pareto_options",
    "refused_pareto_options",
]


@dataclass
class ParetoIdentification:
    """The front of :func:`identify_pareto`, sorted by the first objective.

    Attributes
    ----------
    models : list of IdentifiedModel
        One stable model per front point (validate each as ``identify``'s
        result); ``result.start`` says which candidate it came from and
        ``result.objectives`` holds its objective values by name.
    objectives : ndarray, shape (m, k)
        The objective values of the models, columns in the order of `names`.
    names : tuple of str
        The objectives (keys of :data:`OBJECTIVES`).
    knee : int
        Index of the knee point (:func:`spiralid.optim.knee_point`).
    hypervolume : dict of str to ndarray
        Each search's hypervolume history (index 0: the initial population),
        by structure, e.g. ``"ARX(8, 8, 0)"``; each in its own objectives
        and reference point, so comparable within a search only.
    nfev : int
        Objective evaluations of all searches (the seeds' included).
    elapsed : float
        Wall time in seconds.
    n_unstable : int
        Non-dominated candidates left out for an unstable pole.
    frequency : FrequencyEstimate
        The measured response the ``"frequency"`` objective scores against.
    seeded : bool
        Whether the single-objective estimates seeded the searches.
    """

    models: list[IdentifiedModel]
    objectives: np.ndarray
    names: tuple[str, ...]
    knee: int
    hypervolume: dict[str, np.ndarray] = field(default_factory=dict)
    nfev: int = 0
    elapsed: float = 0.0
    n_unstable: int = 0
    frequency: FrequencyEstimate | None = None
    seeded: bool = True

    def __len__(self) -> int:
        return len(self.models)

    @property
    def knee_model(self) -> IdentifiedModel:
        """The model at the knee point."""
        return self.models[self.knee]


def _structures(orders, nk: int | None) -> list[ARX]:
    if getattr(orders, "family", None) == "arx":
        if nk is not None and nk != orders.nk:
            raise ValueError(
                f"`nk` builds structures from orders given as numbers; {orders} "
                f"has its own nk = {orders.nk}; got nk = {nk!r}"
            )
        return [orders]
    nk = 0 if nk is None else nk
    if isinstance(orders, int | np.integer) and not isinstance(orders, bool):
        orders = [orders]
    if isinstance(orders, str) or not isinstance(orders, Iterable):
        raise ValueError(
            f"`orders` must be an ARX or model orders (integers >= 1); got {orders!r}"
        )
    values = list(orders)
    bad = [
        v
        for v in values
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 1
    ]
    if not values or bad:
        raise ValueError(
            "`orders` must be an ARX or a non-empty list of model orders "
            f"(integers >= 1); got {values!r}"
        )
    if len(set(values)) != len(values):
        raise ValueError(f"`orders` must not repeat an order; got {values!r}")
    return [ARX(int(n), int(n), nk) for n in values]


def _names(objectives, several: bool) -> tuple[str, ...]:
    if isinstance(objectives, str) or not isinstance(objectives, Iterable):
        raise ValueError(
            f"`objectives` must be a list of names among {tuple(OBJECTIVES)}; "
            f"got {objectives!r}"
        )
    names = tuple(objectives)
    unknown = [n for n in names if not isinstance(n, str) or n not in OBJECTIVES]
    if unknown:
        raise ValueError(
            f"`objectives` must be among {tuple(OBJECTIVES)}; got {unknown[0]!r}"
        )
    if len(set(names)) != len(names):
        raise ValueError(f"`objectives` must not repeat a name; got {names!r}")
    if several and "order" not in names:
        names = (*names, "order")
    if not several and "order" in names:
        raise ValueError(
            "`objectives` 'order' needs several orders (e.g. orders=range(2, 13)); "
            "one structure has one order"
        )
    searched = [n for n in names if n != "order"]
    if not 2 <= len(names) <= 3 or len(searched) < 2:
        raise ValueError(
            "`objectives` must name 2 or 3 objectives, at least two of them "
            "searched ('order' counts as one); got "
            f"{names if several else tuple(objectives)!r}"
        )
    return names


def _front_model(
    run: _StructureRun, i: int, objectives, names, data, method, parametrization,
    initial,
) -> IdentifiedModel:  # fmt: skip
    """Candidate `i` of `run` as an IdentifiedModel."""
    theta = np.asarray(run.thetas[i])
    fun = float(run.cost(theta))
    res = run.res
    result = EstimatorResult(
        x=theta,
        fun=fun,
        status=int(res.status),
        success=True,
        message=str(res.message),
        nfev=int(res.nfev),
        nit=int(res.nit),
        start=run.starts[i],
        objectives=dict(zip(names, (float(v) for v in objectives), strict=True)),
        raw=res,
    )
    return IdentifiedModel(
        theta,
        arx=run.arx,
        ts=data.ts,
        method=f"pareto-{method}",
        parametrization=parametrization,
        initial=initial,
        gain=run.cost.w,
        penalty=run.cost.penalty,
        cost=fun,
        result=result,
        timings={"search": float(res.elapsed)},
        bounds=run.box,
        **data.provenance(),
    )


def identify_pareto(
    data: IOData,
    orders,
    objectives=("cost", "frequency"),
    method: str = DEFAULT_PARETO_METHOD,
    *,
    rng=None,
    nk: int | None = None,
    initial: str = "rest",
    gain: str | float = "auto",
    penalty: float = 1e6,
    progress: Callable[[int, int], None] | None = None,
    **options,
) -> ParetoIdentification:
    """A Pareto front of stable ARX models on an estimation record.

    Its search options are passed as ``identify``'s are, through
    ``**options``; :func:`pareto_options` lists those that apply to the
    objectives, and any other is refused in one line naming it.

    Parameters
    ----------
    data : IOData
        Estimation record (as for ``identify``: e.g. the first 2/3 of a
        record, ``data.split(2 / 3)[0]``); the frequency objective's H1
        estimate is made on it too.
    orders : ARX, int or iterable of int
        One structure, or orders ``n`` each searched as ``ARX(n, n, nk)``
        (several add the ``"order"`` objective).
    objectives : sequence of str, default ("cost", "frequency")
        Names from :data:`OBJECTIVES` (see the module docstring).
    method : str or rule, default "learned-metric"
        A name of :data:`~spiralid.optim.pareto.PARETO_METHODS`
        (``"learned-metric"``, the default,
        :data:`~spiralid.optim.pareto.DEFAULT_PARETO_METHOD`; ``"ebsda"``,
        the paper's rule; ``"sda"``, ...) or a rule object, as
        :func:`~spiralid.optim.pareto.minimize_pareto` takes. Not
        ``identify``'s default ``"spiral"``: that method is a search for
        one cost (a memetic polish, restarts, a held-back choice), while
        this one approximates a front, and the learned-metric poll is the
        best front search on the benchmark problems
        (docs/results/multiobjective.md).
    rng : None, int or numpy.random.Generator
        Seed of the searches (one generator, orders in the given order).
    nk : int, optional
        Input delay of the structures built from `orders` given as numbers
        (default 0); an ARX carries its own, and a different `nk` beside it
        is refused.
    initial : {"rest", "measured"}
        Initial condition of the simulation error (see ``identify``).
    gain, penalty
        The cost's gain and stability penalty (:class:`PaperCost`).
    progress : callable, optional
        ``progress(done, total)`` as the evaluations go: ``total`` is what
        the budgets allow, ``len(orders) * (max_nfev + extremes_nfev * k)``
        for ``k`` searched objectives (``done`` stops there).
    **options
        The search's, as :func:`~spiralid.optim.pareto.minimize_pareto`
        names them: ``max_nfev`` (default 5000, each order's budget),
        ``n_points`` (default 50, one subproblem each), ``max_time`` and
        ``neighbours`` (default 10); the models': ``parametrization``
        (``"modal"``, ``"coefficients"`` or ``"reflection"``, what the
        search moves, :mod:`~spiralid.sysid.estimation.linear.parametrizations`;
        ``"modal"``, the default, needs ``initial="rest"``),
        ``seed_estimates`` (default True: seed each search with the
        least-squares, Steiglitz-McBride and output-error estimates and keep
        them among the candidates) and ``extremes_nfev`` (default 200, the
        budget of each extreme's polish, 0 for none; it was
        ``polish_nfev``); with the ``"frequency"`` objective, its H1
        estimate's: ``nperseg`` (Welch segment length), ``fmin``, ``fmax``
        (its band in Hz, default one resolution cell to 0.8 of the Nyquist
        frequency) and ``min_coherence`` (default 0.5: bins with lower
        coherence are not scored;
        :func:`~spiralid.sysid.estimation.linear.frequency.h1_estimate`). The
        defaults differ from ``minimize_pareto``'s 100 points and 10,000
        evaluations because every order is a search of its own: half of
        each gives the same number of iterations (49 of the default rule,
        99 of a spiral rule).

    Returns
    -------
    ParetoIdentification

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(1500)
    >>> y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> y = y + 0.5 * np.random.default_rng(1).standard_normal(1500)
    >>> front = identify_pareto(IOData(u, y, ts=0.01), ARX(2, 2, 1), rng=0,
    ...                         max_nfev=400, n_points=20)
    >>> front.names, all(m.is_stable for m in front.models)
    (('cost', 'frequency'), True)
    >>> bool(np.allclose(front.knee_model.theta[:2], [-1.5, 0.7], atol=0.05))
    True
    """
    t_start = time.perf_counter()
    single_output_record(data, "identify_pareto")
    structures = _structures(orders, nk)
    names = _names(objectives, len(structures) > 1)
    if isinstance(method, str):
        method = method.lower()
    settings = _pareto_settings(method, names, options)
    search = {name: settings[name] for name in _SEARCH_DEFAULTS}
    parametrization = settings["parametrization"]
    gen = generator(rng)
    estimate = h1_estimate(
        data, **{name: settings[name] for name in _FREQUENCY_DEFAULTS}
    )
    searched = [n for n in names if n != "order"]
    count = None
    if progress is not None:
        budget = integer(search["max_nfev"], "max_nfev", 1)
        budget += len(searched) * settings["extremes_nfev"]
        count = _Progress(progress, len(structures) * budget)
    runs = []
    for arx in structures:
        arx.check_length(data)
        runs.append(
            _search_structure(
                data,
                arx,
                FrequencyError(arx, estimate),
                searched,
                method,
                gen,
                parametrization=parametrization,
                cost=PaperCost(arx, data, gain=gain, penalty=penalty, initial=initial),
                seed_estimates=settings["seed_estimates"],
                extremes_nfev=settings["extremes_nfev"],
                initial=initial,
                search=search,
                gain=gain,
                count=count,
            )
        )
    candidates = [(run, i) for run in runs for i in range(len(run.starts))]
    f = np.array([run.rows[i] for run, i in candidates])
    if "order" in names:
        order = np.array([run.arx.n_params for run, _ in candidates], dtype=float)
        f = np.insert(f, names.index("order"), order, axis=1)
    stable = np.array([run.arx.is_stable(run.thetas[i]) for run, i in candidates])
    keep = np.flatnonzero(non_dominated(f))
    n_unstable = int(np.sum(~stable[keep]))
    keep = keep[stable[keep]]
    # Non-dominated among the stable ones (dropping an unstable point can
    # leave what it dominated), sorted by the first objective.
    keep = keep[non_dominated(f[keep])]
    keep = keep[np.lexsort(f[keep].T[::-1])]
    models = [
        _front_model(
            *candidates[i], f[i], names, data, method, parametrization, initial
        )
        for i in keep
    ]
    if not models:
        raise ValueError(
            "`data` gave no stable model on the front; try parametrization='modal'"
        )
    histories = {str(run.arx): np.asarray(run.res.history) for run in runs}
    nfev = sum(run.nfev for run in runs)
    front = f[keep]
    return ParetoIdentification(
        models=models,
        objectives=front,
        names=names,
        knee=knee_point(front) if len(front) > 1 else 0,
        hypervolume=histories,
        nfev=nfev,
        elapsed=time.perf_counter() - t_start,
        n_unstable=n_unstable,
        frequency=estimate,
        seeded=bool(settings["seed_estimates"]),
    )
