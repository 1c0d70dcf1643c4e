"""Progress of long computations on stderr: drawn only on a terminal, one summary line otherwise.

Library functions that can run long take an optional ``progress`` callable and call it as
``progress(done, total)`` (counts of steps, directions, files, ...); they know nothing of
terminals. The command line passes a :class:`Progress`, which

* on a terminal redraws one line in place (``\\r``), at most every ``interval`` seconds, and
  ends it with the summary when the work is done;
* elsewhere (a log file, a pipe, a test) writes nothing while the work runs and one summary
  line at the end — never ``\\r`` frames;
* writes nothing more when the work fails (the error message is the last line).

::

    with Progress("drive", total=len(path)) as bar:
        result = drive(model, path, progress=bar)
"""

from __future__ import annotations

import time
from typing import TextIO


def _is_terminal(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


class Progress:
    """Progress reporter for one long task; a callback ``progress(done, total)`` and a context
    manager.

    Parameters
    ----------
    label : str
        What runs (``"drive"``, ``"configuration --polar"``); starts every line.
    total : int, optional
        Number of units of work when known (a callback call may also give it).
    unit : str
        Name of a unit of work in the summary (``"steps"``, ``"directions"``).
    stream : text stream, optional
        Where to write; ``sys.stderr`` (looked up when writing) by default.
    enabled : bool
        False writes nothing at all (``--quiet``).
    interval : float
        Least time between two redraws on a terminal, seconds.
    """

    def __init__(self, label: str, total: int | None = None, *, unit: str = "steps",
                 stream: TextIO | None = None, enabled: bool = True, interval: float = 0.1):
        self.label, self.total, self.unit = label, total, unit
        self._stream, self.enabled, self.interval = stream, enabled, interval
        self.done = 0
        self.phase_text = ""
        self.start = time.monotonic()
        self._drawn = -float("inf")
        self._width = 0
        self.closed = False
        self._terminal = None

    @property
    def stream(self) -> TextIO:
        import sys
        return self._stream if self._stream is not None else sys.stderr

    @property
    def terminal(self) -> bool:
        if self._terminal is None:
            self._terminal = _is_terminal(self.stream)
        return self._terminal

    @property
    def elapsed(self) -> float:
        return time.monotonic() - self.start

    # ---- the callback ------------------------------------------------------------------------
    def __call__(self, done: int, total: int | None = None) -> None:
        """Record that ``done`` units of ``total`` are finished (redraw on a terminal)."""
        self.done = int(done)
        if total is not None:
            self.total = int(total)
        self._draw(force=self.total is not None and self.done >= self.total)

    def phase(self, text: str) -> None:
        """Name the stage that runs now (``"compiling the law"``): shown on a terminal."""
        self.phase_text = text
        self._draw(force=True)

    def _line(self) -> str:
        parts = [self.label]
        if self.total:
            width = 30
            filled = min(width, width * self.done // self.total)
            parts.append(f"[{'#' * filled}{'-' * (width - filled)}] {self.done}/{self.total}")
        elif self.done:
            parts.append(f"{self.done} {self.unit}")
        if self.phase_text:
            parts.append(self.phase_text)
        parts.append(f"{self.elapsed:.1f} s")
        return "  ".join(parts)

    def _draw(self, force: bool = False) -> None:
        if not self.enabled or self.closed or not self.terminal:
            return
        now = time.monotonic()
        if not force and now - self._drawn < self.interval:
            return
        self._drawn = now
        line = self._line()
        self.stream.write("\r" + line + " " * max(0, self._width - len(line)))
        self._width = len(line)
        self.stream.flush()

    # ---- the end ------------------------------------------------------------------------------
    def summary(self) -> str:
        """The closing line: ``drive: 410/410 steps in 3.2 s``."""
        if not (self.done or self.total):
            return f"{self.label}: done in {self.elapsed:.1f} s"
        count = f"{self.done}/{self.total}" if self.total else f"{self.done}"
        return f"{self.label}: {count} {self.unit} in {self.elapsed:.1f} s"

    def close(self, note: str = "", *, failed: bool = False) -> None:
        """Finish: on success the summary line (with ``note``), on failure only end the
        terminal line so that the error message starts on its own line."""
        if self.closed or not self.enabled:
            self.closed = True
            return
        self.closed = True
        stream = self.stream
        if failed:
            if self.terminal and self._width:
                stream.write("\r" + " " * self._width + "\r")
                stream.flush()
            return
        line = self.summary() + (f"; {note}" if note else "")
        if self.terminal:
            line = "\r" + line + " " * max(0, self._width - len(line))
        stream.write(line + "\n")
        stream.flush()

    def __enter__(self) -> "Progress":
        self.start = time.monotonic()
        self._draw(force=True)  # on a terminal, at once: the first step may take a while
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(failed=exc_type is not None)
