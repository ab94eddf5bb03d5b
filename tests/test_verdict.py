"""The suite verdict (washbench.review.verdict) on hand-made rankings: what it says about ties, the naive references,
a platform standing still, the bracket and what was not compared (issue 52, items 1-3 and 11; issue 55, item 3)."""

from __future__ import annotations

import math

from washbench.analysis.ranking import RankRow, RankRule, tie_groups
from washbench.review.verdict import STILL_MARK, Entry, verdict_lines

RULE = RankRule()


def _entry(label: str, values: dict[str, float], ceiling: float | None = None) -> Entry:
    """A manoeuvre ranked by hand: its values (lower is better), ranked with the rule's ties (the bound unranked)."""
    names = [w for w in values if w != "bound"]
    ranks = tie_groups([values[w] for w in names], RULE.tie_relative, RULE.tie_absolute)
    rows = [RankRow(w, values[w], r, {}) for w, r in zip(names, ranks, strict=True)]
    if "bound" in values:
        rows.append(RankRow("bound", values["bound"], 0, {}))
    table = {}
    if ceiling is not None:
        table = {w: {"score": {"relative_error": v, "ceiling": ceiling, "recovered": math.nan}} for w, v in
                 values.items()}  # fmt: skip
    return Entry(label=label, group=label.split(" / ")[1], ranking=rows, metrics=[], motion={}, ceiling=table)


def _text(entries: list[Entry], washouts: list[str], failed: int = 0) -> str:
    return "\n".join(verdict_lines(entries, washouts, "small-angle", RULE, failed=failed))


def test_no_winner_is_crowned_inside_the_tie_margin() -> None:
    # large-angle's median (0.500) is within 3 % of small-angle's (0.510): no clear winner, though one is first
    entries = [_entry("c172p / a", {"small-angle": 0.51, "large-angle": 0.50}),
               _entry("c172p / b", {"small-angle": 0.40, "large-angle": 0.60}),
               _entry("c172p / c", {"small-angle": 0.90, "large-angle": 0.30})]  # fmt: skip
    text = _text(entries, ["small-angle", "large-angle"])
    assert "**No clear winner**" in text and "gives the truest motion" not in text
    clear = [_entry("c172p / a", {"small-angle": 0.9, "large-angle": 0.5})]
    text = _text(clear, ["small-angle", "large-angle"])
    assert "**large-angle** gives the truest motion" in text and "No clear winner" not in text


def test_worse_than_no_motion_is_said_and_marked() -> None:
    entries = [_entry("c172p / turn", {"small-angle": 1.3, "large-angle": 1.1, "still": 1.0}),
               _entry("c172p / climb", {"small-angle": 0.3, "large-angle": 0.4, "still": 1.0})]  # fmt: skip
    text = _text(entries, ["small-angle", "large-angle", "still"])
    assert "**Worse than no motion**: on 1 of 2 manoeuvres" in text and "c172p / turn (best 1.10)" in text
    row = next(x for x in text.splitlines() if x.startswith("| c172p / turn"))
    assert STILL_MARK in row
    assert STILL_MARK not in next(x for x in text.splitlines() if x.startswith("| c172p / climb"))
    # and the reference that stood still beat every washout there
    assert "beats the best reference on 1 of 2" in text and "c172p / turn (still 1.00 against 1.10)" in text


def test_a_reference_within_the_margin_is_neither_beaten_nor_better() -> None:
    # 0.975 against still's 0.993: 1.8 %, inside the 3 % margin (the C172 coordinated turn of the bundled suite)
    entries = [_entry("c172p / turn", {"small-angle": 1.2, "mpc": 0.975, "still": 0.993}),
               _entry("c172p / climb", {"small-angle": 0.3, "mpc": 0.2, "still": 1.0}),
               _entry("c172p / roll", {"small-angle": 0.9, "mpc": 0.8, "still": 0.7})]  # fmt: skip
    text = _text(entries, ["small-angle", "mpc", "still"])
    assert "beats the best reference on 1 of 3" in text
    assert "Within the ranking's margin of it (3 % or 0.005), neither better, on c172p / turn (still 0.993 against " \
           "0.975)" in text  # fmt: skip
    assert "A reference does better (◆ below) on c172p / roll (still 0.700 against 0.800)" in text
    assert "◆" not in next(x for x in text.splitlines() if x.startswith("| c172p / turn"))


def test_what_was_not_compared_and_the_command_that_does() -> None:
    text = _text([_entry("c172p / a", {"small-angle": 0.5, "large-angle": 0.4})], ["small-angle", "large-angle"])
    assert "Compared: 2 washouts (small-angle, large-angle)." in text
    assert "**Not compared**: 7 built-in washouts" in text and "the references replay, replay-rotation, still" in text
    assert "the bound (how much better any washout could be)" in text
    assert "`washbench suite --out results --washout all` compares them all" in text


def test_the_bracket_and_a_vacuous_ceiling() -> None:
    values = {"small-angle": 0.5, "large-angle": 0.4, "bound": 0.1}
    loose = _entry("c172p / a", values, ceiling=0.001)  # below 5 % of the best achieved (0.1): vacuous
    tight = _entry("c172p / b", values, ceiling=0.08)
    text = _text([loose, tight], ["small-angle", "large-angle", "bound"])
    row_a = next(x for x in text.splitlines() if x.startswith("| c172p / a"))
    row_b = next(x for x in text.splitlines() if x.startswith("| c172p / b"))
    assert "0.00100 (vacuous)" in row_a and "0.100 (bound)" in row_a
    assert "(vacuous)" not in row_b and "0.0800" in row_b and "| 0.0200 |" in row_b  # width: 0.1 - 0.08
    assert "On 1 of 2 manoeuvres the ceiling is below 5 % of the best achieved" in text
    assert "recovers" not in text  # no fraction of a ceiling is offered as information


def test_failures_are_said_first() -> None:
    text = _text([_entry("c172p / a", {"small-angle": 0.5})], ["small-angle"], failed=8)
    lines = [x for x in text.splitlines() if x]
    assert lines[1] == "**8 of 9 manoeuvres failed** (under Failures, below); everything on this page is on the 1 " \
                       "that ran."  # fmt: skip
