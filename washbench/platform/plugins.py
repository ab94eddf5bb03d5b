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
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from washbench.errors import WashbenchError
from washbench.io.entry_points import entry_points as installed_entry_points
from washbench.io.names import identifier_problem
from washbench.io.paths import plugin_file
from washbench.io.plugin_guard import load_module, plugin_call, read_only

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

    def _where(self, what: str) -> str:
        return f"platform {self.kind} ({self.source}): {what}"

    def params(self) -> Any:
        """The parameters as the plugin's ``Params`` model (None without one)."""
        model = plugin_call(self._where("Params"), lambda: getattr(self.factory(), "Params", None), what="a platform")
        if model is None:
            if self.values:
                given = ", ".join(sorted(self.values))
                raise WashbenchError(self._where(f"takes no parameters, the file gives {given}"))
            return None
        try:  # the plugin's own validators run here: guarded
            return plugin_call(self._where("parameters"), lambda: model.model_validate(self.values),
                               passing=(Exception,), what="a platform")  # fmt: skip
        except WashbenchError:
            raise
        except Exception as exc:  # pydantic's message, one line
            raise WashbenchError(self._where(f"parameters: {_lines(exc, 0, 3)}")) from None

    @property
    def unlimited_rotation(self) -> bool:
        """Whether the plugin declares ``unlimited_rotation = True`` (it can follow the unrestricted washouts)."""
        return plugin_call(self._where("unlimited_rotation"),
                           lambda: bool(getattr(self.factory(), "unlimited_rotation", False)), what="a platform")

    def envelope(self) -> Any:
        """The plugin's planning limits (its ``envelope(params)``, checked: Atlas-shaped limits of finite numbers in
        the platform files' ranges, :class:`washbench.platform.hexapod.MotionEnvelope`), or None without one."""
        from washbench.platform.hexapod import MotionEnvelope  # deferred: pydantic

        params = self.params()
        where = self._where("envelope()")

        def checked() -> Any:
            fn = getattr(self.factory(), "envelope", None)
            if not callable(fn):
                return None
            got = fn(params)
            data = got.model_dump() if isinstance(got, MotionEnvelope) else got
            try:
                return MotionEnvelope.model_validate(data)
            except Exception as exc:  # pydantic's message: the first problem, one line
                raise WashbenchError(f"{where}: not Atlas-shaped limits of finite numbers "
                                     f"(washbench.platform.hexapod.MotionEnvelope): {_lines(exc, 1, 3)}") from None

        return plugin_call(where, checked, what="a platform")

    def model_dump(self, mode: str = "python") -> dict[str, Any]:
        """The provenance's values: kind, name, source and parameters, and the plugin's ``envelope`` when it gives
        one (what the report's envelope figure draws the motion against)."""
        out = {"kind": self.kind, "name": self.name, "source": self.source, **self.values}
        envelope = self.envelope()
        if envelope is not None and "envelope" not in self.values:
            out["envelope"] = envelope.model_dump(mode=mode)
        return out


MAX_POSE_M = 1000.0
"""A plugin's pose may be at most this far from neutral (m): ten times the largest travel a platform file may give;
beyond it the bench's difference quotients would overflow (a unit error, not a motion)."""


class PlatformRun:
    """One plugin platform on one washout's set points, under the same contract as a washout plugin
    (:mod:`washbench.io.plugin_guard`): every call guarded (an exception, ``sys.exit()``, a ``KeyboardInterrupt``
    with no signal: one line), the set points given as read-only copies, and every sample's output checked: a pose
    of 3 + 4 real, finite numbers (the position at most :data:`MAX_POSE_M` from neutral, q not zero; normalised
    here) and five flags each 0 or 1 (booleans or the numbers 0 and 1). Anything else is one line naming the
    platform, its source and the sample (WashbenchError)."""

    def __init__(self, platform: PluginPlatform, context: Any) -> None:
        self.kind = platform.kind
        self.source = platform.source
        self.k = -1  # the sample being computed, counted from the recording's first (-1: start)
        self.done = 0  # samples done in earlier blocks
        params = platform.params()
        self.obj = self._call(lambda: platform.factory()(params, context), "making it")

        def methods() -> tuple[bool, bool]:  # attribute look-ups run the plugin's code too (__getattr__)
            for method in ("start", "step"):
                if not callable(getattr(self.obj, method, None)):
                    raise WashbenchError(self._where("making it") + f": the platform has no {method}() method")
            return True, callable(getattr(self.obj, "trace", None))

        self.has_trace = self._call(methods, "making it")[1]

    def _where(self, what: str | None = None) -> str:
        return f"platform {self.kind} ({self.source}): {what or ('start' if self.k < 0 else f'sample {self.k}')}"

    def _call(self, fn: Any, what: str | None = None) -> Any:
        return plugin_call(self._where(what), fn, what="a platform")

    def _numbers(self, value: Any, shape: tuple[int, ...], what: str) -> Any:
        """``value`` as float64 of ``shape``, if it is real numbers (booleans, integers, floats) of that size; of a
        trace (``shape`` (N, k)) the first sample that is not is named."""
        import numpy as np

        arr = np.asarray(value)
        if arr.dtype.kind not in "biuf":
            if len(shape) == 2 and arr.ndim >= 1 and len(arr) == shape[0]:  # which sample of a trace
                first = next((i for i, row in enumerate(arr) if np.asarray(row).dtype.kind not in "biuf"), 0)
                self.k = self.done + first
            kind = "complex numbers" if arr.dtype.kind == "c" else f"{arr.dtype.name} values"
            raise WashbenchError(self._where() + f": {what} are {kind}, not real numbers")
        if arr.size != math.prod(shape):
            raise WashbenchError(self._where() + f": {what} has {arr.size} values, expected {math.prod(shape)}")
        return arr.astype(np.float64).reshape(shape)

    def _pose(self, out: Any, n: int | None, count: int) -> tuple[Any, ...]:
        """The checked output of ``start`` (``count`` 2: pos, q), ``step`` (3: and flags) or ``trace`` (3, ``n``
        samples): float64 pose, normalised q, int64 flags; the first bad sample named."""
        import numpy as np

        name = {2: "start()", 3: "step()" if n is None else "trace()"}[count]
        if not (isinstance(out, tuple | list) and len(out) == count):
            wanted = "(pos_m, q)" if count == 2 else "(pos_m, q, flags)"
            raise WashbenchError(self._where() + f": {name} must return {wanted}")
        rows = () if n is None else (n,)
        p = self._numbers(out[0], (*rows, 3), "the position pos_m")
        q = self._numbers(out[1], (*rows, 4), "the attitude q")
        norm = np.linalg.norm(q, axis=-1, keepdims=True)
        bad_pose = ~(np.isfinite(p).all(axis=-1) & np.isfinite(q).all(axis=-1))
        far = ~bad_pose & (np.abs(p).max(axis=-1) > MAX_POSE_M)
        zero = ~bad_pose & ~((norm[..., 0] > 0.0) & np.isfinite(norm[..., 0]))
        flags = None
        bad_flags = np.zeros(np.shape(bad_pose), dtype=bool)
        if count == 3:
            flags = self._numbers(out[2], (*rows, 5), "the flags")
            bad_flags = ~np.isin(flags, (0.0, 1.0)).all(axis=-1)
        for problem, text, values in ((bad_pose, "the pose is not finite", p),
                                      (far, f"the position is more than {MAX_POSE_M:g} m from neutral", p),
                                      (zero, "the attitude quaternion is zero (or too large to normalise)", q),
                                      (bad_flags, "flags must be five 0/1 values", flags)):  # fmt: skip
            if np.any(problem):
                row = None
                if n is not None:
                    row = int(np.argmax(problem))
                    self.k = self.done + row
                raise WashbenchError(self._where() + f": {text} ({_shown(values, row)})")
        out_flags = None if flags is None else flags.astype(np.int64)
        return p, q / norm, out_flags

    def start(self, pos: Any, q: Any) -> tuple[Any, Any]:
        """The platform's start pose (at rest) for the first set point."""
        self.k = -1
        out = self._call(lambda: self._pose(self.obj.start(read_only(pos), read_only(q)), None, 2))
        return out[0], out[1]

    def run(self, sp_pos: Any, sp_q: Any) -> tuple[Any, Any, Any]:
        """Poses (M, 3), (M, 4) and flags (M, 5) int64 for M set points (its ``trace`` if it has one)."""
        import numpy as np

        m = len(sp_pos)
        if self.has_trace:
            self.k = self.done
            pos, q, flags = self._call(lambda: self._pose(self.obj.trace(read_only(sp_pos), read_only(sp_q)), m, 3))
        else:
            pos, q, flags = np.empty((m, 3)), np.empty((m, 4)), np.zeros((m, 5), dtype=np.int64)
            step = self._call(lambda: self.obj.step)
            for k in range(m):
                self.k = self.done + k
                pos[k], q[k], flags[k] = self._call(
                    lambda k=k: self._pose(step(read_only(sp_pos[k]), read_only(sp_q[k])), None, 3))
        self.done += m
        return pos, q, flags


def _lines(exc: BaseException, first: int, last: int) -> str:
    """Lines ``first..last`` of an exception's message (pydantic's: the field, then the problem) on one line."""
    try:
        lines = str(exc).splitlines()
    except Exception:  # a plugin's exception whose __str__ fails
        return type(exc).__name__
    return " ".join(" ".join(lines[first:last] or lines[:1]).split())


def _shown(values: Any, k: int | None) -> str:
    """The offending sample's values, short."""
    import numpy as np

    row = np.asarray(values)[k] if k is not None else np.asarray(values)
    return "[" + ", ".join(f"{x:.6g}" for x in np.ravel(row)[:5]) + "]"


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
        eps = {ep.name: ep for ep in installed_entry_points(ENTRY_POINT_GROUP)}
        try:
            return eps[kind].load(), source
        except Exception as exc:
            raise WashbenchError(f"platform {kind} (entry point): {type(exc).__name__}: {exc}") from None
    where = where or f"platform plugin {source}"
    file, _, name = source.rpartition(":")
    path = Path(file)
    module = load_module(path, "washbench_platform", where)
    if not hasattr(module, name):
        raise WashbenchError(f"{where}: {path} has no {name!r}")
    return getattr(module, name), source


def source_of(kind: str) -> str | None:
    """Where a plugin kind comes from (loaded file, else an installed entry point), or None if unknown."""
    if kind in _LOADED:
        return _LOADED[kind][1]
    names = {ep.name for ep in installed_entry_points(ENTRY_POINT_GROUP)}
    return f"entry point {kind}" if kind in names else None


def plugin_kinds() -> tuple[str, ...]:
    """The plugin kinds known in this process (loaded ones, then installed entry points)."""
    names = [ep.name for ep in installed_entry_points(ENTRY_POINT_GROUP)]
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
