"""Run a study's tasks on Dask, storing each result as it finishes.

:func:`execute` is the one runner: it runs tasks in this process
(``engine="local"``), in a process pool (``"processes"``) or on a Dask
cluster (``"dask"``: a fresh ``LocalCluster`` of single-threaded worker
processes, or an existing scheduler's address), and yields each finished
task's row in the order of completion. Results depend on the seed alone, not
on the engine or the order (each run draws from its own seeded generator).

:func:`run_study` opens the store, skips the runs it already holds, and
commits every new row as it arrives, so an interrupted study resumes where
it stopped. A rig record with ``all_outputs`` also has its modes identified
from every sensor of the same run (:func:`~spiralid.study.modes.fit_every_sensor`),
once per record, after the runs, and stored beside them.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import signal
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from spiralid._checks import one_of

from .spec import StudySpec
from .store import ResultStore
from .tasks import Task, load_records, run_task, study_tasks

__all__ = ["ENGINES", "StudyRun", "execute", "run_study"]

ENGINES = ("dask", "processes", "local")


@dataclass
class StudyRun:
    """What :func:`run_study` did.

    Attributes
    ----------
    store : Path
    total : int
        Runs in the specification.
    reused : int
        Runs already in the store, not recomputed.
    computed : int
        Runs computed and stored now.
    failures : list of (Task, str)
        Runs that raised, with the message; not stored, so a rerun retries.
    modes_reused, modes_computed : int
        Records whose modes from every sensor (``all_outputs``) the store
        already held, and those identified now.
    """

    store: Path
    total: int
    reused: int
    computed: int
    failures: list[tuple[Task, str]] = field(default_factory=list)
    modes_reused: int = 0
    modes_computed: int = 0


@contextmanager
def _children_ignore_sigint():
    """Processes spawned inside the block start with SIGINT ignored, and a
    Ctrl-C meanwhile still reaches this process when the block ends.

    Ctrl-C sends SIGINT to the whole process group: workers that received it
    would each print a KeyboardInterrupt traceback, and the parent stops them
    anyway. An ignored disposition is the signal state that survives spawn's
    fork and exec (a blocked mask does not), so it is set while the workers
    are spawned; the signal is blocked too, because Linux keeps a blocked
    signal pending even when it is ignored, so that it is delivered to the
    restored handler when the block ends. The workers keep ignoring it
    (`_start_worker`). Known gap: threads started before the block (BLAS's)
    do not block it, and the kernel may hand them a Ctrl-C of those few
    milliseconds, which is then discarded; pressing Ctrl-C again works.
    """
    try:
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    except (AttributeError, ValueError):  # no pthreads / not the main thread
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def _die_with_parent(parent: int) -> None:
    """Have the kernel kill this worker when `parent`, the process that
    started it, dies (Linux's PR_SET_PDEATHSIG), so that `kill -9` of a run
    leaves no idle workers behind; elsewhere a watchdog thread polls the
    parent. A parent that died while this worker was still starting is
    noticed too (the worker has been handed to another process by then)."""
    if os.getppid() != parent:
        os._exit(1)
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        if libc.prctl(pr_set_pdeathsig, signal.SIGKILL) == 0:
            if os.getppid() != parent:  # the parent died before the call
                os._exit(1)
            return
    except (OSError, AttributeError):
        pass
    import threading
    import time

    def watch():
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def _start_worker(parent: int, initializer: Callable | None, initargs: tuple) -> None:
    """Every pool worker's first act: ignore Ctrl-C (the parent stops the
    workers) and die with the parent, then the caller's initializer (e.g. compiling
    the kernels)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent(parent)
    if initializer is not None:
        initializer(*initargs)


def _stop_workers(pool: ProcessPoolExecutor) -> None:
    """Stop a pool's workers now, without waiting for their running tasks."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    for process in processes:
        process.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.join(timeout=5)


def _dask_client(scheduler: str | None, workers: int | None):
    from distributed import Client, LocalCluster

    if scheduler is not None:
        return Client(scheduler), None
    # A Ctrl-C interrupts the cluster's coroutines in this process, whose
    # unretrieved exceptions asyncio would log as tracebacks when they are
    # collected (this process runs no other asyncio code).
    logging.getLogger("asyncio").setLevel(logging.CRITICAL)
    with _single_threaded_blas():
        cluster = LocalCluster(
            n_workers=workers or os.cpu_count() or 1,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            # Errors reach us through the futures; the cluster's own log lines
            # would only add tracebacks to a Ctrl-C.
            silence_logs=logging.CRITICAL,
            # Each worker ignores Ctrl-C; the client closes the cluster.
            preload=["spiralid.study._dask_worker"],
        )
    return Client(cluster), cluster


def _execute_dask(tasks, records, scheduler, workers, detail, initializer, initargs):
    from distributed import as_completed as dask_completed

    client, cluster = _dask_client(scheduler, workers)
    try:
        if initializer is not None:
            client.run(initializer, *initargs)
        needed = {t.data for t in tasks}
        shared = {
            name: client.scatter(records[name], broadcast=True) for name in needed
        }
        futures = {
            client.submit(
                run_task,
                t,
                shared[t.data],
                detail,
                key=f"spiralid-run-{t.key}",
                pure=False,
            ): t
            for t in tasks
        }
        for fut in dask_completed(futures):
            yield futures[fut], _outcome(fut)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _outcome(fut):
    try:
        return fut.result()
    except Exception as exc:  # a failed run is reported, not fatal to the study
        return exc


@contextmanager
def _single_threaded_blas():
    """One BLAS thread in the worker processes started inside the block.

    The workers already run one identification per core; a threaded BLAS
    inside each oversubscribes the cores and its small least-squares solves
    (safe starts, output-error polish) become many times slower. The workers are
    spawned, so they load BLAS afresh and read these variables; a user's own
    setting is kept.
    """
    names = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
    saved = {name: os.environ.get(name) for name in names}
    for name in names:
        os.environ.setdefault(name, "1")
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)


def _execute_processes(tasks, records, workers, detail, initializer, initargs):
    with _single_threaded_blas(), _children_ignore_sigint():
        pool = ProcessPoolExecutor(
            max_workers=workers or os.cpu_count() or 1,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_start_worker,
            initargs=(os.getpid(), initializer, initargs),
        )
        futures = {pool.submit(run_task, t, records[t.data], detail): t for t in tasks}
    try:
        for fut in as_completed(futures):
            yield futures[fut], _outcome(fut)
    except BaseException:
        # Ctrl-C, SIGTERM, a closed generator: the workers ignore SIGINT, so
        # the parent stops them.
        _stop_workers(pool)
        raise
    pool.shutdown(wait=True)


def execute(
    tasks: list[Task],
    records: dict,
    *,
    engine: str = "dask",
    scheduler: str | None = None,
    workers: int | None = None,
    detail: bool = False,
    initializer: Callable | None = None,
    initargs: tuple = (),
) -> Iterator[tuple[Task, dict | Exception]]:
    """Run `tasks` and yield ``(task, row)`` as each finishes.

    Parameters
    ----------
    tasks : list of Task
    records : dict of str to IOData
        The records the tasks name (see :func:`~spiralid.study.load_records`).
    engine : {"dask", "processes", "local"}
        Where the tasks run (see the module docstring).
    scheduler : str, optional
        Address of a running Dask scheduler (``engine="dask"`` only); by
        default a ``LocalCluster`` is started and stopped.
    workers : int, optional
        Worker processes of the local cluster or pool; default the CPU count.
    detail : bool
        Rows also carry the model object and iteration times (see
        :func:`~spiralid.study.run_task`).
    initializer, initargs : callable and tuple, optional
        Run as ``initializer(*initargs)`` once in every worker process (or
        here, for ``engine="local"``) before any task, e.g. to compile
        kernels so that no task's wall time includes the compilation. The
        process pool and the local cluster's workers run with one BLAS thread
        each (a user's own setting is kept).

    Yields
    ------
    (Task, dict or Exception)
        The row of :func:`~spiralid.study.run_task`, or the exception the run
        raised.
    """
    one_of(engine, "engine", ENGINES)
    if scheduler is not None and engine != "dask":
        raise ValueError("`scheduler` needs engine='dask'")
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise ValueError(f"`workers` must be an integer >= 1; got {workers!r}")
    if not tasks:
        return
    if engine == "dask":
        yield from _execute_dask(
            tasks, records, scheduler, workers, detail, initializer, initargs
        )
    elif engine == "processes" and (workers or os.cpu_count() or 1) > 1:
        yield from _execute_processes(
            tasks, records, workers, detail, initializer, initargs
        )
    else:
        if initializer is not None:
            initializer(*initargs)
        for t in tasks:
            try:
                yield t, run_task(t, records[t.data], detail)
            except Exception as exc:
                yield t, exc


def run_study(
    spec: StudySpec,
    store: str | os.PathLike,
    *,
    engine: str = "dask",
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> StudyRun:
    """Run every task of `spec` not yet in `store`, storing each as it ends.

    Parameters
    ----------
    spec : StudySpec
        From :func:`~spiralid.study.load_spec`.
    store : path-like
        The SQLite file (created if missing). Rerunning the same `spec` on
        the same store resumes: finished runs are neither recomputed nor
        lost.
    engine, scheduler, workers
        See :func:`execute`.
    progress : callable, optional
        ``progress(done, total)`` after each stored run (and once at the
        start, counting the runs the store already held).

    Returns
    -------
    StudyRun
    """
    records = load_records(spec)
    tasks = study_tasks(spec, records)
    with ResultStore.open(store, spec.digest(), spec.source) as db:
        finished = db.keys()
        todo = [t for t in tasks if t.key not in finished]
        reused = len(tasks) - len(todo)
        done = reused
        if progress is not None:
            progress(done, len(tasks))
        outcome = StudyRun(Path(store), len(tasks), reused, 0)
        for task, row in execute(
            todo, records, engine=engine, scheduler=scheduler, workers=workers
        ):
            if isinstance(row, Exception):
                outcome.failures.append((task, " ".join(str(row).split())))
                continue
            db.add(row)
            outcome.computed += 1
            done += 1
            if progress is not None:
                progress(done, len(tasks))
        _store_modes(spec, db, outcome)
    return outcome


def _store_modes(spec: StudySpec, db: ResultStore, outcome: StudyRun) -> None:
    """Identify and store the modes from every sensor of each rig record
    with ``all_outputs`` that the store does not hold yet.

    Once per record, not per seed, seeded by the first of the study's seeds
    as ``spiralid reproduce --all-outputs`` seeds its fit: another seed can
    end the search in another minimum, but the rig's three modes move by
    less than 0.02 % between them (docs/guide/studies.md), so one fit says
    what they are.
    """
    from .modes import fit_every_sensor, rig_record

    stored = db.modes()
    for d in spec.data:
        if not d.all_outputs:
            continue
        if d.name in stored:
            outcome.modes_reused += 1
            continue
        rig = d.rig()
        record = rig_record(rig, d.settings.get("noise_seed", 0))
        fit = fit_every_sensor(record, spec.fraction, spec.seeds[0], rig)
        db.add_modes(d.name, fit.to_dict())
        outcome.modes_computed += 1
