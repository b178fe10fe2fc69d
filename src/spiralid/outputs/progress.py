"""What a long command says on standard error while it works, and how long
each of its phases took; dependency-free.

A command runs in phases (loading, searching, validating, writing); a phase
may have steps (evaluations of a search, runs of a study) that the library
reports through a callback, ``progress(done, total)``: the library itself
never prints. On a terminal the phase is one status line, rewritten in
place (a bar for a phase with steps); when standard error is not a terminal
(a log, a pipe, a batch job) a few plain lines are printed instead: one when
the phase is first shown, one at every further tenth of its steps, one
after ``PLAIN_EVERY`` seconds without a line, and ``done in ...`` at the end.
Nothing is shown before the command has run ``TTY_DELAY`` (terminal) or
``PLAIN_DELAY`` (plain) seconds, so short runs stay silent.
"""

from __future__ import annotations

import shutil
import signal
import sys
import threading
import time
from typing import TextIO

__all__ = ["PLAIN_DELAY", "PLAIN_EVERY", "TTY_DELAY", "Progress", "before_message"]

# Seconds of silence before the first output: on a terminal, and in a log.
TTY_DELAY = 1.0
PLAIN_DELAY = 5.0
# Longest gap between two plain lines while a phase runs (seconds).
PLAIN_EVERY = 10.0
# How often the status is looked at between the library's reports (seconds).
_TICK = 0.5
# Shortest gap between two redraws of the terminal line (seconds).
_REDRAW = 0.1


class Progress:
    """Progress of a command on a text stream, and the wall time of its phases.

    Use it as a context manager: leaving it normally says ``done in ... s``
    (if anything was shown); leaving on an exception only ends the status
    line, so the error message that follows starts on a line of its own.

    Parameters
    ----------
    prefix : str
        What every line starts with, e.g. ``"spiralid identify"``.
    enabled : bool
        False (``--quiet``): show nothing, only time the phases.
    stream : file-like, optional
        Where to show it; standard error by default. A stream whose
        ``isatty()`` is true gets the status line, any other plain lines.
    delay : float, optional
        Seconds before the first output; default ``TTY_DELAY`` on a
        terminal, ``PLAIN_DELAY`` otherwise.

    Examples
    --------
    >>> import io
    >>> log = io.StringIO()
    >>> with Progress("spiralid demo", stream=log, delay=0.0) as progress:
    ...     search = progress.phase("search", "searching", total=4, unit="runs")
    ...     for done in range(1, 5):
    ...         search(done)
    >>> print(log.getvalue())  # doctest: +ELLIPSIS
    spiralid demo: searching: 0/4 runs (0 %), 0 s
    spiralid demo: searching: 1/4 runs (25 %), 0 s
    ...
    spiralid demo: done in ... s
    <BLANKLINE>
    >>> sorted(progress.timings())
    ['search', 'total']
    """

    def __init__(
        self,
        prefix: str,
        *,
        enabled: bool = True,
        stream: TextIO | None = None,
        delay: float | None = None,
    ) -> None:
        self.prefix = prefix
        self.enabled = bool(enabled)
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        if delay is None:
            delay = TTY_DELAY if self.tty else PLAIN_DELAY
        self.delay = float(delay)
        self.every = PLAIN_EVERY
        self._start = time.perf_counter()
        self._times: dict[str, float] = {}
        self._name: str | None = None
        self._since = self._start
        self._what = ""
        self._total: int | None = None
        self._unit = ""
        self._done = 0
        self._announced = False
        self._tenth = -1
        self._last: float | None = None  # when something was last shown
        self._drawn = 0  # the length of the terminal line now drawn
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None
        if self.enabled:
            # Between the library's reports (a phase without steps, a long
            # polish after a search) the status still moves.
            self._ticker = threading.Thread(
                target=self._tick, name="spiralid-progress", daemon=True
            )
            self._ticker.start()
        Progress._active = self

    _active: Progress | None = None

    # -- what the command calls ---------------------------------------------------

    def phase(
        self,
        name: str,
        what: str | None = None,
        *,
        total: int | None = None,
        unit: str = "",
    ) -> Progress:
        """End the phase that runs and start phase `name`.

        Parameters
        ----------
        name : str
            Its key in :meth:`timings` (a name used twice adds up).
        what : str, optional
            How it is shown, e.g. ``"searching the front"``; default `name`.
        total : int, optional
            Number of steps, for a phase whose steps are reported by calling
            this object (the returned one), ``progress(done, total=None)``.
        unit : str
            What a step is, e.g. ``"evaluations"``.

        Returns
        -------
        Progress
            This object: the callback to hand to the library.
        """
        with self._lock:
            now = time.perf_counter()
            self._end_phase(now)
            self._name, self._since = name, now
            self._what = name if what is None else what
            self._total = None if total is None else max(int(total), 1)
            self._unit = unit
            self._done = 0
            self._announced = False
            self._tenth = -1
            self._show(now, changed=True)
        return self

    def __call__(self, done: int, total: int | None = None) -> None:
        """Report `done` steps of the running phase (and its `total`, if it
        changed)."""
        with self._lock:
            self._done = int(done)
            if total is not None:
                self._total = max(int(total), 1)
            self._show(time.perf_counter(), changed=False)

    def timings(self) -> dict[str, float]:
        """Seconds spent in each phase so far (the running one until now),
        in the order they ran, and ``"total"`` since the start."""
        now = time.perf_counter()
        with self._lock:
            times = dict(self._times)
            if self._name is not None:
                times[self._name] = times.get(self._name, 0.0) + now - self._since
        times["total"] = now - self._start
        return times

    def close(self, ok: bool = True) -> None:
        """End the output: ``done in ... s`` if `ok` and anything was shown;
        otherwise only the end of the terminal line."""
        self._stop.set()
        if self._ticker is not None and self._ticker is not threading.current_thread():
            self._ticker.join()
        self._ticker = None
        if Progress._active is self:
            Progress._active = None
        with self._lock:
            now = time.perf_counter()
            self._end_phase(now)
            self._name = None
            if not self.enabled or self._last is None:
                return
            if ok:
                done = f"{self.prefix}: done in {now - self._start:.1f} s"
                if self.tty:
                    self._draw(done)
                else:
                    self._write(done + "\n")
            self._end_line()
            self._last = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(ok=exc_type is None)

    # -- showing ------------------------------------------------------------------

    def _end_phase(self, now: float) -> None:
        if self._name is not None:
            self._times[self._name] = (
                self._times.get(self._name, 0.0) + now - self._since
            )

    def _tick(self) -> None:
        # SIGINT and SIGTERM go to the main thread, never to this one (a
        # signal mask is per thread; Python runs its handlers in the main
        # thread anyway).
        try:
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
        except (AttributeError, ValueError, OSError):
            pass
        while not self._stop.wait(_TICK):
            with self._lock:
                if self._name is not None:
                    self._show(time.perf_counter(), changed=False)

    def _show(self, now: float, changed: bool) -> None:
        """Show the running phase if it is time to (under the lock)."""
        elapsed = now - self._start
        if not self.enabled or self._name is None or elapsed < self.delay:
            return
        if self.tty:
            end = self._total is not None and self._done >= self._total
            if changed or end or self._last is None or now - self._last >= _REDRAW:
                self._draw(self._status(elapsed, bar=True))
                self._last = now
            return
        tenth = self._tenths()
        if (
            not self._announced
            or (self._total is not None and tenth > self._tenth)
            or now - (self._last or now) >= self.every
        ):
            self._write(self._status(elapsed, bar=False) + "\n")
            self._announced, self._tenth, self._last = True, tenth, now

    def _tenths(self) -> int:
        if self._total is None:
            return -1
        return min(10 * self._done // self._total, 10)

    def _status(self, elapsed: float, bar: bool) -> str:
        head = f"{self.prefix}: {self._what}"
        if self._total is None:
            return f"{head}, {elapsed:.0f} s"
        done, total = self._done, self._total
        percent = max(min(100 * done // total, 100), 0)
        count = f"{done:,}/{total:,}{' ' + self._unit if self._unit else ''}"
        # At the end of its steps a phase may still have work to finish
        # (a search's polish, a report's figures).
        more = ", finishing" if done >= total else ""
        if bar:
            width = 20
            filled = width * percent // 100
            gauge = "#" * filled + "." * (width - filled)
            return f"{head} [{gauge}] {count}{more}  {elapsed:.0f} s"
        return f"{head}: {count} ({percent} %){more}, {elapsed:.0f} s"

    def _draw(self, text: str) -> None:
        columns = shutil.get_terminal_size((80, 24)).columns
        text = text[: max(columns - 1, 10)]
        self._write("\r" + text + " " * max(self._drawn - len(text), 0))
        self._drawn = len(text)

    def _end_line(self) -> None:
        if self.tty and self._drawn:
            self._write("\n")
            self._drawn = 0

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):
            # A closed pipe or stream: progress is not worth failing for.
            self.enabled = False


def before_message() -> None:
    """End the terminal status line of the running command, if one is drawn,
    so that a message (a warning) starts on a line of its own."""
    progress = Progress._active
    if progress is not None and progress.tty:
        with progress._lock:
            progress._end_line()
