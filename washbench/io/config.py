"""The project configuration file: defaults for ``--params``, ``--platform``, ``--aircraft-dir``, ``--out``, ``--jobs``.

Found the way ruff and pytest find theirs: from the current folder upwards, the first folder holding a
``washbench.toml``, or a ``pyproject.toml`` with a ``[tool.washbench]`` table (``washbench.toml`` wins when a folder
holds both; a ``pyproject.toml`` without the table is passed over). The keys are the options' names::

    # washbench.toml (or [tool.washbench] in pyproject.toml)
    params = "params/my_cw.yaml"        # --params: a file, relative to this file's folder (or a bundled name: cw1)
    platform = "hexapod"                # --platform: the same (a bundled name: atlas, hexapod, rig2dof)
    aircraft-dir = ["aircraft", "/opt/jsbsim-models"]   # --aircraft-dir (a folder or a list of folders)
    out = "results"                     # --out of run, suite, cue, fly, omct, sweep, tune (run and suite share a
                                        # folder; the others each need their own: io.outfolder.folder_owner)
    jobs = 4                            # --jobs (suite, sweep, tune)

A flag given on the command line wins over the file (``--aircraft-dir`` given at all replaces the file's list).
Each key applies to the commands that have that option. The file used is recorded in every result's provenance
(``config``: its path and SHA-256). A bad key or value is one line naming the file, the line and the key, exit
status 2, before anything runs.

Read safely (round three of the hardening, ``docs/hardening.md``): at most :data:`MAX_CONFIG_BYTES`; a UTF-8 byte
order mark is accepted; tables or arrays nested too deeply for the TOML reader, a NUL or another control character
in a path, an unreadable folder on the way up: one line naming the file. The file used is named on stderr
(``washbench: note: configuration from FILE``). As git's ``safe.directory``: a file found upwards that another
user owns (the file or its folder; root excepted) is not used, and a warning names it; trust it with
``WASHBENCH_SAFE_CONFIG=FILE`` (a list separated by ``os.pathsep``, or ``*`` for any).
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

from washbench.errors import WashbenchError, printable
from washbench.io.paths import BUNDLED_PARAMS, BUNDLED_PLATFORMS, resolve_data_file

#: File names, in the order they are tried in each folder.
CONFIG_NAME = "washbench.toml"
PYPROJECT_NAME = "pyproject.toml"
#: The keys a configuration file may hold (the options' names, without ``--``).
KEYS = ("params", "platform", "aircraft-dir", "out", "jobs")
#: Commands whose ``--out`` is a results folder (``signal`` and ``schema`` write one file: no default for them).
OUT_COMMANDS = frozenset({"run", "suite", "cue", "fly", "omct", "sweep", "tune"})
#: Environment variable through which the command tells its worker processes which file it used (provenance).
CONFIG_USED_ENV = "WASHBENCH_CONFIG_USED"
#: Environment variable naming configuration files owned by another user that may be used anyway (``*``: any).
SAFE_CONFIG_ENV = "WASHBENCH_SAFE_CONFIG"
#: Bytes of a configuration file read at most (the YAML files' bound, :data:`washbench.io.budget.MAX_YAML_BYTES`).
MAX_CONFIG_BYTES = 10 * 1024 * 1024


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

    None when no folder from ``start`` up to the filesystem root holds one. WashbenchError (one line) when a folder
    on the way cannot be searched.
    """
    for folder in (start, *start.parents):
        candidate = folder / CONFIG_NAME
        if _is_file(candidate):
            return candidate, ""
        candidate = folder / PYPROJECT_NAME
        if _is_file(candidate) and _has_tool_table(candidate):
            return candidate, "tool.washbench"
    return None


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except OSError as exc:  # a folder on the way that may not be searched
        raise WashbenchError(f"{path}: cannot look for a configuration file: {exc.strerror or exc}") from None


def foreign_owner(path: Path) -> int | None:
    """The uid of the other user who owns ``path`` or its folder (not this process's user, not root), else None."""
    me = os.geteuid() if hasattr(os, "geteuid") else None
    if me is None:  # no owners to compare (Windows)
        return None
    for p in (path, path.parent):
        try:
            uid = p.stat().st_uid
        except OSError:
            continue
        if uid not in (me, 0):
            return uid
    return None


def trusted(path: Path) -> bool:
    """Whether ``path`` is listed in ``WASHBENCH_SAFE_CONFIG`` (or that holds ``*``)."""
    listed = [p for p in os.environ.get(SAFE_CONFIG_ENV, "").split(os.pathsep) if p]
    return "*" in listed or any(os.path.abspath(p) == os.path.abspath(path) for p in listed)


def read_config_text(path: Path) -> str:
    """The text of a configuration file: at most :data:`MAX_CONFIG_BYTES`, UTF-8 (a byte order mark dropped);
    WashbenchError naming the file otherwise."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise WashbenchError(f"{path}: cannot read the configuration file: {exc.strerror or exc}") from None
    if len(data) > MAX_CONFIG_BYTES:
        raise WashbenchError(f"{path}: larger than {MAX_CONFIG_BYTES // (1024 * 1024)} MB: not a configuration file")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise WashbenchError(f"{path}: cannot read the configuration file: not UTF-8 text ({exc.reason} at byte "
                             f"{exc.start})") from None  # fmt: skip


def parse_toml(text: str, path: Path) -> Any:
    """``tomllib.loads(text)``; WashbenchError ``FILE:LINE: not valid TOML`` or ``nested too deeply``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = re.search(r"line (\d+)", str(exc))
        raise WashbenchError(f"{path}:{line.group(1) if line else 1}: not valid TOML: {exc}") from None
    except RecursionError:
        raise WashbenchError(f"{path}: not valid TOML for washbench: arrays or tables nested too deeply") from None


def _has_tool_table(path: Path) -> bool:
    """Whether a pyproject.toml has a ``[tool.washbench]`` table (an unreadable one, or one another tool's tables
    make unreadable, is reported when loaded if it seems to hold the table)."""
    try:
        text = read_config_text(path)
    except WashbenchError:
        return "[tool.washbench]" in _head(path)
    try:
        data = parse_toml(text, path)
    except WashbenchError:
        return "[tool.washbench]" in text
    return isinstance(data.get("tool"), dict) and "washbench" in data["tool"]


def _head(path: Path) -> str:
    """The first :data:`MAX_CONFIG_BYTES` of ``path`` as text (errors replaced), ``""`` if it cannot be read."""
    try:
        with open(path, "rb") as fh:
            return fh.read(MAX_CONFIG_BYTES).decode("utf-8", errors="replace")
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
    text = read_config_text(path)
    data: Any = parse_toml(text, path)
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
            raise fail(key, f"expected a path (a string), got {printable(repr(value))[:80]}")
        if any(ord(c) < 0x20 or ord(c) == 0x7F for c in value):
            raise fail(key, f"a path with a control character (NUL, newline, escape): {printable(value)!r}")
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
        if key in ("params", "platform"):  # a file relative to this one, else a bundled name (hexapod)
            values[key] = a_path(key, value, want_file=False)
            if not values[key].is_file():
                try:
                    values[key] = resolve_data_file(Path(value), f"--{key}")
                except WashbenchError:
                    names = ", ".join(BUNDLED_PLATFORMS if key == "platform" else BUNDLED_PARAMS)
                    raise fail(key, f"no such file {values[key]}, nor a bundled name ({names})") from None
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


def discover(cwd: Path | None = None, notes: list[str] | None = None) -> ProjectConfig | None:
    """The configuration that applies in ``cwd`` (default: the current folder), read and checked; None if none.

    A file another user owns is not used (unless trusted, :func:`trusted`): None, and a warning appended to
    ``notes``. WashbenchError (one line naming the file) for anything wrong with the file that applies.
    """
    found = find_config(Path(os.path.abspath(cwd if cwd is not None else Path.cwd())))
    if not found:
        return None
    uid = foreign_owner(found[0])
    if uid is not None and not trusted(found[0]):
        if notes is not None:
            notes.append(f"{printable(str(found[0]))} belongs to another user (uid {uid}): not used (as git's "
                         f"safe.directory; to use it: {SAFE_CONFIG_ENV}={printable(str(found[0]))})")  # fmt: skip
        return None
    return load_config(*found)


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
