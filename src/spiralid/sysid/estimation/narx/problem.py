"""A NARX estimation as a problem: the record, structure and scaling, the
training and held-back parts, the costs, the residual and its Jacobian for
Levenberg-Marquardt, and the polish in rounds with early stopping. The
estimators of :mod:`.narx` and :mod:`.frols` work on it."""

from __future__ import annotations

import itertools
import math
import time

import numpy as np

from spiralid._checks import integer, nonneg
from spiralid.optim.result import OptimiserResult

from ...models.narx import Scaling
from ..linear.levenberg import levenberg_marquardt
from .subsequences import subsequence_residual

__all__ = [
    "MAX_ROUNDS",
    "PATIENCE",
    "PATIENCE_SHARE",
    "NARXProblem",
    "narx_result",
    "stopping_options",
]

_ROUND = 10  # LM evaluations per early-stopping round
# The default method's early stopping (estimate_spiral): the held-back cost
# decides the training length, the cap on rounds is a safety, and the
# patience grows with the best round (a polish that has gained for 100
# rounds is not stopped by a 3-round plateau). Chosen on seeds 4-7 of the
# paper experiment's nonlinear end-acceleration record (docs/results/narx.md).
MAX_ROUNDS = 500
PATIENCE = 3
PATIENCE_SHARE = 0.5
# LM's tolerances (gradient, relative fall, step): SciPy's least_squares
# defaults, 1e-8.
_TOL = 1e-8


class NARXProblem:
    """A NARX estimation: record, structure, scaling, split and costs.

    Parameters
    ----------
    data : IOData
        Estimation record.
    structure : NARX or PolynomialNARX
    predictor : {"simulation", "one-step"}
    initial : {"rest", "measured"}
    holdout : float
        Share of the record held back for early stopping, in [0, 0.5).
    rng : numpy.random.Generator
    blocks : int
        1: the held-back part is the record's end. More: the record after
        its first full history is cut into `blocks` equal stretches and the
        last `holdout` share of each is held back (training on
        subsequences, :mod:`.subsequences`, whose early stopping must not
        judge on an end the training part never resembles).
    """

    def __init__(self, data, structure, predictor, initial, holdout, rng, blocks=1):
        self.data = data
        self.structure = structure
        self.predictor = predictor
        self.initial = initial
        self.rng = rng
        self.scaling = Scaling.from_data(data, structure.integrator)
        s = self.scaling
        self.ulag = structure.input_lags(data.u, s)
        self.t0, self.hist, self.ystart = structure._history(data.y, s, initial)
        self.phi, self.target = structure.regressors(data.u, data.y, s)
        n = data.n
        lo = max(self.t0, structure.max_lag if predictor == "one-step" else 0)
        # Training on subsequences (.subsequences): the stretches' length
        # while a polish runs on them (None: the free run), and the lengths
        # a training runs through (identify_narx sets them).
        self.horizon = None
        self.stages = (None,)
        if blocks > 1 and holdout > 0:
            self.split = n
            self.train, self.hold = _interleaved(lo, n, holdout, blocks)
        else:
            self.split = n - round(holdout * n) if holdout > 0 else n
            self.train = slice(lo, self.split)
            self.hold = slice(self.split, n) if self.split < n else None
        y = data.y
        self.rms_train = float(np.sqrt(np.mean(y[self.train] ** 2))) or 1.0
        self.rms_hold = (
            float(np.sqrt(np.mean(y[self.hold] ** 2))) or 1.0
            if self.hold is not None
            else 1.0
        )
        self.rms_all = float(np.sqrt(np.mean(y[lo:] ** 2))) or 1.0
        self.lo = lo
        self.nfev = 0

    # -- outputs ---------------------------------------------------------------
    def output(self, params) -> np.ndarray:
        """The predictor's output over the whole record, rows for a batch."""
        st, s = self.structure, self.scaling
        if self.predictor == "one-step":
            z = st.evaluate(params, self.phi)
            if st.integrator:
                prev = np.r_[0.0, self.data.y[:-1]]
                return prev + z * s.y_scale
            return s.y_shift + s.y_scale * z
        z = st.free_run_scaled(params, self.ulag[self.t0 :], self.hist)
        y = st._unscale(z, s, self.ystart)
        if self.t0:
            head = np.broadcast_to(self.data.y[: self.t0], (*y.shape[:-1], self.t0))
            y = np.concatenate([head, y], axis=-1)
        return y

    def costs(self, params) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Training, held-back and whole-record costs (percent RMS), one per
        row of `params`."""
        with np.errstate(over="ignore", invalid="ignore"):
            e = self.data.y - self.output(np.atleast_2d(params))
            tr = 100.0 * np.sqrt(np.mean(e[..., self.train] ** 2, axis=-1))
            tr /= self.rms_train
            if self.hold is not None:
                ho = 100.0 * np.sqrt(np.mean(e[..., self.hold] ** 2, axis=-1))
                ho /= self.rms_hold
            else:
                ho = tr
            al = 100.0 * np.sqrt(np.mean(e[..., self.lo :] ** 2, axis=-1))
            al /= self.rms_all
        bad = ~np.isfinite(tr)
        for arr in (tr, ho, al):
            arr[bad] = np.inf
        return tr, ho, al

    def objective(self, P: np.ndarray) -> np.ndarray:
        """The searches' vectorised objective: training cost of each row."""
        self.nfev += np.atleast_2d(P).shape[0]
        return self.costs(np.atleast_2d(P))[0]

    # -- Levenberg-Marquardt ----------------------------------------------------
    def residual_and_jacobian(self, predictor: str):
        """Scaled training residual and its exact Jacobian (callables), with
        the weight decay's rows ``sqrt(decay M) w`` on the network's weights
        (not the bypass) appended when `decay` > 0."""
        if predictor == "simulation" and self.horizon is not None:
            fun, jac, m = subsequence_residual(self, self.horizon)
        else:
            fun, jac = self._residual_and_jacobian(predictor)
            m = np.arange(self.data.n)[self.train].size
        decay = getattr(self, "decay", 0.0)
        st = self.structure
        if decay <= 0.0 or st.family != "narx" or st.h == 0:
            return fun, jac
        net = np.arange(st.h * (st.n_regressors + 2))
        # The decay weighs against the mean squared residual: M is the
        # residuals' count (the training samples, or the stretches' samples).
        w = math.sqrt(decay * m)

        def fun_decay(p):
            return np.r_[fun(p), w * p[net]]

        def jac_decay(p):
            extra = np.zeros((net.size, p.size))
            extra[np.arange(net.size), net] = w
            return np.vstack([jac(p), extra])

        return fun_decay, jac_decay

    def _residual_and_jacobian(self, predictor: str):
        st, s = self.structure, self.scaling
        tr = self.train
        scale = s.y_scale

        if predictor == "one-step":
            phi, target = self.phi[tr], self.target[tr]

            def fun(p):
                self.nfev += 1
                return target - st.evaluate(p, phi)

            def jac(p):
                self.nfev += 1
                return -st.jacobian(p, phi)

            return fun, jac

        cache = {}

        def run(p):
            key = p.tobytes()
            if key not in cache:
                cache.clear()
                z, sens = st.free_run_jacobian(p, self.ulag[self.t0 :], self.hist)
                if st.integrator:
                    with np.errstate(all="ignore"):
                        z, sens = np.cumsum(z), np.cumsum(sens, axis=0)
                    z = z + self.ystart / scale
                    full = np.r_[self.data.y[: self.t0] / scale, z]
                else:
                    full = np.r_[(self.data.y[: self.t0] - s.y_shift) / scale, z]
                fsens = np.vstack([np.zeros((self.t0, p.size)), sens])
                cache[key] = (full, fsens)
            return cache[key]

        ref = (
            self.data.y / scale if st.integrator else (self.data.y - s.y_shift) / scale
        )

        def fun(p):
            self.nfev += 1
            full, _ = run(p)
            r = ref[tr] - full[tr]
            return np.where(np.isfinite(r), r, 1e10)

        def jac(p):
            _, fsens = run(p)
            return -np.nan_to_num(fsens[tr], nan=0.0, posinf=0.0, neginf=0.0)

        return fun, jac

    def whole(self) -> NARXProblem:
        """The same problem with nothing held back: training covers the
        whole record (the refit after early stopping)."""
        other = NARXProblem.__new__(NARXProblem)
        other.__dict__.update(self.__dict__)
        n = self.data.n
        other.split, other.hold = n, None
        other.train = slice(self.lo, n)
        other.rms_train = self.rms_all
        other.nfev = 0
        return other

    def polish(
        self,
        p0,
        predictor: str,
        max_rounds: int = MAX_ROUNDS,
        patience: int = PATIENCE,
        patience_share: float = PATIENCE_SHARE,
    ) -> tuple[np.ndarray, int]:
        """Levenberg-Marquardt in rounds with early stopping on the held-back
        cost; returns the parameters with the lowest held-back cost (the
        training cost when nothing is held back) and the round that reached
        them (0: the start).

        Parameters
        ----------
        p0 : ndarray
            Start.
        predictor : {"simulation", "one-step"}
            The error minimised.
        max_rounds : int
            Rounds of 10 evaluations at most.
        patience : int
            Rounds without a lower held-back cost before stopping.
        patience_share : float
            The patience grows with the best round: training stops after
            ``max(patience, ceil(patience_share * best_round))`` rounds
            without a lower held-back cost (0: a fixed `patience`).
        """
        fun, jac = self.residual_and_jacobian(predictor)
        p = np.asarray(p0, dtype=float).copy()
        pick = 1 if self.hold is not None else 0
        best_p, best = p.copy(), self._score(p, predictor, pick)
        waited = best_round = 0
        m = fun(p).size
        if m <= p.size:
            return best_p, 0
        for rounds in range(1, max_rounds + 1):
            try:
                with np.errstate(all="ignore"):
                    res = levenberg_marquardt(fun, jac, p, max_nfev=_ROUND, tol=_TOL)
            except (ValueError, np.linalg.LinAlgError):
                break
            moved = not np.array_equal(res.x, p)
            p = res.x
            score = self._score(p, predictor, pick)
            if score < best * (1.0 - 1e-9):
                best_p, best, waited, best_round = p.copy(), score, 0, rounds
            else:
                waited += 1
            # A stop other than the evaluation cap (stop 0) is convergence.
            wait = max(patience, math.ceil(patience_share * best_round))
            if waited >= wait or not moved or res.stop != 0:
                break
        return best_p, best_round

    def _score(self, p, predictor: str, pick: int) -> float:
        if predictor == self.predictor:
            return float(self.costs(p)[pick][0])
        other = NARXProblem.__new__(NARXProblem)
        other.__dict__.update(self.__dict__)
        other.predictor = predictor
        return float(other.costs(p)[pick][0])


def _interleaved(lo: int, n: int, holdout: float, blocks: int):
    """Training and held-back indices: ``[lo, n)`` cut into `blocks` equal
    stretches, the last `holdout` share of each held back."""
    edges = np.linspace(lo, n, blocks + 1).round().astype(int)
    hold = np.zeros(n, dtype=bool)
    for a, b in itertools.pairwise(edges):
        hold[b - round(holdout * (b - a)) : b] = True
    idx = np.arange(n)
    return idx[lo:][~hold[lo:]], idx[hold]


def stopping_options(max_rounds, patience, patience_share) -> dict:
    """The early stopping's options, checked, as :func:`~.training._fit` takes
    them.

    Parameters
    ----------
    max_rounds : int
        Rounds of 10 evaluations at most, >= 1.
    patience : int
        Rounds without a lower held-back cost before stopping, >= 1.
    patience_share : float
        Share of the best round added to the patience, finite and >= 0.

    Returns
    -------
    dict
    """
    return {
        "max_rounds": integer(max_rounds, "max_rounds", 1),
        "patience": integer(patience, "patience", 1),
        "patience_share": nonneg(patience_share, "patience_share"),
    }


def narx_result(problem, p, t0, **extra) -> OptimiserResult:
    tr, ho, al = problem.costs(np.atleast_2d(p))
    out = OptimiserResult(
        x=np.asarray(p, dtype=float),
        fun=float(al[0]),
        train_cost=float(tr[0]),
        holdout_cost=float(ho[0]),
        nfev=int(problem.nfev),
        elapsed=time.perf_counter() - t0,
        success=True,
        status=0,
    )
    out.update(extra)
    linear = out.get("linear_params")
    if linear is not None:
        out["linear_cost"] = float(problem.whole().costs(np.atleast_2d(linear))[2][0])
    out.setdefault("nit", 0)
    out.setdefault("message", "")
    out.setdefault("n_restarts", 0)
    out.setdefault("history", None)
    return out
