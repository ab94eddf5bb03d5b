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


def test_the_tabs_stay_few_and_the_events_tab_in_sight(recording: tuple[Path, object]) -> None:
    path, data = recording
    containers, views = _containers(path), _views(path)
    tab_sets = [c for c in containers.values() if c.get("ContainerBlueprint:container_kind") == [1]]  # 1 = Tabs
    (top,) = [c for c in tab_sets if c.get("ContainerBlueprint:display_name") is None]
    children = [c.split("/")[1] for c in top["ContainerBlueprint:contents"]]
    assert len(children) <= 6  # whatever the number of washouts
    names = [(containers.get(c) or views.get(c) or {}).get("ContainerBlueprint:display_name")
             or (views.get(c) or {}).get("ViewBlueprint:display_name") for c in children]  # fmt: skip
    assert any("events" in n[0] for n in names if n)
    (atlas,) = [c for c in tab_sets if c.get("ContainerBlueprint:display_name") == ["Atlas per washout"]]
    assert len(atlas["ContainerBlueprint:contents"]) == len(data.washouts)  # one tab per washout, inside


def test_false_cues_have_a_tab_and_the_motion_panels_the_room(recording: tuple[Path, object]) -> None:
    path, data = recording
    views, queries = _views(path), _queries(path)
    lanes = {
        vid: v["ViewBlueprint:display_name"][0]
        for vid, v in views.items()
        if v["ViewBlueprint:class_identifier"] == ["StateTimeline"] and v["ViewBlueprint:space_origin"] == ["/lanes"]
    }
    cues = [cue_lane_path(data, w) for w in data.washouts]
    limits = [washout_lane_path(data, w) for w in data.washouts]
    (false_cues,) = [vid for vid, name in lanes.items() if name == "False cues"]
    shown = queries[false_cues]
    assert "+ /lanes/**" in shown and not any(f"- {p}" in shown for p in cues)  # every false-cue lane
    assert all(f"- {p}" in shown for p in limits)
    phases = [vid for vid, name in lanes.items() if name == "Phases"]
    assert len(phases) == 2  # above the perceived and the raw panels: the phases only
    for vid in phases:
        assert all(f"- {p}" in queries[vid] for p in [*cues, *limits])
    for name in ("Perceived", "Raw motion"):
        (stack,) = [c for c in _containers(path).values() if c.get("ContainerBlueprint:display_name") == [name]]
        shares = stack["ContainerBlueprint:row_shares"]
        assert len(shares) == 7 and shares[0] < min(shares[1:])  # each of the six panels taller than the lane


def test_labels_in_the_3d_view_are_staggered_apart(recording: tuple[Path, object]) -> None:
    path, data = recording
    positions = np.asarray(read_static(path, "Points3D:positions")["/world/labels"], dtype=float)
    assert len(positions) == 1 + len(data.washouts)
    spacing = float(np.min(np.diff(positions[:, 1])))
    for i in range(len(positions)):
        same_row = [j for j in range(len(positions)) if j != i and math.isclose(positions[j, 2], positions[i, 2])]
        nearest = min((abs(positions[j, 1] - positions[i, 1]) for j in same_row), default=math.inf)
        # a label as long as "adaptive-large-angle" needs more than two objects' spacing (screenshots)
        assert nearest >= (3.0 if len(positions) > 6 else 1.0) * spacing - 1e-9


def test_the_metrics_panel_ranks_and_keeps_the_bound_a_reference() -> None:
    washouts = SEVEN[:-1]
    rows = [MetricRow(w, d, 1.0 + 0.1 * i, 2.0 + 0.1 * i, 3.0 + 0.1 * i) for i, w in enumerate(washouts) for d in DOFS]
    rows += [MetricRow("bound", d, 0.5, 0.5, 0.5) for d in DOFS]  # better than every washout everywhere
    ranking = [RankRow(w, 0.9 + 0.1 * i, i + 1, {}) for i, w in enumerate(washouts)] + [RankRow("bound", 0.4, 0, {})]
    text = metrics_table_markdown("c172p / steep_turn", rows, ranking, "score")
    assert "**Ranking**" in text and "| 1 | small-angle | 0.9 |" in text
    assert "| - | *bound (oracle bound, not ranked)* | *0.4* |" in text
    tables = re.findall(r"^\| washout \|[^\n]*\n(?:\|[^\n]*\n)+", text, flags=re.M)
    assert len(tables) == 3  # NPC, integral and max error
    for table in tables:
        lines = table.strip().splitlines()
        assert all(line.count("|") == 2 + len(DOFS) for line in lines)  # one column per DOF: as wide with 7 as 3
        (bound,) = [line for line in lines if line.startswith("| *bound*")]
        assert "**" not in bound  # the bound is never "best"
        (best,) = [line for line in lines if line.startswith("| small-angle")]
        assert best.count("**") == 2 * len(DOFS)  # the best washout in every DOF


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
        assert set(colours[p]) == {_rgba(LIMIT_LANE_COLOR)} and set(values[p]) == {"pos", "rate"}
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
