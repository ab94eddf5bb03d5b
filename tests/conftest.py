"""Test-session settings shared by every test module.

Hypothesis runs derandomized: each property test draws the same examples in every run, so a CI run gives the same
verdict as the run before it (a failure found by a random search is kept as an explicit ``@example``).

The tests run in parallel (pytest-xdist, ``-n auto --dist loadfile`` in ``pyproject.toml``): one worker per CPU this
process may use (the count ``washbench`` itself uses for ``--jobs``: affinity and cgroup quota), at most
:data:`MAX_WORKERS`, each test file on one worker (its module fixtures set up once). ``-n 0`` runs them in this process.
"""

from __future__ import annotations

from hypothesis import settings

from washbench.io.cpus import usable_cpus

settings.register_profile("washbench", derandomize=True)
settings.load_profile("washbench")

#: Workers at most: many tests start suites of two processes of their own, and each worker holds JSBSim and numba.
MAX_WORKERS = 4


def pytest_xdist_auto_num_workers(config: object) -> int:
    """``-n auto``: the CPUs this process may use (not the machine's), at most :data:`MAX_WORKERS`."""
    return min(usable_cpus(), MAX_WORKERS)
