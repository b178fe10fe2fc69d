"""A dependency-free progress bar for long runs, drawn on a text stream."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class ProgressBar:
    """Draw ``label [#####.....] done/total  elapsed`` on one terminal line.

    The bar draws only when ``enabled`` and the stream is a terminal, and
    only once the run has lasted ``delay`` seconds, so short runs stay
    silent. Call it with the number of finished steps (and the total, if
    known); ``close()`` ends the line.

    Parameters
    ----------
    total : int
        Number of steps in the run (a call may update it).
    label : str
        Text in front of the bar.
    stream : file-like, optional
        Where to draw; standard error by default.
    enabled : bool
        False turns the bar off (``--quiet``).
    delay : float
        Seconds to wait before the first draw.
    """

    def __init__(
        self,
        total: int,
        label: str = "",
        *,
        stream: TextIO | None = None,
        enabled: bool = True,
        delay: float = 1.0,
        width: int = 30,
    ) -> None:
        self.total = max(int(total), 1)
        self.label = label
        self.stream = sys.stderr if stream is None else stream
        isatty = getattr(self.stream, "isatty", lambda: False)()
        self.enabled = enabled and isatty
        self.delay = delay
        self.width = width
        self._start = time.perf_counter()
        self._drawn = False

    def __call__(self, done: int, total: int | None = None) -> None:
        if total is not None:
            self.total = max(int(total), 1)
        if not self.enabled:
            return
        elapsed = time.perf_counter() - self._start
        if elapsed < self.delay and done < self.total:
            return
        filled = int(self.width * min(done, self.total) / self.total)
        bar = "#" * filled + "." * (self.width - filled)
        self.stream.write(
            f"\r{self.label} [{bar}] {done}/{self.total}  {elapsed:5.1f} s"
        )
        self.stream.flush()
        self._drawn = True

    def close(self) -> None:
        if self._drawn:
            self.stream.write("\n")
            self.stream.flush()
