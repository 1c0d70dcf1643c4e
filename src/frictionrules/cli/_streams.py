"""Standard output and error that survive their reader closing the pipe.

``frictionrules paper --list | head -2`` closes the pipe after two lines. A command then ends
as it would have without the reader: the rest of what it prints is discarded (the stream is
pointed at ``os.devnull``), the files it writes are still written (a folder run of ``solve``
keeps going to its ``--csv``), and its exit code is its own (0 on success). A closed pipe is
never reported as an error, so it never takes the bad-input exit code 2.
"""

from __future__ import annotations

import contextlib
import errno
import os
import sys


def _reader_gone(exc: OSError) -> bool:
    return isinstance(exc, BrokenPipeError) or exc.errno == errno.EPIPE


class _PipeTolerantStream:
    """A text stream over ``stream`` whose writes and flushes, once the reader has closed the
    pipe, go to ``os.devnull`` instead of raising :class:`BrokenPipeError`."""

    def __init__(self, stream):
        self._stream = stream
        self.reader_gone = False

    def _discard_from_now_on(self) -> None:
        self.reader_gone = True
        try:                    # the descriptor itself, so that the exit's flush succeeds too
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self._stream.fileno())
            os.close(devnull)
        except (OSError, AttributeError, ValueError):   # no descriptor (a test's capture)
            pass

    def _guarded(self, method, *args):
        if self.reader_gone and not _has_descriptor(self._stream):
            return None
        try:
            return getattr(self._stream, method)(*args)
        except OSError as exc:
            if not _reader_gone(exc):
                raise
            self._discard_from_now_on()
            with contextlib.suppress(OSError):  # the buffered rest now goes to os.devnull
                return getattr(self._stream, method)(*args)
            return None

    def write(self, text):
        self._guarded("write", text)
        return len(text)

    def writelines(self, lines):
        for line in lines:
            self.write(line)

    def flush(self):
        self._guarded("flush")

    def __getattr__(self, name):        # isatty, fileno, encoding, buffer, ...
        return getattr(self._stream, name)


def _has_descriptor(stream) -> bool:
    try:
        stream.fileno()
    except (OSError, AttributeError, ValueError):
        return False
    return True


@contextlib.contextmanager
def tolerate_closed_pipes():
    """Within the block, ``sys.stdout`` and ``sys.stderr`` tolerate a reader that closes the
    pipe (see the module's docstring); both are flushed at the end and restored."""
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _PipeTolerantStream(saved[0]), _PipeTolerantStream(saved[1])
    try:
        yield
    finally:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(ValueError):   # a stream closed by the command itself
                stream.flush()
        sys.stdout, sys.stderr = saved
