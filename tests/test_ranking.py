"""Suite comparison and ranking rule, checked against hand-computed values."""

import math

import pytest

from washbench.analysis.ranking import DOFS, RankRule, compare, dof_weights, rank, wins
from washbench.io.metrics_csv import MetricRow

SCORE = RankRule("score")
"""The rule before the felt error (the felt error's own hand-worked values: tests/test_felt.py)."""


def rows_for(washout: str, ie: dict[str, float], npc: float = 1.2, max_error: float = 1.0) -> list[MetricRow]:
    return [MetricRow(washout, d, npc, ie.get(d, 0.0), max_error) for d in DOFS]


MOTION = {"surge": 2.0, "sway": 0.001, "heave": 2.0, "roll": 10.0, "pitch": 0.0, "yaw": 30.0}


def test_weights_follow_felt_motion_and_ignore_unfelt_dofs() -> None:
    w = dof_weights(MOTION)
    assert w == pytest.approx({"surge": 0.25, "sway": 0.0, "heave": 0.25, "roll": 0.125, "pitch": 0.0, "yaw": 0.375})
    assert sum(w.values()) == pytest.approx(1.0)


def test_one_group_unfelt_gives_other_group_all_weight() -> None:
    w = dof_weights({"surge": 1.0, "heave": 3.0})
    assert w["surge"] == pytest.approx(0.25) and w["heave"] == pytest.approx(0.75)
    assert dof_weights({}) == dict.fromkeys(DOFS, 0.0)


def test_rank_by_weighted_relative_error() -> None:
    # hand computation: score = 0.25*ie_surge/2 + 0.25*ie_heave/2 + 0.125*ie_roll/10 + 0.375*ie_yaw/30
    a = rows_for("small-angle", {"surge": 1.0, "heave": 1.0, "roll": 5.0, "yaw": 30.0, "sway": 99.0})
    b = rows_for("large-angle", {"surge": 1.0, "heave": 1.0, "roll": 5.0, "yaw": 15.0})
    c = rows_for("unrestricted", {"surge": 1.5, "heave": 1.5, "roll": 0.0, "yaw": 0.0})
    ranking = rank(a + b + c, MOTION, SCORE)
    scores = {r.washout: r.score for r in ranking}
    assert scores["small-angle"] == pytest.approx(0.125 + 0.125 + 0.0625 + 0.375)
    assert scores["large-angle"] == pytest.approx(0.125 + 0.125 + 0.0625 + 0.1875)
    assert scores["unrestricted"] == pytest.approx(0.1875 + 0.1875)
    assert [r.washout for r in ranking] == ["unrestricted", "large-angle", "small-angle"]
    assert [r.rank for r in ranking] == [1, 2, 3]
    assert wins([ranking]) == {"unrestricted": 1, "large-angle": 0, "small-angle": 0}


def test_ties_are_broken_by_the_order_the_washouts_were_listed() -> None:
    same = {"surge": 1.0}
    ranking = rank(rows_for("unrestricted", same) + rows_for("small-angle", same), {"surge": 1.0}, SCORE)
    assert [r.washout for r in ranking] == ["unrestricted", "small-angle"]
    ranking = rank(rows_for("small-angle", same) + rows_for("unrestricted", same), {"surge": 1.0}, SCORE)
    assert [r.washout for r in ranking] == ["small-angle", "unrestricted"]
    assert [(r.rank, r.tied) for r in ranking] == [(1, True), (1, True)]  # equal scores share the rank


def test_comparison_sign_positive_means_better() -> None:
    a = rows_for("small-angle", {"surge": 3.0}, npc=1.5)
    b = rows_for("large-angle", {"surge": 1.0}, npc=math.nan)
    table = compare(a + b)
    row = next(r for r in table if r.dof == "surge" and r.metric == "integral_error")
    assert row.values == {"small-angle": 3.0, "large-angle": 1.0}
    assert row.better_than_reference == {"large-angle": 2.0}
    npc = next(r for r in table if r.dof == "surge" and r.metric == "npc")
    assert math.isnan(npc.better_than_reference["large-angle"])
    assert len(table) == 6 * 3


def test_close_scores_share_a_rank_and_the_margin_does_not_chain() -> None:
    from washbench.analysis.ranking import tie_groups

    # the C172 takeoff case: 0.605 and 0.595 differ by 1.7 % < 3 %: tied
    assert tie_groups([0.605, 0.595, 0.9]) == [1, 1, 3]
    # 1.00, 1.025, 1.05: 1.05 is 5 % from the group's best, so it starts a group of its own (no chaining)
    assert tie_groups([1.05, 1.0, 1.025]) == [3, 1, 1]
    # near zero the absolute margin 0.005 decides
    assert tie_groups([0.0, 0.004, 0.006]) == [1, 1, 3]
    assert tie_groups([0.2, math.nan, 0.1]) == [2, 3, 1]
    assert tie_groups([0.5, 0.5, 0.5]) == [1, 1, 1]


def test_rank_marks_ties_and_counts_undecided_first_places() -> None:
    from washbench.analysis.ranking import undecided

    motion = {"surge": 1.0}
    a = rows_for("small-angle", {"surge": 0.605})
    b = rows_for("large-angle", {"surge": 0.595})
    c = rows_for("unrestricted", {"surge": 0.9})
    ranking = rank(a + b + c, motion, SCORE)
    assert [(r.washout, r.rank, r.tied) for r in ranking] == [  # within the tie by value
        ("large-angle", 1, True), ("small-angle", 1, True), ("unrestricted", 3, False)
    ]
    assert undecided(ranking)
    assert wins([ranking]) == {"small-angle": 1, "large-angle": 1, "unrestricted": 0}
    clear = rank(rows_for("small-angle", {"surge": 0.5}) + c, motion, SCORE)
    assert [(r.rank, r.tied) for r in clear] == [(1, False), (2, False)] and not undecided(clear)


def test_rank_by_false_cues_by_size_and_by_user_dof_weights() -> None:
    import dataclasses

    from washbench.analysis.felt import felt_key
    from washbench.analysis.ranking import rule_from_record

    def with_false(rows, false):
        return [dataclasses.replace(r, felt_error=0.0, felt_false=false.get(r.dof, 0.0)) for r in rows]

    # false parts (m/s^2*s, deg) over their thresholds (0.17 m/s^2, 2.6 deg/s, 3.0 deg/s), over the felt motion in
    # threshold-seconds (surge 1.7 / 0.17 + roll 30 / 3.0 = 20)
    a = with_false(rows_for("small-angle", {"surge": 1.0, "roll": 1.0}), {"surge": 0.17, "yaw": 2.6})
    b = with_false(rows_for("large-angle", {"surge": 0.5, "roll": 8.0}), {"roll": 12.0})
    motion = {"surge": 2.0, "roll": 10.0} | {felt_key(d): 0.0 for d in DOFS} | {felt_key("surge"): 1.7,
                                                                                 felt_key("roll"): 30.0}
    by_false = rank(a + b, motion, RankRule("false-cue"))
    assert [(r.washout, r.score) for r in by_false] == [("small-angle", pytest.approx((1.0 + 1.0) / 20.0)),
                                                        ("large-angle", pytest.approx(4.0 / 20.0))]
    # user weights surge 3, roll 1 (yaw unfelt, its weight dropped): score = 0.75 E_surge/2 + 0.25 E_roll/10
    rule = RankRule("weighted", (("surge", 3.0), ("roll", 1.0), ("yaw", 5.0)))
    by_user = {r.washout: r.score for r in rank(a + b, motion, rule)}
    assert by_user == pytest.approx({"small-angle": 0.75 * 0.5 + 0.25 * 0.1, "large-angle": 0.75 * 0.25 + 0.25 * 0.8})
    assert rule_from_record(rule.record()) == rule
    assert rule_from_record(None) == SCORE  # a result written before rules existed was ranked by the score
    assert RankRule().by == "felt"
    with pytest.raises(ValueError, match="unknown ranking rule"):
        RankRule("best")
