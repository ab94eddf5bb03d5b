"""Test-session settings shared by every test module.

Hypothesis runs derandomized: each property test draws the same examples in every run, so a CI run gives the same
verdict as the run before it (a failure found by a random search is kept as an explicit ``@example``).

The tests run in parallel (pytest-xdist, ``-n auto --dist loadfile`` in ``pyproject.toml``): one worker per CPU this
process may use (the count ``washbench`` itself uses for ``--jobs``: affinity and cgroup quota) and one more, at most
:data:`MAX_WORKERS`, each test file on one worker (its module fixtures set up once). ``-n 0`` runs them in this process.
Before the workers' first test, ``tests/warm_kernels.py`` fills numba's cache once (started while the workers start
and collect), so that after a fresh clone the workers do not each compile the same kernels.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from hypothesis import settings

from washbench.io.cpus import usable_cpus
from washbench.io.pages import small_pages

small_pages()  # as every washbench command (washbench.io.pages): the tests' own arrays and the processes they start

settings.register_profile("washbench", derandomize=True)
settings.load_profile("washbench")

#: Workers at most: many tests start suites of two processes of their own, and each worker holds JSBSim and numba.
MAX_WORKERS = 4
#: Workers beyond the CPUs: the tests spend about an eighth of their time waiting (for a signal to land, a process to
#: start or a viewer to close), and one more worker fills it. On 2 CPUs, with the kernels cached: 2 workers took
#: 222-233 s, 3 workers 210-217 s, 4 workers 231 s (more CPU lost to switching than waiting saved).
EXTRA_WORKERS = 1
#: The folder of the kernels' warm-up (``tests/warm_kernels.py``), passed from the controller to its workers.
WARM_ENV = "WASHBENCH_TESTS_WARM_FOLDER"
WARM_WAIT_S = 600.0


SLOW_ENV = "WASHBENCH_SLOW"
"""Set (to anything), the tests marked ``slow`` run too: the exhaustive and measuring ones that would take the README's
test command past four minutes on two cores (``.ci/run`` runs them after it: ``WASHBENCH_SLOW=1 pytest -m slow``)."""


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", f"slow: run only with {SLOW_ENV}=1 (.ci/run runs them after the test command)")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Without :data:`SLOW_ENV`, the tests marked ``slow`` are skipped, saying how to run them."""
    if os.environ.get(SLOW_ENV):
        return
    skip = pytest.mark.skip(reason=f"slow tier: {SLOW_ENV}=1 pytest -m slow (.ci/run runs it)")
    for item in items:
        if item.get_closest_marker("slow") is not None:
            item.add_marker(skip)


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto``: the CPUs this process may use (not the machine's) and :data:`EXTRA_WORKERS`, at most
    :data:`MAX_WORKERS`."""
    return min(usable_cpus() + EXTRA_WORKERS, MAX_WORKERS)


def pytest_sessionstart(session: pytest.Session) -> None:
    """In the controller of parallel workers (before they start: xdist's own hook runs last), start the warm-up."""
    config = session.config
    if hasattr(config, "workerinput") or not getattr(config.option, "numprocesses", None):
        return
    folder = Path(tempfile.mkdtemp(prefix="wb-warm-"))
    script = Path(__file__).with_name("warm_kernels.py")
    proc = subprocess.Popen([sys.executable, str(script), str(folder)])
    config.stash[_WARM] = (folder, proc)
    os.environ[WARM_ENV] = f"{folder}{os.pathsep}{proc.pid}"  # the workers, started after this hook, inherit it


def pytest_sessionfinish(session: pytest.Session) -> None:
    warm = session.config.stash.get(_WARM, None)
    if warm is not None:
        folder, proc = warm
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        shutil.rmtree(folder, ignore_errors=True)


_WARM = pytest.StashKey[tuple[Path, subprocess.Popen]]()


@pytest.fixture(scope="session", autouse=True)
def _kernels_warm(request: pytest.FixtureRequest) -> None:
    """A worker's first test waits until the warm-up is done (it never fails a test: see warm_kernels.py)."""
    warm = os.environ.get(WARM_ENV)
    if warm is None or not hasattr(request.config, "workerinput"):
        return
    folder, pid = warm.rsplit(os.pathsep, 1)
    deadline = time.monotonic() + WARM_WAIT_S
    while not (Path(folder) / "done").exists() and _running(int(pid)) and time.monotonic() < deadline:
        time.sleep(0.05)


def _running(pid: int) -> bool:
    """Whether process ``pid`` still runs: not gone, not a zombie (the warm-up, ended but not yet waited for by the
    controller). Without /proc (not Linux) the workers do not wait: they compile what they need themselves."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False
