"""Users' own pilot models: ``--pilot-plugin FILE.py:NAME`` (docs/pilot-model.md, "Your own pilot model").

A pilot plugin is a class (or any callable) ``factory(params, context) -> PilotModel``
(:class:`washbench.pilot.model.PilotModel`: ``step(error_rad, rate_radps, force_mps2) -> u``, optionally
``contributions()`` and ``describe()``); ``context`` is a :class:`washbench.pilot.model.PilotContext` (with the
measured controlled element and the condition's motion filter, for a model that adapts itself); ``params`` is the
task file's ``pilot:`` section validated by the class's ``Params`` pydantic model, or ``None`` without one. The
bench does not adapt a plugin (the built-in model's rule, :mod:`washbench.pilot.adapt`, is about its own
parameters): the plugin flies every condition as it is made. Every call into it goes through
:func:`washbench.io.plugin_guard.plugin_call`: whatever it raises is one line.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel

from washbench.errors import WashbenchError
from washbench.io.paths import plugin_file
from washbench.io.plugin_guard import load_module, plugin_call
from washbench.pilot.model import PilotContext


@dataclass(frozen=True)
class PilotPlugin:
    """A loaded pilot plugin: its factory, its ``Params`` model (or None), ``FILE.py:NAME`` and the file's SHA-256."""

    factory: Any
    params_model: type[BaseModel] | None
    source: str
    sha256: str

    def make(self, params: Any, context: PilotContext) -> Any:
        """``factory(params, context)``, guarded; the model's ``step`` is wrapped by the guard too."""
        model = plugin_call(f"pilot plugin {self.source}", lambda: self.factory(params, context))
        if not callable(getattr(model, "step", None)):
            raise WashbenchError(f"pilot plugin {self.source}: what it made has no step(error, rate, force) method")
        return _Guarded(model, self.source)

    def record(self) -> dict[str, str]:
        """What the provenance records of it."""
        return {"source": self.source, "sha256": self.sha256}


class _Guarded:
    """A plugin's model with every call guarded and its control checked to be a finite number."""

    def __init__(self, model: Any, source: str) -> None:
        self.model = model
        self.where = f"pilot plugin {source}"
        if hasattr(model, "contributions"):
            self.contributions = lambda: plugin_call(self.where, lambda: tuple(map(float, model.contributions())))
        if hasattr(model, "describe"):
            self.describe = lambda: plugin_call(self.where, lambda: dict(model.describe()))

    def step(self, error_rad: float, rate_radps: float, force_mps2: float) -> float:
        u = plugin_call(self.where, lambda: float(self.model.step(error_rad, rate_radps, force_mps2)))
        if u != u or u in (float("inf"), float("-inf")):
            raise WashbenchError(f"{self.where}: step returned {u!r}, not a finite number")
        return u


def load_pilot_plugin(spec: str) -> PilotPlugin:
    """Load ``FILE.py:NAME``; WashbenchError (one line) if it cannot be loaded."""
    where, path, name = plugin_file(spec, "--pilot-plugin")
    data = path.read_bytes()
    module = load_module(path, "washbench_pilot_plugin", where)
    if not hasattr(module, name):
        raise WashbenchError(f"{where}: {path} has no {name!r}")
    obj = getattr(module, name)
    if not callable(obj):
        raise WashbenchError(f"{where}: {type(obj).__name__} is not a class or callable")
    params = getattr(obj, "Params", None)
    if params is not None and not (isinstance(params, type) and issubclass(params, BaseModel)):
        raise WashbenchError(f"{where}: its Params must be a pydantic BaseModel class")
    return PilotPlugin(obj, params, f"{path}:{name}", hashlib.sha256(data).hexdigest())
