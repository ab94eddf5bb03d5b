"""Where washbench finds its files: the bundled package data and the user's own aircraft and pilot profiles.

Bundled files: the parameter set and platform limits live in ``washbench/data/``; the aircraft and the
manoeuvres live at the repository root (``aircraft/``, ``manoeuvres/``, beside ``washbench/``, where a user
looks for them), and the wheel carries copies of them as ``washbench/data/aircraft`` and
``washbench/data/manoeuvres`` (``setup.py`` copies them at build time). :func:`bundled_folder` picks the
installed copy when there is one and the checkout's folder otherwise, so an editable checkout and an
installed wheel behave the same from any folder.

A user's aircraft (``<folder>/<name>/<name>.xml`` with its ``Engines/`` and ``Systems/``) is searched, in this
order:

1. the folders given with ``--aircraft-dir DIR`` (repeatable), in the order given;
2. the folders in the ``WASHBENCH_AIRCRAFT_PATH`` environment variable (``os.pathsep``-separated);
3. an ``aircraft/`` folder next to the manoeuvre file or in one of its parents, up to the project root (the
   first parent that holds ``.git``, ``pyproject.toml`` or ``.washbench``; the filesystem root if none does);
4. the bundled aircraft (``aircraft/`` of the checkout, ``washbench/data/aircraft`` in the wheel);
5. JSBSim's own models (``<jsbsim package>/aircraft``).

A pilot profile is, in this order: the file named by the manoeuvre's ``pilot_profile`` key (relative to the
manoeuvre file); ``<folder>/<name>/pilot.yaml`` in the same folders as above, in the same order (so a profile
can sit next to the user's copy of an aircraft, or alone in ``aircraft/<name>/pilot.yaml`` for a JSBSim model);
the bundled profiles are the ``pilot.yaml`` files of the bundled aircraft folders (``aircraft/<name>/pilot.yaml``).
Errors for an unknown aircraft or a missing profile list every place searched.
"""

from __future__ import annotations

import importlib.util
import os
from collections.abc import Sequence
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

from washbench.errors import WashbenchError

#: ``washbench/data``: the bundled parameter set (``cw1.yaml``) and platform files (``atlas.yaml``, ...).
DATA_DIR = Path(str(files("washbench") / "data"))
#: The bundled platform files, ``washbench/data/<name>.yaml``: ``--platform hexapod`` names one from any folder.
BUNDLED_PLATFORMS = ("atlas", "hexapod", "rig2dof")
#: The bundled washout parameter files, ``washbench/data/<name>.yaml``: ``--params cw1``.
BUNDLED_PARAMS = ("cw1",)
#: Top-level folders of the repository that the wheel ships as ``washbench/data/<name>`` (see ``setup.py``).
BUNDLED_FOLDERS = ("aircraft", "manoeuvres", "tasks")


def bundled_folder(name: str) -> Path:
    """A bundled top-level folder: the wheel's ``washbench/data/<name>``, else the checkout's ``<repo>/<name>``."""
    installed = DATA_DIR / name
    if installed.is_dir():
        return installed
    return DATA_DIR.parent.parent / name


#: Bundled aircraft models (``<name>/<name>.xml``) and pilot profiles (``<name>/pilot.yaml``).
AIRCRAFT_DIR = bundled_folder("aircraft")
#: Bundled manoeuvres (``<aircraft>/<name>.yaml``): what ``washbench suite`` runs by default.
MANOEUVRES_DIR = bundled_folder("manoeuvres")
#: Bundled tracking tasks (``<aircraft>/<name>.yaml``): what ``washbench track`` flies by name (c172/roll).
TASKS_DIR = bundled_folder("tasks")
#: Environment variable with extra aircraft folders, separated by ``os.pathsep``.
AIRCRAFT_PATH_ENV = "WASHBENCH_AIRCRAFT_PATH"
#: Files or folders that mark a project root (where the search for ``aircraft/`` next to a manoeuvre stops).
PROJECT_MARKERS = (".git", "pyproject.toml", ".washbench")
#: File name of a pilot profile inside an aircraft folder.
PROFILE_NAME = "pilot.yaml"


def jsbsim_root() -> Path:
    """The folder of the installed jsbsim package (its ``aircraft/``, ``engine/``, ``systems/``, ``scripts/``).

    Found without importing jsbsim (validation and ``--version`` stay fast).
    """
    spec = importlib.util.find_spec("jsbsim")
    if spec is None or spec.origin is None:  # pragma: no cover - jsbsim is a dependency
        raise WashbenchError("the jsbsim package is not installed")
    return Path(spec.origin).resolve().parent


@dataclass(frozen=True)
class SearchPlace:
    """One folder of the search path and why it is on it (for error messages)."""

    folder: Path
    why: str


def _project_folders(manoeuvre_file: Path) -> list[Path]:
    """``aircraft/`` next to the manoeuvre file and in each parent up to the project root."""
    out = []
    for parent in Path(os.path.abspath(manoeuvre_file)).parents:
        out.append(parent / "aircraft")
        if any((parent / marker).exists() for marker in PROJECT_MARKERS):
            break
    return out


def search_places(manoeuvre_file: Path | None = None, aircraft_dirs: Sequence[Path] = ()) -> list[SearchPlace]:
    """The aircraft search path, in order (see the module docstring); folders that do not exist included."""
    places = [SearchPlace(Path(os.path.abspath(d)), "--aircraft-dir") for d in aircraft_dirs]
    env = os.environ.get(AIRCRAFT_PATH_ENV, "")
    places += [SearchPlace(Path(os.path.abspath(d)), AIRCRAFT_PATH_ENV) for d in env.split(os.pathsep) if d]
    if manoeuvre_file is not None:
        places += [SearchPlace(p, "next to the manoeuvre") for p in _project_folders(manoeuvre_file)]
    places.append(SearchPlace(AIRCRAFT_DIR, "bundled"))
    places.append(SearchPlace(jsbsim_root() / "aircraft", "JSBSim"))
    return places


def _listing(places: Sequence[SearchPlace]) -> str:
    """``why: folder, folder; why: folder`` in search order (one line)."""
    groups: dict[str, list[str]] = {}
    for p in places:
        groups.setdefault(p.why, []).append(str(p.folder))
    return "; ".join(f"{why}: {', '.join(folders)}" for why, folders in groups.items())


@dataclass(frozen=True)
class AircraftFiles:
    """Where one manoeuvre's aircraft model and pilot profile were found.

    ``root`` is the folder given to JSBSim's ``set_aircraft_path`` (it holds ``<name>/<name>.xml``).
    """

    name: str
    root: Path
    profile: Path

    @property
    def model_dir(self) -> Path:
        """``<root>/<name>``: the model's own folder (``Engines/``, ``Systems/``)."""
        return self.root / self.name


def find_aircraft(name: str, manoeuvre_file: Path | None = None, aircraft_dirs: Sequence[Path] = ()) -> Path:
    """The folder holding ``<name>/<name>.xml``, first along the search path.

    Raises WashbenchError listing every place searched when none holds the model.
    """
    places = search_places(manoeuvre_file, aircraft_dirs)
    for place in places:
        if (place.folder / name / f"{name}.xml").is_file():
            return place.folder
    raise WashbenchError(
        f"unknown aircraft '{name}': no {name}/{name}.xml in the searched folders ({_listing(places)})"
    )


def find_profile(
    name: str,
    manoeuvre_file: Path | None = None,
    aircraft_dirs: Sequence[Path] = (),
    pilot_profile: str | None = None,
) -> Path:
    """The pilot profile for aircraft ``name``: the manoeuvre's ``pilot_profile`` or ``<folder>/<name>/pilot.yaml``.

    ``pilot_profile`` is relative to the manoeuvre file (or absolute). Raises WashbenchError listing every place
    searched when no profile exists.
    """
    if pilot_profile is not None:
        base = Path(os.path.abspath(manoeuvre_file)).parent if manoeuvre_file is not None else Path.cwd()
        path = base / pilot_profile
        if path.is_file():
            return path
        raise WashbenchError(f"pilot_profile: no such file {path}")
    places = search_places(manoeuvre_file, aircraft_dirs)
    for place in places:
        path = place.folder / name / PROFILE_NAME
        if path.is_file():
            return path
    raise WashbenchError(
        f"no scripted-pilot profile for '{name}': no {name}/{PROFILE_NAME} in the searched folders "
        f"({_listing(places)}) "
        "(or name one with 'pilot_profile:' in the manoeuvre file)"
    )


def find_aircraft_files(
    name: str,
    manoeuvre_file: Path | None = None,
    aircraft_dirs: Sequence[Path] = (),
    pilot_profile: str | None = None,
) -> AircraftFiles:
    """Model folder and pilot profile of one manoeuvre's aircraft (see :func:`find_aircraft`, :func:`find_profile`)."""
    root = find_aircraft(name, manoeuvre_file, aircraft_dirs)
    return AircraftFiles(name, root, find_profile(name, manoeuvre_file, aircraft_dirs, pilot_profile))


def bundled_names() -> list[str]:
    """Names of the bundled manoeuvres, ``<aircraft>/<name>`` (what :func:`resolve_manoeuvre` accepts)."""
    return sorted(p.relative_to(MANOEUVRES_DIR).with_suffix("").as_posix() for p in MANOEUVRES_DIR.glob("*/*.yaml"))


def bundled_file(text: str | Path) -> Path | None:
    """The file a bundled name stands for, as the provenance spells it
    (:func:`washbench.io.provenance.bundled_name`): ``washbench:data/hexapod.yaml``,
    ``washbench:manoeuvres/c172/takeoff.yaml``, ``washbench:aircraft/c172p/pilot.yaml``, ``jsbsim:scripts/c1723.xml``;
    None for any other text (a path). The file need not exist."""
    package, sep, rel = str(text).partition(":")
    if not sep or not rel or rel.startswith("/") or ".." in Path(rel).parts:
        return None
    if package == "jsbsim":
        return jsbsim_root() / rel
    if package != "washbench":
        return None
    top, _, rest = rel.partition("/")
    roots = {"data": DATA_DIR, "aircraft": AIRCRAFT_DIR, "manoeuvres": MANOEUVRES_DIR}
    return roots[top] / rest if top in roots and rest else None


def _script_names() -> list[str]:
    """The ``*.xml`` files in JSBSim's ``scripts/`` folder, by stem (names ``washbench run`` resolves)."""
    return sorted(p.stem for p in (jsbsim_root() / "scripts").glob("*.xml"))


def resolve_manoeuvre(item: Path) -> Path:
    """A manoeuvre argument as given, or, when no such file or folder exists, the bundled one of that name.

    ``c172/takeoff`` (or ``c172/takeoff.yaml``) names a bundled manoeuvre and ``c172`` the bundled folder of an
    aircraft, ``c1723`` (or ``c1723.xml``) a script shipped with JSBSim, and the provenance's spelling
    (``washbench:manoeuvres/c172/takeoff.yaml``, ``jsbsim:scripts/c1723.xml``) either, so ``washbench run
    c172/takeoff`` works from any folder. An existing path always wins; a name found nowhere is returned as given
    (:func:`unknown_manoeuvre` says what was meant).
    """
    if item.exists() or item.is_absolute():
        return item
    named = bundled_file(item)
    if named is not None:
        return named
    for candidate in (MANOEUVRES_DIR / item, MANOEUVRES_DIR / f"{item}.yaml"):
        if candidate.exists():
            return candidate
    if len(item.parts) == 1 and item.suffix.lower() in ("", ".xml"):
        script = jsbsim_root() / "scripts" / f"{item.name[:-4] if item.suffix else item.name}.xml"
        if script.is_file():
            return script
    return item


def unknown_manoeuvre(item: Path) -> WashbenchError:
    """The error for a manoeuvre argument that names nothing (:func:`resolve_manoeuvre` found no file, folder or
    bundled name): one line with the closest bundled manoeuvres or JSBSim scripts, else the bundled names."""
    import difflib

    text = str(item)
    if item.is_absolute():  # a path, plainly: no name was meant
        return WashbenchError(f"{text}: no such file or folder")
    stem = text[:-5] if text.endswith(".yaml") else text[:-4] if text.endswith(".xml") else text
    names = bundled_names()
    close = difflib.get_close_matches(stem, [*names, *_script_names()], n=3, cutoff=0.75)
    if close:
        hint = f"did you mean {' or '.join(close)}?"
    else:
        hint = f"the bundled ones: {', '.join(names)}; or a script shipped with JSBSim by name (c1723)"
    return WashbenchError(f"{text}: no such file or folder, nor a bundled manoeuvre; {hint}")


def resolve_data_file(item: Path, option: str) -> Path:
    """A ``--platform`` or ``--params`` value: an existing file as given; else a bundled file, by the provenance's
    name (``washbench:data/hexapod.yaml``) or by its own (``hexapod``, ``hexapod.yaml``; the names of
    :data:`BUNDLED_PLATFORMS` or :data:`BUNDLED_PARAMS`), so the bundled files are named the same from any folder
    and from an installed wheel. WashbenchError (one line, what the option takes) for anything else, and for a Python
    file (a plugin is loaded with ``--platform-plugin`` / ``--washout-plugin``)."""
    names = BUNDLED_PLATFORMS if option == "--platform" else BUNDLED_PARAMS
    text = str(item)
    if item.suffix == ".py":
        plugin = "--platform-plugin" if option == "--platform" else "--washout-plugin"
        raise WashbenchError(f"{option} {text}: a Python file; {option} takes a YAML file or a bundled name "
                             f"({', '.join(names)}); load a plugin with {plugin} {text}:CLASS")  # fmt: skip
    if item.is_file():
        return item
    named = bundled_file(item)
    if named is None and len(item.parts) == 1 and item.suffix in ("", ".yaml"):
        stem = item.name[:-5] if item.suffix else item.name
        named = DATA_DIR / f"{stem}.yaml" if stem in names else None
    if named is not None and named.is_file():
        return named
    if item.exists() and not item.is_dir():
        return item  # not a regular file (a fifo, a device): reading it says what is wrong
    problem = "a folder, not a file" if item.is_dir() else "no such file"
    stem = item.name[:-5] if item.name.endswith(".yaml") else item.name
    hint = f"; did you mean {option} {stem}?" if stem in names and named is None else ""
    raise WashbenchError(f"{option} {text}: {problem}, nor a bundled name ({', '.join(names)}; or "
                         f"washbench:data/NAME.yaml){hint}")  # fmt: skip


def resolve_task(item: Path) -> Path:
    """A task argument as given, or, when no such file exists, the bundled one of that name (``c172/roll``)."""
    if item.exists() or item.is_absolute():
        return item
    for candidate in (TASKS_DIR / item, TASKS_DIR / f"{item}.yaml"):
        if candidate.is_file():
            return candidate
    return item


def plugin_file(spec: str, option: str) -> tuple[str, Path, str]:
    """A plugin given as ``FILE.py:NAME`` to ``option`` (``--washout-plugin``, ``--platform-plugin``): the text that
    names it in errors (``OPTION SPEC``), the file resolved to an absolute path (worker processes load the same file)
    and NAME. WashbenchError (one line) when the text has no ``:``, or the file does not exist."""
    text = str(spec)
    file, sep, name = text.rpartition(":")
    where = f"{option} {text}"
    if not sep or not file or not name:
        raise WashbenchError(f"{where}: expected FILE.py:NAME")
    path = Path(file).expanduser()
    if not path.is_file():
        raise WashbenchError(f"{where}: {path}: no such file")
    return where, path.resolve(), name
