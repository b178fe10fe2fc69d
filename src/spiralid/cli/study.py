"""``spiralid study`` and ``spiralid study-report``: studies on Dask."""

from __future__ import annotations

import shlex
from pathlib import Path

from .errors import UsageError
from .options import (
    _add_force_option,
    _add_out_option,
    _add_output_options,
    _add_quiet_option,
    _command,
    _positive_int,
    _progress,
)


def _dask_missing() -> bool:
    from importlib.util import find_spec

    return find_spec("distributed") is None


def _cmd_study(args, argv: list[str]) -> int:
    from spiralid.study import DEFAULT_SPEC, load_spec, run_study

    if args.show_default:
        print(DEFAULT_SPEC.read_text(encoding="utf-8"), end="")
        return 0
    try:
        spec = load_spec(args.spec)
    except ValueError as exc:
        raise _spec_error(exc) from None
    out = Path(args.out)
    store = Path(args.store) if args.store is not None else out / STUDY_STORE
    _check_study_dir(out, store, args.force)
    # What the store's opening creates (the file and the folders above it),
    # removed again if no run finishes.
    fresh = [p for p in (store, *store.parents) if not p.exists()]
    if args.engine == "dask" and _dask_missing():
        raise UsageError(
            "the study command runs on Dask: pip install 'spiralid[study]' "
            "(or pass --engine processes)"
        )
    if args.scheduler is not None and args.engine != "dask":
        raise UsageError("--scheduler needs --engine dask")
    with _progress(args) as progress:
        progress.phase("runs", "running the study", unit="runs")
        run = run_study(
            spec,
            store,
            engine=args.engine,
            scheduler=args.scheduler,
            workers=args.workers,
            progress=progress,
        )
        if run.failures and run.reused + run.computed == 0:
            # Every run failed: a store of no run is no study, and a report
            # of nothing would hide the one thing to say, why they failed.
            _remove_fresh_store(fresh)
            raise _failures_error(run)
        report = None
        if not args.no_report:
            # The failures are the one line to say: no warning of missing runs.
            report = _study_report(
                store, out, args, argv, progress, warn=not run.failures
            )
    if not args.quiet:
        print(
            f"{run.total} runs: {run.reused} already in {store}, "
            f"{run.computed} computed now, {len(run.failures)} failed"
        )
        if run.modes_reused or run.modes_computed:
            print(
                f"modes from every sensor: {run.modes_reused} records already "
                f"in the store, {run.modes_computed} identified now"
            )
        if report is not None:
            print(report)
    if run.failures:
        raise _failures_error(run)
    return 0


def _spec_error(exc: ValueError) -> UsageError:
    """A specification's error in the file's words: the keys it names are
    the TOML file's, quoted as written, not the command's options (its
    `ts` is not --ts)."""
    return UsageError(str(exc).replace("`", "'"))


def _failures_error(run) -> UsageError:
    """How many runs failed, and the first one's reason."""
    task, message = run.failures[0]
    seed = "" if task.seed is None else f", seed {task.seed}"
    return UsageError(
        f"{len(run.failures)} of {run.total} runs failed and were not stored "
        f"(rerun to retry); first: {task.label} on {task.data}, {task.predictor}"
        f"{seed}: {message}"
    )


def _remove_fresh_store(fresh: list[Path]) -> None:
    """Remove a store this command created (with SQLite's companions and its
    lock) and the folders created for it, if they hold nothing else."""
    if not fresh:
        return
    store = fresh[0]
    for suffix in ("", "-journal", "-wal", "-shm", ".lock"):
        store.with_name(store.name + suffix).unlink(missing_ok=True)
    for folder in fresh[1:]:
        try:
            folder.rmdir()
        except OSError:  # not empty: something else is in it now
            break


def _study_report(
    store: Path, out: Path, args, argv: list[str], progress, warn: bool = True
) -> str:
    """Analyse the store and write its report; return what to print (the
    summary and the files written). `warn` says in a warning when runs are
    missing (the report itself always says so)."""
    import warnings

    from spiralid.report.study_output import (
        partial_note,
        study_summary,
        write_study_report,
    )
    from spiralid.study import ResultStore, analyse, parse_spec

    progress.phase("analysis", "analysing the store")
    with ResultStore.open(store, readonly=True) as db:
        rows, spec_text, modes = db.rows(), db.meta().get("spec", ""), db.modes()
    try:
        spec = parse_spec(spec_text, where=f"the specification in {store}")
    except ValueError as exc:
        raise _spec_error(exc) from None
    if not rows:
        raise UsageError(
            f"store {str(store)!r} holds no finished run: its study stopped "
            f"before the first of its {spec.n_runs} runs finished; rerun the "
            "study to compute them"
        )
    res = analyse(rows, spec, modes=modes)
    # Before anything is written, so that a failure here writes nothing.
    summary = study_summary(res)
    note = partial_note(res)
    if warn and note:
        warnings.warn(note, stacklevel=1)
    progress.phase("writing", "writing the report")
    written = write_study_report(
        res,
        out,
        spec_text=spec_text,
        force=True,
        command="spiralid " + shlex.join(argv),
    )
    return f"{summary}\n\nwrote {', '.join(p.name for p in written)} in {out}"


def _cmd_study_report(args, argv: list[str]) -> int:
    store = Path(args.store)
    if store.is_dir():
        inside = store / STUDY_STORE
        hint = (
            f"; give the store in it, {str(inside)!r}"
            if inside.is_file()
            else " (a study's store is its study.sqlite file)"
        )
        raise UsageError(f"store {args.store!r} is a folder, not a store file{hint}")
    if not store.is_file():
        raise UsageError(f"store {args.store!r} does not exist")
    out = Path(args.out) if args.out is not None else store.parent
    _check_study_dir(out, store, args.force)
    with _progress(args) as progress:
        report = _study_report(store, out, args, argv, progress)
    if not args.quiet:
        print(report)
    return 0


STUDY_STORE = "study.sqlite"


def _check_study_dir(out: Path, store: Path, force: bool) -> None:
    """Refuse an output folder holding anything but this study's own files.

    A rerun of a study (to resume it) finds its store and its earlier report
    there: those it may replace; anything else needs --force.
    """
    from spiralid.report.study_output import STUDY_FILES

    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {str(out)!r} is a file, not a directory")
    if not out.is_dir() or force:
        return
    # SQLite's own companions of the store: a study killed inside a
    # transaction leaves its rollback journal, which the rerun replays.
    companions = ("-journal", "-wal", "-shm", ".lock")
    own = {*STUDY_FILES, store.name, *(store.name + c for c in companions)}
    foreign = sorted(p.name for p in out.iterdir() if p.name not in own)
    if foreign:
        raise UsageError(
            f"--out {str(out)!r} holds files that are not this study's "
            f"({', '.join(foreign[:3])}); choose another or pass --force"
        )


# A rerun of a study finds its own files in --out (see _check_study_dir).
_OTHER_FILES = "write into an --out with other files"


_DESCRIPTION = (
    "Run every optimiser of SPEC (a TOML file; default the paper's grid) on "
    "every reading (record x predictor x parametrisation) and seed, on a Dask "
    "cluster; each finished run is committed to a SQLite store, so rerunning "
    "the same command after an interruption computes only what is missing. "
    "Then write the 'where the claim holds' report."
)


_REPORT_DESCRIPTION = (
    "Analyse a study's SQLite store: per reading, Eb-SDA against SDA "
    "(rank-sum test, A12, Holm correction), convergence bands, results.json "
    "and report.html."
)


def add_parser(sub) -> None:
    p = _command(
        sub,
        "study",
        "a study over every reading of the paper's cost, on Dask, resumable",
        _DESCRIPTION,
        _cmd_study,
    )
    p.add_argument(
        "spec",
        nargs="?",
        default=None,
        help="study specification (TOML); default the paper's grid "
        "(--show-default prints it)",
    )
    p.add_argument(
        "--show-default",
        action="store_true",
        help="print the default specification (the paper's grid) and exit",
    )
    _add_out_option(p, "spiralid-study")
    p.add_argument(
        "--store",
        default=None,
        help=f"SQLite result store (default OUT/{STUDY_STORE})",
    )
    p.add_argument(
        "--engine",
        choices=["dask", "processes", "local"],
        default="dask",
        help="where runs execute: a Dask cluster, a process pool, or this process",
    )
    p.add_argument(
        "--scheduler",
        default=None,
        help="address of a running Dask scheduler (default: start a LocalCluster)",
    )
    p.add_argument(
        "--workers",
        type=_positive_int,
        default=None,
        help="worker processes of the local cluster (default: CPU count)",
    )
    p.add_argument("--no-report", action="store_true", help="only run and store")
    _add_force_option(p, _OTHER_FILES)
    _add_quiet_option(p)

    p = _command(
        sub,
        "study-report",
        "the report of a study's store",
        _REPORT_DESCRIPTION,
        _cmd_study_report,
    )
    p.add_argument("store", help="SQLite store written by `spiralid study`")
    _add_output_options(
        p, None, "output directory (default: the store's folder)", _OTHER_FILES
    )
