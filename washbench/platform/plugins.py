"""Users' own platforms: ``--platform-plugin FILE.py:NAME`` and the entry-point group ``washbench.platforms``.

A platform plugin is a class (or any callable) ``factory(params, context) -> Platform``
(:class:`washbench.platform.model.Platform`: ``start(pos_m, q) -> (pos_m, q)`` and ``step(pos_m, q) -> (pos_m, q,
flags)``, optionally ``trace(pos_m (N, 3), q (N, 4)) -> (pos_m, q, flags (N, 5))``); ``context`` is a
:class:`washbench.platform.model.PlatformContext`; ``params`` is the platform file's keys other than ``kind`` and
``name`` validated by the class's ``Params`` pydantic model, or ``None`` without one. A class attribute
``unlimited_rotation = True`` lets the unrestricted washouts drive it (refused otherwise). Optionally the class has
``envelope(params) -> MotionEnvelope`` (a static or class method): the Atlas-shaped limits washouts that plan (the
MPC) plan against; without it such a washout cannot run on the platform.

How one is chosen: ``--platform-plugin FILE.py:NAME`` loads it (its kind is its ``platform_name`` attribute, else
NAME) and, without ``--platform``, makes it the run's platform with no parameters; ``--platform FILE`` with
``kind: <its kind>`` gives it the file's parameters. An installed package registers one under the entry-point group
``washbench.platforms`` (the entry point's name is the kind), chosen by ``kind:`` in a platform file.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import importlib.util
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from washbench.errors import WashbenchError
from washbench.io.names import identifier_problem
from washbench.io.paths import plugin_file

ENTRY_POINT_GROUP = "washbench.platforms"
BUILTIN_KINDS = frozenset({"atlas", "hexapod", "rig"})

_LOADED: dict[str, tuple[Any, str]] = {}
"""kind -> (factory, source: ``FILE.py:NAME`` absolute, or ``entry point <name>``)."""


@dataclass(frozen=True)
class PluginPlatform:
    """A loaded platform of a plugin's kind: what a run is told (picklable: the factory is looked up by ``source``
    in each process). ``values``: the platform file's parameters (without ``kind`` and ``name``)."""

    kind: str
    name: str
    source: str
    values: dict[str, Any] = field(default_factory=dict)

    def factory(self) -> Any:
        """The plugin's factory, loaded in this process if need be."""
        return load_source(self.source)[0]

    def params(self) -> Any:
        """The parameters as the plugin's ``Params`` model (None without one)."""
        model = getattr(self.factory(), "Params", None)
        if model is None:
            if self.values:
                raise WashbenchError(f"platform {self.kind} ({self.source}): takes no parameters, the file gives "
                                     f"{', '.join(sorted(self.values))}")  # fmt: skip
            return None
        try:
            return model.model_validate(self.values)
        except Exception as exc:  # pydantic's message, one line
            first = str(exc).splitlines()
            raise WashbenchError(f"platform {self.kind} ({self.source}): parameters: {' '.join(first[:3])}") from None

    @property
    def unlimited_rotation(self) -> bool:
        """Whether the plugin declares ``unlimited_rotation = True`` (it can follow the unrestricted washouts)."""
        return bool(getattr(self.factory(), "unlimited_rotation", False))

    def envelope(self) -> Any:
        """The plugin's planning limits (its ``envelope(params)``), or None."""
        fn = getattr(self.factory(), "envelope", None)
        return fn(self.params()) if callable(fn) else None

    def model_dump(self, mode: str = "python") -> dict[str, Any]:
        """The provenance's values: kind, name, source and parameters, and the plugin's ``envelope`` when it gives
        one (what the report's envelope figure draws the motion against)."""
        out = {"kind": self.kind, "name": self.name, "source": self.source, **self.values}
        envelope = self.envelope()
        if envelope is not None and "envelope" not in self.values:
            out["envelope"] = envelope.model_dump(mode=mode)
        return out


class PlatformRun:
    """One plugin platform on one washout's set points, its output checked: a pose of 3 + 4 finite numbers (q not
    zero; normalised here), five 0/1 flags. Anything else, or an exception in the plugin, is one line naming the
    platform, its source and the sample (WashbenchError)."""

    def __init__(self, platform: PluginPlatform, context: Any) -> None:
        self.kind = platform.kind
        self.source = platform.source
        self.k = -1
        try:
            self.obj = platform.factory()(platform.params(), context)
        except WashbenchError:
            raise
        except Exception as exc:
            raise WashbenchError(self._where("making it") + f": {type(exc).__name__}: {exc}") from None
        for method in ("start", "step"):
            if not callable(getattr(self.obj, method, None)):
                raise WashbenchError(self._where("making it") + f": the platform has no {method}() method")

    def _where(self, what: str | None = None) -> str:
        return f"platform {self.kind} ({self.source}): {what or ('start' if self.k < 0 else f'sample {self.k}')}"

    def _call(self, fn: Any, *args: Any) -> Any:
        try:
            return fn(*args)
        except Exception as exc:
            raise WashbenchError(self._where() + f": {type(exc).__name__}: {exc}") from None

    def _pose(self, pos: Any, q: Any, n: int | None) -> tuple[Any, Any]:
        import numpy as np

        shape_p, shape_q = ((3,), (4,)) if n is None else ((n, 3), (n, 4))
        try:
            p = np.array(pos, dtype=np.float64).reshape(shape_p)
            qq = np.array(q, dtype=np.float64).reshape(shape_q)
        except (TypeError, ValueError):
            raise WashbenchError(self._where() + ": expected a pose (pos_m of 3, q of 4 numbers)") from None
        if not (np.isfinite(p).all() and np.isfinite(qq).all()):
            raise WashbenchError(self._where() + ": the pose is not finite")
        norm = np.linalg.norm(qq, axis=-1, keepdims=True)
        if np.any(norm == 0.0):
            raise WashbenchError(self._where() + ": the attitude quaternion is zero")
        return p, qq / norm

    def start(self, pos: Any, q: Any) -> tuple[Any, Any]:
        """The platform's start pose (at rest) for the first set point."""
        self.k = -1
        out = self._call(self.obj.start, pos, q)
        if not (isinstance(out, tuple | list) and len(out) == 2):
            raise WashbenchError(self._where() + ": start() must return (pos_m, q)")
        return self._pose(out[0], out[1], None)

    def run(self, sp_pos: Any, sp_q: Any) -> tuple[Any, Any, Any]:
        """Poses (M, 3), (M, 4) and flags (M, 5) int64 for M set points (its ``trace`` if it has one)."""
        import numpy as np

        m = len(sp_pos)
        if callable(getattr(self.obj, "trace", None)):
            self.k = 0
            out = self._call(self.obj.trace, sp_pos, sp_q)
            if not (isinstance(out, tuple | list) and len(out) == 3):
                raise WashbenchError(self._where() + ": trace() must return (pos_m, q, flags)")
            pos, q = self._pose(out[0], out[1], m)
            flags = np.asarray(out[2])
        else:
            pos, q, flags = np.empty((m, 3)), np.empty((m, 4)), np.zeros((m, 5), dtype=np.int64)
            for k in range(m):
                self.k = k
                out = self._call(self.obj.step, sp_pos[k], sp_q[k])
                if not (isinstance(out, tuple | list) and len(out) == 3):
                    raise WashbenchError(self._where() + ": step() must return (pos_m, q, flags)")
                pos[k], q[k] = self._pose(out[0], out[1], None)
                flags[k] = np.asarray(out[2]).reshape(5) if np.size(out[2]) == 5 else -1
        if flags.shape != (m, 5) or not np.isin(flags, (0, 1)).all():
            raise WashbenchError(self._where() + ": flags must be five 0/1 values per sample")
        return pos, q, flags.astype(np.int64)


def load_plugin(spec: str) -> str:
    """Load ``FILE.py:NAME`` and register it; return its kind. WashbenchError (one line) if it cannot be loaded."""
    where, path, name = plugin_file(spec, "--platform-plugin")
    source = f"{path}:{name}"
    factory, _ = load_source(source, where)
    kind = str(getattr(factory, "platform_name", name))
    problem = identifier_problem(kind)
    if problem is not None:
        raise WashbenchError(f"{where}: platform name {kind!r}: {problem}")
    if kind in BUILTIN_KINDS:
        raise WashbenchError(f"{where}: platform name {kind!r} is a built-in kind")
    previous = _LOADED.get(kind)
    if previous is not None and previous[1] != source:
        raise WashbenchError(f"{where}: platform name {kind!r} is already loaded from {previous[1]}")
    _LOADED[kind] = (factory, source)
    return kind


@functools.cache
def load_source(source: str, where: str | None = None) -> tuple[Any, str]:
    """(factory, source) of ``/abs/FILE.py:NAME`` or ``entry point <name>``, imported once per process."""
    if source.startswith("entry point "):
        kind = source.removeprefix("entry point ")
        eps = {ep.name: ep for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)}
        try:
            return eps[kind].load(), source
        except Exception as exc:
            raise WashbenchError(f"platform {kind} (entry point): {type(exc).__name__}: {exc}") from None
    where = where or f"platform plugin {source}"
    file, _, name = source.rpartition(":")
    path = Path(file)
    module_name = f"washbench_platform_{hashlib.sha256(str(path).encode()).hexdigest()[:16]}"
    try:
        spec = importlib.util.spec_from_file_location(module_name, path)
        if spec is None or spec.loader is None:
            raise WashbenchError(f"{where}: {path}: not a Python file")
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module
        spec.loader.exec_module(module)
    except WashbenchError:
        raise
    except Exception as exc:  # a user's file: whatever it raises becomes one line
        line = f":{exc.lineno}" if isinstance(exc, SyntaxError) and exc.lineno else ""
        raise WashbenchError(f"{where}: {path}{line}: {type(exc).__name__}: {exc}") from None
    if not hasattr(module, name):
        raise WashbenchError(f"{where}: {path} has no {name!r}")
    return getattr(module, name), source


def source_of(kind: str) -> str | None:
    """Where a plugin kind comes from (loaded file, else an installed entry point), or None if unknown."""
    if kind in _LOADED:
        return _LOADED[kind][1]
    names = {ep.name for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)}
    return f"entry point {kind}" if kind in names else None


def plugin_kinds() -> tuple[str, ...]:
    """The plugin kinds known in this process (loaded ones, then installed entry points)."""
    names = [ep.name for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)]
    return tuple(dict.fromkeys([*_LOADED, *names]))


__all__ = [
    "ENTRY_POINT_GROUP",
    "PlatformRun",
    "PluginPlatform",
    "load_plugin",
    "load_source",
    "plugin_kinds",
    "source_of",
]
