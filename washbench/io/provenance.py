"""Provenance: what produced a result, recorded in every result file that can hold it.

One JSON-able dict (:func:`build_provenance`) records

- ``software``: the versions of washbench (and its git commit when run from a work tree), JSBSim, rerun-sdk,
  numpy, scipy, pyarrow and Python;
- ``manoeuvre``: the manoeuvre file's path (as given) and SHA-256 (``washbench run`` / ``fly``), with the JSBSim
  model file (``aircraft``) and the scripted pilot's profile (``pilot_profile``) it was flown with; or ``input``: the
  recorded trace's path and SHA-256 (``washbench cue``), with the input's own provenance carried along when it
  has one (a ``flight.parquet`` written by ``washbench fly``);
- ``params`` and ``platform``: the parameter set's and platform's name (the ``name`` key of the YAML file), the path
  and SHA-256 of the file actually used (the bundled ``cw1.yaml`` / ``atlas.yaml`` when none was given) and the
  values read from it (so a result can be re-examined without the file);
- a file shipped with washbench or JSBSim is named as bundled, the same on every machine
  (``washbench:data/cw1.yaml``, ``jsbsim:aircraft/c172x/c172x.xml``, :func:`bundled_name`), with ``bundled``: the
  package and version; any other file by its path as given;
- ``washouts``: the washouts that ran, name and kind, and a variant's own parameter values; for a plugin, which
  code ran (``plugin``: its file or module, class, SHA-256, the installed entry point a file replaced, and its
  parameter values);
- ``turbulence``: severity and seed of the manoeuvre's turbulence (``None`` without turbulence);
- ``config``: the project configuration file the command found (``washbench.toml`` or a ``pyproject.toml`` with
  ``[tool.washbench]``, see :mod:`washbench.io.config`), its path and SHA-256; left out when there was none.

It goes into ``run.json`` (``"provenance"``, with the date ``"created_utc"`` beside it), the key-value metadata of
``traces.parquet`` and ``flight.parquet`` (key ``washbench.provenance``, JSON) and the report header. The date is
kept out of the Parquet files: same inputs give the same Parquet files, byte for byte.
"""

from __future__ import annotations

import datetime
import functools
import hashlib
import importlib.metadata
import json
import os
import platform as _platform
import subprocess
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from washbench.io.config import CONFIG_USED_ENV
from washbench.io.paths import AIRCRAFT_DIR, DATA_DIR, MANOEUVRES_DIR, jsbsim_root

PARQUET_KEY = b"washbench.provenance"
"""Key of the provenance JSON in a Parquet file's key-value metadata."""

_PACKAGES = (
    ("washbench", "washbench"),
    ("jsbsim", "jsbsim"),
    ("rerun", "rerun-sdk"),
    ("numpy", "numpy"),
    ("scipy", "scipy"),
    ("pyarrow", "pyarrow"),
)


def sha256_file(path: str | Path) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


@functools.lru_cache(maxsize=1)
def _git_commit() -> str | None:
    """The washbench work tree's commit, with ``-dirty`` when it has uncommitted changes; None outside git."""
    root = Path(__file__).resolve().parents[2]
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=5, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no", "--", "washbench"],
            capture_output=True,
            text=True,
            timeout=5,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return f"{head}-dirty" if dirty else head


@functools.lru_cache(maxsize=1)
def software_versions() -> dict[str, str]:
    """Installed versions of washbench and the packages that decide its numbers (read without importing them)."""
    out: dict[str, str] = {}
    for key, dist in _PACKAGES:
        try:
            out[key] = importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            out[key] = "not installed"
    commit = _git_commit()
    if commit:
        out["washbench_git"] = commit
    out["python"] = _platform.python_version()
    return out


def bundled_name(path: str | Path) -> tuple[str, str] | None:
    """``(package, name)`` of a file shipped with washbench or JSBSim, else None.

    A bundled file is named the same on every machine and in a checkout as in an installed wheel:
    ``washbench:data/cw1.yaml``, ``washbench:aircraft/c172p/pilot.yaml``, ``washbench:manoeuvres/c172/takeoff.yaml``,
    ``jsbsim:aircraft/c172x/c172x.xml`` (not the absolute path of the machine that made the result).
    """
    try:
        resolved = Path(path).resolve()
    except OSError:
        return None
    places = (("washbench", AIRCRAFT_DIR, "aircraft/"), ("washbench", MANOEUVRES_DIR, "manoeuvres/"),
              ("washbench", DATA_DIR, "data/"), ("jsbsim", jsbsim_root(), ""))  # fmt: skip
    for package, root, prefix in places:
        try:
            rel = resolved.relative_to(root.resolve())
        except ValueError:
            continue
        return package, f"{package}:{prefix}{rel.as_posix()}"
    return None


def file_record(
    path: str | Path, name: str | None = None, values: Mapping[str, Any] | None = None, sha256: str | None = None
) -> dict[str, Any]:
    """``{"name", "path", "sha256", "values"}`` of one input file (name and values only when given); ``sha256``:
    the digest of the bytes already read (:func:`washbench.io.yamlio.read_yaml_digest`), else the file is hashed.

    A file shipped with washbench or JSBSim is named as bundled (:func:`bundled_name`, e.g.
    ``washbench:data/cw1.yaml``) with ``"bundled"``: the package and its version; any other file by its path as
    given."""
    rec: dict[str, Any] = {}
    if name is not None:
        rec["name"] = name
    bundled = bundled_name(path)
    if bundled is None:
        rec["path"] = str(path)
    else:
        rec["path"] = bundled[1]
        rec["bundled"] = f"{bundled[0]} {software_versions().get(bundled[0], '?')}"
    rec["sha256"] = sha256 or sha256_file(path)
    if values is not None:
        rec["values"] = dict(values)
    return rec


def build_provenance(
    *,
    params_path: Path | None = None,
    params: Any = None,
    platform_path: Path | None = None,
    platform: Any = None,
    manoeuvre_path: Path | None = None,
    input_path: Path | None = None,
    input_provenance: Mapping[str, Any] | None = None,
    turbulence: Any = None,
    aircraft_files: Any = None,
    washouts: Sequence[Any] = (),
    ranking: Mapping[str, Any] | None = None,
    vestibular: Mapping[str, Any] | None = None,
    digests: Mapping[str, str] | None = None,
    plugins: Mapping[str, Mapping[str, Any]] | None = None,
) -> dict[str, Any]:
    """The provenance of one result (module docstring); no date in it.

    ``params`` and ``platform`` are the loaded models (``WashoutParams``, ``PlatformLimits``: pydantic models with a
    ``name``); their paths are the files actually read (left out when not given: ``washbench fly`` uses neither).
    ``turbulence`` is the manoeuvre's ``Turbulence`` or None. ``aircraft_files`` (``washbench.io.paths.AircraftFiles``,
    where the manoeuvre's aircraft was found) adds the JSBSim model file ``<name>/<name>.xml`` and the pilot profile,
    each with its path and SHA-256 (the model's own file only: engines and systems it includes are not hashed).
    ``washouts`` (``washbench.cueing.variants.Washout``: name, kind, params) lists what ran; a variant's complete
    parameter values are recorded where they differ from the file's base set. ``ranking``: the ranking rule
    (:meth:`washbench.analysis.ranking.RankRule.record`); ``vestibular``: the vestibular model
    (:func:`washbench.perception.vestibular.model_record`: its name and values). ``digests``: path (as given) ->
    SHA-256 of a file already read (:func:`washbench.io.yamlio.read_yaml_digest`), so it is not read again.
    ``plugins``: washout name -> what a plugin washout ran (:func:`washbench.cueing.registry.identity`: file or
    module, class, SHA-256, parameter values), recorded as that washout's ``plugin``.
    """
    digests = digests or {}
    prov: dict[str, Any] = {"software": software_versions()}
    if manoeuvre_path is not None:
        prov["manoeuvre"] = file_record(manoeuvre_path)
    if aircraft_files is not None:
        model = Path(aircraft_files.model_dir) / f"{aircraft_files.name}.xml"
        prov["aircraft"] = file_record(model, aircraft_files.name)
        prov["pilot_profile"] = file_record(aircraft_files.profile)
    if input_path is not None:
        prov["input"] = file_record(input_path)
        if input_provenance:
            prov["input"]["provenance"] = dict(input_provenance)
    if params is not None and params_path is not None:
        prov["params"] = file_record(params_path, params.name, params.model_dump(mode="json"),
                                     digests.get(str(params_path)))  # fmt: skip
    if washouts:
        prov["washouts"] = [_washout_record(w, params, (plugins or {}).get(w.name)) for w in washouts]
    if platform is not None and platform_path is not None:
        prov["platform"] = file_record(platform_path, platform.name, platform.model_dump(mode="json"),
                                       digests.get(str(platform_path)))  # fmt: skip
    if manoeuvre_path is not None:
        prov["turbulence"] = turbulence_record(turbulence)
    config_used = os.environ.get(CONFIG_USED_ENV)
    if config_used and Path(config_used).is_file():
        prov["config"] = file_record(config_used)
    if ranking is not None:
        prov["ranking"] = dict(ranking)
    if vestibular is not None:
        prov["vestibular"] = dict(vestibular)
    return prov


_ORDER = ("software", "manoeuvre", "aircraft", "pilot_profile", "input", "params", "washouts", "platform",
          "turbulence", "config", "ranking", "vestibular")  # fmt: skip
"""The keys of :func:`build_provenance`, in the order it writes them."""


def merge_provenance(*parts: Mapping[str, Any]) -> dict[str, Any]:
    """Several :func:`build_provenance` records as one, in :func:`build_provenance`'s key order (a later part wins a
    key both hold): what one call with all their arguments gives, e.g. a run's records (parameters, washouts,
    platform: built once per run) and a manoeuvre's."""
    merged: dict[str, Any] = {}
    for part in parts:
        merged |= part
    known = [k for k in _ORDER if k in merged]
    return {k: merged[k] for k in [*known, *(k for k in merged if k not in _ORDER)]}


def _washout_record(washout: Any, base: Any, plugin: Mapping[str, Any] | None = None) -> dict[str, Any]:
    rec: dict[str, Any] = {"name": washout.name, "kind": washout.kind}
    if base is None or washout.params != base:
        rec["values"] = washout.params.model_dump(mode="json")
    if plugin is not None:
        rec["plugin"] = dict(plugin)
    return rec


def turbulence_record(turbulence: Any) -> dict[str, Any] | None:
    """``{"severity", "seed"}`` of a manoeuvre's turbulence, or None when it has none."""
    if turbulence is None:
        return None
    seed = turbulence.seed
    return {"severity": turbulence.severity, "seed": int(seed) if seed is not None else None}


def utc_now() -> str:
    """The current date and time, UTC, ISO 8601 to the second (for run.json only: never in a Parquet file)."""
    return datetime.datetime.now(datetime.UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")


def parquet_metadata(prov: Mapping[str, Any]) -> dict[bytes, bytes]:
    """Key-value metadata for a Parquet schema: the provenance as compact, key-sorted JSON (deterministic)."""
    return {PARQUET_KEY: json.dumps(prov, sort_keys=True, separators=(",", ":")).encode()}


def read_parquet_provenance(path: str | Path) -> dict[str, Any] | None:
    """The provenance stored in a Parquet file's metadata, or None when it has none (or it is unreadable)."""
    import pyarrow.parquet as pq

    try:
        meta = pq.read_schema(path).metadata or {}
    except (OSError, ValueError):
        return None
    raw = meta.get(PARQUET_KEY)
    if raw is None:
        return None
    try:
        return json.loads(raw)
    except ValueError:
        return None


def manoeuvre_of(prov: Mapping[str, Any] | None) -> Mapping[str, Any] | None:
    """The manoeuvre record of a provenance, also when it is one step back (``cue`` on a flown trace)."""
    if not prov:
        return None
    if "manoeuvre" in prov:
        return prov["manoeuvre"]
    inner = prov.get("input", {}).get("provenance")
    return manoeuvre_of(inner) if inner else None


def flat_strings(prov: Mapping[str, Any], created_utc: str | None = None) -> dict[str, str]:
    """The provenance as flat ``"a.b.c" -> "text"`` pairs (e.g. recording properties), the file values left out.

    ``{"params": {"name": "CW1", "sha256": ...}}`` becomes ``{"params.name": "CW1", "params.sha256": ...}``; a missing
    value (no turbulence) is ``"none"``; ``created_utc`` is added when given.
    """
    out: dict[str, str] = {}

    def walk(prefix: str, value: Any) -> None:
        if isinstance(value, Mapping):
            for key, item in value.items():
                if key != "values":
                    walk(f"{prefix}.{key}" if prefix else str(key), item)
        else:
            out[prefix] = "none" if value is None else str(value)

    walk("", prov)
    if created_utc:
        out["created_utc"] = created_utc
    return out
