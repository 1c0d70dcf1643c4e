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

While Numba compiles (a first run, before its cache holds the kernels), a
:class:`CompileNotice` draws one line on a terminal, ``compiling kernels (first run): 4.2 s``,
so that the wait is explained; a :class:`Progress` line ends it before drawing its own.
"""

from __future__ import annotations

import threading
import time
from typing import TextIO

#: The line drawn on a terminal while Numba compiles, followed by the seconds spent compiling.
COMPILING = "compiling kernels (first run)"

#: Serialises the writes of a :class:`CompileNotice` (its thread and the compiling thread) and
#: of :class:`Progress` lines; ``_OPEN`` holds the notice whose line is drawn and not ended.
_LOCK = threading.RLock()
_OPEN: list = []


def end_compile_line() -> None:
    """End the line of a :class:`CompileNotice` if one is drawn, so that the next line written
    to the terminal starts on its own line."""
    if _OPEN:
        with _LOCK:
            for notice in list(_OPEN):
                notice._end_line()


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
        end_compile_line()
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
        end_compile_line()
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


class CompileNotice:
    """While Numba compiles, one line on a terminal: ``compiling kernels (first run): 4.2 s``.

    A first run compiles the kernels a command needs (seconds to a minute on a busy machine);
    later runs load them from Numba's cache and draw nothing. The notice listens to Numba's
    compile events (``numba.core.event``, kind ``"numba:compile"``: a compilation, not a load
    from the cache); a thread redraws the line every ``interval`` seconds while a compilation
    runs, once compiling has taken ``after`` seconds, and at the end of each compilation. The
    seconds are those of every compilation since the notice started; the line ends (a newline)
    ``idle`` seconds after the last compilation, when a :class:`Progress` line is drawn, or when
    the notice closes.

    Nothing is drawn (and Numba is not imported) unless ``stream`` (``sys.stderr`` by default)
    is a terminal and ``enabled``. A context manager::

        with CompileNotice(enabled=command_needs_numba):
            run()
    """

    def __init__(self, stream: TextIO | None = None, *, enabled: bool = True, interval: float = 0.25,
                 after: float = 0.5, idle: float = 1.0):
        self._stream, self.enabled = stream, enabled
        self.interval, self.after, self.idle = interval, after, idle
        self.seconds = 0.0          # compiling time of finished compilations
        self._depth, self._since, self._last_end = 0, None, None
        self._open, self._width = False, 0
        self._stop = threading.Event()
        self._thread = self._listener = None

    @property
    def stream(self) -> TextIO:
        import sys
        return self._stream if self._stream is not None else sys.stderr

    @property
    def compiling_seconds(self) -> float:
        """Seconds spent compiling since the notice started (the running compilation included)."""
        running = time.monotonic() - self._since if self._since is not None else 0.0
        return self.seconds + running

    def line(self) -> str:
        """``compiling kernels (first run): 4.2 s``."""
        return f"{COMPILING}: {self.compiling_seconds:.1f} s"

    # ---- the listener's calls (the compiling thread) ------------------------------------------
    def _started(self) -> None:
        with _LOCK:
            self._depth += 1
            if self._depth == 1:
                self._since = time.monotonic()

    def _ended(self) -> None:
        with _LOCK:
            if self._depth == 0:    # a compilation that started before the notice
                return
            self._depth -= 1
            if self._depth == 0:
                self.seconds += time.monotonic() - self._since
                self._since, self._last_end = None, time.monotonic()
                if self._open or self.seconds >= self.after:
                    self._draw()

    # ---- drawing (under _LOCK) ----------------------------------------------------------------
    def _draw(self) -> None:
        line = self.line()
        self.stream.write("\r" + line + " " * max(0, self._width - len(line)))
        self.stream.flush()
        self._width = len(line)
        if not self._open:
            self._open = True
            _OPEN.append(self)

    def _end_line(self) -> None:
        if self._open:
            self.stream.write("\n")
            self.stream.flush()
            self._open, self._width = False, 0
            _OPEN.remove(self)

    def _run(self) -> None:
        while not self._stop.wait(self.interval):
            with _LOCK:
                if self._depth > 0 and self.compiling_seconds >= self.after:
                    self._draw()
                elif (self._open and self._depth == 0 and self._last_end is not None
                      and time.monotonic() - self._last_end >= self.idle):
                    self._end_line()

    # ---- the context --------------------------------------------------------------------------
    def __enter__(self) -> "CompileNotice":
        if not (self.enabled and _is_terminal(self.stream)):
            return self
        from numba.core import event

        notice = self

        class _Listener(event.Listener):
            def on_start(self, ev):
                notice._started()

            def on_end(self, ev):
                notice._ended()

        self._listener = _Listener()
        event.register("numba:compile", self._listener)
        self._thread = threading.Thread(target=self._run, name="frictionrules-compile-notice", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if self._thread is None:
            return
        from numba.core import event
        self._stop.set()
        self._thread.join()
        event.unregister("numba:compile", self._listener)
        with _LOCK:
            self._end_line()
