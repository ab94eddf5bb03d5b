"""The garbage collector's settings (washbench.io.collector): a command's imports and a suite worker's runs are not
rescanned by the collector at CPython's default pace."""

from __future__ import annotations

import gc
import subprocess
import sys
from pathlib import Path

import pytest

from washbench.io import collector
from washbench.runs.pool import worker_pool

ROOT = Path(__file__).resolve().parents[1]
_COUNT = (
    "import contextlib, gc, io, sys\n"
    "young = [0]\n"
    "gc.callbacks.append(lambda phase, info: young.__setitem__(0, young[0] + (phase == 'start'"
    " and info['generation'] == 0)))\n"
    "how, sys.argv = sys.argv[1], ['washbench', 'validate', sys.argv[2]]\n"
    "with contextlib.redirect_stdout(io.StringIO()):\n"
    "    if how == 'entry':\n"
    "        from washbench.__main__ import entry as run\n"
    "    else:\n"
    "        from washbench.cli import main as run\n"
    "    status = run()\n"
    "print(status, young[0])\n"
)


def _young_collections(how: str) -> int:
    """Young-generation collections in a fresh interpreter validating a bundled manoeuvre, through ``how``:
    ``entry`` (the console script) or ``main`` (the CLI called without the console script's settings)."""
    out = subprocess.run([sys.executable, "-c", _COUNT, how, str(ROOT / "manoeuvres" / "c172" / "takeoff.yaml")],
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert out.returncode == 0, out.stderr
    status, young = map(int, out.stdout.split())
    assert status == 0
    return young


def test_the_console_script_collects_far_less_often_than_python_by_default() -> None:
    """The same command, the same imports: through the console script's entry the collector runs a fraction of the
    times it runs at CPython's default threshold (86 against 9 here)."""
    default, tuned = _young_collections("main"), _young_collections("entry")
    assert default >= 40
    assert tuned * 5 <= default


def test_a_pool_worker_never_scans_what_its_process_server_loaded() -> None:
    """A suite worker forked from the process server starts with the preloaded modules (JSBSim, numba's kernels,
    pyarrow, matplotlib, rerun: hundreds of thousands of objects) in the collector's permanent generation, and the
    server's raised threshold."""
    with worker_pool(1) as pool:
        frozen = pool.submit(gc.get_freeze_count).result(timeout=120)
        threshold = pool.submit(gc.get_threshold).result(timeout=120)
    assert frozen > 100_000
    assert threshold[0] > 700  # CPython's default


def test_figure_writers_pause_the_garbage_collector_and_restore_it() -> None:
    """collector.paused: off while the writer runs, then as it was (on or off), also when the writer fails."""
    seen = []

    @collector.paused
    def writer(fail: bool) -> None:
        seen.append(gc.isenabled())
        if fail:
            raise ValueError("drawing failed")

    was = gc.isenabled()
    try:
        for enabled in (True, False):
            (gc.enable if enabled else gc.disable)()
            writer(False)
            with pytest.raises(ValueError, match="drawing failed"):
                writer(True)
            assert gc.isenabled() == enabled
        assert seen == [False] * 4
    finally:
        (gc.enable if was else gc.disable)()
