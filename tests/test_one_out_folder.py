"""Issue 38, item 1: what "washbench wrote this folder" means, the same for every command.

A folder holds one command's results (``run`` and ``suite`` share one: a suite is a set of runs). A command into a
folder of another command's results is refused with one line that names that command and the file saying so, never
with "washbench did not write this" (which would be false), and the folder is left as it was.
"""

from __future__ import annotations

import json
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
    assert f"{suite_folder[0] / 'c172p' / 'other'} is added beside the suite" in proc.stderr  # (issue 52, item 6)

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


def test_a_run_never_replaces_a_result_of_a_suite(suite_folder: tuple[Path, Path]) -> None:
    """Issue 52, item 6 (b), (c): a run onto a manoeuvre the suite holds (another platform's, say) would leave the
    suite's report.md, ranking.csv and suite.json describing a result that is gone: refused, nothing touched; a
    suite into the suite's own aircraft folder is refused saying what that folder is (never "did not write")."""
    out, m = suite_folder
    before = digest(out)
    proc = washbench("run", m, "--out", out, "--platform", "hexapod", "--washout", "small-angle", "--no-recording",
                     "--no-figures", timeout=120)  # fmt: skip
    assert_clean_error(proc, f"{out / 'c172p' / 'short'}: a result of the suite in {out} (suite.json)", "report.md")
    proc = washbench("suite", m, "--out", out / "c172p", "--jobs", "1", "--no-recording", "--no-figures",
                     timeout=120)  # fmt: skip
    line = assert_clean_error(proc, f"{out / 'c172p'}: lies inside the results of `washbench suite` in {out}")[0]
    assert "did not write" not in line and f"--out {out} itself" in line
    assert digest(out) == before


def test_replacing_earlier_results_is_said_before_it_starts(tmp_path: Path) -> None:
    """Issue 52, item 6 (a): a command replacing earlier results of its own kind says so in one line before it
    starts (a suite: how many manoeuvres the earlier one had and when it was written); run results one level too
    high for a suite are named as what they are."""
    m = short(tmp_path)
    out = tmp_path / "S"
    flags = ("--no-recording", "--no-figures", "--jobs", "1", "--quiet")
    first = washbench("suite", m, short(tmp_path, name="other"), "--out", out, *flags, timeout=180)
    assert first.returncode == 0 and "note" not in first.stderr, first.stderr
    written = json.loads((out / "suite.json").read_text())["created_utc"]
    again = washbench("suite", m, "--out", out, *flags[:-1], timeout=180)  # with its progress lines
    assert again.returncode == 0, again.stderr
    assert f"suite: 1 manoeuvre on 1 process -> {out}" in again.stderr.splitlines()  # (issue 52, item 10)
    assert again.stderr.splitlines()[0] == (
        f"washbench: note: {out} holds a suite of 2 manoeuvres, written {written}: this suite of 1 manoeuvre "
        "replaces it when it is complete (until then, and after a failure or Ctrl-C, it stays as it is)")
    runs = tmp_path / "R"
    for _ in range(2):
        proc = washbench("run", m, "--out", runs, "--no-recording", "--no-figures", "--quiet", timeout=120)
        assert proc.returncode == 0, proc.stderr
    assert proc.stderr.strip() == (f"washbench: note: {runs / 'c172p' / 'short'} holds an earlier run of c172p/short: "
                                   "replaced when this one is complete (until then, and after a failure or Ctrl-C, it "
                                   "stays as it is)")  # fmt: skip
    proc = washbench("suite", m, "--out", runs / "c172p", *flags, timeout=120)
    line = assert_clean_error(proc, f"{runs / 'c172p' / 'short'}: a `washbench run` result (run.json)")[0]
    assert f"use --out {runs} or a new folder" in line and "did not write" not in line
    csv = motion_csv(tmp_path / "m.csv")
    for _ in range(2):
        proc = washbench("cue", csv, "--out", tmp_path / "C", "--no-recording", "--no-figures", "--quiet")
        assert proc.returncode == 0, proc.stderr
    assert f"washbench: note: {tmp_path / 'C'} holds earlier `washbench cue` results: replaced" in proc.stderr
