"""Test-session settings shared by every test module.

Hypothesis runs derandomized: each property test draws the same examples in every run, so a CI run gives the same
verdict as the run before it (a failure found by a random search is kept as an explicit ``@example``).
"""

from __future__ import annotations

from hypothesis import settings

settings.register_profile("washbench", derandomize=True)
settings.load_profile("washbench")
