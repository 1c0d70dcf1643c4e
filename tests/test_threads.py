"""Numba's threading layer for the processes that run the dynamic engine on their own
(``frictionrules._threads.prefer_openmp``): OpenMP first, unless the process has chosen."""

from __future__ import annotations

import json
import os
import subprocess
import sys

#: A parallel Numba function, ``total(n)``, for the probes run in fresh interpreters.
PARALLEL_TOTAL = """
from numba import njit, prange
@njit(parallel=True)
def total(n):
    s = 0.0
    for i in prange(n):
        s += i
    return s
"""

_PROBE = """
import json, numba
from frictionrules._threads import prefer_openmp
before = list(numba.config.THREADING_LAYER_PRIORITY)
""" + PARALLEL_TOTAL + """
if {launch_first}:
    total(10)
prefer_openmp()
total(10)
print(json.dumps({{"before": before, "priority": list(numba.config.THREADING_LAYER_PRIORITY),
                  "layer": numba.threading_layer()}}))
"""


def run_probe(code: str, **env) -> dict:
    """Run ``code`` in a fresh interpreter with two Numba threads and no threading layer chosen
    (beyond ``env``); the JSON of its last printed line."""
    clean = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_THREADING_LAYER")}
    out = subprocess.run([sys.executable, "-c", code], env={**clean, "NUMBA_NUM_THREADS": "2", **env},
                         capture_output=True, text=True, check=True, timeout=300)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _probe(launch_first: bool = False, **env) -> dict:
    return run_probe(_PROBE.format(launch_first=launch_first), **env)


def test_openmp_comes_first_where_nothing_was_chosen():
    got = _probe()
    assert got["priority"][0] == "omp"
    # OpenMP where GNU OpenMP loads; else Numba goes on to the next layer
    assert got["layer"] in ("omp", "tbb", "workqueue")


def test_a_chosen_layer_is_kept():
    got = _probe(NUMBA_THREADING_LAYER="workqueue")
    assert got["layer"] == "workqueue"
    got = _probe(NUMBA_THREADING_LAYER_PRIORITY="workqueue omp tbb")
    assert got["priority"][0] == "workqueue" and got["layer"] == "workqueue"


def test_nothing_changes_once_parallel_code_has_run():
    got = _probe(launch_first=True)
    assert got["priority"] == got["before"]
