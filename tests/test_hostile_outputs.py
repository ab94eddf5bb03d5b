"""Results stay inside --out, replace only washbench's own results, and one writer at a time holds a folder."""

from __future__ import annotations

import json
import os
from pathlib import Path

from hostile import assert_clean_error, short, tree, washbench

from washbench.io.lock import output_lock
from washbench.io.outfolder import recover_shared
from washbench.io.result_files import JOURNAL_PREFIX, OLD_PREFIX, RUN_FILES, STAGE_PREFIX


def test_run_replaces_only_its_own_previous_result(tmp_path: Path) -> None:
    manoeuvre = short(tmp_path, seconds=1)
    out = tmp_path / "out"
    theirs = out / "c172p" / "short"
    theirs.mkdir(parents=True)
    (theirs / "notes.txt").write_text("mine")
    proc = washbench("run", manoeuvre, "--out", out, "--quiet", timeout=120)
    assert_clean_error(proc, f"{theirs}: exists and is not a washbench result of aircraft c172p, manoeuvre short")
    assert proc.stdout == "" and tree(out) == ["c172p", "c172p/short", "c172p/short/notes.txt"]

    # a leftover of an interrupted run (its process is gone) is cleaned; a previous result is replaced
    out2 = tmp_path / "out2"
    leftover = out2 / "c172p" / ".short.partial-999999999"  # as an older version left it
    leftover.mkdir(parents=True)
    (leftover / "flight.json").write_text("{")
    (out2 / "c172p" / f"{STAGE_PREFIX}999999999" / "short").mkdir(parents=True)  # killed while building
    (out2 / "c172p" / f"{STAGE_PREFIX}999999999" / "short" / "flight.json").write_text("{")
    (out2 / "c172p" / f"{OLD_PREFIX}999999998").mkdir()  # killed as it deleted the result it replaced
    previous = out2 / "c172p" / "short"
    previous.mkdir()
    (previous / "run.json").write_text(json.dumps({"aircraft": "c172p", "manoeuvre": "short", "ok": False}))
    (previous / "stale.txt").write_text("from an older version")
    proc = washbench("run", manoeuvre, "--out", out2, "--quiet", timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert f"results in {previous}" in proc.stdout
    assert [p for p in tree(out2) if p.count("/") < 2] == ["c172p", "c172p/short"]  # the leftover is gone
    files = tree(previous)
    assert set(RUN_FILES) <= set(files) and "stale.txt" not in files and not any(f.startswith(".") for f in files)
    run = json.loads((previous / "run.json").read_text())
    assert (run["aircraft"], run["manoeuvre"], run["ok"]) == ("c172p", "short", True)


def test_a_shared_folder_is_recovered_only_of_dead_processes_leftovers(tmp_path: Path) -> None:
    """``OUT/<aircraft>/``, where runs (and a suite's workers, side by side) publish their folders: a run killed in
    the middle of its swap is finished from its journal (the new folder in place, the old one gone); what a live
    process is building stays; a user's file of a leftover's name, and the user's files, stay."""
    shared = tmp_path / "c172p"
    dead, live = 999999999, os.getpid()
    stage, old = shared / f"{STAGE_PREFIX}{dead}", shared / f"{OLD_PREFIX}{dead}"
    (stage / "turn").mkdir(parents=True)
    (stage / "turn" / "run.json").write_text("new")  # the new result, not yet moved in
    (shared / "turn").mkdir()
    (shared / "turn" / "run.json").write_text("old")  # the previous one, not yet moved out
    old.mkdir()
    doc = {"stage": stage.name, "old": old.name, "previous": ["turn"], "new": ["turn"]}
    (shared / f"{JOURNAL_PREFIX}{dead}").write_text(json.dumps(doc))
    (shared / f"{STAGE_PREFIX}{live}" / "level").mkdir(parents=True)  # being built by a running process
    (shared / ".draft.partial-12").write_text("a file of the user's, named like an old leftover")
    (shared / "notes.txt").write_text("mine")
    recover_shared(shared)
    assert tree(shared) == sorted([
        ".draft.partial-12", f"{STAGE_PREFIX}{live}", f"{STAGE_PREFIX}{live}/level", "notes.txt", "turn",
        "turn/run.json",
    ])  # fmt: skip
    assert (shared / "turn" / "run.json").read_text() == "new"
    recover_shared(shared, only_dead=False)  # under the lock, nobody else publishing: every leftover goes
    assert tree(shared) == [".draft.partial-12", "notes.txt", "turn", "turn/run.json"]


def test_suite_output_folder_holds_exactly_that_suite(tmp_path: Path) -> None:
    out = tmp_path / "out"
    old = out / "c172p" / "old_turn"
    old.mkdir(parents=True)
    (old / "run.json").write_text(json.dumps({"aircraft": "c172p", "manoeuvre": "old_turn", "ok": True}))
    (out / "report.md").write_text("# an older suite\n")
    (out / "figure.png").write_bytes(b"png")
    (out / "suite.json").write_text(json.dumps({"washbench": "suite", "entries": ["c172p", "figure.png", "report.md"]}))
    inputs = tmp_path / "in"
    inputs.mkdir()
    short(inputs, name="level_a", seconds=1)
    proc = washbench("suite", inputs, "--out", out, "--jobs", "1", "--quiet", timeout=180)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    names = tree(out)
    assert [n for n in names if n.count("/") < 2 and not n.startswith("figures/")] == [
        "c172p", "c172p/level_a", "comparison.csv", "figures", "metrics.csv", "ranking.csv", "report.md", "suite.json",
    ]  # fmt: skip
    assert "figure.png" not in names  # the older suite's file is gone with it
    report = (out / "report.md").read_text()
    assert "1 of 1 manoeuvres" in report and "level_a" in report and "old_turn" not in report
    assert json.loads((out / "suite.json").read_text())["entries"] == [
        "c172p", "comparison.csv", "figures", "metrics.csv", "ranking.csv", "report.md",
    ]  # fmt: skip


def test_suite_refuses_a_folder_holding_what_washbench_did_not_write(tmp_path: Path) -> None:
    out = tmp_path / "out"
    (out / "c172p" / "turn").mkdir(parents=True)
    (out / "c172p" / "turn" / "thesis.tex").write_text("years of work")
    before = tree(out)
    inputs = tmp_path / "in"
    inputs.mkdir()
    short(inputs)
    proc = washbench("suite", inputs, "--out", out, timeout=60)
    assert_clean_error(proc, f"{out / 'c172p' / 'turn'}: washbench did not write this")
    assert tree(out) == before


def test_duplicate_manoeuvre_names_are_refused_before_flying(tmp_path: Path) -> None:
    first = short(tmp_path, name="twin", file="a.yaml")
    second = short(tmp_path, name="twin", file="b.yaml")
    out = tmp_path / "out"
    proc = washbench("suite", first, second, "--out", out, timeout=60)
    (line,) = assert_clean_error(proc, f"{second}:1: name:", str(first))
    assert "both would write c172p/twin/" in line
    assert not out.exists()


def test_a_second_writer_gets_a_clear_error(tmp_path: Path) -> None:
    manoeuvre = short(tmp_path)
    out = tmp_path / "out"
    with output_lock(out):
        for command in ("run", "suite", "fly"):
            proc = washbench(command, manoeuvre, "--out", out, timeout=60)
            assert_clean_error(proc, f"{out}: another washbench command (PID ")
        assert tree(out) == [".washbench.lock"]
    assert tree(out) == []  # the lock is gone with its holder
