"""Test-suite settings.

Property-based tests run derandomized by default, so CI is repeatable: the
same examples every run. To explore new random examples (as done when the
one-way-clutch solver was developed), run with HYPOTHESIS_PROFILE=explore.
"""

import os

from hypothesis import settings

settings.register_profile("repeatable", derandomize=True, deadline=None)
settings.register_profile("explore", derandomize=False, deadline=None, max_examples=300)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))
