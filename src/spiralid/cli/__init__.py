"""The ``spiralid`` command: simulate the rig, identify (one model or a
Pareto front), validate, export, reproduce, study.

Every subcommand has ``--help``. Bad arguments and bad input end with exit
status 2 and a one-line ``spiralid <command>: error: ...`` message on
standard error, never a traceback. Anything else is a bug in spiralid: exit
status 1, one line that says so and how to report it, and the traceback
with ``spiralid --debug <command> ...``. Output directories must be new or empty
unless ``--force``; files are never overwritten without ``--force``.

One module per subcommand, each with ``add_parser(sub)`` (which sets the
subcommand's ``run(args, argv)``); the option groups they share are in
:mod:`spiralid.cli.options`, how the command reports errors, warnings and
interrupts in :mod:`spiralid.cli.errors`.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import warnings
from contextlib import contextmanager

from . import export, identify, pareto, reproduce, simulate, study, validate
from .errors import (
    _Parser,
    _show_warnings,
    _Terminated,
    _user_message,
    is_user_error,
    report_bug,
)

__all__ = ["build_parser", "console", "main"]

# In the order `spiralid --help` lists them.
_SUBCOMMANDS = (simulate, identify, pareto, validate, export, reproduce, study)


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
    parser.add_argument(
        "--debug",
        action="store_true",
        help="on an internal error (a bug in spiralid), print its traceback",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for command in _SUBCOMMANDS:
        command.add_parser(sub)
    return parser


def console() -> None:
    """The ``spiralid`` executable: :func:`main`, then exit with its status.

    After an interrupt (status 130 or 143) the one line has been said, and
    what is left is the interpreter's exit, where Dask's atexit hook closes a
    cluster whose coroutines the signal cut short and may print tracebacks;
    standard error is pointed at the null device first, so the cleanup
    still runs and the line stays the only one.

    BLAS runs on one thread unless the user set its variables: the
    command's linear algebra is small (QR factorisations of N x p, p of a
    few dozen), which a threaded BLAS only slows, by 5-7 times on a loaded
    2-core machine. The parser imports no NumPy, so the setting is read when
    the library first loads it.
    """
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(name, "1")
    status = main()
    if status in (130, 143):
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stderr.fileno())
    sys.exit(status)


def main(argv: list[str] | None = None) -> int:
    """Run the ``spiralid`` command; return its exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    command = next((a for a in argv if not a.startswith("-")), None)
    prefix = f"spiralid {command}" if command else "spiralid"
    with _interrupts() as interrupted:
        with warnings.catch_warnings():
            status = _run(argv, prefix, interrupted)
        if interrupted() and status not in (130, 143):
            # Ctrl-C after the work was done (or swallowed on its way up):
            # still one line and the status a shell expects.
            status = _say_interrupted(prefix, interrupted())
    return status


def _say_interrupted(prefix: str, signum: int) -> int:
    """The one line for an interrupt by `signum`, and its exit status."""
    if signum == signal.SIGTERM:
        print(f"{prefix}: terminated", file=sys.stderr)
        return 143
    print(f"{prefix}: interrupted", file=sys.stderr)
    return 130


@contextmanager
def _interrupts():
    """SIGINT raises KeyboardInterrupt, SIGTERM `_Terminated`, and both are
    remembered, so that one arriving at any moment ends in one line and exit
    status 130 (143); the previous handlers come back on leaving. It yields
    a function that returns the first signal received (0 for none)."""
    received: list[int] = []

    def on_signal(signum, frame):
        received.append(signum)
        if signum == signal.SIGTERM:
            raise _Terminated
        raise KeyboardInterrupt

    previous = {}
    for signum in (signal.SIGINT, signal.SIGTERM):
        try:
            if signal.getsignal(signum) == signal.SIG_IGN:
                # Ignored by whoever started us (a background job of a
                # script, nohup): keep it so, as Python itself does.
                continue
            previous[signum] = signal.signal(signum, on_signal)
        except ValueError:  # not the main thread: leave the signals alone
            pass
    try:
        yield lambda: received[0] if received else 0
    finally:
        for signum, handler in previous.items():
            if received:
                # Interrupted and said so: what is left is the interpreter's
                # exit (Dask's atexit closes its cluster), where a late
                # signal would only add a traceback to the one line.
                handler = signal.SIG_IGN
            signal.signal(signum, handler)


def _run(argv: list[str], prefix: str, interrupted=lambda: 0) -> int:
    try:
        # Inside the try: building the parser imports the library, and a
        # Ctrl-C during that import is one line like any other.
        parser = build_parser()
        args = parser.parse_args(argv)
        _show_warnings(prefix, getattr(args, "quiet", False))
        if args.command is None:
            parser.print_help()
            return 2
        return args.run(args, argv)
    except Exception as exc:
        if interrupted():
            # The interrupt landed inside a library's call, which turned it
            # into an error of its own (a compiled kernel's SystemError):
            # it is the interrupt, not a bug nor the user's mistake.
            return _say_interrupted(prefix, interrupted())
        if is_user_error(exc):
            print(f"{prefix}: error: {_user_message(exc)}", file=sys.stderr)
            return 2
        report_bug(prefix, exc, debug="--debug" in argv)
        return 1
    except KeyboardInterrupt as exc:
        terminated = isinstance(exc, _Terminated)
        return _say_interrupted(prefix, signal.SIGTERM if terminated else signal.SIGINT)
