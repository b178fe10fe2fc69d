"""Option groups and argument types shared by the subcommands, and loading
the record the options describe."""

from __future__ import annotations

import argparse
import math
from dataclasses import replace
from pathlib import Path

from .errors import UsageError


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
        if not (math.isfinite(value) and ok(value)):
            raise argparse.ArgumentTypeError(f"must be {allowed}; got {text!r}")
        return value

    return parse


_positive_float = _number(float, "a positive number", lambda v: v > 0)
_nonneg_float = _number(float, "a number >= 0", lambda v: v >= 0)
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


def _add_detrend_option(p: argparse.ArgumentParser, help_extra: str = "") -> None:
    p.add_argument(
        "--detrend",
        action="store_true",
        help="remove the means of input and output (those of the estimation "
        "part, or of the part before --fraction, from the whole record) first"
        + help_extra,
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
        if (
            ts is not None
            and ts_file is not None
            and not math.isclose(ts, ts_file, rel_tol=1e-5, abs_tol=1e-8)
        ):
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
    import numpy as np

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


def _listing(paths: list[Path], out: str) -> str:
    """'a, b and c in OUT' for the files a command wrote."""
    names = [p.name for p in paths]
    head = ", ".join(names[:-1])
    return f"{head + ' and ' if head else ''}{names[-1]} in {out}"
