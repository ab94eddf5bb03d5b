"""The felt error: the ranking's measure of how far a simulator pilot's motion is from the aircraft pilot's, as a
pilot would feel the difference (docs/metrics.md, "The felt error").

Per degree of freedom d (surge, sway, heave: perceived specific force, m/s^2; roll, pitch, yaw: perceived angular
velocity, deg/s), from the aircraft pilot's perceived signal ``x`` and a simulator pilot's ``y`` on one uniform
grid of step ``dt`` (the vestibular models' outputs, linear in the head motion), with ``T_d`` the DOF's perception
threshold (Zacharias 1978: :data:`washbench.perception.thresholds.ZACHARIAS`):

* **felt error** ``E_d = integral max(|x - y| - T_d, 0) dt``: a difference below the threshold is not felt (a
  differential threshold applied to the error; a dead band of the error is convex in ``y``, so in the head motion);
* **false part** ``F_d = integral max(-s (y - x0) - T_d, 0) dt`` where the aircraft pilot feels the DOF (``s`` the
  sign of ``x - x0`` where ``|x - x0| > T_d``) and ``integral max(|y - x0| - T_d, 0) dt`` where he does not: the
  simulator pilot's cue in the wrong direction, or where there is none to give, by its size and its duration
  (``x0 = x`` at the first sample, the level a still platform keeps); convex in ``y`` because ``s`` depends on the
  aircraft alone;
* **jolt** (surge, sway, heave only) ``J_a = sum_k dt max(|f_k - f_{k-1}| / dt - |F_k - F_{k-1}| / dt - J_T, 0)``
  with ``f`` the simulator pilot's head specific force on body axis a and ``F`` the aircraft pilot's (m/s^2, not
  perceived): the jerk the platform adds beyond the aircraft's own, beyond a dead band ``J_T``, summed over the
  flight: the total size of the platform's own jolts (end stops, hard braking), which the otolith model attenuates
  (its response falls as 1/omega above about 1.5 rad/s) and a pilot feels (jerk raises perceived intensity: Grant
  and Haycock 2008; de Winkel et al. 2020). Convex in ``f`` (``|F_k - F_{k-1}|`` is data).

The aircraft pilot's **felt motion** ``M_d = integral max(|x - x0| - T_d, 0) dt`` is what a still platform leaves
unfelt. The **score** sums every term in threshold units (a DOF's integrals divided by its ``T_d``, a jolt's by its
axis's ``T``, times the jolt time ``tau_j``):

    S = [ sum_d (E_d + lambda F_d) / T_d  +  tau_j sum_a J_a / T_a ] / max( sum_d M_d / T_d , D_min )

so each DOF weighs what the pilot felt there above threshold (``w_d = (M_d / T_d) / sum``), not a fixed half per
group; false cues in a DOF the pilot did not feel still count; a still platform scores 1 (``E_d = M_d``, no false
part, no jolt) and 0 is a simulator pilot who feels what the aircraft pilot felt. ``S`` is a sum of convex
functions of the head motion over a positive constant: the ceiling is a linear programme on exactly this measure
(:mod:`washbench.analysis.ceiling`).

Integrals by the trapezoid rule on the sample grid, of the pointwise values (the linear programme's own rule); the
jolt by the rectangle rule on the sample differences. ``lambda`` (:data:`FALSE_WEIGHT`), ``tau_j``
(:data:`JOLT_TIME_S`), ``J_T`` (:data:`JERK_DEADBAND_MPS3`) and ``D_min`` (:data:`FELT_FLOOR_S`) are CHOSEN
(docs/metrics.md shows their effect). Without thresholds (``deadband=False``) the dead bands are 0 and ``T_d``
stays the unit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from washbench.numerics.jitcache import announce_compile
from washbench.perception.thresholds import ZACHARIAS, Thresholds

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
"""The degrees of freedom in order (the same as :data:`washbench.analysis.metrics.DOFS`)."""

FALSE_WEIGHT = 1.0
"""lambda: a false cue counts this much more than a missing cue of the same size and duration (chosen: twice in
all; pilots rate false cues worse than missing ones, docs/metrics.md)."""

JOLT_TIME_S = 1.0
"""tau_j (s): a jolt of total size J (m/s^2) counts as a felt error of J held for tau_j (chosen, docs/metrics.md)."""

JERK_DEADBAND_MPS3 = 50.0
"""J_T (m/s^3): jerk the platform may add beyond the aircraft's own without it counting (chosen, docs/metrics.md:
above ride-comfort jerk limits of 1-3 m/s^3, far below an end stop's 1000)."""

FELT_FLOOR_S = 1.0
"""D_min (s): the least felt motion the score divides by, in threshold-seconds (one threshold held for 1 s), so a
flight felt barely or not at all cannot blow the score up (chosen)."""


@dataclass(frozen=True)
class FeltMeasure:
    """The felt error's parameters (module docstring). ``thresholds``: the DOFs' units and dead bands (Zacharias by
    default); ``deadband``: False keeps them as units only (no dead band)."""

    thresholds: Thresholds = ZACHARIAS
    deadband: bool = True
    false_weight: float = FALSE_WEIGHT
    jolt_time_s: float = JOLT_TIME_S
    jerk_deadband_mps3: float = JERK_DEADBAND_MPS3
    felt_floor_s: float = FELT_FLOOR_S

    def __post_init__(self) -> None:
        for name in ("false_weight", "jolt_time_s", "jerk_deadband_mps3", "felt_floor_s"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")
        if self.felt_floor_s <= 0.0:
            raise ValueError("felt_floor_s must be > 0")
        if not all(u > 0.0 for u in self.units()):
            raise ValueError("every threshold must be > 0 (it is the DOF's unit)")

    def units(self) -> np.ndarray:
        """T_d (6,): m/s^2 for surge, sway, heave; deg/s for roll, pitch, yaw."""
        t = self.thresholds
        return np.array([t.f_x_mps2, t.f_y_mps2, t.f_z_mps2, t.omega_x_degps, t.omega_y_degps, t.omega_z_degps])

    def bands(self) -> np.ndarray:
        """The dead bands (6,): the units with thresholds, zeros without."""
        return self.units() if self.deadband else np.zeros(6)

    def record(self) -> dict[str, object]:
        """The parameters as recorded in the provenance (``ranking.measure``)."""
        return {
            "thresholds": self.thresholds.model_dump(),
            "deadband": self.deadband,
            "false_weight": self.false_weight,
            "jolt_time_s": self.jolt_time_s,
            "jerk_deadband_mps3": self.jerk_deadband_mps3,
            "felt_floor_s": self.felt_floor_s,
        }

    @classmethod
    def from_record(cls, record: object) -> FeltMeasure:
        """The measure of a provenance's ``ranking.measure`` (the default for a result written before it)."""
        if not isinstance(record, Mapping):
            return DEFAULT_MEASURE
        th = record.get("thresholds")
        return cls(
            thresholds=Thresholds.model_validate(th) if isinstance(th, Mapping) else ZACHARIAS,
            deadband=bool(record.get("deadband", True)),
            false_weight=float(record.get("false_weight", FALSE_WEIGHT)),
            jolt_time_s=float(record.get("jolt_time_s", JOLT_TIME_S)),
            jerk_deadband_mps3=float(record.get("jerk_deadband_mps3", JERK_DEADBAND_MPS3)),
            felt_floor_s=float(record.get("felt_floor_s", FELT_FLOOR_S)),
        )


DEFAULT_MEASURE = FeltMeasure()

FELT_PREFIX = "felt_"
"""The aircraft pilot's felt motion above threshold per DOF (:func:`felt_motion`) is kept in the motion mapping
(:func:`washbench.analysis.ranking.perceived_motion`, run.json's ``perceived_motion``) under ``felt_<dof>``, beside
the plain ``<dof>`` of the ``score`` rule."""


def felt_key(dof: str) -> str:
    """The motion mapping's key of a DOF's felt motion above threshold."""
    return FELT_PREFIX + dof


def _compiled() -> tuple:
    """The compiled sums (:mod:`washbench.analysis.metric_sums`), imported at the first use: numba is paid only by a
    command that computes a metric, and the studies' evaluation kernel adds the same sums in the same order (the same
    bits as ``washbench cue``)."""
    from washbench.analysis.metric_sums import felt_sums, jolt_sums  # deferred: numba

    announce_compile(felt_sums)
    return felt_sums, jolt_sums


def _columns(f_mps2: np.ndarray, omega_radps: np.ndarray) -> np.ndarray:
    """(N, 6), contiguous: specific force in m/s^2, angular velocity in deg/s (the DOFs' units)."""
    return np.ascontiguousarray(np.column_stack([np.asarray(f_mps2, dtype=np.float64),
                                                 np.degrees(np.asarray(omega_radps, dtype=np.float64))]))  # fmt: skip


def felt_motion(
    perceived_f_mps2: np.ndarray, perceived_omega_radps: np.ndarray, dt_s: float, measure: FeltMeasure = DEFAULT_MEASURE
) -> np.ndarray:
    """M_d (6,): the aircraft pilot's felt motion per DOF, ``integral max(|x - x0| - T_d, 0) dt`` (m/s^2*s; deg)."""
    x = _columns(perceived_f_mps2, perceived_omega_radps)
    if len(x) == 0:
        return np.zeros(6)
    out = np.empty((2, 6))
    _compiled()[0](x, np.ascontiguousarray(np.broadcast_to(x[:1], x.shape)), measure.bands(), float(dt_s), out)
    return out[0]


def felt_errors(
    aircraft_f_mps2: np.ndarray,
    aircraft_omega_radps: np.ndarray,
    sim_f_mps2: np.ndarray,
    sim_omega_radps: np.ndarray,
    dt_s: float,
    measure: FeltMeasure = DEFAULT_MEASURE,
) -> tuple[np.ndarray, np.ndarray]:
    """(E, F), each (6,): the felt error and its false part per DOF (m/s^2*s; deg), from the perceived signals
    (trapezoid rule of the pointwise values, summed in sample order)."""
    x = _columns(aircraft_f_mps2, aircraft_omega_radps)
    y = _columns(sim_f_mps2, sim_omega_radps)
    if x.shape != y.shape:
        raise ValueError(f"aircraft and simulator signals differ in shape: {x.shape} and {y.shape}")
    if len(x) == 0:
        return np.zeros(6), np.zeros(6)
    out = np.empty((2, 6))
    _compiled()[0](x, y, measure.bands(), float(dt_s), out)
    return out[0].copy(), out[1].copy()


def jolt(sim_head_f_mps2: np.ndarray, aircraft_head_f_mps2: np.ndarray, dt_s: float,
         measure: FeltMeasure = DEFAULT_MEASURE) -> np.ndarray:  # fmt: skip
    """J (3,): the jerk the platform adds at the head beyond the aircraft's and the dead band, integrated, per body
    axis (m/s^2) (module docstring), from the head specific forces (N, 3), m/s^2."""
    f = np.ascontiguousarray(sim_head_f_mps2, dtype=np.float64)
    a = np.ascontiguousarray(aircraft_head_f_mps2, dtype=np.float64)
    if f.shape != a.shape:
        raise ValueError(f"aircraft and simulator head signals differ in shape: {a.shape} and {f.shape}")
    out = np.zeros(3)
    if len(f) >= 2:
        _compiled()[1](f, a, measure.jerk_deadband_mps3 * float(dt_s), out)
    return out


def dof_terms(e: np.ndarray, f: np.ndarray, j: np.ndarray, measure: FeltMeasure = DEFAULT_MEASURE) -> np.ndarray:
    """Each DOF's part of the score's numerator (6,), in threshold-seconds: ``(E_d + lambda F_d + tau_j J_d) / T_d``
    (``j``: the jolts (3,) of surge, sway, heave)."""
    jj = np.concatenate([np.asarray(j, dtype=np.float64), np.zeros(3)])
    return (np.asarray(e) + measure.false_weight * np.asarray(f) + measure.jolt_time_s * jj) / measure.units()


def felt_total(m: np.ndarray, measure: FeltMeasure = DEFAULT_MEASURE) -> float:
    """The score's denominator: ``max(sum_d M_d / T_d, D_min)`` in threshold-seconds."""
    return max(float(np.sum(np.asarray(m) / measure.units())), measure.felt_floor_s)


def felt_weights(m: np.ndarray, measure: FeltMeasure = DEFAULT_MEASURE) -> dict[str, float]:
    """What each DOF weighs in the score: ``(M_d / T_d) / max(sum, D_min)`` (they sum to 1 unless the flight is
    felt less than ``D_min``)."""
    total = felt_total(m, measure)
    return {d: float(v) / total for d, v in zip(DOFS, np.asarray(m) / measure.units(), strict=True)}


def felt_score(e: np.ndarray, f: np.ndarray, j: np.ndarray, m: np.ndarray,
               measure: FeltMeasure = DEFAULT_MEASURE) -> float:  # fmt: skip
    """The score S (module docstring) from the felt errors, false parts, jolts and the felt motion."""
    return float(np.sum(dof_terms(e, f, j, measure))) / felt_total(m, measure)
