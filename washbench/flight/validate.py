"""``washbench validate``: check manoeuvre files and JSBSim scripts without flying them.

It takes what ``washbench suite`` takes: files, folders (searched recursively for ``*.yaml`` manoeuvres and
``*.xml`` JSBSim scripts, :func:`manoeuvre_files`) and bundled manoeuvres by name (``c172/takeoff``). A
manoeuvre is read and checked as ``run`` reads it (:func:`washbench.flight.manoeuvre.load_manoeuvre`, every
problem of the file, one line each); a JSBSim script as ``run`` reads its header
(:func:`washbench.flight.scripts.load_script_info`: well-formed XML, a ``<runscript>``, a known aircraft, a
``<run>`` with ``dt`` and ``end``).

Every problem of a file is reported: every field that does not fit the schema (a misspelt key, text where a number
belongs), or, once they all fit, every independent problem between fields (the first of each open-loop input, each
phase's holds and end conditions, each check). The checks between fields need the fields' values, so they wait for
the schema's problems to be fixed.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from washbench.errors import WashbenchError, located, printable
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.flight.scripts import is_runscript, is_script, load_script_info
from washbench.io.paths import resolve_manoeuvre, unknown_manoeuvre


def manoeuvre_files(item: Path) -> list[Path]:
    """The manoeuvre files and JSBSim scripts an argument names: the file itself (a missing one too: reading it
    says so), a folder's (recursively: ``*.yaml`` and the ``*.xml`` whose root is ``<runscript>``), or a bundled
    manoeuvre or folder by name. WashbenchError for a folder holding none."""
    item = resolve_manoeuvre(item)
    if not item.exists() and not item.is_symlink() and not item.is_absolute():
        raise unknown_manoeuvre(item)  # a name meant: the closest bundled ones
    if not item.is_dir():
        return [item]
    found = sorted(p for p in item.rglob("*.yaml") if p.is_file())
    found += sorted(p for p in item.rglob("*.xml") if p.is_file() and is_runscript(p))
    if not found:
        raise WashbenchError(located(item, "no manoeuvre files (*.yaml) or JSBSim scripts (*.xml) in this folder"))
    return found


def validate_command(paths: Sequence[Path], aircraft_dirs: Sequence[Path] = ()) -> int:
    """``washbench validate FILE|FOLDER...``: ``FILE: OK`` or every problem of the file, one line each; 2 if any
    file is bad (every file is checked)."""
    bad = 0
    files: list[Path | WashbenchError] = []
    for item in paths:
        try:
            files.extend(manoeuvre_files(item))
        except WashbenchError as exc:
            files.append(exc)
    for path in dict.fromkeys(files):
        try:
            if isinstance(path, WashbenchError):
                raise path
            if is_script(path):
                load_script_info(path, aircraft_dirs)
            else:
                load_manoeuvre(path, aircraft_dirs)
        except WashbenchError as exc:
            for problem in exc.problems:
                print(f"washbench: error: {printable(problem)}", file=sys.stderr)
            bad += 1
        else:
            print(f"{path}: OK")
    return 2 if bad else 0
