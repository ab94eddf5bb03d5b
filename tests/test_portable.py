"""Portability: the spawn start method (Windows has no forkserver), the user cache folder for numba's cache when
the package folder is read-only, and when the native viewer is chosen."""

from __future__ import annotations

import csv
import multiprocessing
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hostile import short

from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.review.replay import _has_display
from washbench.runs import pool, suite


def test_suite_runs_with_spawn_where_forkserver_does_not_exist(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(multiprocessing, "get_all_start_methods", lambda: ["spawn"])
    ctx, initializer = pool.pool_context()
    assert ctx.get_start_method() == "spawn" and initializer is not None
    # two short flights (what is tested is the start method: every worker imports and loads the kernels itself)
    files = [short(tmp_path, name="spawn_a", seconds=2), short(tmp_path, name="spawn_b", seconds=2)]
    outcomes = suite.run_suite(files, tmp_path / "out", jobs=2, progress=False)
    assert [o.run.ok for o in outcomes] == [True, True]
    with open(tmp_path / "out" / "c172p" / "spawn_a" / "metrics.csv", newline="") as f:
        assert len(list(csv.DictReader(f))) == 6 * len(DEFAULT_WASHOUTS)  # the default washouts x 6 DOFs
    assert (tmp_path / "out" / "c172p" / "spawn_b" / "figures" / "perceived.png").is_file()
    assert (tmp_path / "out" / "c172p" / "spawn_b" / "recording.rrd").is_file()


def test_numba_cache_goes_to_the_user_cache_folder_when_the_package_is_read_only(tmp_path: Path) -> None:
    """In a fresh interpreter with the package folders reported read-only, NUMBA_CACHE_DIR points at the user cache
    (XDG_CACHE_HOME here) and numba writes the kernel's cache there."""
    code = (
        "import os, washbench.numerics.jitcache as j\n"
        "j._writable = lambda folder: False\n"
        "j.configure_cache()\n"
        "print(os.environ['NUMBA_CACHE_DIR'])\n"
        "from washbench.platform.kinematics import brake_speed\n"
        "brake_speed(1.0, 2.0, 0.01)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == str(tmp_path / "cache" / "washbench" / "numba")
    assert list((tmp_path / "cache" / "washbench" / "numba").rglob("kinematics.brake_speed-*.nbi"))


@pytest.mark.parametrize(
    ("platform", "environ", "native"),
    [
        ("linux", {}, False),
        ("linux", {"DISPLAY": ":0"}, True),
        ("linux", {"WAYLAND_DISPLAY": "wayland-0"}, True),
        ("darwin", {}, True),
        ("win32", {}, True),
        ("darwin", {"SSH_CONNECTION": "1.2.3.4 5 6.7.8.9 22"}, False),
    ],
)
def test_native_viewer_on_desktops(platform: str, environ: dict[str, str], native: bool) -> None:
    assert _has_display(platform, environ) is native


def test_a_first_compile_is_announced_in_one_line_and_a_cached_one_not(tmp_path: Path) -> None:
    """Two kernels compiled in one process (a fresh numba cache): one line; the same again from the cache: none."""
    code = (
        "import numpy as np\n"
        "from washbench.review.thinning import keep_changes, keep_samples\n"
        "v = np.cumsum(np.ones((50, 2)), axis=0)\n"
        "keep_samples(np.arange(50.0), v, 0.1, 10.0)\n"
        "keep_changes(v, 0.1, 10)\n"
        "keep_samples(np.arange(50.0), v, 0.1, 10.0)\n"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    first, again = (subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
                    for _ in range(2))  # fmt: skip
    assert first.returncode == 0 and again.returncode == 0, first.stderr + again.stderr
    lines = first.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("washbench: compiling"), first.stderr
    assert str(tmp_path / "numba") in lines[0]
    assert again.stderr.strip() == ""
