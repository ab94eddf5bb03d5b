"""One run of a tracking task: JSBSim, the washout and platform, the vestibular models and the pilot model in one
loop, sample by sample (:func:`fly_run`).

Each JSBSim step (``washbench.flight.fly.fly`` with its two hooks, the scripted pilot holding the other axes):

1. the step hook gets the completed sample ``k - 1`` of the aircraft pilot's head motion (specific force, body
   rates) and turns it into the simulator pilot's head motion for the condition (:class:`Condition`): the same
   motion (``aircraft``), none (``none``: at rest, ``[0, 0, -g]`` and no rotation), or the washout's on its
   platform (:class:`washbench.cueing.CueingBank`, the streaming form ``washbench run`` uses); the canals and
   otoliths (:class:`washbench.pilot.senses.AxisPerception`) turn that into what the pilot feels;
2. the command hook, at sample ``k``: the displayed error ``e = f_t(t) - attitude`` (bank angle, or pitch angle
   minus its trim), the pilot model's step on it and on what it feels (one sample late: the context's
   ``motion_lag_samples`` is 1), and the control sent: the trim command plus ``u`` plus the disturbance ``f_d(t)``
   (on the elevator with the nose-up sign for pitch).

The forcing functions rise from zero over the task's ``fade_in_s``; the measurement window is the last
``measurement_s`` of the run, after ``run_in_s``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from washbench.cueing import CueingBank
from washbench.cueing.kernel import NFIELDS, O_HEAD_F, O_HEAD_OMEGA
from washbench.cueing.variants import Washout
from washbench.flight.fly import FlightResult, fly
from washbench.flight.manoeuvre import Manoeuvre
from washbench.io.units import G0_MPS2
from washbench.perception.vestibular import VestibularParams
from washbench.pilot.forcing import Multisine
from washbench.pilot.model import PilotModel
from washbench.pilot.senses import SENSED, AxisPerception
from washbench.pilot.task import Task

AIRCRAFT = "aircraft"
"""The condition in which the simulator pilot feels the aircraft's own motion (what a pilot feels in flight)."""
NO_MOTION = "no-motion"
"""The condition in which the simulator stands still."""


@dataclass(frozen=True)
class Condition:
    """A motion condition: ``name`` (:data:`AIRCRAFT`, :data:`NO_MOTION` or a washout's name) and the washout
    (``None`` for the first two) with the platform it drives (``limits``: the loaded platform model)."""

    name: str
    washout: Washout | None = None
    limits: Any = None

    @property
    def kind(self) -> str:
        return self.name if self.washout is None else "washout"


_CONTROL_INDEX = {"roll": 0, "pitch": 1}  # aileron, elevator in fly's (aileron, elevator, rudder, throttle)
_CONTROL_SIGN = {"roll": 1.0, "pitch": -1.0}  # + aileron rolls right; - elevator pitches up
_ATTITUDE_INDEX = {"roll": 0, "pitch": 1}  # phi, theta in the command hook's state


@dataclass
class RunSignals:
    """One run, every sample (N = the task's steps): the forcing functions, the loop's signals, the motion.

    Angles in rad, rates in rad/s, specific force in m/s^2, control in the task's units (:mod:`washbench.pilot.
    model`). ``head_*``: the simulator pilot's head motion on the sensed axes; ``felt_*``: what the vestibular
    models report of it; ``aircraft_rate_radps``: the aircraft pilot's rate about the task's axis. ``platform``:
    the washout's bank rows (N, fields) when kept, for the recording. ``flight``: what JSBSim flew.
    """

    t_s: np.ndarray
    target_rad: np.ndarray
    disturbance: np.ndarray
    error_rad: np.ndarray
    control: np.ndarray
    control_visual: np.ndarray
    control_vestibular: np.ndarray
    attitude_rad: np.ndarray
    aircraft_rate_radps: np.ndarray
    head_rate_radps: np.ndarray
    head_force_mps2: np.ndarray
    felt_rate_radps: np.ndarray
    felt_force_mps2: np.ndarray
    flight: FlightResult
    axis: str = "roll"
    saturated_steps: int = 0
    platform: np.ndarray | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        return self.flight.ok

    @property
    def reason(self) -> str:
        return self.flight.reason


def _ramp(n: int, fade_steps: int) -> np.ndarray:
    """0 to 1 over the first ``fade_steps`` samples (half a cosine), then 1."""
    r = np.ones(n)
    if fade_steps > 0:
        k = np.arange(min(n, fade_steps))
        r[: len(k)] = 0.5 - 0.5 * np.cos(math.pi * k / fade_steps)
    return r


def fly_run(
    task: Task,
    manoeuvre: Manoeuvre,
    condition: Condition,
    model: PilotModel | None,
    target: Multisine,
    disturbance: Multisine,
    vestibular: VestibularParams | None = None,
    *,
    filter_start: str = "steady",
    keep_platform: bool = False,
) -> RunSignals:
    """Fly one run of ``task`` (its manoeuvre ``manoeuvre``, :func:`washbench.pilot.task.load_task`) in
    ``condition`` with the pilot model ``model`` (made for this run: its context's steps and seed). ``target`` is
    in rad of attitude, ``disturbance`` in control units (the module docstring). ``keep_platform``: keep the
    washout's rows for the recording. ``model`` None: a probe, the scripted pilot flies the task's axis too
    (``manoeuvre`` from :func:`washbench.pilot.task.manoeuvre_data` with ``probe=True``), the disturbance is added
    to its command and the command's change from its first value is recorded as the control."""
    axis = task.axis
    n = task.steps
    dt = task.dt_s
    t = np.arange(n) * dt
    ramp = _ramp(n, round(task.fade_in_s / dt))
    ft = (target.at(t) * ramp).tolist()
    fd = (disturbance.at(t) * ramp).tolist()
    rate_axis, force_axis = SENSED[axis]
    senses = AxisPerception(axis, dt, vestibular)
    out = {name: np.zeros(n) for name in ("e", "u", "uv", "um", "att", "ac_rate", "head_rate", "head_force",
                                          "felt_rate", "felt_force")}  # fmt: skip
    rows = np.zeros((n + 1, NFIELDS)) if keep_platform and condition.washout is not None else None
    bank = None
    if condition.washout is not None:
        bank = CueingBank([condition.washout], None, condition.limits, dt, filter_start)
    rest_force = -G0_MPS2 if force_axis == 2 else 0.0
    felt = [0.0, 0.0]  # what the pilot feels of the last completed sample: rate, specific force (from its first)
    force0: list[float] = []
    omega_deg = np.empty(3)
    contributions = getattr(model, "contributions", None)
    att_i, ctl_i, sign = _ATTITUDE_INDEX[axis], _CONTROL_INDEX[axis], _CONTROL_SIGN[axis]
    theta0: list[float] = []
    base0: list[float] = []
    saturated = [0]

    def sample(k: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> None:
        """The completed sample k of the aircraft pilot's head: the simulator's, then what it feels."""
        if k >= n:
            return
        out["ac_rate"][k] = omega_radps[rate_axis]
        if condition.name == NO_MOTION:
            w, f = 0.0, rest_force
        elif bank is None:
            w, f = float(omega_radps[rate_axis]), float(f_mps2[force_axis])
        else:  # as washbench run feeds its washouts: the rates as flight.parquet stores them (deg/s) and back
            np.degrees(omega_radps, out=omega_deg)
            r = bank.step(f_mps2, np.radians(omega_deg))
            if rows is not None:
                rows[k] = r[0]
            w, f = float(r[0, O_HEAD_OMEGA + rate_axis]), float(r[0, O_HEAD_F + force_axis])
        out["head_rate"][k], out["head_force"][k] = w, f
        fw_, ff_ = senses.step(w, f)
        if not force0:
            force0.append(ff_)
        felt[0], felt[1] = fw_, ff_ - force0[0]
        out["felt_rate"][k], out["felt_force"][k] = fw_, felt[1]

    def command(k: int, state: np.ndarray, commands: tuple[float, ...]) -> tuple[float, ...]:
        """Sample k: the displayed error, the pilot model's step, the control sent."""
        if k >= n:
            return commands
        attitude = float(state[att_i])
        if axis == "pitch":
            if not theta0:
                theta0.append(attitude)
            attitude -= theta0[0]
        e = ft[k] - attitude
        if model is None:  # the scripted pilot flies the axis (a probe): its command's change is the control
            if not base0:
                base0.append(commands[ctl_i])
            u = sign * (commands[ctl_i] - base0[0])
            base = base0[0]
        else:
            u = float(model.step(e, felt[0], felt[1]))
            base = commands[ctl_i]
        if not math.isfinite(u):
            raise FloatingPointError(f"the pilot model returned {u!r} at sample {k}")
        out["e"][k], out["u"][k], out["att"][k] = e, u, attitude
        if contributions is not None:
            out["uv"][k], out["um"][k] = contributions()
        sent = list(commands)
        cmd = base + sign * (u + fd[k])
        if cmd > 1.0 or cmd < -1.0:
            saturated[0] += 1
            cmd = 1.0 if cmd > 1.0 else -1.0
        sent[ctl_i] = cmd
        return tuple(sent)

    flight = fly(manoeuvre, step_hook=sample, command_hook=command)
    return RunSignals(
        t_s=t, target_rad=np.array(ft), disturbance=np.array(fd), error_rad=out["e"], control=out["u"],
        control_visual=out["uv"], control_vestibular=out["um"], attitude_rad=out["att"],
        aircraft_rate_radps=out["ac_rate"], head_rate_radps=out["head_rate"], head_force_mps2=out["head_force"],
        felt_rate_radps=out["felt_rate"], felt_force_mps2=out["felt_force"], flight=flight, axis=axis,
        saturated_steps=saturated[0], platform=None if rows is None else rows[:n],
    )  # fmt: skip
