"""How the command reports: one-line errors, warnings and interrupts."""

from __future__ import annotations

import argparse
import re
import sys
import traceback
import warnings
from pathlib import Path


class UsageError(Exception):
    """A problem with what the user asked for: exit 2 with one line."""


class _Parser(argparse.ArgumentParser):
    """argparse that reports a bad argument in one line, not usage + error,
    and records in ``given`` the destinations of the options the user typed
    (in full or abbreviated), so that one given equal to its default can
    still be refused where it does not apply."""

    def error(self, message: str):  # type: ignore[override]
        raise UsageError(message)

    def parse_known_args(self, args=None, namespace=None):
        parsed, extras = super().parse_known_args(args, namespace)
        if namespace is None and args is not None and "given" not in vars(parsed):
            # argparse fills in a default only where the namespace has no
            # value yet: parsed again over a namespace holding a marker in
            # every destination, what still holds the marker was not given.
            marked = argparse.Namespace(**dict.fromkeys(vars(parsed), _NOT_GIVEN))
            super().parse_known_args(args, marked)
            parsed.given = frozenset(
                k for k, v in vars(marked).items() if v is not _NOT_GIVEN
            )
        return parsed, extras


_NOT_GIVEN = object()


_PACKAGE = Path(__file__).resolve().parents[1]


def is_user_error(exc: BaseException) -> bool:
    """Whether `exc` is about what the user asked for (exit 2, one line)
    rather than a bug in spiralid (exit 1).

    A usage error, an operating-system error (a missing file, a full disk,
    a permission) and a ``ValueError`` raised by spiralid's own checks are
    the user's, and so is a ``TypeError`` of those checks (a message that
    starts with the argument's name in backticks, which Python's own
    TypeErrors never do); a ``ValueError`` raised from inside another
    library means an input got past our checks, and any other exception is
    a bug."""
    if isinstance(exc, UsageError | OSError):
        return True
    named = isinstance(exc, TypeError) and str(exc).startswith("`")
    if not (isinstance(exc, ValueError) or named):
        return False
    tb = exc.__traceback__
    if tb is None:
        return True
    while tb.tb_next is not None:
        tb = tb.tb_next
    return Path(tb.tb_frame.f_code.co_filename).resolve().is_relative_to(_PACKAGE)


def report_bug(prefix: str, exc: BaseException, debug: bool) -> None:
    """One line saying that `exc` is a bug and how to report it; the
    traceback first with ``--debug``."""
    if debug:
        traceback.print_exception(exc, file=sys.stderr)
    what = " ".join(f"{type(exc).__name__}: {exc}".split())
    how = (
        "please report it with the command you ran and this traceback"
        if debug
        else "please report it with the command you ran and the output of "
        "`spiralid --debug` with the same arguments"
    )
    print(
        f"{prefix}: internal error (a bug in spiralid, not in what you asked "
        f"for): {what}; {how}",
        file=sys.stderr,
    )


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that partial output is cleaned up."""


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
    "integrator": "--integrator",
    "na": "--na",
    "nb": "--nb",
    "nk": "--nk",
    "n_points": "--points",
    "max_iter": "--iterations",
    "max_nfev": "--budget",
    "rng": "--seed",
    "duration": "--duration",
    "fs": "--fs",
    "lags": "the number of residual-test lags (25)",
    "orders": "--orders",
    "objectives": "--objectives",
    "extremes_nfev": "--polish",
    "min_coherence": "--min-coherence",
}


def _user_message(exc: BaseException) -> str:
    """One line in the command line's words, without NumPy scalar reprs.

    Only the message's own words are rewritten, never what it quotes from
    the user (a CSV cell, a file name)."""
    text = " ".join(str(exc).split())
    parts = re.split(r"""('[^']*'|"[^"]*")""", text)
    return "".join(
        part if i % 2 else _in_user_words(part) for i, part in enumerate(parts)
    )


def _in_user_words(text: str) -> str:
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
        from spiralid.outputs.progress import before_message

        before_message()  # a line of its own, not after a progress line
        print(f"{prefix}: warning: {_user_message(message)}", file=sys.stderr)

    warnings.showwarning = show
