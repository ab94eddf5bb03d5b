"""Comparing washouts across a suite: the Table-4 style comparison and a per-manoeuvre ranking.

Comparison (like the paper's Table 4). For each manoeuvre, degree of freedom and metric, every
washout's value and its difference from the reference washout (small-angle when it runs, otherwise the
first washout listed: :func:`reference_washout`), signed so that POSITIVE MEANS BETTER than the
reference. All three metrics are "lower is better" (NPC is 1.0 for a perfect
correlation and grows as the correlation worsens), so the difference is ``small_angle - washout``.
An undefined NPC (flat signal) gives an empty difference.

Ranking (the scoring rule). For one manoeuvre, washout W gets the score

    score(W) = sum over DOFs d of  w_d * E(W, d) / M_d

- ``E(W, d)`` is the integral of |aircraft perceived - simulator perceived| over the manoeuvre
  (Eq. 22) for that DOF.
- ``M_d`` is the aircraft pilot's own perceived motion in that DOF: the integral of
  |perceived(t) - perceived(0)| dt, i.e. the error a simulator that stayed still (after the first
  sample) would make. ``E/M`` is therefore a relative error: 0 is perfect, 1 is no better than
  staying still, above 1 is worse than staying still (false cues).
- ``w_d`` weighs each DOF by how much the aircraft pilot felt there, within its group: the three
  specific-force DOFs (surge, sway, heave) share half the weight in proportion to their M_d, the
  three angular DOFs (roll, pitch, yaw) the other half in proportion to theirs. A DOF with little
  motion therefore weighs little, and one the pilot does not feel at all (M_d below the floor,
  ``MOTION_FLOOR``) weighs nothing, so a tiny denominator cannot blow a score up. If a whole group is
  below the floor, the other group takes all the weight.

Lower score is better; ranks are 1 (best) to the number of washouts, ties broken by the order the washouts
were listed in (the configuration's), for determinism. The score is
objective (computed from the traces only) and is reported next to every rank.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from washbench.analysis.metrics import DOFS, MetricRow, integral_abs_error

TRANSLATIONAL_DOFS = DOFS[:3]  # surge, sway, heave
ROTATIONAL_DOFS = DOFS[3:]  # roll, pitch, yaw
METRICS = ("npc", "integral_error", "max_error")
REFERENCE_WASHOUT = "small-angle"

#: Motion below which a DOF is not weighed: integral of |perceived change| in m/s^2*s for the
#: translational DOFs and deg for the rotational ones. 0.05 m/s^2 (about the otolith threshold of
#: Zacharias) held for 1 s, and 0.5 deg/s (about the canal threshold) for 1 s.
MOTION_FLOOR = {"surge": 0.05, "sway": 0.05, "heave": 0.05, "roll": 0.5, "pitch": 0.5, "yaw": 0.5}


@dataclass(frozen=True)
class ComparisonRow:
    """One metric in one DOF: each washout's value and its improvement over small-angle."""

    dof: str
    metric: str
    values: dict[str, float]  # washout -> value (NaN if undefined)
    better_than_reference: dict[str, float]  # washout -> reference - value (positive = better)


@dataclass(frozen=True)
class RankRow:
    """A washout's score (lower is better) and rank within one manoeuvre."""

    washout: str
    score: float
    rank: int
    weights: dict[str, float]


def washout_order(rows: Iterable[MetricRow]) -> list[str]:
    """The washouts of ``rows`` in the order they first appear (the order the configuration listed them)."""
    return list(dict.fromkeys(r.washout for r in rows))


def reference_washout(washouts: Sequence[str]) -> str:
    """The washout the others are compared with: ``small-angle`` when it runs, otherwise the first listed."""
    return REFERENCE_WASHOUT if REFERENCE_WASHOUT in washouts or not washouts else washouts[0]


def compare(rows: Sequence[MetricRow], reference: str | None = None) -> list[ComparisonRow]:
    """Table-4 style comparison of every washout against ``reference`` (default :func:`reference_washout`)."""
    by_key = {(r.washout, r.dof): r for r in rows}
    washouts = washout_order(rows)
    reference = reference_washout(washouts) if reference is None else reference
    out: list[ComparisonRow] = []
    for dof in DOFS:
        if not any((w, dof) in by_key for w in washouts):
            continue
        for metric in METRICS:
            values = {w: float(getattr(by_key[(w, dof)], metric)) for w in washouts if (w, dof) in by_key}
            ref = values.get(reference, math.nan)
            diffs = {w: (ref - v) for w, v in values.items() if w != reference}
            out.append(ComparisonRow(dof=dof, metric=metric, values=values, better_than_reference=diffs))
    return out


def dof_weights(motion: Mapping[str, float]) -> dict[str, float]:
    """Weights of the scoring rule from the aircraft pilot's perceived motion per DOF (see module doc)."""
    weights = dict.fromkeys(DOFS, 0.0)
    felt = {d: float(motion.get(d, 0.0)) for d in DOFS}
    groups = [g for g in (TRANSLATIONAL_DOFS, ROTATIONAL_DOFS) if any(felt[d] >= MOTION_FLOOR[d] for d in g)]
    for group in groups:
        total = sum(felt[d] for d in group if felt[d] >= MOTION_FLOOR[d])
        for d in group:
            if felt[d] >= MOTION_FLOOR[d]:
                weights[d] = felt[d] / total / len(groups)
    return weights


def perceived_motion(perceived_f_mps2: np.ndarray, perceived_omega_radps: np.ndarray, dt_s: float) -> dict[str, float]:
    """How much the aircraft pilot felt per DOF (the M_d): integral of |perceived(t) - perceived(0)| dt.

    Surge, sway, heave in m/s^2*s; roll, pitch, yaw in deg (the units of metrics.csv).
    """
    columns = np.column_stack([perceived_f_mps2, np.degrees(perceived_omega_radps)])
    return {dof: integral_abs_error(x, np.full_like(x, x[0]), dt_s) for dof, x in zip(DOFS, columns.T, strict=True)}


def score_of(integral_error: np.ndarray, weights: Mapping[str, float], motion: Mapping[str, float]) -> np.ndarray:
    """The rule's score from integral errors (..., 6) in DOFS order: sum of w_d * E_d / M_d (shape (...))."""
    e = np.asarray(integral_error, dtype=np.float64)
    total = np.zeros(e.shape[:-1])
    for j, d in enumerate(DOFS):
        wd = weights[d]
        if wd > 0.0:
            total = total + wd * e[..., j] / motion[d]
    return total


def rank(rows: Sequence[MetricRow], motion: Mapping[str, float]) -> list[RankRow]:
    """Score and rank the washouts of one manoeuvre (module doc gives the rule)."""
    weights = dof_weights(motion)
    washouts = washout_order(rows)
    by_key = {(r.washout, r.dof): r for r in rows}
    scores = {w: float(score_of(np.array([by_key[(w, d)].integral_error for d in DOFS]), weights, motion))
              for w in washouts}
    order = {w: i for i, w in enumerate(washouts)}
    ordered = sorted(washouts, key=lambda w: (scores[w], order[w]))
    return [RankRow(washout=w, score=scores[w], rank=i + 1, weights=weights) for i, w in enumerate(ordered)]


def wins(rankings: Iterable[Sequence[RankRow]]) -> dict[str, int]:
    """How many manoeuvres each washout ranked first in."""
    count: dict[str, int] = {}
    for ranking in rankings:
        for r in ranking:
            count.setdefault(r.washout, 0)
            if r.rank == 1:
                count[r.washout] += 1
    return count
