"""The pilot-model stage's interface: what any pilot model receives and returns, sample by sample.

A pilot model flies one axis of a compensatory tracking task (:mod:`washbench.pilot.task`) in closed loop with
JSBSim. The bench (:mod:`washbench.pilot.loop`) gives it, at every step ``k`` (``t = k dt``)::

    displayed error e (rad) ------------------------------------------+
    simulator head motion --> washout + platform --> canals, otoliths --+--> pilot model --> u --> JSBSim control

- ``error_rad``: the displayed error, target minus attitude on the task's axis (roll: bank angle; pitch: pitch
  angle from its trim value), rad; positive when the aircraft must roll right (pitch up) to null it;
- ``rate_radps``: what the semicircular canals report of the simulator pilot's angular velocity about the task's
  axis (body x for roll, body y for pitch), rad/s: the project's canal model (:mod:`washbench.perception.
  vestibular`) on the head motion of the condition (the aircraft's own, none, or a washout's on its platform);
- ``force_mps2``: what the otoliths report of the specific force along the task's sensed axis (body y for roll,
  body z for pitch), minus its value at the start, m/s^2.

Both perceived signals reach the model ``context.motion_lag_samples`` samples late (the head motion of sample
``k`` is complete one step after JSBSim produced it): a model with delays shortens its vestibular delay line by as
much. It returns ``u``: the control in the task's units: normalised aileron (+ rolls right) for roll,
normalised elevator with the nose-up sign (``-fcs/elevator-cmd-norm``) for pitch, added to the trim command
together with the disturbance forcing function.

Optionally a model has ``contributions() -> tuple[float, float]``: the visual and the vestibular (canal and
otolith) parts of the last ``u`` (the report's contribution of each modality; without it they are not reported),
and ``describe() -> dict[str, float]``: its parameters for the report.

A plugin is a class (or any callable) ``factory(params, context) -> PilotModel``; ``params`` is the ``pilot:``
section of the task file validated by the class's ``Params`` pydantic model (``None`` when it declares none). See
docs/pilot-model.md for a worked example and ``--pilot-plugin FILE.py:NAME``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

AXES = ("roll", "pitch")
"""The task axes: roll (bank angle, ailerons) and pitch (pitch angle, elevator)."""


@dataclass(frozen=True)
class PilotContext:
    """What a pilot model is told when it is made: the run's fixed facts, SI.

    ``dt_s``: time step, s. ``axis``: ``"roll"`` or ``"pitch"``. ``steps``: samples in the run. ``seed``: this
    run's seed (its remnant; derived from the task's seed and the run's index). ``motion_lag_samples``: how late the
    perceived motion arrives (module docstring). ``plant`` and ``motion``: the loop as the bench measured it before
    the run, on ``frequencies_radps`` (the forcing functions' frequencies): the controlled element (attitude per
    unit control, complex) and the condition's motion filter (simulator over aircraft angular velocity on the
    task's axis; 1 for the aircraft's own motion, 0 for none): what a model that adapts itself would use.
    """

    dt_s: float
    axis: str
    steps: int
    seed: int
    motion_lag_samples: int = 1
    frequencies_radps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    plant: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=complex))
    motion: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=complex))


@runtime_checkable
class PilotModel(Protocol):
    """One pilot model, sample by sample (see the module docstring for units, signs and timing)."""

    def step(self, error_rad: float, rate_radps: float, force_mps2: float) -> float:
        """Advance by one sample; return the control ``u`` (task's control units)."""
        ...


__all__ = ["AXES", "PilotContext", "PilotModel"]
