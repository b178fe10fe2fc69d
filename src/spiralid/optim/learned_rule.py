"""The learned-metric spiral's settings: :class:`LearnedMetricSpiral`.

The rule is a frozen record of the algorithm's switches and constants,
checked once; :mod:`spiralid.optim.learned` describes the algorithm and
holds the search that runs it (and the multi-objective search,
:mod:`spiralid.optim.pareto`, reads the same rule).
"""

import math
from dataclasses import dataclass

from spiralid._checks import one_of, positive

__all__ = ["LearnedMetricSpiral"]

_SAMPLINGS = ("gaussian", "orthogonal")
_PATH_FRAMES = ("basis", "cma")
_BASIS_GAPS = ("purecma", "every", "n/10")


@dataclass(frozen=True)
class LearnedMetricSpiral:
    """The learned-metric spiral rule (see :mod:`spiralid.optim.learned`).

    Its ingredients can be switched off one at a time, to measure each.

    Parameters
    ----------
    basis : bool
        Learn the basis by Adaptive Encoding (default); False polls the
        box's own axes.
    success_steps : bool
        Adapt a step per direction from success (default); False shrinks
        every step by the periodic setting's ``delta^(1/k_max)`` per period.
    model_step : bool
        After each period, try the minimum of the diagonal quadratic model
        that the pairs' costs give in the learned basis (one evaluation;
        default).
    populations : bool
        With restarts, alternate fresh polls with population periods
        (default); False restarts polls only.
    sampling : {"gaussian", "orthogonal"}
        The population periods' ``lambda / 2`` directions ``z_l``:
        ``"gaussian"`` (default) draws them independently;
        ``"orthogonal"`` takes them in blocks of ``n`` mutually orthogonal
        directions of a uniformly random rotation, each with a length drawn
        as a Gaussian vector's (chi with ``n`` degrees of freedom), so that
        each block spans every direction once as the poll's period does.
    run_stall : bool
        Count a run's stall from its own best cost (default): a restarted
        run still converging is not cut short because an earlier run went
        lower. False counts it from the best cost of all runs.
    basis_gap : {"purecma", "every", "n/10"}
        When the learned metric is decomposed into the basis; in between
        the metric keeps learning while the basis, its inverse and the
        condition stay as they were (CMA-ES's lazy update).
        ``"purecma"`` (default): the lazy gap of Hansen's reference CMA-ES
        (pycma's ``cma.purecma``), after more than ``0.5 n lambda /
        ((c_1 + c_mu) n^2)`` evaluations, that is every ``k``-th update
        with ``k`` the least integer above ``0.5 / ((c_1 + c_mu) n)``. At
        the poll's rates (``c_1 + c_mu = 1/n``) that is every period; in the
        search's population runs (``lambda`` twice CMA-ES's default, then
        doubled) every period up to ``n = 22`` (the same search as
        ``"every"``) and every second period of the first population run
        from ``n = 23`` (``n = 40``: ``lambda = 30``). ``"every"``: every
        period. ``"n/10"``: every ``max(1, n // 10)`` periods, polls too; it
        cut the optimiser's own time at ``n = 40`` by a third but lost
        triples on BBOB (the ellipsoids' metric learned too slowly; figures
        in the BBOB results).
    unbiased_sigma : bool
        Adapt the step size of every population run after the first
        without the bias that mirrored pairs give cumulative step-size
        adaptation (default True). When both members of a pair are
        selected, their directions cancel in the mean, so under blind
        selection (a plateau, a ridge) the mean's path is shorter than the
        adaptation expects and ``sigma`` collapses (Auger, Brockhoff and
        Hansen, 2011): on BBOB's step ellipsoid a run ends on a plateau
        that CMA-ES's unmirrored samples step off. The path's step is then
        scaled by the selection's own ``mu_eff``, that of the weights
        summed per pair with opposite signs, so it is a standard normal
        vector under blind selection. The first population run keeps the
        bias: its quicker convergence is what the suspended poll and the
        multimodal functions gain from (figures in the BBOB results).
        False keeps it in every run.
    path_frame : {"basis", "cma"}
        The coordinates in which a population run's step-size path adds up
        the mean's steps. ``"basis"`` (default): those of the latest
        decomposition, ``B^-1 (m' - m) / sigma`` with ``B = V D`` its
        eigenvectors scaled; the order and signs of the eigenvectors change
        from one decomposition to the next, so the path adds steps in
        frames that move, comes out shorter and shrinks ``sigma`` sooner.
        ``"cma"``: CMA-ES's ``C^-1/2 (m' - m) / sigma = V D^-1 V^T (m' -
        m) / sigma`` (Hansen's tutorial, 2016), in fixed coordinates. On
        BBOB at D = 20 ``"cma"`` gains the sharp ridge (0.38 to 0.46 of the
        triples) and loses the step ellipsoid (0.90 to 0.58) and
        Gallagher's functions: 0.560 against 0.569 in all (figures in the
        BBOB results), so the default keeps the moving frame.
    suspend_crawl : bool
        With restarts, suspend a poll that crawls instead of letting it spend
        the budget: a population run goes next, with half the poll's
        evaluations (or more, ``extend_closing``); if it does not go below
        the poll's cost by then, the poll resumes where it stopped (once; it
        is not suspended again). A poll crawls when, over its last
        ``max(30, crawl_window n)`` periods, its gains fell by less than a
        tenth of what the fall of its largest step predicts for a
        converging run (the square), while the metric's condition grew by
        less than 1.5 and stays below 1e7, with its largest step below 1e-3
        of the box. Default True: on BBOB at D = 20 it gains the attractive
        sector and Schaffer's functions (figures in the BBOB results); a
        converging poll is left alone.
    crawl_window : float
        The crawl test's window in periods per dimension (at least 30
        periods; default 2, so 40 at n = 20). The population run that a
        crawling poll hands over to needs what is left of the budget: with
        4 (the previous default) a poll could be suspended only after
        ``8 n`` periods, a third of a ``1000 n`` budget at n = 20, and the
        attractive sector's population runs ran out of budget (figures in
        the BBOB results).
    extend_closing : bool
        With ``suspend_crawl``, let the population run go on past its half
        of the poll's evaluations while it is closing in on the poll's
        cost: at its rate over its last ``n`` periods it would reach that
        cost within ``3 n`` more (default True). On BBOB's attractive
        sector the population run converges at a steady rate from a
        uniform centre, but was cut while still above the crawled poll's
        cost, and the resumed poll crawled on to ``1e-6`` where the
        continued population run reaches ``1e-8`` (figures in the BBOB
        results). False cuts it at the half.
    max_condition : float or None
        Bound on the poll's metric's condition, ``>= 1`` (its eigenvalues
        are raised to the largest over it); default 1e8. The normalised
        update grows a direction that every period's best points favour
        without bound (the bent cigar's, to 1e13, where the run collapsed
        at 1e14); 1e8 leaves the 1e6 of BBOB's ill-conditioned functions
        room, and the poll's steps carry any scale beyond it. None leaves
        it unbounded.
    grow, shrink : float
        Step factors after a success (``> 1``) and a failure (in (0, 1));
        default 2 and 1/2, Adaptive Coordinate Descent's.
    delta : float
        Contraction over the run's budget when ``success_steps=False``.
    crossover : float
        :func:`~spiralid.optim.minimize_pareto` only: the share of
        subproblems that poll a crossover pair instead of a basis direction
        at each iteration (default 0.5; 0 polls the basis directions
        only). The pair is ``x* +- M (x_r - x*)`` with ``x_r`` the incumbent
        of a random subproblem and ``M`` a random half of the coordinates:
        a uniform crossover of the centre with ``x_r`` and its mirror, which
        carries a coordinate found good elsewhere on the front and steps
        past the front's ends (WFG2's outer pieces). The single-objective
        search refuses any other value than the default.
    first_sigma : float or None
        None (default): the search starts with a poll from the best of its
        ``n_points`` first points. A step in (0, 1] of the unit cube: it
        starts instead with a population run centred at ``x0`` (its first
        row; a uniform point without ``x0``) with this step, as CMA-ES run
        from ``x0`` with ``sigma0`` does; the ``n_points`` first points are
        not drawn. For a start that carries information (a model's initial
        values); :func:`~spiralid.optim.minimize` only.
    local_sigma : float or None
        None (default): a population restart is centred at a uniform point
        with step 0.2 of the unit cube. A step in (0, 1]: population
        restarts alternate between one centred at the best point so far
        with this step (BIPOP-CMA-ES's local regime) and a uniform one, the
        local first. :func:`~spiralid.optim.minimize` only.

    Examples
    --------
    >>> import numpy as np
    >>> from spiralid.optim import minimize
    >>> H = np.diag(10.0 ** np.linspace(0, 6, 5))  # condition 1e6
    >>> res = minimize(lambda x: float(x @ H @ x), [(-5, 5)] * 5,
    ...                LearnedMetricSpiral(), max_nfev=5000, rng=0)
    >>> bool(res.fun < 1e-10)
    True
    """

    basis: bool = True
    success_steps: bool = True
    model_step: bool = True
    populations: bool = True
    sampling: str = "gaussian"
    path_frame: str = "basis"
    run_stall: bool = True
    basis_gap: str = "purecma"
    suspend_crawl: bool = True
    unbiased_sigma: bool = True
    crawl_window: float = 2.0
    extend_closing: bool = True
    max_condition: float | None = 1e8
    grow: float = 2.0
    shrink: float = 0.5
    delta: float = 1e-3
    crossover: float = 0.5
    first_sigma: float | None = None
    local_sigma: float | None = None

    def __post_init__(self):
        for name in (
            "basis",
            "success_steps",
            "model_step",
            "populations",
            "run_stall",
            "suspend_crawl",
            "unbiased_sigma",
            "extend_closing",
        ):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"`{name}` must be True or False")
        for name, allowed in (
            ("sampling", _SAMPLINGS),
            ("path_frame", _PATH_FRAMES),
            ("basis_gap", _BASIS_GAPS),
        ):
            one_of(getattr(self, name), name, allowed)
        if self.max_condition is not None:
            cap = positive(self.max_condition, "max_condition")
            if cap < 1.0:
                raise ValueError(
                    f"`max_condition` must be >= 1 or None; got {self.max_condition!r}"
                )
            object.__setattr__(self, "max_condition", cap)
        object.__setattr__(
            self, "crawl_window", positive(self.crawl_window, "crawl_window")
        )
        grow = positive(self.grow, "grow")
        if grow <= 1.0:
            raise ValueError(f"`grow` must be > 1; got {self.grow!r}")
        for name in ("shrink", "delta"):
            value = positive(getattr(self, name), name)
            if value >= 1.0:
                raise ValueError(f"`{name}` must be in (0, 1); got {value!r}")
            object.__setattr__(self, name, value)
        object.__setattr__(self, "grow", grow)
        try:
            crossover = float(self.crossover)
        except (TypeError, ValueError):
            crossover = math.nan
        if isinstance(self.crossover, bool) or not 0.0 <= crossover <= 1.0:
            raise ValueError(f"`crossover` must be in [0, 1]; got {self.crossover!r}")
        object.__setattr__(self, "crossover", crossover)
        for name in ("first_sigma", "local_sigma"):
            if getattr(self, name) is not None:
                value = positive(getattr(self, name), name)
                if value > 1.0:
                    raise ValueError(
                        f"`{name}` must be in (0, 1] or None; got {value!r}"
                    )
                object.__setattr__(self, name, value)

    def eigen_every(self, encoding) -> int:
        """Updates of `encoding` (an :class:`AdaptiveEncoding`) between two
        decompositions of its metric, as ``basis_gap`` says."""
        if self.basis_gap == "every":
            return 1
        if self.basis_gap == "n/10":
            return max(1, encoding.n // 10)
        return encoding.lazy_gap()

    def poll_cost(self, n: int) -> int:
        """Evaluations of a poll period in dimension ``n``: ``2n`` polls and
        the model step's one."""
        return 2 * n + self.model_step
