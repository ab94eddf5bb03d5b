"""The project configuration file: defaults for ``--params``, ``--platform``, ``--aircraft-dir``, ``--out``, ``--jobs``.

Found the way ruff and pytest find theirs: from the current folder upwards, the first folder holding a
``washbench.toml``, or a ``pyproject.toml`` with a ``[tool.washbench]`` table (``washbench.toml`` wins when a folder
holds both; a ``pyproject.toml`` without the table is passed over). The keys are the options' names::

    # washbench.toml (or [tool.washbench] in pyproject.toml)
    params = "params/my_cw.yaml"        # --params: a file, relative to this file's folder
    platform = "params/my_atlas.yaml"   # --platform
    aircraft-dir = ["aircraft", "/opt/jsbsim-models"]   # --aircraft-dir (a folder or a list of folders)
    out = "results"                     # --out of run, suite, cue, fly, omct, sweep, tune (run and suite share a
                                        # folder; the others each need their own: io.outfolder.folder_owner)
    jobs = 4                            # --jobs (suite, sweep, tune)

A flag given on the command line wins over the file (``--aircraft-dir`` given at all replaces the file's list).
Each key applies to the commands that have that option. The file used is recorded in every result's provenance
(``config``: its path and SHA-256). A bad key or value is one line naming the file, the line and the key, exit
status 2, before anything runs.
"""

from __future__ import annotations

import difflib
import os
import re
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from washbench.errors import WashbenchError

#: File names, in the order they are tried in each folder.
CONFIG_NAME = "washbench.toml"
PYPROJECT_NAME = "pyproject.toml"
#: The keys a configuration file may hold (the options' names, without ``--``).
KEYS = ("params", "platform", "aircraft-dir", "out", "jobs")
#: Commands whose ``--out`` is a results folder (``signal`` and ``schema`` write one file: no default for them).
OUT_COMMANDS = frozenset({"run", "suite", "cue", "fly", "omct", "sweep", "tune"})
#: Environment variable through which the command tells its worker processes which file it used (provenance).
CONFIG_USED_ENV = "WASHBENCH_CONFIG_USED"


@dataclass(frozen=True)
class ProjectConfig:
    """The defaults read from one configuration file (None: not set there); paths are absolute."""

    path: Path
    params: Path | None = None
    platform: Path | None = None
    aircraft_dirs: tuple[Path, ...] = field(default_factory=tuple)
    out: Path | None = None
    jobs: int | None = None


def find_config(start: Path) -> tuple[Path, str] | None:
    """The configuration file that applies in folder ``start``: ``(path, table)``, table ``""`` or ``"tool.washbench"``.

    None when no folder from ``start`` up to the filesystem root holds one.
    """
    for folder in (start, *start.parents):
        candidate = folder / CONFIG_NAME
        if candidate.is_file():
            return candidate, ""
        candidate = folder / PYPROJECT_NAME
        if candidate.is_file() and _has_tool_table(candidate):
            return candidate, "tool.washbench"
    return None


def _has_tool_table(path: Path) -> bool:
    """Whether a pyproject.toml has a ``[tool.washbench]`` table (an unreadable one is reported when loaded)."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return "[tool.washbench]" in _text_or_empty(path)
    return isinstance(data.get("tool"), dict) and "washbench" in data["tool"]


def _text_or_empty(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""


_HEADER = re.compile(r"^\s*\[\s*([^\[\]]+?)\s*\]\s*(#.*)?$")


def _key_line(text: str, table: str, key: str) -> int:
    """1-based line of ``key = ...`` inside ``[table]`` (``""``: before any table); the table's line if not found."""
    current = ""
    table_line = 1
    pattern = re.compile(rf"^\s*(\"{re.escape(key)}\"|'{re.escape(key)}'|{re.escape(key)})\s*=")
    for number, line in enumerate(text.splitlines(), start=1):
        header = _HEADER.match(line)
        if header:
            current = re.sub(r"\s*\.\s*", ".", header.group(1)).replace('"', "")
            if current == table:
                table_line = number
            continue
        if current == table and pattern.match(line):
            return number
    return table_line


def load_config(path: Path, table: str = "") -> ProjectConfig:
    """Read and check one configuration file (``table``: ``"tool.washbench"`` for a pyproject.toml).

    Raises WashbenchError ``file:line: key: problem`` for bad TOML, an unknown key or a bad value.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise WashbenchError(f"{path}: cannot read the configuration file: {exc}") from None
    try:
        data: Any = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = re.search(r"line (\d+)", str(exc))
        raise WashbenchError(f"{path}:{line.group(1) if line else 1}: not valid TOML: {exc}") from None
    prefix = f"{table}." if table else ""
    for part in table.split(".") if table else ():
        data = data.get(part, {})
    if not isinstance(data, dict):
        raise WashbenchError(f"{path}:{_key_line(text, '', table)}: {table}: expected a table")
    base = path.parent

    def fail(key: str, problem: str) -> WashbenchError:
        return WashbenchError(f"{path}:{_key_line(text, table, key)}: {prefix}{key}: {problem}")

    def a_path(key: str, value: Any, want_file: bool) -> Path:
        if not isinstance(value, str) or not value.strip():
            raise fail(key, f"expected a path (a string), got {value!r}")
        resolved = Path(os.path.abspath(base / os.path.expanduser(value)))
        if want_file and not resolved.is_file():
            raise fail(key, f"no such file {resolved}")
        return resolved

    values: dict[str, Any] = {}
    for key, value in data.items():
        if key not in KEYS:
            close = difflib.get_close_matches(key.replace("_", "-"), KEYS, n=1)
            hint = f"did you mean '{close[0]}'?" if close else f"valid keys: {', '.join(KEYS)}"
            raise fail(key, f"unknown key ({hint})")
        if key in ("params", "platform"):
            values[key] = a_path(key, value, want_file=True)
        elif key == "out":
            values["out"] = a_path(key, value, want_file=False)
        elif key == "aircraft-dir":
            items = [value] if isinstance(value, str) else value
            if not isinstance(items, list) or not items:
                raise fail(key, f"expected a folder or a list of folders, got {value!r}")
            dirs = tuple(a_path(key, item, want_file=False) for item in items)
            for d in dirs:
                if not d.is_dir():
                    raise fail(key, f"no such folder {d}")
            values["aircraft_dirs"] = dirs
        elif key == "jobs":
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise fail(key, f"expected a whole number of at least 1 process, got {value!r}")
            values["jobs"] = value
    return ProjectConfig(path=path, **values)


def discover(cwd: Path | None = None) -> ProjectConfig | None:
    """The configuration that applies in ``cwd`` (default: the current folder), read and checked; None if none."""
    found = find_config(Path(os.path.abspath(cwd if cwd is not None else Path.cwd())))
    return load_config(*found) if found else None


def defaults_for(config: ProjectConfig, command: str, dests: Sequence[str]) -> dict[str, Any]:
    """The argparse defaults ``config`` gives a command that has the options ``dests`` (argparse ``dest`` names)."""
    out: dict[str, Any] = {}
    if "params" in dests and config.params is not None:
        out["params"] = config.params
    if "platform" in dests and config.platform is not None:
        out["platform"] = config.platform
    if "aircraft_dir" in dests and config.aircraft_dirs:
        out["aircraft_dir"] = list(config.aircraft_dirs)
    if "out" in dests and command in OUT_COMMANDS and config.out is not None:
        out["out"] = config.out
    if "jobs" in dests and config.jobs is not None:
        out["jobs"] = config.jobs
    return out
