"""The washout stage's interface: what any washout algorithm receives and returns.

A washout algorithm turns the aircraft pilot-head motion into the platform's **set points**; the kinematic Atlas
model (:mod:`washbench.platform`) tracks them within its limits and gives the simulator pilot-head motion. So
every algorithm, built in or a user's, sits on the same bench::

    f, omega (aircraft pilot head) --> washout --> set point (position, attitude) --> Atlas --> simulator head

Per sample the algorithm receives

- ``f_mps2``: specific force at the aircraft pilot's head, aircraft body axes (x forward, y right, z down), m/s^2;
  [0, 0, -g] at rest (f = a - g). float64 array of shape (3,), a read-only copy: do not keep a reference to it.
- ``omega_radps``: aircraft body angular velocity, body axes, rad/s, float64 (3,), read-only.

and returns a :data:`SetPoint` ``(pos_m, q)``:

- ``pos_m``: the platform's translational set point, inertial north-east-down axes, metres from the stage's
  centre, array-like of 3 finite floats;
- ``q``: the cockpit's attitude set point, a unit quaternion, scalar first [w, x, y, z], mapping simulator body
  vectors to inertial ones (v_I = q v_B q*), array-like of 4 finite floats (normalised by the bench).

The time step ``dt_s`` (s) is fixed for a run and given when the algorithm is made (:class:`WashoutContext`).
State lives in the algorithm object (one object per run and washout: the bench makes a new one for every
recording or flight and calls :meth:`WashoutAlgorithm.start` once before the first :meth:`~WashoutAlgorithm.step`).

The platform starts at the set point :meth:`WashoutAlgorithm.start` returns, at rest (``filter_start="rest"``) or
already moving at the rate between that set point and the first step's (``"steady"``).

Optionally an algorithm has ``trace(f_mps2 (N, 3), omega_radps (N, 3)) -> (pos_m (N, 3), q (N, 4))``: the
whole-trace form, called instead of N steps after :meth:`~WashoutAlgorithm.start` (it must give the same numbers
as the steps; the bench uses it for recorded files, studies and the OMCT).

Optionally an algorithm has ``steps(f_mps2 (M, 3), omega_radps (M, 3)) -> (pos_m (M, 3), q (M, 4))``: the block
form, the next M samples from where it is (after :meth:`~WashoutAlgorithm.start` or earlier steps), the same
numbers as M steps; the bench then calls it once per block of samples (a flight's lockstep takes 120 at a time)
instead of ``step`` per sample. Its set points are checked as a step's are; it gives no flags (but see
``block_tilt`` below).

Optionally a whole-recording algorithm (``whole_only``) has ``consider(alongside)``: before its ``trace`` the bench
gives it an :class:`Alongside`, the motions the run's other washouts made on the same recording, a way to fly set
points of its own through the run's platform model exactly as the bench will fly its result, and how the run scores
a motion; its :meth:`~WashoutAlgorithm.start` is then asked after its ``trace`` (its start may come from its plan).
The bound (the best achieved, :mod:`washbench.analysis.best_motion`) is such an algorithm.

Optionally an algorithm has ``flags() -> tuple[bool, bool]``: whether its own tilt-rate and rotational-rate limits
acted on the last step (the ``sat_tilt_rate`` and ``sat_rot_rate`` columns); without it both are False.

Optionally an algorithm has ``tilt_rate() -> float``: the tilt-coordination rate it commanded on the last step,
rad/s, after its own tilt-rate limit and measured as that limit measures it (the ``mpc`` washout limits the roll
and pitch tilt rates each: the larger of the two); NaN when it commanded none. The bench records it (the
``tilt_rate_radps`` field, the recording's ``/envelope/tilt_rate``); without it the field is NaN.

A block form (``trace``, ``steps``) gives no flags and no tilt rate unless the algorithm also has ``block_tilt() ->
(tilt_rate_radps (M,), at_limit (M,))``: for each of the M samples of its last ``trace`` or ``steps`` call, what
``tilt_rate()`` and the first of ``flags()`` would have said after that sample's step (the rotational flag of a
block stays False).

A plugin is a class (or any callable) ``factory(params, context) -> WashoutAlgorithm``; ``params`` is the validated
section of the parameter file named after the plugin (an instance of the class's ``Params`` pydantic model, or
``None`` when it declares none). See ``docs/washouts.md`` for a worked example and how to load one
(``--washout-plugin FILE.py:NAME``, the ``washbench.washouts`` entry-point group).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from washbench.platform.hexapod import MotionEnvelope
from washbench.platform.limits import PlatformLimits
from washbench.platform.model import PlatformModel
from washbench.platform.plugins import PluginPlatform

SetPoint = tuple[np.ndarray, np.ndarray]
"""(pos_m (3,) inertial NED, m; q (4,) body->inertial, scalar first)."""


@dataclass(frozen=True)
class WashoutContext:
    """What an algorithm is told when it is made: the run's fixed facts, SI.

    dt_s: sample interval, s. gravity_mps2: g, m/s^2 (g_I = [0, 0, +g]). limits: the platform's limits in the
    Atlas's shape (position, velocity, acceleration per inertial axis; rotation rate and acceleration): the Atlas
    file's own, or for another platform a box about neutral (:func:`washbench.platform.model.planning_limits`); the
    platform enforces its own limits whatever the set points, an algorithm may use these to plan. filter_start:
    ``"steady"`` (the first sample is a steady state) or ``"rest"`` (the simulator was level and still before it).
    head_offset_m: the pilot's head from the cockpit centre (the motion reference point), simulator body axes, m.
    platform: the loaded platform file of any kind (:data:`washbench.platform.model.PlatformModel`, a plugin's
    :class:`washbench.platform.plugins.PluginPlatform`), or None (unknown: plan against ``limits`` alone). A washout
    that knows a kind's own geometry plans against it from here: the ``mpc`` washout, on a hexapod
    (:class:`washbench.platform.hexapod.HexapodModel`), against its legs (docs/optimal-mpc.md).
    """

    dt_s: float
    gravity_mps2: float
    limits: PlatformLimits | MotionEnvelope
    filter_start: str
    head_offset_m: tuple[float, float, float]
    platform: PlatformModel | PluginPlatform | None = None


@dataclass(frozen=True)
class Alongside:
    """What a whole-recording algorithm with ``consider`` is told before its ``trace`` (module docstring).

    motions: washout name -> its trace (:class:`washbench.cueing.bank.WashoutTrace`: the platform's motion and the
    simulator pilot's head on this recording, as the bench flew them): every other washout of the run, or of the
    call (the streaming :class:`washbench.cueing.bank.CueingBank` knows none: empty). fly: ``fly(start_pos (3,),
    start_q (4,), pos (N, 3), q (N, 4))`` -> the trace of these set points (from that start set point) flown through
    the run's platform model with this washout's configuration (its head, the filters' start): what the bench will
    make of them, bit for bit. scoring: how the run scores a motion (its ranking rule and vestibular model, opaque
    to the cueing stage: :class:`washbench.analysis.best_motion.Scoring`), or None (the defaults)."""

    motions: Mapping[str, Any]
    fly: Callable[[Any, Any, Any, Any], Any]
    scoring: object | None = None


@runtime_checkable
class WashoutAlgorithm(Protocol):
    """One washout, sample by sample (see the module docstring for units, frames and state)."""

    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """Initialise from the first sample (or, with ``filter_start="rest"``, from rest: [0, 0, -g] and 0);
        return the set point the platform starts at."""
        ...

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """Advance by one sample (dt_s); return the new set point."""
        ...


__all__ = ["Alongside", "SetPoint", "WashoutAlgorithm", "WashoutContext"]
