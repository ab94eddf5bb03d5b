"""Issue 38, item 1: what "washbench wrote this folder" means, the same for every command.

A folder holds one command's results (``run`` and ``suite`` share one: a suite is a set of runs). A command into a
folder of another command's results is refused with one line that names that command and the file saying so, never
with "washbench did not write this" (which would be false), and the folder is left as it was.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hostile import assert_clean_error, short, washbench
from test_hostile_round2 import digest, motion_csv


@pytest.fixture(scope="module")
def suite_folder(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A real suite's folder (one short manoeuvre) and the manoeuvre file."""
    root = tmp_path_factory.mktemp("suite")
    m = short(root)
    out = root / "X"
    proc = washbench("suite", m, "--out", out, "--no-recording", "--no-figures", "--jobs", "1", "--quiet",
                     timeout=180)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert (out / "suite.json").is_file() and not (out / ".washbench.json").exists()
    return out, m


@pytest.mark.parametrize("command", ["fly", "cue", "omct"])
def test_a_suite_folder_is_refused_naming_the_suite(
    suite_folder: tuple[Path, Path], command: str, tmp_path: Path
) -> None:
    out, m = suite_folder
    before = digest(out)
    args = {"fly": ("fly", m), "cue": ("cue", motion_csv(tmp_path / "m.csv")), "omct": ("omct",)}[command]
    proc = washbench(*args, "--out", out, timeout=120)
    line = assert_clean_error(proc, "`washbench suite`", "suite.json", f"`washbench {command}`")[0]
    assert "did not write" not in line
    assert digest(out) == before


def test_run_and_suite_share_a_folder_other_commands_do_not(suite_folder: tuple[Path, Path], tmp_path: Path) -> None:
    """run adds to a suite's folder; run and suite into a fly folder are refused naming fly; fly's own is reused."""
    m = short(tmp_path, name="other")
    proc = washbench("run", m, "--out", suite_folder[0], "--no-recording", "--no-figures", timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert (suite_folder[0] / "c172p" / "other" / "run.json").is_file()

    flown = tmp_path / "F"
    assert washbench("fly", m, "--out", flown, timeout=120).returncode == 0
    before = digest(flown)
    for command in ("run", "suite"):
        proc = washbench(command, m, "--out", flown, "--no-recording", "--no-figures", timeout=120)
        line = assert_clean_error(proc, "`washbench fly`", ".washbench.json", f"`washbench {command}`")[0]
        assert "did not write" not in line
    assert digest(flown) == before
    assert washbench("fly", m, "--out", flown, timeout=120).returncode == 0  # its own folder: replaced


def test_a_run_folder_is_refused_by_cue_naming_run(tmp_path: Path) -> None:
    m = short(tmp_path)
    out = tmp_path / "R"
    assert washbench("run", m, "--out", out, "--no-recording", "--no-figures", timeout=120).returncode == 0
    proc = washbench("cue", motion_csv(tmp_path / "m.csv"), "--out", out, timeout=120)
    assert_clean_error(proc, "`washbench run`", "run.json", "`washbench cue`")
