"""Suite comparison and ranking rule, checked against hand-computed values."""

import math

import pytest

from washbench.analysis.metrics import MetricRow
from washbench.analysis.ranking import DOFS, compare, dof_weights, rank, wins


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
    ranking = rank(a + b + c, MOTION)
    scores = {r.washout: r.score for r in ranking}
    assert scores["small-angle"] == pytest.approx(0.125 + 0.125 + 0.0625 + 0.375)
    assert scores["large-angle"] == pytest.approx(0.125 + 0.125 + 0.0625 + 0.1875)
    assert scores["unrestricted"] == pytest.approx(0.1875 + 0.1875)
    assert [r.washout for r in ranking] == ["unrestricted", "large-angle", "small-angle"]
    assert [r.rank for r in ranking] == [1, 2, 3]
    assert wins([ranking]) == {"unrestricted": 1, "large-angle": 0, "small-angle": 0}


def test_ties_are_broken_by_the_order_the_washouts_were_listed() -> None:
    same = {"surge": 1.0}
    ranking = rank(rows_for("unrestricted", same) + rows_for("small-angle", same), {"surge": 1.0})
    assert [r.washout for r in ranking] == ["unrestricted", "small-angle"]
    ranking = rank(rows_for("small-angle", same) + rows_for("unrestricted", same), {"surge": 1.0})
    assert [r.washout for r in ranking] == ["small-angle", "unrestricted"]


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
