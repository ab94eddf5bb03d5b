"""Issue 38, item 10: the recording's layout holds up with seven washouts as with three.

With seven washouts the tabs ran to eleven (the events tab out of sight), the lane view above the perceived panels
left each panel about 55 px while no false-cue lane was on screen, the Metrics panel's washout columns ran off it
and bolded the oracle bound as the best washout, and the 3D view's labels ran into one word. Checked on the stored
blueprint of a real recording (synthetic data: tests/test_rerun_log.py's make_data) and on the Metrics markdown.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from test_rerun_log import _containers, _views, make_data

from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import RankRow
from washbench.io.metrics_csv import MetricRow
from washbench.review.metrics_table import metrics_table_markdown
from washbench.review.rerun_log import (
    FALSE_CUE_COLOR,
    LIMIT_LANE_COLOR,
    cue_lane_path,
    phase_lane_path,
    series_color,
    washout_lane_path,
    write_recording,
)
from washbench.review.rrd_read import read_blueprint_components, read_static

SEVEN = ("small-angle", "large-angle", "unrestricted", "adaptive-large-angle", "optimal", "mpc", "bound")
THREE = SEVEN[:3]


@pytest.fixture(scope="module", params=[THREE, SEVEN], ids=["three", "seven"])
def recording(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    data = make_data(n=300, washouts=request.param)
    path = tmp_path_factory.mktemp("layout") / "recording.rrd"
    write_recording(path, data)
    return path, data


def _queries(path: Path) -> dict[str, list[str]]:
    """View id -> its contents query (one line per rule)."""
    out = {}
    for entity, comps in read_blueprint_components(path).items():
        parts = entity.strip("/").split("/")
        if parts[0] == "view" and "ViewContents:query" in comps:
            out[parts[1]] = [line for q in comps["ViewContents:query"] for line in str(q).splitlines()]
    return out


def _tab_names(path: Path) -> tuple[list[str], dict]:
    containers, views = _containers(path), _views(path)
    tab_sets = [c for c in containers.values() if c.get("ContainerBlueprint:container_kind") == [1]]  # 1 = Tabs
    (top,) = [c for c in tab_sets if c.get("ContainerBlueprint:display_name") is None]
    children = [c.split("/")[1] for c in top["ContainerBlueprint:contents"]]
    names = [((containers.get(c) or {}).get("ContainerBlueprint:display_name")
              or (views.get(c) or {}).get("ViewBlueprint:display_name"))[0] for c in children]  # fmt: skip
    return names, {"tab_sets": tab_sets}


def test_the_tabs_stay_few_and_the_events_tab_in_sight(recording: tuple[Path, object]) -> None:
    """Seven tabs whatever the number of washouts, their names short enough to fit the 870 px the tab bar has in a
    1280 px window (screenshots: about 7.5 px a character and 40 px a tab for its icon and gaps)."""
    path, data = recording
    names, found = _tab_names(path)
    assert len(names) == 7 and "Events" in names and "3-D view" in names[4]
    assert sum(7.5 * len(n) + 40 for n in names) <= 870, names
    (atlas,) = [c for c in found["tab_sets"] if c.get("ContainerBlueprint:display_name") == ["Atlas per washout"]]
    assert len(atlas["ContainerBlueprint:contents"]) == len(data.washouts)  # one tab per washout, inside


def test_false_cues_have_a_tab_and_the_motion_panels_the_room(recording: tuple[Path, object]) -> None:
    path, data = recording
    views, queries = _views(path), _queries(path)
    lanes = {vid: v["ViewBlueprint:display_name"][0] for vid, v in views.items()
             if v["ViewBlueprint:class_identifier"] == ["StateTimeline"]}  # fmt: skip
    cues = [cue_lane_path(data, w) for w in data.washouts]
    limits = [washout_lane_path(data, w) for w in data.washouts]
    (false_cues,) = [vid for vid, name in lanes.items() if name.startswith("False cues")]
    assert queries[false_cues] == [f"+ {p}" for p in cues]  # every false-cue lane, nothing else
    (held,) = [vid for vid, name in lanes.items() if name.startswith("Limits held")]
    assert queries[held] == [f"+ {p}" for p in limits]  # one lane per washout (per kind ran off a 720 px window)
    phases = [vid for vid, name in lanes.items() if name == "Phases"]
    assert len(phases) == 5  # two columns of the perceived and raw tabs, the false-cue tab: the phases only
    assert all(queries[vid] == [f"+ {phase_lane_path()}"] for vid in phases)
    containers = _containers(path)
    for name in ("Perceived", "Raw motion"):
        (tab,) = [c for c in containers.values() if c.get("ContainerBlueprint:display_name") == [name]]
        for column in tab["ContainerBlueprint:contents"]:
            shares = containers[column.split("/")[1]]["ContainerBlueprint:row_shares"]
            # three panels a column: each at least a quarter of the tab's height, the phase lane less than a panel
            assert len(shares) == 4 and shares[0] < min(shares[1:]) and min(shares[1:]) / sum(shares) >= 0.25


def test_labels_in_the_3d_view_stay_apart(recording: tuple[Path, object]) -> None:
    """At most four objects a row (eight in one row ran their labels into one word): each label a whole spacing from
    its row's neighbours, the rows behind one another, every object's label under it."""
    path, data = recording
    positions = np.asarray(read_static(path, "Points3D:positions")["/world/labels"], dtype=float)
    assert len(positions) == 1 + len(data.washouts)
    rows = sorted(set(np.round(positions[:, 0], 6)))
    assert len(rows) == math.ceil(len(positions) / 4)
    spacing = None
    for x in rows:
        row = np.sort(positions[np.isclose(positions[:, 0], x), 1])
        assert 1 <= len(row) <= 4
        if len(row) > 1:
            spacing = spacing or float(np.min(np.diff(row)))
            assert np.min(np.diff(row)) >= spacing - 1e-9
    if len(rows) > 1:
        assert np.min(np.diff(rows)) >= spacing  # the rows as far apart as the objects in a row
    statics = read_static(path, "Transform3D:translation")
    centres = [statics["/world/aircraft"][0]] + [statics[f"/world/atlas/{w}"][0] for w in data.washouts]
    np.testing.assert_allclose(positions[:, :2], np.asarray(centres, dtype=float)[:, :2], atol=1e-6)


def test_the_metrics_panel_ranks_and_keeps_the_bound_a_reference() -> None:
    washouts = SEVEN[:-1]
    rows = [MetricRow(w, d, 1.0 + 0.1 * i, 2.0 + 0.1 * i, 3.0 + 0.1 * i) for i, w in enumerate(washouts) for d in DOFS]
    rows += [MetricRow("bound", d, 0.5, 0.5, 0.5) for d in DOFS]  # better than every washout everywhere
    ranking = [RankRow(w, 0.9 + 0.1 * i, i + 1, {}) for i, w in enumerate(washouts)] + [RankRow("bound", 0.4, 0, {})]
    text = metrics_table_markdown("c172p / steep_turn", rows, ranking, "score")
    assert "**Ranking**" in text and "| 1 | small-angle | 0.9 |" in text
    assert "| - | *bound* (not ranked) | *0.4* |" in text
    tables = re.findall(r"^\| washout \|[^\n]*\n(?:\|[^\n]*\n)+", text, flags=re.M)
    assert len(tables) == 3  # NPC, integral and max error
    for table in tables:
        lines = table.strip().splitlines()
        assert all(line.count("|") == 2 + len(DOFS) for line in lines)  # one column per DOF: as wide with 7 as 3
        (bound,) = [line for line in lines if line.startswith("| *bound*")]
        assert "**" not in bound  # the bound is never "best"
        (best,) = [line for line in lines if line.startswith("| small-angle")]
        assert best.count("**") == 2 * len(DOFS)  # the best washout in every DOF


def test_the_metrics_panel_gives_the_ceiling_and_each_washouts_share_recovered() -> None:
    """With the bound's record (run.json ``bound``), the ranking ends with the ceiling, and each washout's recovered
    share is the record's: (still - score) / (still - ceiling), here with still = 1 (one DOF weighted 1)."""
    washouts = SEVEN[:-1]
    rows = [MetricRow(w, d, 1.0, 2.0, 3.0) for w in SEVEN for d in DOFS]
    scores = {w: 0.9 - 0.1 * i for i, w in enumerate(washouts)} | {"bound": 0.25}
    ranking = [RankRow(w, scores[w], i + 1, {}) for i, w in enumerate(washouts)] + [RankRow("bound", 0.25, 0, {})]
    ceiling = 0.2
    record = {"ceiling": {"score": ceiling}, "recovered": {w: {"score": (1.0 - v) / (1.0 - ceiling)}
                                                           for w, v in scores.items()}}  # fmt: skip
    text = metrics_table_markdown("c172p / steep_turn", rows, ranking, "score", record)
    assert "| rank | washout | score | recovered |" in text
    assert "| 1 | small-angle | 0.9 | 12 % |" in text  # (1 - 0.9) / 0.8
    assert "| 6 | mpc | 0.4 | 75 % |" in text
    assert "| - | *bound* (not ranked) | *0.25* | *94 %* |" in text
    assert "| - | **ceiling** | **0.2** | 100 % |" in text
    without = metrics_table_markdown("c172p / steep_turn", rows, ranking, "score")
    assert "ceiling" not in without and "| rank | washout | score |" in without


def test_lane_bars_take_fixed_colours_apart_from_the_washouts(recording: tuple[Path, object]) -> None:
    """Limit bars one neutral grey, false-cue bars the cue figure's red, phases blue-grey: none a washout colour
    (rerun's colours by label looked like washout colours)."""
    path, data = recording
    colours = read_static(path, "StateConfiguration:colors")
    values = read_static(path, "StateConfiguration:values")
    washout = {_rgba(series_color(w, list(data.washouts))) for w in data.washouts} | {_rgba(series_color("aircraft"))}
    limit_lanes = [p for p in colours if p.startswith("/limits/")]
    assert len(limit_lanes) == len(data.washouts)  # make_data: every washout reaches its "pos" and "rate" limits
    for p in limit_lanes:
        assert set(colours[p]) == {_rgba(LIMIT_LANE_COLOR)}
        assert {"pos", "rate"} <= set(values[p]) and all(set(v.split("+")) <= {"pos", "rate", "tilt_rate"}
                                                         for v in values[p])  # fmt: skip
    for w in data.washouts:
        p = cue_lane_path(data, w)
        if p in colours:
            assert set(colours[p]) == {_rgba(FALSE_CUE_COLOR)} and all(v.startswith("false: ") for v in values[p])
    assert set(colours[phase_lane_path()]).isdisjoint(washout)
    for p in colours:
        assert set(colours[p]).isdisjoint(washout), p


def _rgba(rgb: tuple[int, int, int]) -> int:
    r, g, b = rgb
    return (r << 24) | (g << 16) | (b << 8) | 0xFF


def test_the_legend_shows_every_line_in_a_720_px_window(recording: tuple[Path, object]) -> None:
    """The side column holds the legend over the Metrics panel; at 1280x720 (a side column of about 620 px) the legend
    needs about 120 px for its title bar, axes and margins and 23 px a line (screenshots: sized for a taller window,
    the last two of nine lines were cut off)."""
    path, data = recording
    views, containers = _views(path), _containers(path)
    (legend,) = [vid for vid, v in views.items() if v["ViewBlueprint:space_origin"] == ["/legend"]]
    (side,) = [c for c in containers.values() if f"view/{legend}" in c.get("ContainerBlueprint:contents", [])]
    shares = side["ContainerBlueprint:row_shares"]
    lines = len(data.washouts) + 2  # the aircraft, every washout, the threshold
    assert shares[0] / sum(shares) * 620 >= 120 + 23 * lines - 0.5  # (the shares are stored as float32)


def test_the_envelope_tab_holds_every_lane_and_its_panels_in_a_720_px_window(recording: tuple[Path, object]) -> None:
    """At 1280x720 the tab has about 610 px; a lane view needs about 45 px for its title bar and axis and 40 px a
    lane (screenshots), a usage panel about 100 px to show its 0 and 1. One lane per washout, the panels in a grid."""
    path, data = recording
    views, containers = _views(path), _containers(path)
    (tab,) = [c for c in containers.values() if c.get("ContainerBlueprint:display_name") == ["Atlas envelope"]]
    lanes_id, grid_id = (c.split("/")[1] for c in tab["ContainerBlueprint:contents"])
    shares = tab["ContainerBlueprint:row_shares"]
    lanes_px = shares[0] / sum(shares) * 610
    assert views[lanes_id]["ViewContents:query"] == [f"+ {washout_lane_path(data, w)}" for w in data.washouts]
    assert lanes_px >= 45 + 40 * len(data.washouts)
    grid = containers[grid_id]
    panels = len(grid["ContainerBlueprint:contents"])
    rows = math.ceil(panels / grid["ContainerBlueprint:grid_columns"][0])
    assert (610 - lanes_px) / rows >= 100, (panels, rows)
