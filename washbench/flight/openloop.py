"""Open-loop inputs of a phase, applied at every step on top of (or instead of) the pilot's commands.

Per axis (elevator, aileron, rudder, throttle) the command sent to JSBSim is

- the pilot's command plus the signal, when the axis is not free (the pilot keeps the loop closed
  and sees, and fights, the effect of the signal);
- a fixed base plus the signal, when the axis is free (``free``, ``fixed_norm`` or ``fixed_deg``):
  the base is the fixed value, else the command at the start of the phase (controls fixed), or,
  when the previous phase had the axis free as well, its base (the signal ends with its phase).

A signal in degrees (``amplitude_deg``, ``fixed_deg``) is added to the surface deflection and
mapped back through the profile's surface travel, trim included: the command is
``surface_norm(surface_deg(base + trim) + a s(t)) - trim``, so the surface moves by exactly
``a s(t)`` degrees within its travel. Beyond it the surface stops at the limit: a manoeuvre file is refused
where that cannot be avoided (:func:`washbench.flight.manoeuvre.load_manoeuvre`), and otherwise the steps
clipped are counted per phase and axis (:attr:`OpenLoop.clipped`) and the flight fails a check saying for how
long. Open-loop signals bypass the pilot's surface rate limit
(a step is a step). When a free axis is given back to the pilot in a later phase, its loop starts
from the command it finds (bumpless). A property input writes ``fixed`` (else the value at the
phase start) plus the signal; after the phase the property keeps the last value written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from washbench.errors import WashbenchError
from washbench.flight.inputs import surface_deg, surface_norm, unit_shape
from washbench.flight.manoeuvre_schema import ControlInput, Inputs, PropertyInput, Signal
from washbench.flight.pilot import Pilot
from washbench.flight.profile import PilotProfile, Surface

AXES = ("aileron", "elevator", "rudder", "throttle")
_TRAVEL_SLACK_DEG = 1e-6  # a deflection asked this far past a stop is rounding, not a clipped input
AXIS_PROPERTIES = ("fcs/aileron-cmd-norm", "fcs/elevator-cmd-norm", "fcs/rudder-cmd-norm", "fcs/throttle-cmd-norm")


@dataclass(frozen=True)
class _Plan:
    """One axis or property for the current phase: base and signal, all resolved at the phase start."""

    index: int  # 0..3: aileron, elevator, rudder, throttle; -1: a property
    free: bool
    base: float  # free axis: the command (norm) or, with ``deg``, the surface deflection (deg); property: its value
    deg: bool  # work in surface degrees
    amplitude: float  # of the signal: deg with ``deg``, else norm (or the property's unit)
    signal: Signal | None
    trim: float  # trim command added before the surface scale (deg mode)
    travel: tuple[float, float]  # surface travel (min_deg, max_deg) (deg mode)
    lo: float  # command limits (norm mode)
    hi: float
    node: Any = None  # property inputs: the JSBSim node written

    def shape(self, t: float) -> float:
        """The signal at ``t`` (s since the phase start), amplitude included."""
        s = self.signal
        if s is None or s.shape is None:
            return 0.0
        return self.amplitude * unit_shape(s.shape, t, s.start_s, s.duration_s, s.period_s, s.start_hz, s.end_hz,
                                           s.sweep)  # fmt: skip

    def command(self, t: float, pilot_command: float) -> tuple[float, bool]:
        """(the command, True when the deflection asked in degrees lies beyond the travel and was clipped)."""
        base = self.base if self.free else pilot_command
        if self.deg:
            lo_deg, hi_deg = self.travel
            base_deg = base if self.free else surface_deg(base + self.trim, lo_deg, hi_deg)
            want = base_deg + self.shape(t)
            clipped = want < lo_deg - _TRAVEL_SLACK_DEG or want > hi_deg + _TRAVEL_SLACK_DEG
            return surface_norm(want, lo_deg, hi_deg) - self.trim, clipped
        u = base + self.shape(t)
        return (self.lo if u < self.lo else self.hi if u > self.hi else u), False


class OpenLoop:
    """The open-loop inputs of the phase being flown; ``active`` is False when it has none."""

    def __init__(self, fdm: Any, profile: PilotProfile, pilot: Pilot) -> None:
        self.pm = fdm.get_property_manager()
        self.surfaces = profile.surfaces
        self.pilot = pilot
        self.axis_nodes = [self.pm.get_node(name) for name in AXIS_PROPERTIES]
        self.plans: list[_Plan | None] = [None] * 4
        self.props: list[_Plan] = []
        self.active = False
        self.phase = ""
        self.clipped: dict[tuple[str, str], int] = {}
        """(phase, axis) -> steps at which the deflection asked in degrees lay beyond the surface travel."""

    def begin_phase(self, inputs: Inputs | None, phase: str = "") -> None:
        """Resolve the inputs of a new phase from the present commands; give freed axes back to the pilot."""
        self.phase = phase
        previous = self.plans
        self.plans = [None] * 4
        self.props = []
        if inputs is not None:
            for i, axis in enumerate(AXES):
                ci: ControlInput | None = getattr(inputs, axis)
                if ci is not None:
                    before = previous[i]
                    carried = before.command(-1.0, 0.0)[0] if before is not None and before.free else None
                    self.plans[i] = self._axis_plan(i, ci, carried)
            self.props = [self._property_plan(pi) for pi in inputs.properties]
        for i, plan in enumerate(previous):
            now = self.plans[i]
            if plan is not None and plan.free and not (now is not None and now.free):
                self.pilot.take_back(AXES[i], self.axis_nodes[i].get_double_value())
        self.active = any(p is not None for p in self.plans) or bool(self.props)

    def _axis_plan(self, i: int, ci: ControlInput, carried: float | None) -> _Plan:
        """``carried``: the base command of the previous phase if it had this axis free too (kept, not its signal)."""
        now = self.axis_nodes[i].get_double_value() if carried is None else carried
        free = ci.free or ci.fixed_norm is not None or ci.fixed_deg is not None
        deg = ci.fixed_deg is not None or ci.amplitude_deg is not None
        lo, hi = (0.0, 1.0) if AXES[i] == "throttle" else (-1.0, 1.0)
        trim, travel = 0.0, (-1.0, 1.0)
        if deg:
            surface: Surface = getattr(self.surfaces, AXES[i])  # load_manoeuvre checked the profile has them
            travel = (surface.min_deg, surface.max_deg)
            if surface.trim_property is not None and self.pm.hasNode(surface.trim_property):
                trim = self.pm.get_node(surface.trim_property).get_double_value()
        if ci.fixed_deg is not None:
            base = ci.fixed_deg
        elif ci.fixed_norm is not None:
            base = surface_deg(ci.fixed_norm + trim, *travel) if deg else ci.fixed_norm
        else:
            base = surface_deg(now + trim, *travel) if deg else now
        amplitude = ci.amplitude_deg if ci.amplitude_deg is not None else (ci.amplitude_norm or 0.0)
        return _Plan(i, free, base, deg, amplitude, ci, trim, travel, lo, hi)

    def _property_plan(self, pi: PropertyInput) -> _Plan:
        if not self.pm.hasNode(pi.property):  # load_manoeuvre checks it; a manoeuvre built in Python may not be
            raise WashbenchError(f"unknown JSBSim property '{pi.property}' in an open-loop input")
        node = self.pm.get_node(pi.property)
        base = pi.fixed if pi.fixed is not None else node.get_double_value()
        return _Plan(-1, True, base, False, pi.amplitude or 0.0, pi, 0.0, (-1.0, 1.0), -math.inf, math.inf, node)

    def apply(self, t: float, aileron: float, elevator: float, rudder: float, throttle: float) -> tuple[float, ...]:
        """The commands to send at ``t`` (s since the phase start), from the pilot's; writes property inputs."""
        out = [aileron, elevator, rudder, throttle]
        for i, plan in enumerate(self.plans):
            if plan is not None:
                out[i], clipped = plan.command(t, out[i])
                if clipped:
                    key = (self.phase, AXES[i])
                    self.clipped[key] = self.clipped.get(key, 0) + 1
        for plan in self.props:
            plan.node.set_double_value(plan.base + plan.shape(t))
        return tuple(out)
