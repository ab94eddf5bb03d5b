"""The platform stage's interface: what any motion platform receives and returns, and how one is chosen.

A washout gives set points; the platform follows them within its own limits and its motion is what the simulator
pilot feels::

    washout --> set point (pos_m, q) --> platform --> pose (pos_m, q), its own state and saturation flags --> head

Per sample a platform receives the washout's set point

- ``pos_m``: the motion reference point's (MRP's) displacement from neutral, inertial north-east-down, m, (3,);
- ``q``: the cockpit attitude, unit quaternion, scalar first [w, x, y, z], body -> inertial, (4,);

and returns the pose it reached (same frames), with its own state (the Atlas's omni-wheel speeds, the hexapod's
leg lengths) and 0/1 flags of the limits that acted (``sat_pos``, ``sat_vel``, ``sat_acc``, ``sat_rate``,
``sat_angacc``: see docs/platforms.md for what each kind means by them). The bench derives the platform's velocity,
acceleration and body rates and the simulator pilot-head motion from the poses (the same way for every kind). A
platform never leaves its limits, whatever the set points.

Kinds (the ``kind`` key of the file given to ``--platform FILE``; without the key: ``atlas``):

- ``atlas``: the kinematic Atlas (:mod:`washbench.platform.limits`, :mod:`washbench.platform.kinematics`);
- ``hexapod``: a 6-6 Gough-Stewart platform (:mod:`washbench.platform.hexapod`);
- ``rig``: a 2- or 3-DOF rig (:mod:`washbench.platform.rig`).

Every built-in kind runs in the compiled per-sample step (:mod:`washbench.cueing.kernel`). :class:`Platform` is the
Python form of the same contract: what a user's platform (:mod:`washbench.platform.plugins`,
``--platform-plugin FILE.py:NAME`` or the entry-point group ``washbench.platforms``) implements.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, Union, runtime_checkable

import numpy as np

from washbench.errors import WashbenchError, located
from washbench.io.yamlio import line_of, read_yaml_digest, validate_data
from washbench.platform import plugins
from washbench.platform.hexapod import HexapodModel, MotionEnvelope
from washbench.platform.limits import DEFAULT_LIMITS_PATH, PlatformLimits
from washbench.platform.rig import RigModel

PlatformModel = Union[PlatformLimits, HexapodModel, RigModel]  # noqa: UP007 (a runtime alias)
"""A loaded platform file of any kind."""

KINDS: dict[str, type] = {"atlas": PlatformLimits, "hexapod": HexapodModel, "rig": RigModel}
"""The ``kind`` key's values and the model each selects."""

Pose = tuple[np.ndarray, np.ndarray]
"""(pos_m (3,) inertial NED from neutral, m; q (4,) body -> inertial, scalar first)."""


@dataclass(frozen=True)
class PlatformContext:
    """What a platform is told when it is made: the run's fixed facts, SI.

    dt_s: sample interval, s. gravity_mps2: g, m/s^2. filter_start: ``"steady"`` or ``"rest"``.
    """

    dt_s: float
    gravity_mps2: float
    filter_start: str


@runtime_checkable
class Platform(Protocol):
    """One motion platform, sample by sample (module docstring: units, frames, flags)."""

    def start(self, pos_m: np.ndarray, q: np.ndarray) -> Pose:
        """Place the platform at rest at (or as near as it can to) the first set point; return that pose."""
        ...

    def step(self, pos_m: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, tuple[int, int, int, int, int]]:
        """Follow the new set point by one sample (dt_s); return the pose reached and the five limit flags."""
        ...


def platform_kind(model: Any) -> str:
    """``atlas``, ``hexapod`` or ``rig`` of a loaded platform model."""
    return getattr(model, "kind", "atlas")


def planning_limits(model: Any) -> PlatformLimits | MotionEnvelope | None:
    """The Atlas-shaped limits a washout plans against (:attr:`WashoutContext.limits`): the Atlas's own, or another
    kind's box about neutral (:meth:`HexapodModel.envelope`, :meth:`RigModel.envelope`, a plugin's ``envelope``:
    None without one)."""
    return model if platform_kind(model) == "atlas" else model.envelope()


def platform_from_data(path: Path, data: Any, lines: Any) -> Any:
    """Validate a parsed platform file by its ``kind`` key (absent: ``atlas``; a plugin's kind: its parameters, see
    :mod:`washbench.platform.plugins`); errors name file, line and field."""
    kind = data.get("kind", "atlas") if isinstance(data, dict) else "atlas"
    if kind not in KINDS:
        source = plugins.source_of(str(kind))
        if source is None:
            line = line_of(lines, ("kind",))
            valid = ", ".join([*KINDS, *plugins.plugin_kinds()])
            raise WashbenchError(located(path, f"unknown platform kind {kind!r} (valid: {valid})", line=line,
                                         field="kind"))  # fmt: skip
        values = {k: v for k, v in data.items() if k not in ("kind", "name")}
        platform = plugins.PluginPlatform(kind=str(kind), name=str(data.get("name", kind)), source=source,
                                          values=values)  # fmt: skip
        try:
            platform.params()
        except WashbenchError as exc:
            raise WashbenchError(located(path, str(exc))) from None
        return platform
    if kind == "atlas" and "kind" in data:
        data = {k: v for k, v in data.items() if k != "kind"}  # the Atlas model has no kind field
    return validate_data(path, data, lines, KINDS[kind])


_DEFAULT_PLUGIN: list[str] = []
"""The kind of ``--platform-plugin`` when no ``--platform`` is given (this process)."""


def set_default_plugin(kind: str | None) -> None:
    """Make the plugin ``kind`` the platform of a run given no ``--platform`` (None: the Atlas again)."""
    _DEFAULT_PLUGIN[:] = [kind] if kind else []


def resolve_platform(path: Path | None) -> tuple[Any, Path, str]:
    """(model, the file it came from, its SHA-256): ``path``; or without one the ``--platform-plugin`` loaded
    (its Python file, no parameters), else the bundled Atlas."""
    if path is None and _DEFAULT_PLUGIN:
        kind = _DEFAULT_PLUGIN[0]
        source = plugins.source_of(kind) or ""
        file = Path(source.rpartition(":")[0])
        platform = plugins.PluginPlatform(kind=kind, name=kind, source=source)
        platform.params()
        return platform, file, hashlib.sha256(file.read_bytes()).hexdigest()
    source_path = Path(path) if path is not None else DEFAULT_LIMITS_PATH
    data, lines, sha = read_yaml_digest(source_path)
    return platform_from_data(source_path, data, lines), source_path, sha


def load_platform(path: Path | None = None) -> tuple[Any, str]:
    """A platform file (``None``: the ``--platform-plugin`` loaded, else the bundled Atlas) as its model, and the
    SHA-256 of the bytes read."""
    model, _, sha = resolve_platform(path)
    return model, sha


def load_platform_model(path: Path | None = None) -> PlatformModel:
    """:func:`load_platform` without the digest."""
    return load_platform(path)[0]


__all__ = [
    "KINDS",
    "Platform",
    "PlatformContext",
    "PlatformModel",
    "Pose",
    "load_platform",
    "load_platform_model",
    "planning_limits",
    "platform_from_data",
    "platform_kind",
    "resolve_platform",
    "set_default_plugin",
]
