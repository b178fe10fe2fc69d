"""The ``spiralid`` command: simulate the rig, identify, validate, reproduce.

Every subcommand has ``--help``. Bad arguments and bad input end with exit
status 2 and a one-line ``spiralid <command>: error: ...`` message on
standard error, never a traceback. Output directories must be new or empty
unless ``--force``; files are never overwritten without ``--force``.
"""

from __future__ import annotations

import argparse
import json
import re
import shlex
import signal
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

__all__ = ["main"]


class UsageError(Exception):
    """A problem with what the user asked for: exit 2 with one line."""


class _Parser(argparse.ArgumentParser):
    """argparse that reports a bad argument in one line, not usage + error."""

    def error(self, message: str):  # type: ignore[override]
        raise UsageError(message)


class _HelpFormatter(argparse.HelpFormatter):
    """--help shows the default of every option that has one."""

    def _get_help_string(self, action):
        text = action.help or ""
        if (
            "%(default)" in text
            or not action.option_strings
            or action.default is None
            or action.default is False
            or action.default is argparse.SUPPRESS
        ):
            return text
        return f"{text} (default: %(default)s)"


# -- helpers ------------------------------------------------------------------


def _column(value: str) -> str | int:
    """A column given by name, or by 0-based index when it is all digits."""
    return int(value) if value.isdigit() else value


def _number(kind: type, allowed: str, ok):
    """An argparse type: `kind` parsed from text, accepted when `ok` holds."""

    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            what = (
                "an integer"
                if kind is int
                else "a number such as 0.5 or 2/3"
                if kind is _ratio
                else "a number"
            )
            raise argparse.ArgumentTypeError(f"must be {what}; got {text!r}") from None
        if not (np.isfinite(value) and ok(value)):
            raise argparse.ArgumentTypeError(f"must be {allowed}; got {text!r}")
        return value

    return parse


_positive_float = _number(float, "a positive number", lambda v: v > 0)
_nonneg_int = _number(int, ">= 0", lambda v: v >= 0)
_positive_int = _number(int, ">= 1", lambda v: v >= 1)


def _ratio(text: str) -> float:
    """A number, or a quotient such as ``2/3`` (the README's split)."""
    top, slash, bottom = text.partition("/")
    if not slash:
        return float(text)
    try:
        return float(top) / float(bottom)
    except ZeroDivisionError:
        raise ValueError(text) from None


_fraction = _number(_ratio, "in (0, 1), e.g. 0.5 or 2/3", lambda v: 0 < v < 1)


def _add_initial_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--initial",
        choices=["rest", "measured"],
        default="rest",
        help="initial condition of the simulation error: 'rest' (the paper's free "
        "run; records that start at rest) or 'measured' (start from the "
        "first measured samples; records that start in motion)",
    )


def _add_data_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--input",
        type=_column,
        default=None,
        help="input column (CSV name or 0-based index) or variable (NPZ/MAT); "
        "default 'u', or 'torque_Nm' in files written by `spiralid simulate`",
    )
    p.add_argument(
        "--output",
        type=_column,
        default=None,
        help="output column or variable; default 'y', or "
        "'end_acceleration_m_s2' in files written by `spiralid simulate`",
    )
    p.add_argument(
        "--ts",
        type=_positive_float,
        default=None,
        help="sample time in seconds (CSV: required unless a time_s column is "
        "present; NPZ/MAT: default the file's 'ts')",
    )
    p.add_argument(
        "--input-unit",
        default=None,
        help="unit of the input for figures and tables, e.g. 'N m' (default: "
        "from a CSV header such as 'torque [N m]')",
    )
    p.add_argument(
        "--output-unit",
        default=None,
        help="unit of the output, e.g. 'm/s^2' (default: from the CSV header)",
    )


def _add_detrend_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--detrend",
        action="store_true",
        help="remove the means of input and output (those of the estimation "
        "part, or of the part before --fraction, from the whole record) first",
    )


def _load_data(args, default_ts: float | None = None):
    """The record the options describe, with the units they give."""
    data = _load(args.data, args.input, args.output, args.ts, default_ts)
    units = {
        k: v
        for k, v in (("input_unit", args.input_unit), ("output_unit", args.output_unit))
        if v is not None
    }
    return replace(data, **units) if units else data


def _detrended(data, fraction: float | None):
    """`data` less the means of its part before `fraction` (all of it if None):
    the validation part is shifted by the offsets the model was estimated
    with, as new data would be."""
    reference = data if fraction is None else data.split(fraction)[0]
    return data.detrend(like=reference)


def _load(path: str, input, output, ts, default_ts: float | None = None):
    """Read CSV, NPZ or MAT into IOData, with the defaults of `simulate` files.

    The sample time is `ts` if given, else the file's own (a ``time_s`` CSV
    column, a ``ts`` variable), else `default_ts`.
    """
    from spiralid import datasets
    from spiralid.sysid import IOData

    file = Path(path)
    if not file.exists() and path in datasets.NAMES:
        if (input, output) != (None, None):
            raise UsageError(
                f"--input and --output do not apply to the shipped data set {path!r}"
            )
        return datasets.load(path, ts)
    if not file.exists():
        raise UsageError(
            f"data file {path!r} does not exist (shipped data sets: "
            f"{', '.join(datasets.NAMES)})"
        )
    if not file.is_file():
        raise UsageError(f"data file {path!r} is not a file")
    suffix = file.suffix.lower()
    if suffix == ".csv":
        try:
            with file.open(encoding="utf-8-sig") as fh:
                header = [c.strip() for c in fh.readline().strip().split(",")]
        except UnicodeDecodeError:
            raise UsageError(f"data file {path!r} is not a text CSV file") from None
        written_by_us = "torque_Nm" in header
        if input is None:
            input = "torque_Nm" if written_by_us else "u"
        if output is None:
            output = "end_acceleration_m_s2" if written_by_us else "y"
        ts_file = _csv_sample_time(file, header) if "time_s" in header else None
        if ts is not None and ts_file is not None and not np.isclose(ts, ts_file):
            raise UsageError(
                f"--ts {ts:g} contradicts the time_s column of {path!r} (steps of "
                f"{ts_file:g} s); leave --ts out or correct the file"
            )
        ts = next((t for t in (ts, ts_file, default_ts) if t is not None), None)
        if ts is None:
            raise UsageError(
                f"--ts is required for {path!r}: a CSV file carries no sample "
                "time (or give a 'time_s' column)"
            )
        data = IOData.from_csv(file, input=input, output=output, ts=ts)
        if written_by_us:
            data = replace(
                data,
                input_unit=_UNITS.get(data.input_name, data.input_unit),
                output_unit=_UNITS.get(data.output_name, data.output_unit),
            )
        return data
    if suffix in (".npz", ".mat"):
        if input is None:
            input = "u"
        if output is None:
            output = "y"
        if isinstance(input, int) or isinstance(output, int):
            raise UsageError(
                f"--input/--output must be variable names for {suffix} files"
            )
        loader = IOData.from_npz if suffix == ".npz" else IOData.from_mat
        try:
            return loader(file, input=input, output=output, ts=ts)
        except ValueError:
            if ts is not None or default_ts is None:
                raise
            # The file carries no `ts`: fall back to the caller's default.
            return loader(file, input=input, output=output, ts=default_ts)
    raise UsageError(f"data file {path!r} must end in .csv, .npz or .mat")


# Units of the columns `spiralid simulate` writes (their names carry them).
_UNITS = {
    "torque_Nm": "N m",
    "hub_angle_rad": "rad",
    "hub_velocity_rad_s": "rad/s",
    "end_acceleration_m_s2": "m/s^2",
}


def _csv_sample_time(file: Path, header: list[str]) -> float:
    """The step of an evenly spaced ``time_s`` column."""
    t = np.loadtxt(
        file,
        delimiter=",",
        skiprows=1,
        usecols=[header.index("time_s")],
        encoding="utf-8-sig",
        ndmin=1,
    )
    steps = np.diff(t)
    if t.size < 2 or not np.allclose(steps, steps[0], rtol=1e-6):
        raise UsageError(f"the time_s column of {str(file)!r} is not evenly spaced")
    return float(steps.mean())


def _open_folder(path: str, force: bool):
    """The output folder, locked and proved writable before any computation."""
    from spiralid.report.atomic import OutputFolder

    return OutputFolder(path, force).open()


def _save_figures(figures: dict, folder: Path, prefix: str = "") -> None:
    for name, fig in figures.items():
        fig.savefig(folder / f"{prefix}{name}.png", dpi=110)


def _progress(args, total: int, label: str):
    from spiralid.report.progress import ProgressBar

    return ProgressBar(total, label, enabled=not args.quiet)


# -- subcommands ----------------------------------------------------------------


def _cmd_simulate(args) -> int:
    suffix = Path(args.out).suffix.lower()
    if suffix not in (".csv", ".npz"):
        raise UsageError(f"--out {args.out!r} must end in .csv or .npz")
    from spiralid.report.atomic import OutputFile

    with OutputFile(args.out, args.force) as target:
        rec, rig = _simulate_record(args)
        _write_record(rec, target.path, suffix)
        target.commit()
    if not args.quiet:
        print(
            f"wrote {args.out} ({rec.u.size} samples at {args.fs:g} Hz; rig modes "
            + ", ".join(f"{f:.2f}" for f in rig.modes(3))
            + " Hz)"
        )
    return 0


def _simulate_record(args):
    from spiralid.fms import (
        Experiment,
        FlexibleManipulator,
        Sensors,
        bang_bang,
        chirp,
        prbs,
    )

    rig = FlexibleManipulator(payload_mass=args.payload)
    fs = args.fs
    paper = Experiment()
    if args.signal == "paper":
        # One pulse per period, as many as the duration holds (even count: the
        # hub returns to where it started).
        n_pulses = max(2 * int(args.duration // (2 * paper.period)), 1)
        exp = Experiment(
            amplitude=paper.amplitude if args.amplitude is None else args.amplitude,
            width=paper.width if args.width is None else args.width,
            duration=args.duration,
            fs=fs,
            n_pulses=n_pulses,
        )
        torque = exp.torque()
    elif args.signal == "bang-bang":
        amp = paper.amplitude if args.amplitude is None else args.amplitude
        width = paper.width if args.width is None else args.width
        torque = bang_bang(amp, width, paper.start, args.duration, fs)
    elif args.signal == "prbs":
        amp = 0.1 if args.amplitude is None else args.amplitude
        torque = prbs(amp, args.duration, fs)
    else:
        amp = 0.1 if args.amplitude is None else args.amplitude
        torque = chirp(amp, 1.0, min(100.0, fs / 2), args.duration, fs)
    sensors = Sensors(accel_noise=args.accel_noise, tach_noise=args.tach_noise)
    rec = rig.simulate(torque, fs=fs, rng=args.seed, sensors=sensors)
    return rec, rig


def _write_record(rec, path: Path, suffix: str) -> None:
    columns = {
        "time_s": rec.t,
        "torque_Nm": rec.u,
        "hub_angle_rad": rec.hub_angle,
        "hub_velocity_rad_s": rec.hub_velocity,
        "end_acceleration_m_s2": rec.end_acceleration,
    }
    if suffix == ".npz":
        np.savez(
            path,
            ts=np.float64(rec.ts),
            u=rec.u,
            y=rec.end_acceleration,
            **columns,
        )
    else:
        np.savetxt(
            path,
            np.column_stack(list(columns.values())),
            delimiter=",",
            header=",".join(columns),
            comments="",
            fmt="%.10g",
        )


def _structure(args):
    from spiralid.sysid import ARX

    return ARX(args.na, args.nb, args.nk)


def _cmd_identify(args) -> int:
    from spiralid.sysid import METHODS, identify, validate
    from spiralid.sysid.plots import plot_convergence

    data = _load_data(args)
    if args.detrend:
        data = _detrended(data, args.fraction)
    arx = _structure(args)
    est, val = data.split(args.fraction)
    arx.check_length(est, "estimation part of DATA")
    options = {}
    if METHODS[args.method].search:
        # The budget rule is identify()'s (estimators.search_options).
        options = {"n_points": args.points, "max_nfev": args.budget}
        if args.iterations is not None:
            options["max_iter"] = args.iterations
    elif args.refine:
        searches = ", ".join(name for name, m in METHODS.items() if m.search)
        raise UsageError(f"--refine applies to the search methods {searches}")
    with _open_folder(args.out, args.force) as folder:
        model = identify(
            est,
            arx,
            method=args.method,
            predictor=args.predictor,
            initial=args.initial,
            parametrization=args.parametrization,
            refine=args.refine,
            rng=args.seed,
            **options,
        )
        v_est = validate(model, est, label=f"{args.method} (estimation)")
        v_val = validate(model, val, warmup=est, label=f"{args.method} (validation)")
        staged = folder.path
        (staged / "model.json").write_text(json.dumps(model.to_dict(), indent=2))
        (staged / "validation.json").write_text(
            json.dumps(
                {"estimation": v_est.to_dict(), "validation": v_val.to_dict()},
                indent=2,
            )
        )
        summary = "\n\n".join(
            [
                f"{arx} by {args.method} on {args.data}: H(z) = {model.tf_string()}",
                f"estimation cost (eq. 2): {model.cost:.6g}",
                v_est.summary(),
                v_val.summary(),
            ]
        )
        (staged / "summary.txt").write_text(summary + "\n")
        _save_figures(v_val.plot(), staged, "validation_")
        _save_figures(v_est.plot(), staged, "estimation_")
        if model.history is not None:
            plot_convergence(
                {args.method: model.history},
                cost_label="best cost, eq. (2) (% of rms(y))",
            ).savefig(staged / "convergence.png", dpi=110)
        written = folder.commit(last="model.json")
    if not args.quiet:
        print(summary)
        print(f"\nwrote {_listing(written, args.out)}")
    return 0


def _listing(paths: list[Path], out: str) -> str:
    """'a, b and c in OUT' for the files a command wrote."""
    names = [p.name for p in paths]
    head = ", ".join(names[:-1])
    return f"{head + ' and ' if head else ''}{names[-1]} in {out}"


def _cmd_validate(args) -> int:
    from spiralid.sysid import IdentifiedModel, validate

    path = Path(args.model)
    if not path.is_file():
        raise UsageError(f"model file {args.model!r} does not exist")
    try:
        model = IdentifiedModel.from_dict(json.loads(path.read_text()))
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        message = " ".join(str(exc).split())
        raise UsageError(
            f"{args.model!r} is not a valid spiralid model file ({message})"
        ) from None
    # The data's own sample time wins; validate() refuses one that differs
    # from the model's. Only a file without one borrows the model's.
    data = _load_data(args, default_ts=model.ts)
    if args.detrend:
        data = _detrended(data, args.fraction)
    if args.fraction is not None:
        warm, data = data.split(args.fraction)
    else:
        warm = None
    if args.out is None:
        v = validate(model, data, warmup=warm, label=model.method)
        if not args.quiet:
            print(v.summary())
        return 0
    with _open_folder(args.out, args.force) as folder:
        v = validate(model, data, warmup=warm, label=model.method)
        (folder.path / "validation.json").write_text(json.dumps(v.to_dict(), indent=2))
        (folder.path / "summary.txt").write_text(v.summary() + "\n")
        _save_figures(v.plot(), folder.path)
        written = folder.commit(last="validation.json")
    if not args.quiet:
        print(v.summary())
        print(f"\nwrote {_listing(written, args.out)}")
    return 0


def _cmd_reproduce(args, argv: list[str]) -> int:
    from spiralid import datasets
    from spiralid.report import reproduce, summary_text, write_reproduction

    data = source = None
    if args.data is not None:
        data = _load_data(args)
        source = (
            {"kind": "shipped data set", "name": args.data}
            if not Path(args.data).exists() and args.data in datasets.NAMES
            else {"kind": "user data", "path": str(Path(args.data).resolve())}
        )
    elif (args.input, args.output, args.ts, args.input_unit, args.output_unit) != (
        (None,) * 5
    ):
        raise UsageError(
            "--input, --output, --ts and the units describe --data; give --data too"
        )
    with _open_folder(args.out, args.force) as folder:
        bar = _progress(args, 1, "reproduce")
        try:
            rep = reproduce(
                data,
                seeds=range(args.first_seed, args.first_seed + args.seeds),
                max_nfev=args.budget,
                n_points=args.points,
                initial=args.initial,
                source=source,
                workers=args.workers,
                progress=bar,
            )
        finally:
            bar.close()
        command = "spiralid " + shlex.join(argv)
        write_reproduction(rep, folder, command=command)
    if not args.quiet:
        print(summary_text(rep))
        print(f"\nwrote figures, results.json and report.html in {args.out}")
    return 0


def _dask_missing() -> bool:
    from importlib.util import find_spec

    return find_spec("distributed") is None


def _cmd_study(args, argv: list[str]) -> int:
    from spiralid.study import DEFAULT_SPEC, load_spec, run_study

    if args.show_default:
        print(DEFAULT_SPEC.read_text(encoding="utf-8"), end="")
        return 0
    spec = load_spec(args.spec)
    out = Path(args.out)
    store = Path(args.store) if args.store is not None else out / STUDY_STORE
    _check_study_dir(out, store, args.force)
    if args.engine == "dask" and _dask_missing():
        raise UsageError(
            "the study command runs on Dask: pip install 'spiralid[study]' "
            "(or pass --engine processes)"
        )
    if args.scheduler is not None and args.engine != "dask":
        raise UsageError("--scheduler needs --engine dask")
    bar = _progress(args, 1, "study")
    try:
        run = run_study(
            spec,
            store,
            engine=args.engine,
            scheduler=args.scheduler,
            workers=args.workers,
            progress=bar,
        )
    finally:
        bar.close()
    if not args.quiet:
        print(
            f"{run.total} runs: {run.reused} already in {store}, "
            f"{run.computed} computed now, {len(run.failures)} failed"
        )
    if not args.no_report:
        _study_report(store, out, args, argv)
    if run.failures:
        task, message = run.failures[0]
        raise UsageError(
            f"{len(run.failures)} runs failed and were not stored (rerun to retry); "
            f"first: {task.label} on {task.data}, {task.predictor}, seed "
            f"{task.seed}: {message}"
        )
    return 0


def _study_report(store: Path, out: Path, args, argv: list[str]) -> None:
    from spiralid.report.study_output import study_summary, write_study_report
    from spiralid.study import ResultStore, analyse, parse_spec

    with ResultStore.open(store, readonly=True) as db:
        rows, spec_text = db.rows(), db.meta().get("spec", "")
    res = analyse(rows, parse_spec(spec_text, where=f"the specification in {store}"))
    written = write_study_report(
        res,
        out,
        spec_text=spec_text,
        force=True,
        command="spiralid " + shlex.join(argv),
    )
    if not args.quiet:
        print(study_summary(res))
        print(f"\nwrote {', '.join(p.name for p in written)} in {out}")


def _cmd_study_report(args, argv: list[str]) -> int:
    store = Path(args.store)
    if not store.is_file():
        raise UsageError(f"store {args.store!r} does not exist")
    out = Path(args.out) if args.out is not None else store.parent
    _check_study_dir(out, store, args.force)
    _study_report(store, out, args, argv)
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
    own = {*STUDY_FILES, store.name, store.name + ".lock"}
    foreign = sorted(p.name for p in out.iterdir() if p.name not in own)
    if foreign:
        raise UsageError(
            f"--out {str(out)!r} holds files that are not this study's "
            f"({', '.join(foreign[:3])}); choose another or pass --force"
        )


# -- the parser -------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``spiralid`` command."""
    from spiralid.sysid.estimators import DEFAULT_METHOD, METHODS
    from spiralid.sysid.parametrizations import (
        PARAMETRIZATIONS,
    )

    parser = _Parser(
        prog="spiralid",
        description="System identification with spiral dynamic optimisation "
        "(SDA and exponential-based SDA) for flexible structures.",
    )
    from importlib.metadata import version

    parser.add_argument(
        "--version", action="version", version=f"spiralid {version('spiralid')}"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser(
        "simulate",
        formatter_class=_HelpFormatter,
        help="simulate the flexible manipulator rig and write a CSV or NPZ",
        description="Drive the finite-element flexible manipulator rig with a "
        "torque signal and write time, torque, hub angle, hub velocity and "
        "end-point acceleration (CSV header carries the units).",
    )
    p.add_argument(
        "--signal",
        choices=["paper", "bang-bang", "prbs", "chirp"],
        default="paper",
        help="torque input: 'paper' is the reproduction's train of bang-bang "
        "pulses (one per second), 'bang-bang' a single pulse pair (default paper)",
    )
    p.add_argument(
        "--amplitude", type=float, default=None, help="torque (N m); default 0.3"
    )
    p.add_argument(
        "--width",
        type=_positive_float,
        default=None,
        help="bang-bang pulse width (s); default 0.04",
    )
    p.add_argument(
        "--duration", type=_positive_float, default=6.0, help="record length (s)"
    )
    p.add_argument("--fs", type=_positive_float, default=500.0, help="sample rate (Hz)")
    p.add_argument("--payload", type=float, default=0.0, help="tip payload (kg)")
    p.add_argument(
        "--accel-noise", type=float, default=1.0, help="accelerometer noise std (m/s^2)"
    )
    p.add_argument(
        "--tach-noise", type=float, default=0.01, help="tachometer noise std (rad/s)"
    )
    p.add_argument("--seed", type=_nonneg_int, default=0, help="noise seed")
    p.add_argument("--out", default="rig.csv", help="output file, .csv or .npz")
    p.add_argument("--force", action="store_true", help="overwrite --out")
    p.add_argument("--quiet", action="store_true", help="print nothing")

    p = sub.add_parser(
        "identify",
        formatter_class=_HelpFormatter,
        help="identify an ARX model from a data file",
        description="Estimate an ARX model on the first --fraction of DATA and "
        "validate it on the rest; write model.json, validation.json, "
        "summary.txt and figures into --out.",
    )
    p.add_argument(
        "data", help="CSV, NPZ or MAT file, or 'robot_arm' (the shipped DaISy arm)"
    )
    _add_data_options(p)
    p.add_argument("--na", type=_nonneg_int, default=8, help="poles")
    p.add_argument("--nb", type=_positive_int, default=8, help="numerator terms")
    p.add_argument("--nk", type=_nonneg_int, default=0, help="input delay (samples)")
    p.add_argument(
        "--method",
        choices=list(METHODS),
        default=DEFAULT_METHOD,
        help="estimator: a search over the paper's cost, least squares or output error",
    )
    p.add_argument(
        "--predictor",
        choices=["simulation", "one-step"],
        default="simulation",
        help="error of the cost: free-run simulation or one-step prediction",
    )
    p.add_argument(
        "--parametrization",
        choices=list(PARAMETRIZATIONS),
        default=None,
        help="what a search moves: the ARX coefficients (the paper), the "
        "denominator's reflection coefficients or modal frequencies and dampings "
        "(every candidate stable); default the method's own (modal for spiral)",
    )
    _add_initial_option(p)
    _add_detrend_option(p)
    p.add_argument(
        "--refine", action="store_true", help="polish a spiral result locally"
    )
    p.add_argument("--points", type=_positive_int, default=50, help="search points")
    p.add_argument(
        "--iterations",
        type=_positive_int,
        default=None,
        help="max iterations (default 500, or no cap below --budget)",
    )
    p.add_argument(
        "--budget", type=_positive_int, default=None, help="max cost evaluations"
    )
    p.add_argument("--seed", type=_nonneg_int, default=0, help="seed of the search")
    p.add_argument(
        "--fraction",
        type=_fraction,
        default="2/3",
        help="share of the record that estimates; the rest validates",
    )
    p.add_argument("--out", default="spiralid-identify", help="output directory")
    p.add_argument("--force", action="store_true", help="write into a non-empty --out")
    p.add_argument("--quiet", action="store_true", help="print nothing")

    p = sub.add_parser(
        "validate",
        formatter_class=_HelpFormatter,
        help="validate a saved model on a data file",
        description="Fit %, error range, residual tests, spectra, modes, "
        "stability and realisation tests of MODEL on DATA.",
    )
    p.add_argument("model", help="model.json written by `spiralid identify`")
    p.add_argument(
        "data", help="CSV, NPZ or MAT file, or 'robot_arm' (the shipped DaISy arm)"
    )
    _add_data_options(p)
    p.add_argument(
        "--fraction",
        type=_fraction,
        default=None,
        help="run the model over the whole record but score only the part after "
        "this share (e.g. 2/3 for the validation third); default: score all",
    )
    _add_detrend_option(p)
    p.add_argument(
        "--out", default=None, help="directory for validation.json and figures"
    )
    p.add_argument("--force", action="store_true", help="write into a non-empty --out")
    p.add_argument("--quiet", action="store_true", help="print nothing")

    p = sub.add_parser(
        "reproduce",
        formatter_class=_HelpFormatter,
        help="the paper's SDA vs Eb-SDA experiment with baselines and statistics",
        description="Identify ARX(8, 8, 0) by SDA and Eb-SDA (paper-faithful and "
        "reflection parametrisations, refine, gain sensitivity) over several "
        "seeds at an equal budget, beside least squares and output error; write "
        "Table-2, Figures 6-7, results.json and report.html into --out.",
    )
    p.add_argument("--seeds", type=_positive_int, default=6, help="number of seeds")
    p.add_argument("--first-seed", type=_nonneg_int, default=0, help="first seed")
    p.add_argument(
        "--budget", type=_positive_int, default=20_000, help="cost evaluations per run"
    )
    p.add_argument("--points", type=_positive_int, default=50, help="search points")
    p.add_argument(
        "--workers",
        type=_positive_int,
        default=None,
        help="processes (default: one per core)",
    )
    p.add_argument(
        "--data",
        default=None,
        help="your own CSV/NPZ/MAT record, or 'robot_arm' (the shipped DaISy arm)",
    )
    _add_data_options(p)
    _add_initial_option(p)
    p.add_argument("--out", default="spiralid-reproduce", help="output directory")
    p.add_argument("--force", action="store_true", help="write into a non-empty --out")
    p.add_argument("--quiet", action="store_true", help="no progress bar or summary")

    p = sub.add_parser(
        "study",
        help="a study over every reading of the paper's cost, on Dask, resumable",
        description="Run every optimiser of SPEC (a TOML file; default the "
        "paper's grid) on every reading (record x predictor x parametrisation) "
        "and seed, on a Dask cluster; each finished run is committed to a SQLite "
        "store, so rerunning the same command after an interruption computes "
        "only what is missing. Then write the 'where the claim holds' report.",
    )
    p.add_argument("spec", nargs="?", default=None, help="study specification (TOML)")
    p.add_argument(
        "--show-default",
        action="store_true",
        help="print the default specification (the paper's grid) and exit",
    )
    p.add_argument("--out", default="spiralid-study", help="output directory")
    p.add_argument(
        "--store",
        default=None,
        help=f"SQLite result store (default OUT/{STUDY_STORE})",
    )
    p.add_argument(
        "--engine",
        choices=["dask", "processes", "local"],
        default="dask",
        help="where runs execute: a Dask cluster (default), a process pool, or "
        "this process",
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
    p.add_argument(
        "--force", action="store_true", help="write into an --out with other files"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar or summary")

    p = sub.add_parser(
        "study-report",
        help="the report of a study's store",
        description="Analyse a study's SQLite store: per reading, Eb-SDA "
        "against SDA (rank-sum test, A12, Holm correction), convergence bands, "
        "results.json and report.html.",
    )
    p.add_argument("store", help="SQLite store written by `spiralid study`")
    p.add_argument(
        "--out", default=None, help="output directory (default: the store's folder)"
    )
    p.add_argument(
        "--force", action="store_true", help="write into an --out with other files"
    )
    p.add_argument("--quiet", action="store_true", help="print nothing")
    return parser


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that partial output is cleaned up."""


def _on_sigterm(signum, frame):
    raise _Terminated


def main(argv: list[str] | None = None) -> int:
    """Run the ``spiralid`` command; return its exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    command = argv[0] if argv and not argv[0].startswith("-") else None
    prefix = f"spiralid {command}" if command else "spiralid"
    try:
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    except ValueError:  # not the main thread: leave SIGTERM alone
        previous = None
    try:
        with warnings.catch_warnings():
            return _run(parser, argv, prefix)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


# Library messages name arguments as the code does (in backticks); the
# command line says them as the user typed them.
_USER_WORDS = {
    "data": "the data",
    "path": "DATA",
    "u": "the input",
    "y": "the output",
    "ts": "--ts",
    "input": "--input",
    "output": "--output",
    "fraction": "--fraction",
    "na": "--na",
    "nb": "--nb",
    "nk": "--nk",
    "n_points": "--points",
    "max_iter": "--iterations",
    "max_nfev": "--budget",
    "rng": "--seed",
    "lags": "the number of residual-test lags (25)",
}


def _user_message(exc: BaseException) -> str:
    """One line in the command line's words, without NumPy scalar reprs."""
    text = " ".join(str(exc).split())
    text = re.sub(r"np\.(?:float|int|uint|bool_?)\d*\(([^()]*)\)", r"\1", text)
    text = re.sub(r"`([^`]+)`", lambda m: _USER_WORDS.get(m[1], m[1]), text)
    # Bare keyword names, as in "must be >= 2 * n_points".
    return re.sub(
        r"\b(n_points|max_iter|max_nfev)\b", lambda m: _USER_WORDS[m[1]], text
    )


def _show_warnings(prefix: str, quiet: bool) -> None:
    """Warnings as one line each, once; none at all with --quiet."""
    if quiet:
        warnings.simplefilter("ignore")
        return
    warnings.simplefilter("once")

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"{prefix}: warning: {_user_message(message)}", file=sys.stderr)

    warnings.showwarning = show


def _run(parser, argv: list[str], prefix: str) -> int:
    try:
        args = parser.parse_args(argv)
        _show_warnings(prefix, getattr(args, "quiet", False))
        if args.command is None:
            parser.print_help()
            return 2
        if args.command == "simulate":
            return _cmd_simulate(args)
        if args.command == "identify":
            return _cmd_identify(args)
        if args.command == "validate":
            return _cmd_validate(args)
        if args.command == "study":
            return _cmd_study(args, argv)
        if args.command == "study-report":
            return _cmd_study_report(args, argv)
        return _cmd_reproduce(args, argv)
    except (UsageError, ValueError, OSError) as exc:
        print(f"{prefix}: error: {_user_message(exc)}", file=sys.stderr)
        return 2
    except _Terminated:
        print(f"{prefix}: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print(f"{prefix}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
