"""The suite report's first screen: which washout, per manoeuvre and per group of similar manoeuvres, by how much
against the paper's CW1 (small-angle), and how much of what the platform could give it reaches.

Pure functions over the suite's rankings (:func:`washbench.analysis.ranking.rank`), metrics and, where the bound
ran, the ceilings (``ceiling.csv``, :mod:`washbench.analysis.ceiling`). Every figure shown is one of:

- **gain over the reference**: ``(S_ref - S_best) / S_ref`` of the ranking's value (score), positive = better;
- **ceiling reached**: the recovered fraction of the best washout's score, ``(1 - S) / (1 - S_ceiling)``;
- **wins**: manoeuvres where a washout is first alone; manoeuvres with a shared first place are counted once, as
  shared, so the counts add up to the manoeuvres ranked.

Manoeuvres keep the suite's order, washouts the order they were listed in, everywhere on the page.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from washbench.analysis.ranking import BOUND_WASHOUT, MOTION_FLOOR, ROTATIONAL_DOFS, TRANSLATIONAL_DOFS, RankRow
from washbench.io.metrics_csv import MetricRow
from washbench.review.numbers import sig

GAIN_AIM = 0.20
"""The gain over CW1 the verdict counts manoeuvres against (the project's aim: 20 % better)."""


@dataclass(frozen=True)
class Entry:
    """One ranked manoeuvre: its label (``aircraft / manoeuvre``), group (the manoeuvre's name), ranking, metrics,
    the aircraft pilot's perceived motion per DOF, and its ceiling table (``ceiling.csv``; empty without the bound)."""

    label: str
    group: str
    ranking: Sequence[RankRow]
    metrics: Sequence[MetricRow]
    motion: Mapping[str, float]
    ceiling: Mapping[str, Mapping[str, Mapping[str, float]]]


def _pct(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{100.0 * x:+.0f} %"


def _share(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{100.0 * x:.0f} %"


def firsts(ranking: Sequence[RankRow]) -> list[str]:
    """The washouts ranked first (several: a tie within the margin)."""
    return [r.washout for r in ranking if r.rank == 1]


def gain(ranking: Sequence[RankRow], washout: str, reference: str) -> float:
    """``(S_ref - S_w) / S_ref`` (NaN when either is missing or the reference's is not positive)."""
    scores = {r.washout: r.score for r in ranking}
    ref, w = scores.get(reference, math.nan), scores.get(washout, math.nan)
    return (ref - w) / ref if math.isfinite(ref) and math.isfinite(w) and ref > 0.0 else math.nan


def reached(entry: Entry, washout: str) -> float:
    """The washout's recovered fraction of the ceiling on the score (NaN without the bound)."""
    return float(entry.ceiling.get(washout, {}).get("score", {}).get("recovered", math.nan))


def group_errors(entry: Entry, washout: str) -> tuple[float, float]:
    """The washout's mean relative error over the felt specific-force DOFs and over the felt rotational DOFs."""
    by = {r.dof: r.integral_error for r in entry.metrics if r.washout == washout}
    out = []
    for group in (TRANSLATIONAL_DOFS, ROTATIONAL_DOFS):
        rel = [by[d] / entry.motion[d] for d in group if d in by and entry.motion.get(d, 0.0) >= MOTION_FLOOR[d]]
        out.append(sum(rel) / len(rel) if rel else math.nan)
    return out[0], out[1]


def _median(xs: Sequence[float]) -> float:
    xs = [x for x in xs if math.isfinite(x)]
    return statistics.median(xs) if xs else math.nan


def verdict_lines(entries: Sequence[Entry], washouts: Sequence[str], reference: str) -> list[str]:
    """The verdict section (module docstring): a paragraph that answers, the per-manoeuvre table, the groups."""
    ranked = [e for e in entries if e.ranking]
    contenders = [w for w in washouts if w != BOUND_WASHOUT]
    if not ranked or not contenders:
        return []
    has_ceiling = any(e.ceiling for e in ranked)
    n = len(ranked)
    alone = dict.fromkeys(contenders, 0)
    shared = 0
    for e in ranked:
        top = firsts(e.ranking)
        if len(top) == 1:
            alone[top[0]] += 1
        else:
            shared += 1
    gains = {w: [gain(e.ranking, w, reference) for e in ranked] for w in contenders}
    median_gain = {w: _median(g) for w, g in gains.items()}
    at_aim = {w: sum(1 for g in gains[w] if math.isfinite(g) and g >= GAIN_AIM) for w in contenders}
    others = [w for w in contenders if w != reference]
    best = max(others or contenders, key=lambda w: (median_gain[w] if math.isfinite(median_gain[w]) else -math.inf,
                                                     alone[w]))  # fmt: skip
    lines = ["## Verdict", ""]
    text = (f"**{best}** is the best washout of this suite by the median gain over {reference}: "
            f"{_pct(median_gain[best])} (first alone on {alone[best]} of {n} manoeuvres; at least "
            f"{100 * GAIN_AIM:.0f} % better than {reference} on {at_aim[best]} of {n}).")  # fmt: skip
    if has_ceiling:
        reach = _median([reached(e, best) for e in ranked])
        text += (f" It recovers a median {_share(reach)} of what this platform could recover (the ceiling, the least "
                 "error any motion of the platform could reach: 100 %; standing still: 0 %).")  # fmt: skip
    if not has_ceiling:
        text += (" How much better any washout could be on each manoeuvre (the ceiling) needs `--washout bound` "
                 "(docs/yardstick.md).")
    lines += [text, ""]
    # why: the specific-force cues against the rotational ones
    errors = {w: [group_errors(e, w) for e in ranked] for w in contenders}  # (specific force, rotation) per manoeuvre
    trans = {w: _median([t for t, _ in errors[w]]) for w in contenders}
    rot = {w: _median([r for _, r in errors[w]]) for w in contenders}
    best_t = min(contenders, key=lambda w: trans[w] if math.isfinite(trans[w]) else math.inf)
    best_r = min(contenders, key=lambda w: rot[w] if math.isfinite(rot[w]) else math.inf)

    def versus(w: str, values: Mapping[str, float]) -> str:
        ref = "" if w == reference else f", {reference} {sig(values.get(reference, math.nan))}"
        return f"median relative error {sig(values[w])}{ref}"

    why = (f"Why: the specific-force cues (surge, sway, heave) are best given by **{best_t}** "
           f"({versus(best_t, trans)}), the rotational cues (roll, pitch, yaw) by **{best_r}** "
           f"({versus(best_r, rot)}); relative error: the integral error over what the aircraft pilot felt, 1 = a "
           "platform standing still.")
    if best_t != best_r:
        why += " No washout has both halves: the score trades one against the other."
    lines += [why, ""]
    wins = ", ".join(f"{w} {alone[w]}" for w in contenders)
    lines += [f"First place alone: {wins}; shared (a tie within the margin): {shared}; "
              f"together {sum(alone.values()) + shared} of {n} manoeuvres.", ""]  # fmt: skip
    # per manoeuvre
    head = ["manoeuvre", "best washout", f"gain over {reference}"]
    head += ["ceiling reached", "replay reached"] if has_ceiling else []
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for e in ranked:
        top = firsts(e.ranking)
        name = " = ".join(top) + (" (tie)" if len(top) > 1 else "")
        lead = top[0]
        row = [e.label, name, _pct(gain(e.ranking, lead, reference)) if lead != reference else "0 % (it is the best)"]
        if has_ceiling:
            row += [_share(reached(e, lead)), _share(reached(e, BOUND_WASHOUT))]
        lines.append("| " + " | ".join(row) + " |")
    lines.append("")
    # per group of similar manoeuvres (one manoeuvre name over the aircraft)
    groups: dict[str, list[Entry]] = {}
    for e in ranked:
        groups.setdefault(e.group, []).append(e)
    if any(len(g) > 1 for g in groups.values()):
        lines += ["Per group of similar manoeuvres (the same manoeuvre on each aircraft):", ""]
        lines += [f"| group | manoeuvres | best by median gain over {reference} | its median gain |",
                  "|---|---|---|---|"]
        for name, members in groups.items():
            med = {w: _median([gain(e.ranking, w, reference) for e in members]) for w in others or contenders}
            top = max(med, key=lambda w: med[w] if math.isfinite(med[w]) else -math.inf)
            lines.append(f"| {name} | {len(members)} | {top} | {_pct(med[top])} |")
        lines.append("")
    return lines


__all__ = ["GAIN_AIM", "Entry", "firsts", "gain", "group_errors", "reached", "verdict_lines"]
