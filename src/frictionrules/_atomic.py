"""Atomic file output; kept for the modules that import it from here: the writers live in
:mod:`frictionrules._output` (atomic, permissions from the umask, errors naming the target)."""

from __future__ import annotations

from ._output import atomic_path, write_text

__all__ = ["atomic_path", "write_text"]
