"""The ``spiralid`` command: simulate the rig, identify, validate, reproduce,
study.

Every subcommand has ``--help``. Bad arguments and bad input end with exit
status 2 and a one-line ``spiralid <command>: error: ...`` message on
standard error, never a traceback. Output directories must be new or empty
unless ``--force``; files are never overwritten without ``--force``.

One module per subcommand, each with ``add_parser(sub)`` (which sets the
subcommand's ``run(args, argv)``); the option groups they share are in
:mod:`spiralid.cli.options`, how the command reports errors, warnings and
interrupts in :mod:`spiralid.cli.errors`.
"""

from __future__ import annotations

import argparse
import signal
import sys
import warnings

from . import identify, reproduce, simulate, study, validate
from .errors import (
    UsageError,
    _on_sigterm,
    _Parser,
    _show_warnings,
    _Terminated,
    _user_message,
)

__all__ = ["build_parser", "main"]

# In the order `spiralid --help` lists them.
_SUBCOMMANDS = (simulate, identify, validate, reproduce, study)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``spiralid`` command."""
    from importlib.metadata import version

    parser = _Parser(
        prog="spiralid",
        description="System identification with spiral dynamic optimisation "
        "(SDA and exponential-based SDA) for flexible structures.",
    )
    parser.add_argument(
        "--version", action="version", version=f"spiralid {version('spiralid')}"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for command in _SUBCOMMANDS:
        command.add_parser(sub)
    return parser


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


def _run(parser, argv: list[str], prefix: str) -> int:
    try:
        args = parser.parse_args(argv)
        _show_warnings(prefix, getattr(args, "quiet", False))
        if args.command is None:
            parser.print_help()
            return 2
        return args.run(args, argv)
    except (UsageError, ValueError, OSError) as exc:
        print(f"{prefix}: error: {_user_message(exc)}", file=sys.stderr)
        return 2
    except _Terminated:
        print(f"{prefix}: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print(f"{prefix}: interrupted", file=sys.stderr)
        return 130
