"""What the simulator pilot's vestibular organs report, one sample at a time, for the pilot model.

The project's vestibular models (:mod:`washbench.perception.vestibular`: the canal and otolith transfer functions,
discretised once as parallel first-order sections with a first-order hold) stepped per sample on the one axis the
task needs: the canals on the head's angular velocity about the task's axis, the otoliths on the head's specific
force along the task's sensed axis. Each section is ``x[k] = phi x[k-1] + b1 u[k] + b0 u[k-1]`` and the output is
the sum, exactly :meth:`washbench.perception.vestibular.DiscreteModel.apply` (the same coefficients and the same
order of operations; ``tests/test_pilot_model.py`` checks the bits), started in the steady state of the first
sample. The perception thresholds of the model, when it has them, are the same dead band
(:func:`washbench.perception.thresholds.deadband`).
"""

from __future__ import annotations

import math

from washbench.perception.thresholds import STANDARD_GRAVITY_MPS2
from washbench.perception.vestibular import DiscreteModel, VestibularParams, canal_model, otolith_model

DEFAULT_VESTIBULAR = "telban-cardullo"
"""The vestibular models the pilot model feels with unless told (docs/pilot-model.md, "Perception": the project's
canal model with a lead, as the multimodal pilot-model literature's; the Young-Oman canals have none and the
vestibular channel then gains almost nothing over the visual one)."""

SENSED = {"roll": (0, 1), "pitch": (1, 2)}
"""Task axis -> (the angular velocity's body axis, the specific force's body axis): roll: x and y; pitch: y and z."""


class _Sections:
    """One scalar input through the sections of a :class:`DiscreteModel`."""

    def __init__(self, model: DiscreteModel) -> None:
        b, phi, steady = model.arrays()
        self.b1 = [float(v) for v in b[:, 0]]
        self.b0 = [float(v) for v in b[:, 1]]
        self.phi = [float(v) for v in phi]
        self.steady = [float(v) for v in steady]
        self.x: list[float] | None = None
        self.u_prev = 0.0

    def step(self, u: float) -> float:
        if self.x is None:
            self.x = [s * u for s in self.steady]
            self.u_prev = u
        x = self.x
        y = 0.0
        for i in range(len(x)):
            x[i] = self.phi[i] * x[i] + self.b1[i] * u + self.b0[i] * self.u_prev
            y += x[i]
        self.u_prev = u
        return y


class AxisPerception:
    """The canals about a task's axis and the otoliths along its sensed axis (:data:`SENSED`), per sample."""

    def __init__(self, axis: str, dt_s: float, params: VestibularParams | None = None) -> None:
        p = params if params is not None else VestibularParams()
        self.rate_axis, self.force_axis = SENSED[axis]
        self.canals = _Sections(canal_model(p.canals, dt_s))
        self.otoliths = _Sections(otolith_model(p.otolith, dt_s))
        th = p.thresholds
        self.rate_threshold = 0.0 if th is None else float(th.omega_radps()[self.rate_axis])
        self.force_threshold = 0.0 if th is None else float(th.f_mps2()[self.force_axis])
        self.force_rest = -STANDARD_GRAVITY_MPS2 if self.force_axis == 2 else 0.0

    def step(self, omega_radps: float, f_mps2: float) -> tuple[float, float]:
        """(perceived angular velocity, rad/s; perceived specific force, m/s^2) of the next sample."""
        w = self.canals.step(omega_radps)
        f = self.otoliths.step(f_mps2)
        if self.rate_threshold > 0.0:
            w = _deadband(w, self.rate_threshold, 0.0)
        if self.force_threshold > 0.0:
            f = _deadband(f, self.force_threshold, self.force_rest)
        return w, f


def _deadband(x: float, threshold: float, reference: float) -> float:
    """:func:`washbench.perception.thresholds.deadband` for one number."""
    d = x - reference
    return reference + math.copysign(max(abs(d) - threshold, 0.0), d) if d != 0.0 else reference
