"""The suite report's first screen: what was compared, which washout gives the truest motion, whether it beats the
naive references and a platform standing still, and, where the bound ran, how much better any motion could be.

Pure functions over the suite's rankings (:func:`washbench.analysis.ranking.rank`), metrics and, where the bound
ran, the ceilings (``ceiling.csv``, :mod:`washbench.analysis.ceiling`). Every figure shown is one of:

- a washout's **value** of the ranking rule on a manoeuvre (the felt error by default: 1 = a platform standing
  still, 0 = what the aircraft pilot felt), and its **median** over the manoeuvres;
- **gain over the reference washout** (small-angle, the paper's CW1, when it ran): ``(S_ref - S) / S_ref``;
- **wins**: manoeuvres where a washout is first alone; a shared first place (within the rule's tie margin) is counted
  once, as shared;
- the **bracket** (with ``--washout bound``): the ceiling (the least value any motion of the platform could reach,
  certified) and the **best achieved** (the least value of every motion run on the flight: the washouts, the naive
  references and the bound: with ``--washout bound`` a motion searched for from the best of all of them, never worse);
  the best washout's distance to each.

The **naive references** (``replay``, ``replay-rotation``, ``still``: :mod:`washbench.cueing.references`) are ranked
with the washouts but are not candidates for "the best washout": the verdict says whether the best washout beats the
best of them, and marks the manoeuvres where one does better. The bound (the best achieved) is scored, never
ranked.

Manoeuvres keep the suite's order, washouts the order they were listed in, everywhere on the page.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from washbench.analysis.felt import felt_key
from washbench.analysis.ranking import (
    BOUND_WASHOUT,
    DEFAULT_RULE,
    MOTION_FLOOR,
    ROTATIONAL_DOFS,
    TRANSLATIONAL_DOFS,
    RankRow,
    RankRule,
    tie_groups,
)
from washbench.cueing.registry import REFERENCE_KINDS
from washbench.cueing.variants import EVERY_BUILTIN
from washbench.io.metrics_csv import MetricRow
from washbench.review.bound_section import VACUOUS, vacuous
from washbench.review.numbers import sig

REFERENCES = REFERENCE_KINDS
"""The naive references' names (:data:`washbench.cueing.registry.REFERENCE_KINDS`)."""

BUILT_IN = tuple(w for w in EVERY_BUILTIN if w not in REFERENCE_KINDS and w != BOUND_WASHOUT)
"""The built-in causal washouts, for "not compared"."""


STILL_MARK = "▲"
"""Marks a manoeuvre on which every washout is worse than a platform standing still (value above 1)."""

REFERENCE_MARK = "◆"
"""Marks a manoeuvre on which a naive reference does better than every washout."""


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


def _median(xs: Sequence[float]) -> float:
    xs = [x for x in xs if math.isfinite(x)]
    return statistics.median(xs) if xs else math.nan


def firsts(ranking: Sequence[RankRow]) -> list[str]:
    """The washouts ranked first (several: a tie within the margin)."""
    return [r.washout for r in ranking if r.rank == 1]


def values(ranking: Sequence[RankRow]) -> dict[str, float]:
    """Every motion's value of the rule on the manoeuvre (the bound's included)."""
    return {r.washout: r.score for r in ranking}


def gain(ranking: Sequence[RankRow], washout: str, reference: str) -> float:
    """``(S_ref - S_w) / S_ref`` (NaN when either is missing or the reference's is not positive)."""
    scores = values(ranking)
    ref, w = scores.get(reference, math.nan), scores.get(washout, math.nan)
    return (ref - w) / ref if math.isfinite(ref) and math.isfinite(w) and ref > 0.0 else math.nan


def reached(entry: Entry, washout: str) -> float:
    """The washout's recovered fraction of the ceiling on the rule's value (NaN without the bound)."""
    return float(entry.ceiling.get(washout, {}).get("score", {}).get("recovered", math.nan))


def ceiling_value(entry: Entry) -> float:
    """The ceiling of the rule's value on the manoeuvre (NaN without the bound)."""
    for rows in entry.ceiling.values():
        v = float(rows.get("score", {}).get("ceiling", math.nan))
        if math.isfinite(v):
            return v
    return math.nan


def best_of(entry: Entry, names: Sequence[str]) -> tuple[str, float]:
    """The least value among ``names`` on the manoeuvre, and whose (``("", nan)`` when none ran)."""
    scores = values(entry.ranking)
    ran = [(scores[n], n) for n in names if n in scores and math.isfinite(scores[n])]
    if not ran:
        return "", math.nan
    v, n = min(ran)
    return n, v


def group_errors(entry: Entry, washout: str, rule: RankRule = DEFAULT_RULE) -> tuple[float, float]:
    """The washout's mean relative error over the felt specific-force DOFs and over the felt rotational DOFs: under
    the felt error, each DOF's terms over what the pilot felt there above threshold; otherwise the integral error over
    the perceived motion (1 = a platform standing still in that DOF, above 1 worse than one)."""
    by = {r.dof: r for r in entry.metrics if r.washout == washout}
    out = []
    m = rule.measure
    for group in (TRANSLATIONAL_DOFS, ROTATIONAL_DOFS):
        rel = []
        for d in group:
            if d not in by:
                continue
            r = by[d]
            if rule.by == "felt":
                felt = float(entry.motion.get(felt_key(d), 0.0))
                if felt > 0.0 and math.isfinite(r.felt_error):
                    jolt = 0.0 if math.isnan(r.jolt) else r.jolt
                    rel.append((r.felt_error + m.false_weight * r.felt_false + m.jolt_time_s * jolt) / felt)
            elif entry.motion.get(d, 0.0) >= MOTION_FLOOR[d]:
                rel.append(r.integral_error / entry.motion[d])
        out.append(sum(rel) / len(rel) if rel else math.nan)
    return out[0], out[1]


def _list(names: Sequence[str]) -> str:
    return ", ".join(names) if names else "none"


def compared_lines(washouts: Sequence[str], command: str = "washbench suite --out results --washout all") -> list[str]:
    """What was compared and what was not (the built-in washouts, the references, the bound), with the command that
    compares them all."""
    causal = [w for w in washouts if w not in REFERENCES and w != BOUND_WASHOUT]
    refs = [w for w in washouts if w in REFERENCES]
    missing = [w for w in BUILT_IN if w not in washouts]
    missing_refs = [w for w in REFERENCES if w not in washouts]
    text = f"Compared: {len(causal)} washout{'s' if len(causal) != 1 else ''} ({_list(causal)})"
    text += f" and {len(refs)} naive reference{'s' if len(refs) != 1 else ''} ({_list(refs)})" if refs else ""
    text += "; the best achieved (the bound) and the ceiling." if BOUND_WASHOUT in washouts else "."
    gaps = []
    if missing:
        gaps.append(f"{len(missing)} built-in washout{'s' if len(missing) != 1 else ''} ({_list(missing)})")
    if missing_refs:
        gaps.append(f"the reference{'s' if len(missing_refs) != 1 else ''} {_list(missing_refs)}")
    if BOUND_WASHOUT not in washouts:
        gaps.append("the bound (how much better any washout could be)")
    if gaps:
        text += f" **Not compared**: {'; '.join(gaps)}; `{command}` compares them all (docs/yardstick.md)."
    return [text, ""]


def verdict_lines(
    entries: Sequence[Entry],
    washouts: Sequence[str],
    reference: str,
    rule: RankRule = DEFAULT_RULE,
    failed: int = 0,
) -> list[str]:
    """The verdict section (module docstring): what was compared, a paragraph that answers, the per-manoeuvre table,
    the groups. ``failed``: manoeuvres that did not run or failed (said first)."""
    ranked = [e for e in entries if e.ranking]
    causal = [w for w in washouts if w != BOUND_WASHOUT and w not in REFERENCES]
    refs = [w for w in washouts if w in REFERENCES]
    lines = ["## Verdict", ""]
    if failed:
        total = failed + len(ranked)
        lines += [f"**{failed} of {total} manoeuvres failed** (under Failures, below); everything on this page is on "
                  f"the {len(ranked)} that ran.", ""]  # fmt: skip
    if not ranked or not causal:
        return [*lines, "Nothing was ranked." if not ranked else "No washout ran (only references or the bound).", ""]
    lines += compared_lines(washouts)
    n = len(ranked)
    scale = ("felt error (1 = a platform standing still, 0 = what the aircraft pilot felt)" if rule.by == "felt"
             else f"{rule.by} (lower is better)")  # fmt: skip
    med = {w: _median([values(e.ranking).get(w, math.nan) for e in ranked]) for w in washouts}
    alone = dict.fromkeys(causal, 0)
    shared = 0
    for e in ranked:
        top = [w for w in firsts(_causal_ranking(e.ranking, causal, rule)) if w in causal]
        if len(top) == 1:
            alone[top[0]] += 1
        else:
            shared += 1
    order = sorted(causal, key=lambda w: (med[w] if math.isfinite(med[w]) else math.inf, causal.index(w)))
    best = order[0]
    ranks = tie_groups([med[w] for w in order], rule.tie_relative, rule.tie_absolute)
    tied = [w for w, r in zip(order, ranks, strict=True) if r == 1]
    gains = {w: _median([gain(e.ranking, w, reference) for e in ranked]) for w in causal}
    ref_note = "" if best == reference or reference not in med else \
        f", {reference} {sig(med[reference])} (a median gain of {_pct(gains[best])})"  # fmt: skip
    if len(tied) > 1:
        text = (f"**No clear winner**: {', '.join(f'**{w}** ({sig(med[w])})' for w in tied)} have median {scale} "
                f"within the ranking's margin ({100 * rule.tie_relative:g} % or {rule.tie_absolute:g}) of each other"
                f"{ref_note}; first alone on " + ", ".join(f"{w} {alone[w]}" for w in tied) + f" of {n} manoeuvres.")
    else:
        text = (f"**{best}** gives the truest motion of this suite: median {scale} {sig(med[best])}{ref_note}; "
                f"first alone on {alone[best]} of {n} manoeuvres.")
    lines += [text, ""]
    # the references and the still platform
    marks: dict[str, list[str]] = {e.label: [] for e in ranked}
    if refs:
        ref_wins, ref_ties = [], []
        for e in ranked:
            _, b = best_of(e, causal)
            rn, rv = best_of(e, refs)
            if not (rn and math.isfinite(b)):
                continue
            if tie_groups([b, rv], rule.tie_relative, rule.tie_absolute) == [1, 1]:
                ref_ties.append(f"{e.label} ({rn} {sig(rv)} against {sig(b)})")
            elif rv < b:
                ref_wins.append(f"{e.label} ({rn} {sig(rv)} against {sig(b)})")
                marks[e.label].append(REFERENCE_MARK)
        beaten = n - len(ref_wins) - len(ref_ties)
        text = (f"Against the naive references ({_list(refs)}): the best washout of each manoeuvre beats the best "
                f"reference on {beaten} of {n}.")
        if ref_ties:
            text += (f" Within the ranking's margin of it ({100 * rule.tie_relative:g} % or {rule.tie_absolute:g}), "
                     "neither better, on " + "; ".join(ref_ties) + ".")  # fmt: skip
        if ref_wins:
            text += f" A reference does better ({REFERENCE_MARK} below) on " + "; ".join(ref_wins) + "."
        lines += [text, ""]
    worse = [e for e in ranked if best_of(e, causal)[1] > 1.0]
    if worse and rule.by in ("felt", "score"):
        for e in worse:
            marks[e.label].append(STILL_MARK)
        lines += [f"**Worse than no motion**: on {len(worse)} of {n} manoeuvres every washout is worse than a platform "
                  f"standing still (its value above 1; {STILL_MARK} below): "
                  + ", ".join(f"{e.label} (best {sig(best_of(e, causal)[1])})" for e in worse) + ".", ""]  # fmt: skip
    lines += _why(ranked, causal, reference, rule)
    has_ceiling = any(math.isfinite(ceiling_value(e)) for e in ranked)
    if has_ceiling:
        lines += _bracket_summary(ranked, causal, refs)
    elif BOUND_WASHOUT not in washouts:
        lines += ["How much better any washout could be on each manoeuvre (the ceiling and the best achieved) needs "
                  "`--washout bound` (docs/yardstick.md).", ""]  # fmt: skip
    lines += [f"First place alone among the washouts: {', '.join(f'{w} {alone[w]}' for w in causal)}; shared (a tie "
              f"within the margin): {shared}; together {sum(alone.values()) + shared} of {n} manoeuvres.", ""]
    lines += _table(ranked, causal, refs, reference, marks, has_ceiling, rule)
    lines += _groups(ranked, causal)
    return lines


def _causal_ranking(ranking: Sequence[RankRow], causal: Sequence[str], rule: RankRule) -> list[RankRow]:
    """The ranking among the causal washouts alone (the references and the bound set aside), with the rule's ties."""
    rows = [r for r in ranking if r.washout in causal]
    ranks = tie_groups([r.score for r in rows], rule.tie_relative, rule.tie_absolute)
    return [RankRow(washout=r.washout, score=r.score, rank=k, weights=r.weights) for r, k in zip(rows, ranks,
                                                                                                 strict=True)]


def _why(ranked: Sequence[Entry], causal: Sequence[str], reference: str, rule: RankRule) -> list[str]:
    errors = {w: [group_errors(e, w, rule) for e in ranked] for w in causal}
    trans = {w: _median([t for t, _ in errors[w]]) for w in causal}
    rot = {w: _median([r for _, r in errors[w]]) for w in causal}
    if not any(math.isfinite(v) for v in (*trans.values(), *rot.values())):
        return []
    best_t = min(causal, key=lambda w: trans[w] if math.isfinite(trans[w]) else math.inf)
    best_r = min(causal, key=lambda w: rot[w] if math.isfinite(rot[w]) else math.inf)

    def versus(w: str, vals: Mapping[str, float]) -> str:
        ref = "" if w == reference or reference not in vals else f", {reference} {sig(vals[reference])}"
        worse = " (worse than no motion)" if vals[w] > 1.0 else ""
        return f"median relative error {sig(vals[w])}{worse}{ref}"

    what = ("each DOF's felt error over what the aircraft pilot felt there above threshold" if rule.by == "felt"
            else "the integral error over what the aircraft pilot felt")  # fmt: skip
    why = (f"Why: the specific-force cues (surge, sway, heave) are best given by **{best_t}** "
           f"({versus(best_t, trans)}), the rotational cues (roll, pitch, yaw) by **{best_r}** "
           f"({versus(best_r, rot)}); relative error: {what}, "
           "1 = a platform standing still, above 1 worse than no motion at all.")
    if best_t != best_r:
        why += " No washout has both halves: the ranking trades one against the other."
    return [why, ""]


def _bracket_summary(ranked: Sequence[Entry], causal: Sequence[str], refs: Sequence[str]) -> list[str]:
    loose = []
    for e in ranked:
        c = ceiling_value(e)
        _, achieved = best_of(e, [r.washout for r in e.ranking])
        if vacuous(c, achieved):
            loose.append(e.label)
    text = ("How much better could one be: per manoeuvre below, the **bracket** [ceiling, best achieved]: the best any "
            "motion of this platform could reach lies inside it. The ceiling is certified (no motion can score below "
            "it); the best achieved is the least value of every motion run on the flight (the washouts, the "
            "references, and the bound, a motion searched for from the best of them on the ranking's own measure and "
            "flown through the platform model). The best washout is at most its value minus the ceiling from the best "
            "possible, and at least its value minus the best achieved.")
    if loose:
        text += (f" On {len(loose)} of {len(ranked)} manoeuvres the ceiling is below {100 * VACUOUS:.0f} % of the best "
                 "achieved (\"vacuous\" below): there it only says that no motion scores below 0, and how much better "
                 "a washout could be is known only from the best achieved (why: docs/yardstick.md, \"What the ceiling "
                 "cannot say\").")
    return [text, ""]


def _table(ranked: Sequence[Entry], causal: Sequence[str], refs: Sequence[str], reference: str,
           marks: Mapping[str, list[str]], has_ceiling: bool, rule: RankRule) -> list[str]:  # fmt: skip
    head = ["manoeuvre", "best washout", "its value", f"gain over {reference}"]
    head += ["best reference"] if refs else []
    head += ["ceiling", "best achieved", "bracket's width"] if has_ceiling else []
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for e in ranked:
        top = [w for w in firsts(_causal_ranking(e.ranking, causal, rule)) if w in causal]
        lead, value = best_of(e, causal)
        top = top or [lead]
        name = " = ".join(top) + (" (tie)" if len(top) > 1 else "")
        flag = " ".join(marks.get(e.label, []))
        row = [f"{e.label} {flag}".rstrip(), name, sig(value),
               _pct(gain(e.ranking, lead, reference)) if lead != reference else "0 % (it is the best)"]  # fmt: skip
        if refs:
            rn, rv = best_of(e, refs)
            row.append(f"{rn} {sig(rv)}" if rn else "-")
        if has_ceiling:
            c = ceiling_value(e)
            an, av = best_of(e, [r.washout for r in e.ranking])
            row += [f"{sig(c)}{' (vacuous)' if vacuous(c, av) else ''}", f"{sig(av)} ({an})" if an else "-",
                    sig(av - c) if math.isfinite(av) and math.isfinite(c) else "-"]  # fmt: skip
        lines.append("| " + " | ".join(row) + " |")
    lines.append("")
    legend = [f"{STILL_MARK}: every washout worse than a platform standing still"] if any(
        STILL_MARK in m for m in marks.values()) else []  # fmt: skip
    legend += [f"{REFERENCE_MARK}: a naive reference better than every washout"] if any(
        REFERENCE_MARK in m for m in marks.values()) else []  # fmt: skip
    legend += [f"gain over {reference}: (its value - the best's) / its value"]
    if has_ceiling:
        legend += ["ceiling: the least value any motion of the platform could reach (certified); best achieved: the "
                   "least value of every motion run (who in brackets); bracket's width: best achieved - ceiling, how "
                   "much is not known"]  # fmt: skip
    return [*lines, "; ".join(legend) + ".", ""]


def _groups(ranked: Sequence[Entry], causal: Sequence[str]) -> list[str]:
    groups: dict[str, list[Entry]] = {}
    for e in ranked:
        groups.setdefault(e.group, []).append(e)
    if not any(len(g) > 1 for g in groups.values()):
        return []
    lines = ["Per group of similar manoeuvres (the same manoeuvre on each aircraft):", "",
             "| group | manoeuvres | best by median value | its median |", "|---|---|---|---|"]  # fmt: skip
    for name, members in groups.items():
        med = {w: _median([values(e.ranking).get(w, math.nan) for e in members]) for w in causal}
        top = min(med, key=lambda w: med[w] if math.isfinite(med[w]) else math.inf)
        lines.append(f"| {name} | {len(members)} | {top} | {sig(med[top])} |")
    return [*lines, ""]


__all__ = [
    "BUILT_IN",
    "REFERENCES",
    "Entry",
    "best_of",
    "ceiling_value",
    "compared_lines",
    "firsts",
    "gain",
    "group_errors",
    "reached",
    "values",
    "verdict_lines",
]
