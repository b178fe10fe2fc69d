"""Option groups and argument types shared by the subcommands, and loading
the record the options describe."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Collection, Sequence
from dataclasses import replace
from pathlib import Path

from .errors import UsageError


class _HelpFormatter(argparse.HelpFormatter):
    """--help shows the default of every option that has one."""

    def _get_help_string(self, action):
        text = action.help or ""
        if (
            "%(default)" in text
            or "(default:" in text  # said in its own words
            or not action.option_strings
            or action.default is None
            or action.default is False
            or action.default is argparse.SUPPRESS
        ):
            return text
        return f"{text} (default: %(default)s)"


def _given(args, *flags: str) -> list[str]:
    """Those of `flags` the user typed (in full or abbreviated), in the
    order listed; one equal to its default counts (see ``_Parser``)."""
    given = getattr(args, "given", frozenset())
    return [f for f in flags if f.removeprefix("--").replace("-", "_") in given]


def _refuse_unused(flags: list[str], where: str) -> None:
    """Refuse options that would be ignored without a word: '--a, --b apply
    `where`' (e.g. "to --model narx, not to --model arx")."""
    if flags:
        verb = "applies" if len(flags) == 1 else "apply"
        raise UsageError(f"{', '.join(flags)} {verb} {where}")


def _refuse_inapplicable(
    flags: list[str], table: dict[str, str], takes: Collection[str], where: str
) -> None:
    """Refuse `flags`, which do not apply to `where` (e.g. "--method ls"),
    naming the options that do: those of `table` (flag -> the library's
    option name) whose names are in `takes`."""
    if flags:
        able = [f for f, name in table.items() if name in takes]
        verb = "does" if len(flags) == 1 else "do"
        raise UsageError(
            f"{', '.join(flags)} {verb} not apply to {where}; "
            f"the options that do: {', '.join(able)}"
        )


def _column(value: str) -> str | int:
    """A column given by name, or by 0-based index when it is all digits."""
    return int(value) if value.isdigit() else value


def _columns(value: str) -> str | int | list:
    """--output: one column, or several separated by commas (a record of
    several outputs)."""
    parts = [v.strip() for v in value.split(",")]
    return _column(parts[0]) if len(parts) == 1 else [_column(v) for v in parts]


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
    """A number, or a quotient such as ``2/3`` (the paper's split)."""
    top, slash, bottom = text.partition("/")
    if not slash:
        return float(text)
    try:
        return float(top) / float(bottom)
    except ZeroDivisionError:
        raise ValueError(text) from None


_fraction = _number(_ratio, "in (0, 1), e.g. 0.5 or 2/3", lambda v: 0 < v < 1)


def _interval(low: float, high: float) -> Callable[[str], float]:
    """An argparse type: a number in [`low`, `high`), with one message for
    text that is not a number and for a number outside."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not low <= value < high:
            raise argparse.ArgumentTypeError(
                f"must be a number in [{low:g}, {high:g}); got {text!r}"
            )
        return value

    return parse


def _orders(text: str) -> list[int]:
    """``2:12`` (both ends included) or ``2,4,8``: orders, lags or sizes,
    distinct integers >= 1 (``8`` is one)."""
    try:
        if ":" in text:
            lo, hi = (int(v) for v in text.split(":"))
            values = list(range(lo, hi + 1))
        else:
            values = [int(v) for v in text.split(",")]
    except ValueError:
        values = []
    if not values or min(values) < 1 or len(set(values)) != len(values):
        raise argparse.ArgumentTypeError(
            f"must be integers >= 1 such as 8, 2:12 or 2,4,8 (distinct, increasing "
            f"ranges); got {text!r}"
        )
    return values


# -- the options several subcommands share, each defined here once -----------
# Functions, not argparse parents: a parent's options come first in --help,
# while each subcommand lists the shared ones among its own.

_DATA_HELP = "CSV, NPZ or MAT file, or 'robot_arm' (the shipped DaISy arm)"
_NON_EMPTY = "write into a non-empty --out"


def _command(
    sub: argparse._SubParsersAction,
    name: str,
    summary: str,
    description: str,
    run: Callable[[argparse.Namespace, list[str]], int],
    formatter: type[argparse.HelpFormatter] = _HelpFormatter,
) -> argparse.ArgumentParser:
    """The parser of subcommand `name`, which runs `run(args, argv)`;
    `summary` is its line in ``spiralid --help``."""
    p = sub.add_parser(
        name, formatter_class=formatter, help=summary, description=description
    )
    p.set_defaults(run=run)
    return p


def _add_order_options(p: argparse.ArgumentParser) -> None:
    """--na, --nb, --nk: the ARX orders and the input delay."""
    p.add_argument("--na", type=_nonneg_int, default=8, help="poles")
    p.add_argument("--nb", type=_positive_int, default=8, help="numerator terms")
    p.add_argument("--nk", type=_nonneg_int, default=0, help="input delay (samples)")


def _add_points_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--points", type=_positive_int, default=50, help="search points")


def _add_seed_option(
    p: argparse.ArgumentParser, help: str = "seed of the search"
) -> None:
    p.add_argument("--seed", type=_nonneg_int, default=0, help=help)


def _add_fraction_option(
    p: argparse.ArgumentParser,
    default: str | None = "2/3",
    help: str = "share of the record that estimates; the rest validates",
) -> None:
    p.add_argument("--fraction", type=_fraction, default=default, help=help)


def _add_by_fit_option(p: argparse.ArgumentParser, help: str) -> None:
    """--by-fit POINTS: choose among candidates by their validation fit."""
    p.add_argument(
        "--by-fit", type=_nonneg_float, default=None, metavar="POINTS", help=help
    )


def _add_method_option(
    p: argparse.ArgumentParser, names: Sequence[str], default: str, help: str
) -> None:
    """--method among `names` (case-insensitive)."""
    p.add_argument(
        "--method", type=str.lower, choices=names, default=default, help=help
    )


def _add_parametrization_option(
    p: argparse.ArgumentParser, default: str | None, help: str
) -> None:
    """--parametrization: what a search moves."""
    # Names only: building the parser loads no estimator.
    from spiralid.choices import PARAMETRIZATION_NAMES

    p.add_argument(
        "--parametrization", choices=PARAMETRIZATION_NAMES, default=default, help=help
    )


def _add_out_option(
    p: argparse.ArgumentParser,
    default: str | None,
    help: str = "output directory",
    metavar: str | None = None,
) -> None:
    p.add_argument("--out", default=default, metavar=metavar, help=help)


def _add_force_option(p: argparse.ArgumentParser, help: str = _NON_EMPTY) -> None:
    p.add_argument("--force", action="store_true", help=help)


def _add_quiet_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--quiet",
        action="store_true",
        help="print no progress, summary or warnings (errors still print)",
    )


def _add_output_options(
    p: argparse.ArgumentParser,
    default: str | None,
    help: str = "output directory",
    force: str = _NON_EMPTY,
    metavar: str | None = None,
) -> None:
    """--out (`default`, `help`, `metavar`), --force (`force` its help) and
    --quiet: where a command writes and how much it says."""
    _add_out_option(p, default, help, metavar)
    _add_force_option(p, force)
    _add_quiet_option(p)


def _add_initial_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--initial",
        choices=["rest", "measured"],
        default="rest",
        help="initial condition of the simulation error: 'rest' (the paper's free "
        "run; records that start at rest) or 'measured' (start from the "
        "first measured samples; records that start in motion)",
    )


def _one_column(value: str) -> str | int:
    """--output of a command that models one output."""
    if "," in value:
        raise argparse.ArgumentTypeError(
            f"this command takes one output; got {value!r} (`spiralid identify "
            "--output a,b` fits one model of several outputs)"
        )
    return _column(value)


def _one_input(value: str) -> str | int:
    """--input of a command that models one input."""
    if "," in value:
        raise argparse.ArgumentTypeError(
            f"this command takes one input; got {value!r} (`spiralid identify "
            "--input a,b` fits one model of several inputs)"
        )
    return _column(value)


def _add_data_options(
    p: argparse.ArgumentParser, several_outputs: bool = True, positional: bool = True
) -> None:
    """DATA, --input, --output (several only where the command models
    several), --ts and the units. `positional` False leaves DATA out, for a
    command whose record is an option of its own (``reproduce --data``)."""
    if positional:
        p.add_argument("data", help=_DATA_HELP)
    p.add_argument(
        "--input",
        type=_columns if several_outputs else _one_input,
        default=None,
        help="input column (CSV name or 0-based index) or variable (NPZ/MAT); "
        "default 'u', or 'torque_Nm' in files written by `spiralid simulate`"
        + (
            "; several separated by commas (a,b) for one model of every input"
            if several_outputs
            else ""
        ),
    )
    p.add_argument(
        "--output",
        type=_columns if several_outputs else _one_column,
        default=None,
        help="output column or variable; default 'y', or "
        "'end_acceleration_m_s2' in files written by `spiralid simulate`"
        + (
            "; several separated by commas (a,b,c) for one model of every output"
            if several_outputs
            else ""
        ),
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
    from spiralid.datasets import read_record

    data = read_record(args.data, args.input, args.output, args.ts, default_ts)
    units = {
        k: v
        for k, v in (("input_unit", args.input_unit), ("output_unit", args.output_unit))
        if v is not None
    }
    for key, count in (("output_unit", data.n_outputs), ("input_unit", data.n_inputs)):
        if key in units and count > 1:
            # One unit for every channel, or one each separated by commas.
            given = units[key].split(",")
            units[key] = given[0] if len(given) == 1 else tuple(given)
    return replace(data, **units) if units else data


def _detrended(data, fraction: float | None):
    """`data` less the means of its part before `fraction` (all of it if None):
    the validation part is shifted by the offsets the model was estimated
    with, as new data would be."""
    reference = data if fraction is None else data.split(fraction)[0]
    return data.detrend(like=reference)


def _open_folder(path: str, force: bool):
    """The output folder, locked and proved writable before any computation."""
    from spiralid.outputs.atomic import OutputFolder

    return OutputFolder(path, force).open()


def _save_figures(figures: dict, folder: Path, prefix: str = "") -> None:
    for name, fig in figures.items():
        fig.savefig(folder / f"{prefix}{name}.png", dpi=110)


def _progress(args):
    """The command's progress on standard error (a status line on a
    terminal, a few plain lines in a log; nothing with --quiet), which
    also times its phases for timings.json."""
    from spiralid.outputs.progress import Progress

    return Progress(f"spiralid {args.command}", enabled=not args.quiet)


def _listing(paths: list[Path], out: str) -> str:
    """'a, b and c in OUT' for the files a command wrote."""
    names = [p.name for p in paths]
    head = ", ".join(names[:-1])
    return f"{head + ' and ' if head else ''}{names[-1]} in {out}"
