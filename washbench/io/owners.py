"""Who owns an output folder, and when a command's results replace earlier ones: said, or refused.

One rule for every command (``docs/reference/outputs.md``, "When results are replaced"):

- **Replaced, and said so.** A command replaces only earlier results of its own kind in its ``--out``: ``cue``
  (and ``live``, whose results are a ``cue``'s), ``fly``, ``omct``, ``sweep`` and ``tune`` their own previous result
  set; ``suite`` a previous suite or ``run`` results gathered there; ``run`` an earlier run of the same manoeuvre.
  Before it starts it says so in one line on standard error (:func:`announce`): what is there and that it is
  replaced once the new results are complete. Until then, and for good after a failure or Ctrl-C, the earlier
  results stay as they were.
- **Refused**, in one line before any work, with nothing touched: another command's results
  (:func:`refuse_other_owner`); anything washbench did not write; a ``run`` of a manoeuvre that a suite in that
  folder holds (the suite's ``report.md``, ``ranking.csv`` and ``suite.json`` would go on describing a result that
  is gone); an ``--out`` inside another result folder (:func:`refuse_nested`: the next command there would find a
  stranger in its folder).

What "washbench wrote this folder" means is :func:`folder_owner`'s: a manifest ``.washbench.json`` names its
command, a suite's ``suite.json`` says ``suite``, and ``OUT/<aircraft>/<manoeuvre>/run.json`` says ``run``.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
from pathlib import Path

from washbench.errors import WashbenchError, located, printable
from washbench.io.result_files import MANIFEST, RUN_FILE, SUITE_FILE, is_own_hidden


def announce(text: str) -> None:
    """One line on standard error, ``washbench: note: TEXT``: what a command is about to replace."""
    print(f"washbench: note: {printable(text)}", file=sys.stderr, flush=True)


def read_manifest(out_dir: Path) -> tuple[str, list[str]] | None:
    """(command, top-level names) from ``out_dir/.washbench.json``, or None if missing or not washbench's."""
    path = out_dir / MANIFEST
    if path.is_symlink() or not path.is_file():
        return None
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict) or not isinstance(doc.get("command"), str) or not isinstance(doc.get("entries"), list):
        return None
    names = [n for n in doc["entries"] if isinstance(n, str) and "/" not in n and n not in ("", ".", "..")]
    return doc["command"], names


def folder_owner(out_dir: Path) -> tuple[str, Path] | None:
    """Which command's results ``out_dir`` holds, and the file that says so; None if no command's.

    The one meaning of "washbench wrote this folder", for every command: a manifest ``.washbench.json`` names its
    command (``cue``, ``fly``, ``omct``, ``sweep``, ``tune``); a suite's ``suite.json`` says ``suite``; a folder
    ``OUT/<aircraft>/<manoeuvre>/`` holding ``run.json`` says ``run`` (a run's results gather in ``OUT`` beside
    other runs, and a suite replaces them, so ``run`` and ``suite`` share a folder).
    """
    manifest = read_manifest(out_dir)
    if manifest is not None:
        return manifest[0], out_dir / MANIFEST
    suite = out_dir / SUITE_FILE
    if suite.is_file() and not suite.is_symlink():
        with contextlib.suppress(OSError, ValueError):
            doc = json.loads(suite.read_text(encoding="utf-8"))
            if isinstance(doc, dict) and doc.get("washbench") == "suite":
                return "suite", suite
    try:
        tops = sorted(e for e in out_dir.iterdir() if e.is_dir() and not e.is_symlink() and not is_own_hidden(e.name))
    except OSError:
        return None
    for top in tops:
        with contextlib.suppress(OSError):
            for sub in sorted(top.iterdir()):
                marker = sub / RUN_FILE
                if sub.is_dir() and not sub.is_symlink() and marker.is_file() and not marker.is_symlink():
                    return "run", marker
    return None


def refuse_other_owner(out_dir: Path, command: str) -> None:
    """Raise WashbenchError (one line, naming the command and the file that says so) when ``out_dir`` holds the
    results of a command whose results ``command``'s would not replace (:func:`folder_owner`).

    A folder holds one command's results; ``run`` and ``suite`` share one (a suite is a set of runs).
    """
    owner = folder_owner(out_dir)
    if owner is None:
        return
    sharing = {"run", "suite"}
    if owner[0] == command or (owner[0] in sharing and command in sharing):
        return
    problem = (
        f"holds the results of `washbench {owner[0]}` ({owner[1].name}), not of `washbench {command}`: a folder "
        "holds one command's results (run and suite share one); not replaced; choose another --out"
    )
    raise WashbenchError(located(out_dir, problem))


def _marker_owner(folder: Path) -> tuple[str, Path] | None:
    """Which command's result folder ``folder`` itself is, by a marker file in it (not in its sub-folders): a
    manifest names its command, ``suite.json`` says ``suite``, a run's ``run.json`` says ``run``."""
    manifest = read_manifest(folder)
    if manifest is not None:
        return manifest[0], folder / MANIFEST
    for name, key, value in ((SUITE_FILE, "washbench", "suite"), (RUN_FILE, "manoeuvre", None)):
        marker = folder / name
        if marker.is_symlink() or not marker.is_file():
            continue
        with contextlib.suppress(OSError, ValueError):
            doc = json.loads(marker.read_text(encoding="utf-8"))
            if isinstance(doc, dict) and key in doc and (value is None or doc[key] == value):
                return ("suite" if name == SUITE_FILE else "run"), marker
    return None


def enclosing_result(out_dir: str | Path) -> tuple[Path, str, Path] | None:
    """The result folder that ``out_dir`` lies inside (a folder above it that is a command's results, by its marker
    file): ``(folder, command, marker)``, the nearest; None when there is none."""
    for parent in Path(os.path.abspath(out_dir)).parents:
        owner = _marker_owner(parent)
        if owner is not None:
            return parent, owner[0], owner[1]
    return None


def refuse_nested(out_dir: str | Path, command: str) -> None:
    """WashbenchError (one line) when ``out_dir`` lies inside another result folder (:func:`enclosing_result`):
    a result is never written inside another, where the next command into the outer folder finds a stranger (a
    suite's ``results/c172p`` is not a results folder of its own)."""
    found = enclosing_result(out_dir)
    if found is None:
        return
    folder, owner, marker = found
    if not Path(out_dir).is_absolute():  # named as the user named --out
        folder = Path(os.path.relpath(folder))
    same = owner == command or {owner, command} <= {"run", "suite"}
    instead = f"--out {folder} itself, or a folder outside it" if same else f"a folder outside {folder}"
    problem = (
        f"lies inside the results of `washbench {owner}` in {folder} ({marker.name}): results are never written "
        f"inside other results; choose {instead}"
    )
    raise WashbenchError(located(out_dir, problem))


def suite_holding(place: Path) -> Path | None:
    """The ``suite.json`` of a suite in ``OUT`` when ``place`` (``OUT/<aircraft>/<manoeuvre>``, a run's result
    folder) is, or holds, one of that suite's results; else None."""
    out = place.parent.parent
    marker = out / SUITE_FILE
    if marker.is_symlink() or not marker.is_file():
        return None
    try:
        doc = json.loads(marker.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict) or doc.get("washbench") != "suite" or not isinstance(doc.get("manoeuvres"), list):
        return None
    rel = f"{place.parent.name}/{place.name}"
    results = [e.get("result") for e in doc["manoeuvres"] if isinstance(e, dict)]
    held = any(isinstance(r, str) and (r == rel or r.startswith(rel + "/")) for r in results)
    return marker if held else None
