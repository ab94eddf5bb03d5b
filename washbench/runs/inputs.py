"""The inputs of a suite or a study: manoeuvre files and JSBSim scripts found in files and folders, and the check
that no two of them would write the same result folder."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.flight.scripts import is_runscript, is_script, load_script_info
from washbench.io.paths import MANOEUVRES_DIR, resolve_manoeuvre, unknown_manoeuvre


def find_manoeuvres(inputs: Sequence[Path], scripts: Sequence[Path] = ()) -> list[Path]:
    """Manoeuvre files and JSBSim scripts from files and folders (folders are searched recursively for
    ``*.yaml`` manoeuvres and ``*.xml`` JSBSim scripts), then ``scripts``; no inputs at all: the bundled
    manoeuvres."""

    if not inputs and not scripts:
        inputs = [MANOEUVRES_DIR]
    found: list[Path] = []
    for item in map(resolve_manoeuvre, inputs):
        if item.is_dir():
            found.extend(sorted(p for p in item.rglob("*.yaml") if p.is_file()))
            found.extend(sorted(p for p in item.rglob("*.xml") if p.is_file() and is_runscript(p)))
        elif item.is_file():
            found.append(item)
        else:
            raise unknown_manoeuvre(item)
    found.extend(scripts)
    unique = list(dict.fromkeys(p.resolve() for p in found))
    if not unique:
        raise WashbenchError(located(inputs[0], "no manoeuvre files (*.yaml) or JSBSim scripts (*.xml) found"))
    return unique


def check_unique_names(files: Sequence[Path], aircraft_dirs: Sequence[Path] = ()) -> None:
    """Refuse two manoeuvre files with the same aircraft and name (they would share a result folder).

    Files that do not load are left for the run to report. Raises WashbenchError naming both files.
    """

    seen: dict[tuple[str, str], Path] = {}
    for path in files:
        try:
            if is_script(path):  # a JSBSim script's result folder is named after its file
                info = load_script_info(path, aircraft_dirs)
                key, where = (info.aircraft, info.name), f"{path}: the script's file name:"
            else:
                m = load_manoeuvre(path, aircraft_dirs)
                key, where = (m.aircraft, m.name), m.located(("name",), "")[:-1]
        except WashbenchError:
            continue
        if key in seen:
            raise WashbenchError(
                f"{where} '{key[1]}' ({key[0]}) is also the name of {seen[key]}: both would write "
                f"{key[0]}/{key[1]}/; give each its own name"
            )
        seen[key] = path
