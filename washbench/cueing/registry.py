"""Which washout algorithms exist: the compiled built-ins, the built-in Python ones, and users' plugins.

A washout *kind* names an algorithm. The compiled kinds (:data:`washbench.cueing.params.WASHOUT_KINDS`) run inside
the numba kernel. Every other kind is a Python algorithm (:mod:`washbench.cueing.algorithm`): a factory
``factory(params, context) -> WashoutAlgorithm`` whose parameters are the section of the parameter file named after
the kind, validated by the factory's ``Params`` pydantic model (``params`` is ``None`` when it has none).

Where Python algorithms come from, in this order:

- built in (:data:`BUILTIN_PYTHON`, imported when first used);
- plugins loaded from a file, ``--washout-plugin FILE.py:NAME`` (:func:`load_plugin`);
- installed packages, through the entry-point group ``washbench.washouts`` (the entry point's name is the kind).

A plugin's kind is its ``washout_name`` attribute if it has one, else ``NAME``. Kinds are plain identifiers
(letters, digits, ``_`` and ``-``): they become column prefixes, entity paths and parts of file names.
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import importlib.metadata
import importlib.util
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from washbench.cueing.params import WASHOUT_KINDS
from washbench.errors import WashbenchError, located
from washbench.io.entry_points import entry_points as installed_entry_points
from washbench.io.names import identifier_problem
from washbench.io.paths import plugin_file
from washbench.io.plugin_guard import load_module, plugin_call
from washbench.io.yamlio import line_of

ENTRY_POINT_GROUP = "washbench.washouts"

RESERVED_NAMES = frozenset({"aircraft", "limit", "t_s"})
"""Names no washout (variant or plugin) may take: they are column prefixes of the outputs."""

BUILTIN_PYTHON: dict[str, str] = {
    "optimal": "washbench.cueing.optimal:OptimalWashout",
    "mpc": "washbench.cueing.mpc:MpcWashout",
    "mpc-unrestricted": "washbench.cueing.mpc_unrestricted:MpcUnrestrictedWashout",
    # the oracle bound replayed as a washout (whole recordings only); by name, so cueing imports no analysis module
    "bound": "washbench.analysis.bound_replay:BoundWashout",
    # the naive references (cueing/references.py)
    "replay": "washbench.cueing.references:ReplayWashout",
    "replay-rotation": "washbench.cueing.references:ReplayRotationWashout",
    "still": "washbench.cueing.references:StillWashout",
}
"""Built-in Python algorithms: kind -> ``module:attribute`` of the factory (imported on first use)."""

REFERENCE_KINDS: tuple[str, ...] = ("replay", "replay-rotation", "still")
"""The naive references' washout names (:mod:`washbench.cueing.references`)."""


@dataclass(frozen=True)
class Algorithm:
    """A Python washout algorithm: its kind, factory, parameter model (or None) and where it came from."""

    kind: str
    factory: Callable[..., Any]
    params_model: type[BaseModel] | None
    source: str

    def make_params(self, section: dict[str, Any] | None, where: str, lines: Any = None) -> BaseModel | None:
        """The validated parameter section (``section``: the raw mapping from the parameter file, or None).

        WashbenchError ``WHERE[:LINE]: KIND.FIELD: problem``; ``lines`` (a YAML line map, optional) gives the line.
        """

        if self.params_model is None:
            if section:
                raise WashbenchError(located(where, "this washout takes no parameters", field=self.kind))
            return None
        import pydantic

        model = self.params_model
        try:  # the model is the plugin's code (its validators): guarded
            return plugin_call(
                f"{where}: {self.kind} parameters",
                lambda: model.model_validate(section or {}),
                passing=(pydantic.ValidationError,),
            )
        except pydantic.ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            loc = tuple(err["loc"])
            line = line_of(lines, (self.kind, *loc)) if lines else None
            field = ".".join((self.kind, *(str(p) for p in loc)))
            msg = str(err["msg"]).removeprefix("Value error, ")  # (a model validator's own words)
            raise WashbenchError(located(where, msg, line=line, field=field)) from None


_LOADED: dict[str, Algorithm] = {}
_PLUGIN_SPECS: dict[str, str] = {}  # kind -> FILE.py:NAME, for processes that must load it again


def _params_model(obj: Any, where: str) -> type[BaseModel] | None:
    model = getattr(obj, "Params", None)
    if model is None:
        return None
    if not (isinstance(model, type) and issubclass(model, BaseModel)):
        raise WashbenchError(f"{where}: its Params must be a pydantic BaseModel class")
    return model


def _algorithm(obj: Any, kind: str, source: str) -> Algorithm:
    where = f"washout plugin {source}"
    if not callable(obj):
        raise WashbenchError(f"{where}: {type(obj).__name__} is not a class or callable")
    problem = identifier_problem(kind)
    if problem is not None:
        raise WashbenchError(f"{where}: washout name {kind!r}: {problem}")
    if kind in WASHOUT_KINDS or kind in BUILTIN_PYTHON or kind in RESERVED_NAMES:
        raise WashbenchError(f"{where}: washout name {kind!r} is taken by a built-in washout or output")
    return Algorithm(kind, obj, _params_model(obj, where), source)


def load_plugin(spec: str) -> Algorithm:
    """Load ``FILE.py:NAME`` and register it; WashbenchError (one line) if it cannot be loaded."""
    where, path, name = plugin_file(spec, "--washout-plugin")
    text = f"{path}:{name}"  # absolute: worker processes load the same file
    for kind, loaded in _PLUGIN_SPECS.items():
        if loaded == text:
            return _LOADED[kind]
    module = load_module(path, "washbench_plugin", where)

    def named() -> tuple[Any, str]:
        if not hasattr(module, name):
            raise WashbenchError(f"{where}: {path} has no {name!r}")
        obj = getattr(module, name)
        return obj, str(getattr(obj, "washout_name", name))

    obj, kind = plugin_call(where, named)
    algo = _algorithm(obj, kind, text)
    previous = _PLUGIN_SPECS.get(kind)
    if previous is not None and previous != text:
        raise WashbenchError(f"{where}: washout name {kind!r} is already loaded from {previous}")
    _LOADED[kind] = algo
    _PLUGIN_SPECS[kind] = text
    return algo


@functools.cache
def _entry_points() -> dict[str, importlib.metadata.EntryPoint]:
    """The ``washbench.washouts`` entry points installed, read once per process (every name check asks)."""
    return {ep.name: ep for ep in installed_entry_points(ENTRY_POINT_GROUP)}


def python_kinds() -> tuple[str, ...]:
    """Every Python algorithm's kind known in this process: built in, loaded plugins, entry points."""
    return tuple(dict.fromkeys([*BUILTIN_PYTHON, *_LOADED, *_entry_points()]))


def known_kinds() -> tuple[str, ...]:
    """Every washout kind: compiled built-ins, then the Python ones."""
    return WASHOUT_KINDS + python_kinds()


def is_python(kind: str) -> bool:
    """Whether ``kind`` is a Python algorithm (not one of the compiled built-ins)."""
    return kind not in WASHOUT_KINDS


def needs_whole(factory: Any, section: Any = None) -> bool:
    """Whether an algorithm made by ``factory`` with the raw parameter section ``section`` (a mapping or None) needs
    the whole recording: the factory's ``whole_only`` attribute, a bool (the oracle bound) or a function of the section
    (the MPC washouts with ``preview_s`` > 0)."""
    attr = getattr(factory, "whole_only", False)
    if callable(attr):
        return bool(attr(dict(section) if isinstance(section, dict) else {}))
    return bool(attr)


def whole_only(kind: str, spec: str | None = None, section: Any = None) -> bool:
    """Whether the Python algorithm ``kind`` (with the raw parameter section ``section``) needs the whole recording
    (:func:`needs_whole`: it has a ``trace`` form and is cued after the flight, e.g. the oracle bound, or an MPC
    washout with preview); compiled kinds never do."""
    return is_python(kind) and needs_whole(get(kind, spec).factory, section)


def considers(kind: str, spec: str | None = None) -> bool:
    """Whether the Python algorithm ``kind``'s factory has ``consider`` (it is told the run's other motions before its
    trace: :class:`washbench.cueing.algorithm.Alongside`, e.g. the bound); compiled kinds never do."""
    return is_python(kind) and callable(getattr(get(kind, spec).factory, "consider", None))


def plugin_spec(kind: str) -> str | None:
    """``FILE.py:NAME`` of a plugin loaded from a file, for worker processes (None otherwise)."""
    return _PLUGIN_SPECS.get(kind)


def plugin_specs() -> tuple[str, ...]:
    """Every plugin loaded from a file in this process, as ``FILE.py:NAME`` (for worker processes)."""
    return tuple(_PLUGIN_SPECS.values())


def check_washouts(washouts: Sequence[str]) -> tuple[str, ...]:
    """Built-in or registered washout names as a tuple; WashbenchError if none, one is unknown or one is listed
    twice."""
    names = tuple(washouts)
    if not names:
        raise WashbenchError("no washout selected")
    for name in names:
        if name not in known_kinds():
            raise WashbenchError(f"unknown washout {name!r} (valid: {', '.join(known_kinds())})")
    if len(set(names)) != len(names):
        raise WashbenchError(f"washout listed twice: {', '.join(names)}")
    return names


def get(kind: str, spec: str | None = None) -> Algorithm:
    """The Python algorithm ``kind`` (loading ``spec`` = ``FILE.py:NAME`` first if it is not loaded here)."""
    if kind in _LOADED:
        return _LOADED[kind]
    if spec is not None:
        algo = load_plugin(spec)
        if algo.kind == kind:
            return algo
    if kind in BUILTIN_PYTHON:
        module, _, attr = BUILTIN_PYTHON[kind].partition(":")
        obj = getattr(importlib.import_module(module), attr)
        algo = Algorithm(kind, obj, _params_model(obj, kind), "built-in")
        _LOADED[kind] = algo
        return algo
    eps = _entry_points()
    if kind in eps:
        source = f"entry point {eps[kind].value}"
        obj = plugin_call(f"washout plugin {source}", eps[kind].load)
        algo = _algorithm(obj, kind, source)
        _LOADED[kind] = algo
        return algo
    raise WashbenchError(f"unknown washout {kind!r} (valid: {', '.join(known_kinds())})")


def _sha256(path: str | Path) -> str | None:
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def _distribution(ep: importlib.metadata.EntryPoint) -> dict[str, str]:
    dist = getattr(ep, "dist", None)
    if dist is None:
        return {}
    return {"distribution": str(dist.metadata["Name"]), "version": str(dist.version)}


def identity(kind: str, params: Any = None) -> dict[str, Any] | None:
    """Which code a plugin washout ``kind`` ran and with which values: what its provenance records; None for the
    compiled and built-in kinds (washbench's own, named by its version).

    A file plugin: ``{"from": "file", "path", "object", "sha256"}`` (the file as loaded, its bytes' SHA-256); with
    ``"shadows"`` naming an installed entry point of the same name, which the file replaced in this run. An entry
    point: ``{"from": "entry point", "module", "object", "distribution", "version", "sha256"}`` (of the module's
    file). Both with ``"values"``: the plugin's parameters as its ``Params`` validated them from the
    ``kind`` section of ``params`` (``WashoutParams``; defaults filled in; ``{}`` without ``Params``).
    """
    if not is_python(kind) or kind in BUILTIN_PYTHON:
        return None
    algo = get(kind, plugin_spec(kind))
    rec: dict[str, Any]
    spec = _PLUGIN_SPECS.get(kind)
    entry = _entry_points().get(kind)
    if spec is not None:
        file, _, name = spec.rpartition(":")
        rec = {"from": "file", "path": file, "object": name, "sha256": _sha256(file)}
        if entry is not None:
            dist = _distribution(entry)
            owner = f" ({dist['distribution']} {dist['version']})" if dist else ""
            rec["shadows"] = f"entry point {entry.value}{owner}"
    elif entry is not None:
        module, _, attr = entry.value.partition(":")
        rec = {"from": "entry point", "module": module.strip(), "object": attr.strip(), **_distribution(entry)}
        mod = sys.modules.get(module.strip())
        file = getattr(mod, "__file__", None)
        if file:  # the module's file (named by module and distribution: its place differs from machine to machine)
            rec["sha256"] = _sha256(file)
    else:  # registered some other way (a test's): its source as the registry knows it
        rec = {"from": algo.source}
    section = getattr(params, "sections", {}).get(kind) if params is not None else None
    values = algo.make_params(section, f"washout {kind}") if algo.params_model is not None else None
    rec["values"] = values.model_dump(mode="json") if values is not None else {}
    return rec


__all__ = [
    "BUILTIN_PYTHON",
    "ENTRY_POINT_GROUP",
    "RESERVED_NAMES",
    "Algorithm",
    "check_washouts",
    "considers",
    "get",
    "identity",
    "is_python",
    "known_kinds",
    "load_plugin",
    "needs_whole",
    "plugin_spec",
    "plugin_specs",
    "python_kinds",
    "whole_only",
]
