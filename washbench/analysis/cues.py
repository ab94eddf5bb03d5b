"""Cue classification: at each instant, is a simulator pilot's cue correct, false, missing or scaled?

Per degree of freedom (DOF), from the aircraft pilot's perceived signal ``x`` and a simulator pilot's ``y``
(the vestibular models' outputs, same uniform grid) and the DOF's perception threshold ``T``. Both are taken
as deviations from the resting value ``r`` (``[0, 0, -g0]`` for specific force, 0 for angular velocity, as the
dead band of :mod:`washbench.perception.thresholds`): ``a = x - r``, ``b = y - r``. A pilot *feels* the DOF
when ``|a| > T`` (aircraft) or ``|b| > T`` (simulator). At each sample the class is

===========  ===================================================================================
``none``     neither pilot feels the DOF (nothing to cue, nothing cued)
``correct``  both feel it, same direction, and the ratio ``|b| / |a|`` is inside ``SCALE_BAND``
``scaled``   both feel it, same direction, the ratio outside ``SCALE_BAND`` (too weak or too strong)
``false``    the simulator pilot feels it and the aircraft pilot does not, or both feel it in
             opposite directions (the paper's "negative" cue)
``missing``  the aircraft pilot feels it and the simulator pilot does not
===========  ===================================================================================

The five time fractions sum to 1. A **false-cue event** is a maximal run of consecutive ``false`` samples;
runs separated by less than ``MERGE_GAP_S`` are one event, and events shorter than ``MIN_EVENT_S`` are
counted in the time fraction but not listed. An event has its start and end time [s] (first and last false
sample), its DOF and its peak ``max |b|`` (the simulator pilot's strongest false sensation, m/s^2 or deg/s).

The classes follow the terms of Reid and Nahon (1986, Part 3) and Grant and Reid (PROTEST, J. Aircraft 34(2),
1997): false cues (spurious or wrong-direction motion), missing cues and scaled cues; the published work
states them in words, so the threshold rule, ``SCALE_BAND``, ``MERGE_GAP_S`` and ``MIN_EVENT_S`` are CHOSEN
here (docs/fidelity.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from washbench.perception.thresholds import STANDARD_GRAVITY_MPS2, ZACHARIAS

CLASSES: tuple[str, ...] = ("none", "correct", "scaled", "false", "missing")
NONE, CORRECT, SCALED, FALSE, MISSING = range(5)

SCALE_BAND: tuple[float, float] = (0.5, 2.0)
"""Ratio |simulator| / |aircraft| (perceived deviations) counted as a correct cue (chosen: within a factor 2)."""

MERGE_GAP_S = 0.25
"""False samples separated by less than this [s] belong to one event (chosen)."""

MIN_EVENT_S = 0.1
"""Shortest false-cue event listed [s] (chosen; shorter runs still count in the false time fraction)."""


@dataclass(frozen=True)
class FalseCueEvent:
    """One false-cue event: ``start_s``..``end_s`` (times of its first and last false sample), DOF, peak."""

    dof: str
    start_s: float
    end_s: float
    peak: float


@dataclass(frozen=True)
class CueSummary:
    """Time fractions per class (``CLASSES`` order, sum 1) and the false-cue events of one DOF."""

    fractions: tuple[float, float, float, float, float]
    events: tuple[FalseCueEvent, ...]

    def fraction(self, name: str) -> float:
        """The time fraction of class ``name`` (one of ``CLASSES``)."""
        return self.fractions[CLASSES.index(name)]


def classify(
    aircraft: np.ndarray,
    simulator: np.ndarray,
    threshold: float,
    rest: float = 0.0,
    band: tuple[float, float] = SCALE_BAND,
) -> np.ndarray:
    """Class index (int8, (N,), ``CLASSES`` order) at each sample of two perceived signals (N,) of one DOF.

    ``threshold`` and ``rest`` in the signals' unit (module docstring gives the rule).
    """
    a = np.asarray(aircraft, dtype=np.float64) - rest
    b = np.asarray(simulator, dtype=np.float64) - rest
    if a.ndim != 1 or a.shape != b.shape:
        raise ValueError(f"expected two 1-D signals of equal length, got shapes {a.shape} and {b.shape}")
    if not threshold >= 0.0:
        raise ValueError(f"threshold must be >= 0, got {threshold!r}")
    felt_a = np.abs(a) > threshold
    felt_b = np.abs(b) > threshold
    both = felt_a & felt_b
    same = np.sign(a) == np.sign(b)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(b) / np.abs(a)
    inside = (ratio >= band[0]) & (ratio <= band[1])
    out = np.full(a.shape, NONE, dtype=np.int8)
    out[both & same & inside] = CORRECT
    out[both & same & ~inside] = SCALED
    out[(both & ~same) | (felt_b & ~felt_a)] = FALSE
    out[felt_a & ~felt_b] = MISSING
    return out


def false_events(
    classes: np.ndarray, simulator_deviation: np.ndarray, dt_s: float, dof: str, t0_s: float = 0.0
) -> tuple[FalseCueEvent, ...]:
    """The false-cue events of one DOF (module docstring); ``simulator_deviation`` = ``b`` (N,), times from t0."""
    idx = np.flatnonzero(classes == FALSE)
    if idx.size == 0:
        return ()
    gap = max(1, round(MERGE_GAP_S / dt_s))
    breaks = np.flatnonzero(np.diff(idx) > gap)
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    out = []
    b = np.abs(np.asarray(simulator_deviation, dtype=np.float64))
    for s, e in zip(starts, ends, strict=True):
        if (e - s) * dt_s + 1e-12 < MIN_EVENT_S:
            continue
        seg = classes[s : e + 1] == FALSE
        out.append(FalseCueEvent(dof, t0_s + s * dt_s, t0_s + e * dt_s, float(np.max(b[s : e + 1][seg]))))
    return tuple(out)


def summarise(
    aircraft: np.ndarray,
    simulator: np.ndarray,
    threshold: float,
    dt_s: float,
    dof: str,
    rest: float = 0.0,
    band: tuple[float, float] = SCALE_BAND,
) -> CueSummary:
    """Time fractions and false-cue events of one DOF (module docstring)."""
    cls = classify(aircraft, simulator, threshold, rest, band)
    counts = np.bincount(cls, minlength=len(CLASSES)).astype(np.float64)
    fractions = tuple(float(c) for c in counts / cls.size)
    events = false_events(cls, np.asarray(simulator, dtype=np.float64) - rest, dt_s, dof)
    return CueSummary(fractions=fractions, events=events)  # type: ignore[arg-type]


def events_text(events: tuple[FalseCueEvent, ...]) -> str:
    """Events as ``start-end@peak`` (s, s, the DOF's unit) joined by ``;`` (the metrics.csv field)."""
    return ";".join(f"{e.start_s:.3f}-{e.end_s:.3f}@{e.peak:.4g}" for e in events)


def parse_events(text: str, dof: str) -> tuple[FalseCueEvent, ...]:
    """Read back :func:`events_text` (ValueError on a malformed field)."""
    out = []
    for part in filter(None, text.split(";")):
        span, peak = part.split("@")
        start, end = span.split("-", 1)
        out.append(FalseCueEvent(dof, float(start), float(end), float(peak)))
    return tuple(out)


def dof_thresholds() -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Zacharias thresholds per DOF (m/s^2 for surge, sway, heave; deg/s for roll, pitch, yaw) and resting values."""

    th = ZACHARIAS
    thresholds = (th.f_x_mps2, th.f_y_mps2, th.f_z_mps2, th.omega_x_degps, th.omega_y_degps, th.omega_z_degps)
    return thresholds, (0.0, 0.0, -STANDARD_GRAVITY_MPS2, 0.0, 0.0, 0.0)


def dof_columns(f_mps2: np.ndarray, omega_radps: np.ndarray) -> np.ndarray:
    """Perceived motion (N, 3) + (N, 3) as (6, N) in DOFS order, rotations in deg/s (the units of metrics.csv)."""
    return np.vstack([np.asarray(f_mps2, dtype=np.float64).T, np.degrees(np.asarray(omega_radps).T)])


def classified_rows(
    rows: list, ac_f_mps2: np.ndarray, ac_omega_radps: np.ndarray, sim_f_mps2: np.ndarray,
    sim_omega_radps: np.ndarray, dt_s: float,
) -> list:  # fmt: skip
    """``rows`` (six :class:`washbench.io.metrics_csv.MetricRow`, DOFS order) with their cue classification."""
    import dataclasses

    thresholds, rest = dof_thresholds()
    a = dof_columns(ac_f_mps2, ac_omega_radps)
    s = dof_columns(sim_f_mps2, sim_omega_radps)
    out = []
    for j, row in enumerate(rows):
        summ = summarise(a[j], s[j], thresholds[j], dt_s, row.dof, rest[j])
        out.append(
            dataclasses.replace(
                row,
                cue_correct_frac=summ.fraction("correct"),
                cue_scaled_frac=summ.fraction("scaled"),
                cue_false_frac=summ.fraction("false"),
                cue_missing_frac=summ.fraction("missing"),
                false_cue_events=events_text(summ.events),
            )
        )
    return out
