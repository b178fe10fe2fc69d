"""A grey-box search's simulations on several processes.

A grey box costs one simulation per point, and a Python ``f`` makes that
simulation the whole time of a fit, so the points of a batch are run on
workers: a process pool of ``workers`` processes that the fit starts and
closes, a :class:`concurrent.futures.Executor` the caller owns, or a Dask
``distributed.Client`` (the study's engine, through its
``get_executor()``).

The result is the same bit for bit as in one process: a point's cost is a
pure function of the point, each worker runs the same code on a copy of
the problem, and the costs come back in the batch's order. The batch is cut
into as many chunks as there are workers, so the problem (record and
structure) is sent once per chunk, not once per point.

Only the batches are parallel: the learned-metric spiral polls two points
at a time (so at most two workers are busy during its polls), the paper's
spirals a population at a time, and the Jacobian of the polish one column
per free parameter.
"""

from __future__ import annotations

import os
import pickle
from concurrent.futures import Executor, ProcessPoolExecutor

import numpy as np

from spiralid._checks import is_integer

from .problem import GreyBoxProblem

__all__ = ["ParallelEvaluator", "workers_of"]


def _chunk_residuals(problem: GreyBoxProblem, zs: np.ndarray) -> list[np.ndarray]:
    return [problem.residual(z) for z in zs]


def _chunk_costs(problem: GreyBoxProblem, zs: np.ndarray) -> np.ndarray:
    return np.array([problem(z) for z in zs])


def workers_of(workers) -> tuple[Executor | None, int, bool]:
    """``(executor, n_workers, owned)`` for identify's `workers` argument:
    None or 1 (no executor), an int >= 2 (a process pool this module owns
    and closes), an Executor, or a Dask client; a one-line error otherwise."""
    if workers is None or (is_integer(workers) and int(workers) == 1):
        return None, 1, False
    if is_integer(workers):
        if int(workers) < 1:
            raise ValueError(f"`workers` must be >= 1; got {workers!r}")
        n = int(workers)
        return ProcessPoolExecutor(max_workers=n), n, True
    if isinstance(workers, Executor):
        n = getattr(workers, "_max_workers", None) or os.cpu_count() or 1
        return workers, int(n), False
    if callable(getattr(workers, "get_executor", None)) and callable(
        getattr(workers, "nthreads", None)
    ):
        return workers.get_executor(), max(1, sum(workers.nthreads().values())), False
    raise TypeError(
        "`workers` must be None, an int, a concurrent.futures.Executor or a Dask "
        f"Client; got {type(workers).__name__}"
    )


class ParallelEvaluator:
    """Costs and residuals of batches of unit-box points of `problem` on
    `workers` (see :func:`workers_of`); a context manager that closes the
    pool it started.

    Parameters
    ----------
    problem : GreyBoxProblem
        The problem evaluated; its ``nfev`` counts every point.
    workers : None, int, Executor or Dask Client
        Where the points run.
    """

    def __init__(self, problem: GreyBoxProblem, workers) -> None:
        self.problem = problem
        self.executor, self.n_workers, self._owned = workers_of(workers)
        if self.executor is not None:
            self._check_picklable()

    def _check_picklable(self) -> None:
        # A process pool pickles the problem; a lambda or closure in the
        # structure would fail deep inside the pool instead of here.
        try:
            pickle.dumps(self.problem.structure)
        except (pickle.PicklingError, AttributeError, TypeError) as error:
            self.close()
            raise ValueError(
                "`workers` sends the grey box to other processes, which cannot "
                f"take its functions ({error}): define them at a module's top "
                "level, or run with workers=None"
            ) from None

    def __enter__(self) -> ParallelEvaluator:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Shut down the pool this evaluator started (not the caller's)."""
        if self._owned and self.executor is not None:
            self.executor.shutdown()
            self.executor = None

    def _map(self, fun, zs: np.ndarray) -> list:
        """``fun(problem, chunk)`` over `zs` cut into one chunk per worker,
        in order."""
        zs = np.atleast_2d(np.asarray(zs, dtype=float))
        if self.executor is None or zs.shape[0] == 1:
            return [fun(self.problem, zs)]
        # The workers' copies count their evaluations where nobody reads them.
        self.problem.nfev += zs.shape[0]
        chunks = np.array_split(zs, min(self.n_workers, zs.shape[0]))
        return list(self.executor.map(fun, [self.problem] * len(chunks), chunks))

    def costs(self, zs) -> np.ndarray:
        """The cost of each row of `zs`, shape (k,): the search's
        vectorised objective."""
        return np.concatenate(self._map(_chunk_costs, zs))

    def residuals(self, zs) -> list[np.ndarray]:
        """The simulation error at each row of `zs`."""
        return [r for chunk in self._map(_chunk_residuals, zs) for r in chunk]
