"""Shared by the benchmarks: timing and an atomically written Markdown results table."""

from __future__ import annotations

import platform
import time
from pathlib import Path

from frictionrules._atomic import write_text

RESULTS = Path(__file__).resolve().parent / "results"


def best_of(fun, repeat: int = 7) -> float:
    """Smallest wall time of ``repeat`` calls of ``fun()`` (seconds)."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fun()
        best = min(best, time.perf_counter() - t0)
    return best


def write_table(name: str, title: str, header: list[str], rows: list[list], notes: str = "") -> Path:
    """Write ``results/<name>.md`` and return its path; also print the table."""
    lines = [f"# {title}", "", f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, "
             f"Python {platform.python_version()}", "",
             "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    if notes:
        lines += ["", notes]
    text = "\n".join(lines) + "\n"
    print(text)
    return write_text(RESULTS / f"{name}.md", text)
