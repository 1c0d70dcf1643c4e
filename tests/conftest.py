"""Test configuration.

Hypothesis runs derandomized by default, so a CI run is reproducible: the same examples on
every machine. ``HYPOTHESIS_PROFILE=explore`` draws fresh random examples (use it, with
``--hypothesis-seed``, to hunt for new counterexamples; add any you find with ``@example``).
"""
import os

import matplotlib
from hypothesis import settings

matplotlib.use("Agg")

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", derandomize=False, deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
