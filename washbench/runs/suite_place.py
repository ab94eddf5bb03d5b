"""What a suite's ``--out`` may hold, and what a suite says it replaces there (:mod:`washbench.io.owners`).

A suite's folder holds exactly one suite's results: a new suite replaces a previous suite's files and every
``washbench run`` result folder (``OUT/<aircraft>/<manoeuvre>/``) gathered there, and says so in one line before it
starts; anything else in ``OUT`` keeps it out, in one line that says truly what is in the way.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.outfolder import folder_owner, refuse_other_owner
from washbench.io.publish import is_washbench_result, read_marker
from washbench.io.result_files import SUITE_FILE, SUITE_FILES, is_own_hidden, publication_pid
from washbench.runs.result_folder import RUN_MARKER

#: The file that marks a folder as a suite's (it lists everything a suite wrote at the top level).
SUITE_MARKER = SUITE_FILE


def _is_run_folder(entry: Path, aircraft: str) -> bool:
    """A ``run`` result of this aircraft (a JSBSim script that resets: a folder of such results)."""
    return is_washbench_result(entry, RUN_MARKER, {"aircraft": aircraft}, nested=True)


def previous_results(out_dir: Path) -> list[Path]:
    """The entries of ``out_dir`` a new suite replaces: a previous suite's files and run result folders.

    Raises WashbenchError naming the first entry washbench did not write (the suite then does not start).
    """
    refuse_other_owner(out_dir, "suite")
    marker = read_marker(out_dir, SUITE_MARKER) or {}
    listed = marker.get("entries", []) if marker.get("washbench") == "suite" else []
    listed = {n for n in listed if isinstance(n, str) and "/" not in n and n not in ("", ".", "..")}
    found: list[Path] = []
    for entry in sorted(out_dir.iterdir()):
        name = entry.name
        if is_own_hidden(name):
            continue
        if entry.is_symlink():  # never followed, never replaced (nor anything deleted through it)
            raise WashbenchError(located(entry, "is a symbolic link: washbench never follows or replaces a link in "
                                         "its output folder; remove it or choose another --out"))  # fmt: skip
        if name in SUITE_FILES or name == SUITE_MARKER or name in listed:
            found.append(entry)
            continue
        if entry.is_dir():
            subs = [e for e in entry.iterdir() if publication_pid(e.name) is None]
            if subs and all(_is_run_folder(e, name) for e in subs):  # an empty folder is the user's
                found.append(entry)
                continue
            stranger = next((e for e in subs if not _is_run_folder(e, name)), entry)
            raise WashbenchError(_not_a_run_here(out_dir, entry, stranger))
        raise WashbenchError(
            located(entry, "washbench did not write this: a suite replaces only a previous washbench result as a "
                    "whole; choose an empty or new --out folder")
        )  # fmt: skip
    return found


def _not_a_run_here(out_dir: Path, entry: Path, stranger: Path) -> str:
    """Why ``stranger`` (in ``entry``, a folder of ``out_dir``) keeps a suite out of ``out_dir``, truly: a washbench
    result of another kind, a run's result one level too high (``out_dir`` is itself an aircraft folder of results:
    ``--out results/c172p``), or something washbench did not write."""
    if read_marker(entry, RUN_MARKER) is not None:
        return located(entry, f"a `washbench run` result ({RUN_MARKER}) where a suite keeps an aircraft's folder: "
                       f"{out_dir} is itself a folder of run results, not a results folder; use --out "
                       f"{out_dir.parent} or a new folder")  # fmt: skip
    for holder in (entry, stranger):
        owner = folder_owner(holder) if holder.is_dir() and not holder.is_symlink() else None
        if owner is not None and not (owner[0] == "run" and holder == entry):
            return located(holder, f"holds the results of `washbench {owner[0]}` ({owner[1].name}), not a run of a "
                           "suite: not replaced; move it out of the folder or choose another --out")  # fmt: skip
    return located(stranger, "washbench did not write this: a suite replaces only a previous washbench result as "
                   "a whole; choose an empty or new --out folder")  # fmt: skip


def replacing(out_dir: Path, previous: Sequence[Path], n_files: int) -> str:
    """The line that says what a suite into ``out_dir`` replaces (``previous``: a suite's files, run results)."""
    doc = read_marker(out_dir, SUITE_MARKER) or {}
    new = f"this suite of {n_files} manoeuvre{'s' if n_files != 1 else ''}"
    if doc.get("washbench") == "suite" and isinstance(doc.get("manoeuvres"), list):
        n = len(doc["manoeuvres"])
        when = f", written {doc['created_utc']}" if isinstance(doc.get("created_utc"), str) else ""
        return (f"{out_dir} holds a suite of {n} manoeuvre{'s' if n != 1 else ''}{when}: {new} replaces it when it "
                "is complete (until then, and after a failure or Ctrl-C, it stays as it is)")  # fmt: skip
    runs = sum(1 for e in previous if e.is_dir() for _ in e.iterdir())
    return (f"{out_dir} holds {runs} `washbench run` result{'s' if runs != 1 else ''}: {new} replaces them when it is "
            "complete (until then, and after a failure or Ctrl-C, they stay as they are)")  # fmt: skip
