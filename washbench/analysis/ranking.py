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

Lower score is better. The score is objective (computed from the traces only) and is reported next to every rank.

**The oracle bound** (washout :data:`BOUND_WASHOUT`, :mod:`washbench.analysis.bound`) gets its score by the same
rule but no rank: it is not a washout a simulator could run (it knows the future), and it is optimal for its own
cost, not for this score. Its row comes last with ``rank`` 0 ("not ranked"); the washouts are ranked among
themselves as if it were not there.

The rules (:class:`RankRule`, ``--rank-by`` and the parameter file's ``ranking:`` section), all lower is better:

- ``felt`` (the default): the felt error of :mod:`washbench.analysis.felt`: the perceived error beyond the
  perception thresholds, its false part counted again, and the jolts the platform adds at the head, in threshold
  units, divided by what the aircraft pilot felt above threshold (1: a still platform; 0: the aircraft's own motion
  as felt). Its DOF weights follow what the pilot felt above threshold, in threshold units.
- ``score``: the rule above, the ranking before the felt error (kept for comparison with earlier results).
- ``false-cue``: the false cues by size and duration, ``sum_d F_d / T_d`` over the felt motion ``sum_d M_d / T_d``
  (:func:`washbench.analysis.felt.felt_errors`: the simulator pilot's cue beyond threshold in the wrong direction,
  or where the aircraft pilot felt none, integrated; 0: no false cue).
- ``weighted``: ``sum_d u_d E(W, d) / M_d`` with the user's DOF weights ``u_d`` (the parameter file's
  ``ranking: dof_weights:``), over the DOFs the aircraft pilot felt (``M_d`` at least ``MOTION_FLOOR``), the
  weights renormalised to sum 1 over those DOFs.

**Ties** (honest ranks). Values are sorted (lower first); a tie group starts at the best value ``v0`` not yet
ranked and takes every further value ``v`` with ``v - v0 <= max(TIE_RELATIVE * |v0|, TIE_ABSOLUTE)`` (measured
from the group's best, so a group never chains beyond the margin). Every washout of a group gets the same rank,
one more than the number of washouts ranked before the group ("1, 1, 3"), and is marked ``tied``. Rows are
ordered by rank, then value, then the order the washouts were listed in. The margins are CHOSEN
(docs/fidelity.md): 3 % of the score (0.605 against 0.595 is a tie) or 0.005, whichever is larger.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from washbench.analysis.felt import (
    DEFAULT_MEASURE,
    FeltMeasure,
    dof_terms,
    felt_key,
    felt_motion,
    felt_total,
    felt_weights,
)
from washbench.analysis.metrics import DOFS, integral_abs_error
from washbench.io.metrics_csv import MetricRow

TRANSLATIONAL_DOFS = DOFS[:3]  # surge, sway, heave
ROTATIONAL_DOFS = DOFS[3:]  # roll, pitch, yaw
METRICS = ("npc", "integral_error", "max_error")
REFERENCE_WASHOUT = "small-angle"
BOUND_WASHOUT = "bound"
"""The oracle bound's name in every output: scored, never ranked (module doc)."""

RANK_BY: tuple[str, ...] = ("felt", "score", "false-cue", "weighted")
"""The ranking rules (module docstring); the first is the default."""

TIE_RELATIVE = 0.03
"""Relative margin within which two values tie (chosen, docs/fidelity.md)."""

TIE_ABSOLUTE = 0.005
"""Absolute margin within which two values tie (chosen; for values near 0, e.g. false-cue time)."""

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
    """A washout's value of the rule (``score``, lower is better) and rank within one manoeuvre.

    ``tied``: another washout shares this rank (their values differ by less than the tie margin). ``rank`` 0: not
    ranked (the oracle bound, :data:`BOUND_WASHOUT`).
    """

    washout: str
    score: float
    rank: int
    weights: dict[str, float]
    tied: bool = False


@dataclass(frozen=True)
class RankRule:
    """How washouts are ranked: ``by`` one of RANK_BY; ``dof_weights`` (DOF -> weight >= 0) for ``weighted``."""

    by: str = "felt"
    dof_weights: tuple[tuple[str, float], ...] = ()
    tie_relative: float = TIE_RELATIVE
    tie_absolute: float = TIE_ABSOLUTE
    measure: FeltMeasure = DEFAULT_MEASURE

    def __post_init__(self) -> None:
        if self.by not in RANK_BY:
            raise ValueError(f"unknown ranking rule {self.by!r} (valid: {', '.join(RANK_BY)})")
        if self.by == "weighted" and not any(w > 0.0 for _, w in self.dof_weights):
            raise ValueError("ranking rule 'weighted' needs dof_weights with at least one positive weight")

    def record(self) -> dict[str, object]:
        """The rule as recorded in the provenance (``ranking``)."""
        return {
            "by": self.by,
            "dof_weights": dict(self.dof_weights) if self.by == "weighted" else None,
            "tie_relative": self.tie_relative,
            "tie_absolute": self.tie_absolute,
            "measure": self.measure.record(),
        }

    def label(self) -> str:
        """One line for reports: the rule and its tie margin."""
        band = "above the perception thresholds" if self.measure.deadband else "without perception thresholds"
        what = {
            "felt": f"felt error (perceived error {band}, false cues twice, the platform's jolts; relative to a "
            "still platform)" if self.measure.false_weight == 1.0 else
            f"felt error (perceived error {band}, false cues x{1 + self.measure.false_weight:g}, the platform's "
            "jolts; relative to a still platform)",
            "score": "score (weighted relative integral error, the rule before the felt error)",
            "false-cue": "false cues by size and duration, relative to the felt motion",
            "weighted": "user-weighted relative integral error ("
            + ", ".join(f"{d} {w:g}" for d, w in self.dof_weights)
            + ")",
        }[self.by]
        return (
            f"{what}; ties: values within {100 * self.tie_relative:g} % or {self.tie_absolute:g} of the "
            "best of their group share a rank"
        )


DEFAULT_RULE = RankRule()


def rule_from_record(record: object) -> RankRule:
    """The rule of a provenance's ``ranking`` entry (the default for a result written before rules existed)."""
    if not isinstance(record, Mapping):
        return RankRule(by="score")  # a result written before rules existed was ranked by the score
    weights = record.get("dof_weights") or {}
    return RankRule(
        by=str(record.get("by", "score")),
        measure=FeltMeasure.from_record(record.get("measure")),
        dof_weights=tuple((str(d), float(w)) for d, w in weights.items()) if isinstance(weights, Mapping) else (),
        tie_relative=float(record.get("tie_relative", TIE_RELATIVE)),
        tie_absolute=float(record.get("tie_absolute", TIE_ABSOLUTE)),
    )


def washout_order(rows: Iterable[MetricRow]) -> list[str]:
    """The washouts of ``rows`` in the order they first appear (the order the configuration listed them)."""
    return list(dict.fromkeys(r.washout for r in rows))


def reference_washout(washouts: Sequence[str]) -> str:
    """The washout the others are compared with: ``small-angle`` when it runs, otherwise the first listed (the
    oracle bound only when nothing else ran)."""
    if REFERENCE_WASHOUT in washouts or not washouts:
        return REFERENCE_WASHOUT
    return next((w for w in washouts if w != BOUND_WASHOUT), washouts[0])


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


def perceived_motion(
    perceived_f_mps2: np.ndarray,
    perceived_omega_radps: np.ndarray,
    dt_s: float,
    measure: FeltMeasure = DEFAULT_MEASURE,
) -> dict[str, float]:
    """How much the aircraft pilot felt per DOF: under the DOF's name the M_d of the ``score`` rule, integral of
    |perceived(t) - perceived(0)| dt; under :func:`felt_key` the felt motion above threshold of the ``felt`` rule
    (:func:`washbench.analysis.felt.felt_motion` with ``measure``).

    Surge, sway, heave in m/s^2*s; roll, pitch, yaw in deg (the units of metrics.csv).
    """
    columns = np.column_stack([perceived_f_mps2, np.degrees(perceived_omega_radps)])
    out = {dof: integral_abs_error(x, np.full_like(x, x[0]), dt_s) for dof, x in zip(DOFS, columns.T, strict=True)}
    felt = felt_motion(perceived_f_mps2, perceived_omega_radps, dt_s, measure)
    return out | {felt_key(d): float(v) for d, v in zip(DOFS, felt, strict=True)}


def felt_of(motion: Mapping[str, float]) -> np.ndarray | None:
    """The felt motion above threshold (6,) from a motion mapping, or None when it has none (a result written
    before the felt error)."""
    if not all(felt_key(d) in motion for d in DOFS):
        return None
    return np.array([float(motion[felt_key(d)]) for d in DOFS])


def felt_value(by_dof: Mapping[str, MetricRow], felt: np.ndarray, measure: FeltMeasure) -> float:
    """The ``felt`` rule's value of one washout (its six rows by DOF): :func:`washbench.analysis.felt.felt_score`;
    NaN when a row has no felt error (written before it)."""
    e = np.array([by_dof[d].felt_error for d in DOFS])
    f = np.array([by_dof[d].felt_false for d in DOFS])
    j = np.nan_to_num(np.array([by_dof[d].jolt for d in DOFS[:3]]), nan=0.0)
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(f))):
        return math.nan
    return float(np.sum(dof_terms(e, f, j, measure))) / felt_total(felt, measure)


def score_of(integral_error: np.ndarray, weights: Mapping[str, float], motion: Mapping[str, float]) -> np.ndarray:
    """The rule's score from integral errors (..., 6) in DOFS order: sum of w_d * E_d / M_d (shape (...))."""
    e = np.asarray(integral_error, dtype=np.float64)
    total = np.zeros(e.shape[:-1])
    for j, d in enumerate(DOFS):
        wd = weights[d]
        if wd > 0.0:
            total = total + wd * e[..., j] / motion[d]
    return total


def user_weights(motion: Mapping[str, float], weights: Mapping[str, float]) -> dict[str, float]:
    """The ``weighted`` rule's weights: the user's, on the DOFs felt (MOTION_FLOOR), renormalised to sum 1."""
    felt = {d: float(weights.get(d, 0.0)) if float(motion.get(d, 0.0)) >= MOTION_FLOOR[d] else 0.0 for d in DOFS}
    total = sum(felt.values())
    return {d: (w / total if total > 0.0 else 0.0) for d, w in felt.items()}


def tie_groups(values: Sequence[float], rel: float = TIE_RELATIVE, absolute: float = TIE_ABSOLUTE) -> list[int]:
    """Competition ranks ("1, 1, 3") of ``values`` (lower is better) with ties within the margin (module doc).

    A NaN value ranks last and ties with nothing. Returns the rank of each value in the given order.
    """
    idx = sorted(range(len(values)), key=lambda i: (math.isnan(values[i]), values[i] if not math.isnan(values[i])
                                                     else 0.0, i))  # fmt: skip
    ranks = [0] * len(values)
    pos = 0
    while pos < len(idx):
        v0 = values[idx[pos]]
        end = pos + 1
        if not math.isnan(v0):
            margin = max(rel * abs(v0), absolute)
            while end < len(idx) and not math.isnan(values[idx[end]]) and values[idx[end]] - v0 <= margin:
                end += 1
        for i in idx[pos:end]:
            ranks[i] = pos + 1
        pos = end
    return ranks


def rule_values(
    rows: Sequence[MetricRow], motion: Mapping[str, float], rule: RankRule = DEFAULT_RULE
) -> tuple[dict[str, float], dict[str, float]]:
    """Each washout's value of ``rule`` (lower is better) and the DOF weights it used."""
    washouts = washout_order(rows)
    by_key = {(r.washout, r.dof): r for r in rows}
    if rule.by in ("felt", "false-cue"):
        felt = felt_of(motion)
        if felt is None:
            return dict.fromkeys(washouts, math.nan), dict.fromkeys(DOFS, math.nan)
        m = rule.measure
        if rule.by == "felt":
            values = {w: felt_value({d: by_key[(w, d)] for d in DOFS}, felt, m) for w in washouts}
            return values, felt_weights(felt, m)
        values = {w: float(sum(by_key[(w, d)].felt_false / u for d, u in zip(DOFS, m.units(), strict=True)))
                  / felt_total(felt, m) for w in washouts}  # fmt: skip
        return values, felt_weights(felt, m)
    weights = dof_weights(motion) if rule.by == "score" else user_weights(motion, dict(rule.dof_weights))
    values = {w: float(score_of(np.array([by_key[(w, d)].integral_error for d in DOFS]), weights, motion))
              for w in washouts}  # fmt: skip
    return values, weights


def rank(rows: Sequence[MetricRow], motion: Mapping[str, float], rule: RankRule = DEFAULT_RULE) -> list[RankRow]:
    """Rank the washouts of one manoeuvre by ``rule`` with honest ties (module doc gives the rules).

    Rows come best first; within a tie by value (the shared rank says the order is not a verdict), equal values
    in the order the washouts were listed.
    """
    values, weights = rule_values(rows, motion, rule)
    washouts = [w for w in washout_order(rows) if w != BOUND_WASHOUT]
    ranks = tie_groups([values[w] for w in washouts], rule.tie_relative, rule.tie_absolute)
    share = {r: ranks.count(r) for r in ranks}
    def value(i: int) -> float:
        v = values[washouts[i]]
        return math.inf if math.isnan(v) else v

    ordered = sorted(range(len(washouts)), key=lambda i: (ranks[i], value(i), i))
    out = [
        RankRow(washout=washouts[i], score=values[washouts[i]], rank=ranks[i], weights=weights,
                tied=share[ranks[i]] > 1)
        for i in ordered
    ]  # fmt: skip
    if BOUND_WASHOUT in values:  # scored, not ranked (module doc)
        out.append(RankRow(washout=BOUND_WASHOUT, score=values[BOUND_WASHOUT], rank=0, weights=weights))
    return out


def undecided(ranking: Sequence[RankRow]) -> bool:
    """True when the first place is shared: the ranking is decided by less than the tie margin."""
    return sum(1 for r in ranking if r.rank == 1) > 1


def wins(rankings: Iterable[Sequence[RankRow]]) -> dict[str, int]:
    """How many manoeuvres each washout ranked first in (a shared first place counts for each)."""
    count: dict[str, int] = {}
    for ranking in rankings:
        for r in ranking:
            if r.rank < 1:  # the oracle bound: not ranked
                continue
            count.setdefault(r.washout, 0)
            if r.rank == 1:
                count[r.washout] += 1
    return count
