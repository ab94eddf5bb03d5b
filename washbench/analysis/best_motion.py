"""The best achieved: the least value of the ranking's own measure that a motion of the platform model reaches on a
flight, searched for with the whole flight known (docs/yardstick.md, "The best achieved").

It starts from the best of every motion the bench knows for the flight: every other washout the run flew on it
(given by the bench, :class:`washbench.cueing.algorithm.Alongside`), the naive references
(:mod:`washbench.cueing.references`, made by the bound when the run did not select them) and the bound's replay
(:mod:`washbench.analysis.bound_replay`); each is flown again through the platform model from its own start
(:func:`candidate_of`: the same motion, to the platform's rounding) and scored by the run's rule
(:class:`Yardstick`). From the best, **sequential convex programming**: the rule's value as a linear programme with
the attitude's kinematics linearised about the current motion, within a trust region
(:mod:`washbench.analysis.felt_programme`), solved; its plan flown through the platform model; the flown motion
scored exactly; taken only if it scores better (the trust region then grows when the programme predicted the gain
well), else the trust region shrinks and the current motion stays. So the result is never worse than its start,
and every step it reports is a motion the platform made.

The search is a heuristic with a guarantee on one side only: at or below every motion it started from; how far
above the true best it stays is what the bracket [ceiling, best achieved] shows (the ceiling,
:mod:`washbench.analysis.ceiling`; docs/yardstick.md, "What the ceiling cannot say"). What it costs is estimated
before it starts, with the bound's other parts (:func:`washbench.io.cost.bound`, ``BOUND_SEARCH``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from washbench.analysis.felt import felt_errors, felt_motion, felt_total, jolt
from washbench.analysis.felt_programme import (
    Aircraft,
    Reference,
    Sphere,
    Weights,
    qexp,
    qmul,
    solve_step,
)
from washbench.analysis.metrics import DOFS, dof_metrics
from washbench.analysis.ranking import DEFAULT_RULE, RankRule, dof_weights, perceived_motion, user_weights
from washbench.perception.vestibular import VestibularModel, VestibularParams, canal_model, otolith_model

Fly = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], Any]
"""``fly(start_pos (3,), start_q (4,), pos (N, 3), q (N, 4))`` -> a trace (``head_f_mps2``, ``head_omega_radps``,
``q``, ``acc_mps2``, ``omega_radps``, ``pos_m``): set points flown through the run's platform model
(:func:`washbench.cueing.bank.flyer`)."""

REPLAY = "bound's replay"
"""The candidate name of the bound's replay plan (:func:`washbench.analysis.bound_replay.replay`)."""


@dataclass(frozen=True)
class Scoring:
    """How a run scores a motion: its ranking rule (:class:`washbench.analysis.ranking.RankRule`, the felt error by
    default) and its vestibular model (None: the default)."""

    rule: RankRule = DEFAULT_RULE
    vestibular: VestibularParams | None = None


@dataclass(frozen=True)
class Settings:
    """The search's settings (the parameter file's ``bound:`` section, :class:`washbench.analysis.bound.BoundParams`):
    ``steps`` linear programmes at most (0: the best of the candidates, no search); ``trust_rad`` the first trust
    region of the attitude's turn (rad); ``iterations`` PIQP's iterations per programme; ``tolerance`` its gap and
    feasibility tolerances."""

    steps: int = 3
    trust_rad: float = 0.05
    iterations: int = 30
    tolerance: float = 1e-3


STATIONARY = 1e-6
"""A programme that predicts a gain below this fraction of the current value ends the search (chosen)."""

TRUST_GROWTH = 2.0
TRUST_SHRINK = 0.4
TRUST_MAX = 8.0
"""The trust region doubles after a step that gained at least half of what the programme predicted, shrinks to 0.4
of itself after a step not taken, and stays within 8 times its first size (chosen; docs/yardstick.md)."""


class Yardstick:
    """A run's rule on one flight (N samples ``dt_s`` apart): the aircraft pilot's perceived motion, the rule's value of
    any simulator pilot's head motion (:meth:`value`, as the ranking computes it from metrics.csv) and the programme's
    weights that make the same value (:meth:`weights`)."""

    def __init__(self, f_mps2: np.ndarray, omega_radps: np.ndarray, dt_s: float, scoring: Scoring | None = None,
                 filter_start: str = "steady") -> None:  # fmt: skip
        self.scoring = scoring if scoring is not None else Scoring()
        self.rule = self.scoring.rule
        self.dt = float(dt_s)
        self.filter_start = filter_start
        self.f_air = np.array(f_mps2, dtype=np.float64)  # a writable copy: the compiled jolt's one signature
        self.model = VestibularModel(self.dt, self.scoring.vestibular)
        self.aircraft = self.model.perceive(self.f_air, np.asarray(omega_radps, dtype=np.float64), filter_start)
        measure = self.rule.measure
        self.felt = felt_motion(self.aircraft.f_mps2, self.aircraft.omega_radps, self.dt, measure)
        self.motion = perceived_motion(self.aircraft.f_mps2, self.aircraft.omega_radps, self.dt, measure)

    def value(self, head_f_mps2: np.ndarray, head_omega_radps: np.ndarray) -> float:
        """The rule's value (lower is better) of a simulator pilot's head motion (N, 3) each, m/s^2 and rad/s."""
        p = self.model.perceive(head_f_mps2, head_omega_radps, self.filter_start)
        ac, m, dt = self.aircraft, self.rule.measure, self.dt
        units = m.units()
        if self.rule.by in ("felt", "false-cue"):
            e, f = felt_errors(ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt, m)
            if self.rule.by == "false-cue":
                return float(np.sum(f / units)) / felt_total(self.felt, m)
            j = jolt(np.asarray(head_f_mps2, dtype=np.float64), self.f_air, dt, m)
            terms = (e + m.false_weight * f + m.jolt_time_s * np.concatenate([j, np.zeros(3)])) / units
            return float(np.sum(terms)) / felt_total(self.felt, m)
        rows = dof_metrics("x", ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt)
        w = self._score_weights()
        return float(sum(w[d] * r.integral_error / self.motion[d] for d, r in zip(DOFS, rows, strict=True)
                         if w[d] > 0.0))  # fmt: skip

    def _score_weights(self) -> dict[str, float]:
        if self.rule.by == "score":
            return dof_weights(self.motion)
        return user_weights(self.motion, dict(self.rule.dof_weights))

    def weights(self) -> Weights:
        """The programme's objective (:class:`washbench.analysis.felt_programme.Weights`, rotations in rad) whose value
        is the rule's (:meth:`value`)."""
        m = self.rule.measure
        rad = np.array([1.0, 1.0, 1.0, math.pi / 180.0, math.pi / 180.0, math.pi / 180.0])
        if self.rule.by in ("felt", "false-cue"):
            total = felt_total(self.felt, m)
            per = 1.0 / (m.units() * rad * total)  # per m/s^2*s and per rad of a DOF's integral
            felt_rule = self.rule.by == "felt"
            return Weights(error=per if felt_rule else np.zeros(6),
                           false=per * (m.false_weight if felt_rule else 1.0), band=m.bands() * rad,
                           jolt=(m.jolt_time_s / (m.units()[:3] * total)) if felt_rule else np.zeros(3),
                           jerk_deadband_mps3=m.jerk_deadband_mps3)  # fmt: skip
        w = self._score_weights()
        error = np.array([w[d] / self.motion[d] / rad[i] if w[d] > 0.0 else 0.0 for i, d in enumerate(DOFS)])
        return Weights(error=error, false=np.zeros(6), band=np.zeros(6), jolt=np.zeros(3))


@dataclass(frozen=True)
class Candidate:
    """A motion to start from: its name, its start set point (``start_pos`` (3,) m, ``start_q`` (4,)) and its set
    points (``pos`` (N, 3) m, ``q`` (N, 4))."""

    name: str
    start_pos: np.ndarray
    start_q: np.ndarray
    pos: np.ndarray
    q: np.ndarray


def candidate_of(name: str, trace: Any, dt_s: float) -> Candidate:
    """A flown motion (``pos_m`` (N, 3), ``q`` (N, 4), ``omega_radps`` (N, 3): a washout's trace) as set points that
    the platform model flies again as it was flown: the motion itself, from the attitude the first sample's rate
    turned from (``q_0 exp(-omega_0 dt)``: the start the platform turned from at the rate it had), the stage from
    the centre (where the platform always starts)."""
    q = np.ascontiguousarray(trace.q, dtype=np.float64)
    w0 = np.asarray(trace.omega_radps, dtype=np.float64)[0]
    start = qmul(q[0], qexp(-w0 * float(dt_s)))
    return Candidate(name, np.zeros(3), start / np.linalg.norm(start), np.ascontiguousarray(trace.pos_m,
                     dtype=np.float64), q)  # fmt: skip


@dataclass
class Result:
    """The search's result: the start set point and set points of the best motion found (``start_pos`` (3,),
    ``start_q`` (4,), ``pos`` (N, 3), ``q`` (N, 4)), its value, the candidate it started from and every candidate's
    value (flown again), the programmes solved (``steps``), the steps taken (``accepted``) and PIQP's iterations in
    all."""

    start_pos: np.ndarray
    start_q: np.ndarray
    pos: np.ndarray
    q: np.ndarray
    value: float
    start_from: str
    candidates: dict[str, float]
    steps: int = 0
    accepted: int = 0
    iterations: int = 0
    history: list[tuple[float, float, bool]] = field(default_factory=list)
    """Per programme: (its predicted value, the flown value, taken)."""

    def report(self) -> dict[str, float]:
        """Numbers for run.json (``algorithms.bound``): the value found, the start's, each candidate's, the counts."""
        out = {"value": self.value, "start_value": self.candidates[self.start_from], "steps": float(self.steps),
               "accepted": float(self.accepted), "iterations": float(self.iterations)}  # fmt: skip
        out |= {f"candidate:{name}": v for name, v in self.candidates.items() if math.isfinite(v)}
        return out


def sphere_of(limits: Any) -> Sphere:
    """The limits the programme keeps, from Atlas-shaped limits (a platform's own or its box,
    :func:`washbench.platform.model.planning_limits`)."""
    t = limits.translation
    return Sphere(pos=np.array(t.position_limit_m.xyz, dtype=np.float64),
                  vel=np.array(t.velocity_limit_mps.xyz, dtype=np.float64),
                  acc=np.array(t.acceleration_limit_mps2.xyz, dtype=np.float64),
                  rate=math.radians(limits.rotation.rate_limit_degps),
                  ang_acc=math.radians(limits.rotation.acceleration_limit_degps2))  # fmt: skip


def search(
    yard: Yardstick,
    candidates: Sequence[Candidate],
    fly: Fly,
    limits: Any,
    gravity_mps2: float,
    settings: Settings | None = None,
) -> Result:
    """The best achieved (module docstring): the candidates flown and scored, then up to ``settings.steps`` linear
    programmes from the best of them. ``limits``: Atlas-shaped limits the programmes keep (the platform model flies
    every plan and keeps its own)."""
    if not candidates:
        raise ValueError("the search needs at least one motion to start from")
    st = settings if settings is not None else Settings()
    dt = yard.dt
    values: dict[str, float] = {}
    best: tuple[float, Candidate, Any] | None = None
    for c in candidates:
        tr = fly(c.start_pos, c.start_q, c.pos, c.q)
        v = yard.value(tr.head_f_mps2, tr.head_omega_radps)
        values[c.name] = v
        if math.isfinite(v) and (best is None or v < best[0]):
            best = (v, c, tr)
    if best is None:
        raise ValueError("no candidate motion has a finite value")
    value, start, flown = best
    result = Result(start.start_pos, start.start_q, start.pos, start.q, value, start.name, values)
    n = len(start.pos)
    if st.steps <= 0 or n < 2:
        return result
    vest = yard.scoring.vestibular if yard.scoring.vestibular is not None else VestibularParams()
    oto, can = otolith_model(vest.otolith, dt), canal_model(vest.canals, dt)
    aircraft = Aircraft(yard.aircraft.f_mps2, yard.aircraft.omega_radps, yard.f_air)
    weights = yard.weights()
    sphere = sphere_of(limits)
    rest = yard.filter_start == "rest"
    rho = st.trust_rad
    for _ in range(st.steps):
        if value <= 0.0:  # nothing left to gain
            break
        ref = Reference(q=np.ascontiguousarray(flown.q), acc=np.ascontiguousarray(flown.acc_mps2),
                        q_start=result.start_q)  # fmt: skip
        step = solve_step(ref, aircraft, dt, gravity_mps2, sphere, oto, can, weights, rest, rho, st.tolerance,
                          st.iterations)  # fmt: skip
        result.steps += 1
        result.iterations += step.iterations
        usable = step.status in ("Solved", "MaxIterations") and np.isfinite(step.pos).all() \
            and np.isfinite(step.turn).all()
        taken = False
        if usable and step.value >= value - STATIONARY * max(value, 1e-12):
            break  # the programme sees no gain about this motion: a stationary point of its model
        if usable:
            q_sp = qmul(ref.q, qexp(step.turn))
            q_sp /= np.linalg.norm(q_sp, axis=1)[:, None]
            tr = fly(result.start_pos, result.start_q, step.pos, q_sp)
            v = yard.value(tr.head_f_mps2, tr.head_omega_radps)
            result.history.append((step.value, v, bool(v < value)))
            if v < value:  # taken: the motion flown is the new current one
                predicted = value - step.value
                gained = value - v
                value, flown = v, tr
                result.pos, result.q, result.value = step.pos, q_sp, v
                result.accepted += 1
                taken = True
                if predicted > 0.0 and gained >= 0.5 * predicted:
                    rho = min(rho * TRUST_GROWTH, TRUST_MAX * st.trust_rad)
        if not taken:
            rho *= TRUST_SHRINK
    return result


def flown_candidates(motions: Mapping[str, Any], dt_s: float) -> list[Candidate]:
    """The run's other motions as candidates (:func:`candidate_of`), in the run's order."""
    return [candidate_of(name, tr, dt_s) for name, tr in motions.items()]


__all__ = ["REPLAY", "Candidate", "Fly", "Result", "Scoring", "Settings", "Yardstick", "candidate_of",
           "flown_candidates", "search", "sphere_of"]  # fmt: skip
