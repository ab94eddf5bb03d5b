"""Issue 38, item 10, and issue 52, item 13: the recording's layout holds up with eight and ten washouts as with three.

With seven washouts the tabs ran to eleven (the events tab out of sight), the lane view above the perceived panels
left each panel about 55 px while no false-cue lane was on screen, the Metrics panel's washout columns ran off it
and bolded the oracle bound as the best washout, and the 3D view's labels ran into one word. With eight (issue 52,
at 1920x1080): the legend was an empty plot a quarter of the screen, the phase lane appeared twice, the envelope tab's
lanes took 60 % of it (half empty) and left its six panels 170 px, sway, pitch and yaw showed a lone "0" tick, the 3D
view cut its front row off, the thresholds vanished on the dark theme, the events table cut its time column, and
without the bound the Metrics panel still spoke of it. Checked on the stored blueprint of a real recording (synthetic
data: tests/test_rerun_log.py's make_data), against the pixels measured on the viewer's screenshots
(:mod:`washbench.review.viewer_geometry`) and against egui_plot's rule for labelling a y axis, written out here.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from test_rerun_log import _containers, _views, make_data

from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import RankRow, RankRule
from washbench.io.metrics_csv import MetricRow
from washbench.review import scene3d
from washbench.review.lane_bars import bars
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
from washbench.review.viewer_geometry import (
    LANE_PX,
    LEGEND_ROW_PX,
    PANEL_CHROME_PX,
    TAB_PX,
    TABS_WIDTH_PX,
    labelled_range,
    lane_view_px,
)

SEVEN = ("small-angle", "large-angle", "unrestricted", "adaptive-large-angle", "optimal", "mpc", "bound")
THREE = SEVEN[:3]
EIGHT = (*SEVEN[:-1], "mpc-unrestricted", "bound")
TEN = (*SEVEN[:-1], "mpc-unrestricted", "replay-rotation", "still", "bound")
"""Any names: the viewer knows none but the bundled three's colours (the lead's reference washouts among them)."""


@pytest.fixture(scope="module", params=[THREE, EIGHT, TEN], ids=["three", "eight", "ten"])
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


def _tab(path: Path, name: str) -> dict:
    (tab,) = [c for c in _containers(path).values() if c.get("ContainerBlueprint:display_name") == [name]]
    return tab


def _children(container: dict) -> list[str]:
    return [c.split("/")[1] for c in container["ContainerBlueprint:contents"]]


def _shares(container: dict, key: str = "ContainerBlueprint:row_shares") -> list[float]:
    shares = container.get(key) or [1.0] * len(container["ContainerBlueprint:contents"])
    return [float(v) / sum(shares) for v in shares]


def test_false_cues_have_a_tab_and_the_motion_panels_the_room(recording: tuple[Path, object]) -> None:
    """The phase lane once a tab (it appeared twice in the motion tabs, once over each column): over the left column
    of the perceived and raw tabs, over the false-cue lanes; the motion panels share what the top row leaves, a third
    each, at least 230 px tall in the 1920x1080 window (at least 150 px at 1280x720)."""
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
    assert len(phases) == 3  # the perceived, raw and false-cue tabs, once each
    assert all(queries[vid] == [f"+ {phase_lane_path()}"] for vid in phases)
    containers = _containers(path)
    for name in ("Perceived", "Raw motion"):
        tab = _tab(path, name)
        top, columns = _children(tab)
        top_share, panels_share = _shares(tab)
        assert [views[v]["ViewBlueprint:class_identifier"][0] for v in _children(containers[top])] == [
            "StateTimeline", "2D"]  # fmt: skip
        assert top_share * TAB_PX["1280x720"] >= lane_view_px(1, title=False) - 0.5  # the phase lane whole
        for column in _children(containers[columns]):
            shares = _shares(containers[column])
            assert len(shares) == 3 and max(shares) - min(shares) < 1e-6
            assert panels_share / 3 * TAB_PX["1920x1080"] >= 230 and panels_share / 3 * TAB_PX["1280x720"] >= 150


def test_labels_in_the_3d_view_stay_apart(recording: tuple[Path, object]) -> None:
    """At most four objects a row (eight in one row ran their labels into one word): each label a whole spacing from
    its row's neighbours, the rows behind one another; every object's label in front of (south of) its box's lower
    front edge and behind the box of the row in front, where it lies over no object seen from above and behind."""
    path, data = recording
    positions = np.asarray(read_static(path, "Points3D:positions")["/world/labels"], dtype=float)
    assert len(positions) == 1 + len(data.washouts)
    statics = read_static(path, "Transform3D:translation")
    centres = np.asarray([statics["/world/aircraft"][0]] + [statics[f"/world/atlas/{w}"][0] for w in data.washouts],
                         dtype=float)  # fmt: skip
    rows = sorted(set(np.round(centres[:, 0], 6)))
    assert len(rows) == math.ceil(len(centres) / 4)
    spacing = None
    for x in rows:
        row = np.sort(positions[np.isclose(centres[:, 0], x), 1])
        assert 1 <= len(row) <= 4
        if len(row) > 1:
            spacing = spacing or float(np.min(np.diff(row)))
            assert np.min(np.diff(row)) >= spacing - 1e-9
    if len(rows) > 1:
        assert np.min(np.diff(rows)) >= spacing  # the rows as far apart as the objects in a row
    np.testing.assert_allclose(positions[:, 1], centres[:, 1], atol=1e-6)  # each label under its object's middle
    half = data.envelope.sphere_diameter_m / 2
    box = np.maximum(half, np.asarray(data.envelope.pos_m, dtype=float))  # a cockpit's sphere or its range box
    front = centres[:, 0] - np.where(np.arange(len(centres)) == 0, half, box[0])
    assert np.all(positions[:, 0] < front) and np.all(positions[:, 2] >= centres[:, 2] + half - 1e-6)
    for k, x in enumerate(rows[1:], start=1):  # behind the row in front's boxes
        assert np.all(positions[np.isclose(centres[:, 0], x), 0] > rows[k - 1] + box[0])


def _project(points: np.ndarray, eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """(right, up) of each point over its depth, for a camera at ``eye`` looking at ``target`` with NED's up (-z)
    on top: the tangents of the angles off the line of sight (rerun's perspective eye)."""
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, [0.0, 0.0, -1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    rel = points - eye
    depth = rel @ fwd
    assert np.all(depth > 0)
    return np.column_stack([rel @ right / depth, rel @ up / depth])


VIEW_ASPECTS = (1340.0 / 964.0, 893.0 / 604.0)
"""The 3-D view's width / height at 1920x1080 and at 1280x720 (the tab less the view's title bar)."""


@pytest.mark.parametrize("n_washouts", range(1, 11))
def test_the_3d_camera_frames_every_object_and_label(n_washouts: int) -> None:
    """Every object (the aircraft's shape, each cockpit's sphere or stage range box) and every label point inside
    rerun's 55 deg vertical field of view at the 3-D view's aspect in both windows, with room for the labels' text;
    and the scene centred and filling the view: its top and bottom margins within a tenth of the view of each other
    (the hand-set camera cut the front row off at the bottom and left the top third empty), so are its left and right
    ones, and it spans four fifths of the view's height or width."""
    travel, diameter = np.array([1.5, 1.5, 1.0]), 2.9
    offsets = scene3d.object_offsets(n_washouts, travel, diameter)
    eye, target = (np.asarray(v, dtype=float) for v in scene3d.camera(offsets, travel, diameter))
    half = diameter / 2
    corners = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], dtype=float)
    boxes = [offsets[0] + corners * half] + [o + corners * np.maximum(half, travel) for o in offsets[1:]]
    points = np.vstack([*boxes, scene3d.label_points(offsets, travel, diameter)])
    tan = math.tan(math.radians(55.0) / 2)
    xy = _project(points, eye, target)
    label_px = 20.0  # a label's text reaches this far under its point
    for aspect in VIEW_ASPECTS:
        view_px = TABS_WIDTH_PX["1280x720"] / aspect  # the smaller window: the label's pixels weigh most
        assert np.all(np.abs(xy[:, 0]) <= tan * aspect), aspect
        assert np.all(xy[:, 1] >= -tan * (1 - 2 * label_px / view_px)) and np.all(xy[:, 1] <= tan)
    top, bottom = tan - xy[:, 1].max(), xy[:, 1].min() + tan
    aspect = VIEW_ASPECTS[0]
    left, right = xy[:, 0].min() + tan * aspect, tan * aspect - xy[:, 0].max()
    assert abs(top - bottom) < 0.2 * tan and abs(left - right) < 0.2 * tan * aspect, (top, bottom, left, right)
    assert max(1 - (top + bottom) / (2 * tan), 1 - (left + right) / (2 * tan * aspect)) >= 0.8


def test_the_recording_s_camera_is_the_fitted_one(recording: tuple[Path, object]) -> None:
    path, data = recording
    (scene,) = [v for v in _views(path).values() if v["ViewBlueprint:class_identifier"] == ["3D"]]
    offsets = scene3d.object_offsets(len(data.washouts), np.asarray(data.envelope.pos_m, dtype=float),
                                     data.envelope.sphere_diameter_m)  # fmt: skip
    eye, target = scene3d.camera(offsets, np.asarray(data.envelope.pos_m, dtype=float), data.envelope.sphere_diameter_m)
    np.testing.assert_allclose(scene["EyeControls3D:position"][0], eye, rtol=1e-6)  # float32 in the blueprint
    np.testing.assert_allclose(scene["EyeControls3D:look_target"][0], target, rtol=1e-6)


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


def test_without_the_bound_the_metrics_panel_does_not_speak_of_it() -> None:
    """Run without ``--washout bound``, the Metrics panel said "(the oracle bound, in italics, is a reference)" all
    the same: no word of the bound or the ceiling now; with it, the note stays."""
    rows = [MetricRow(w, d, 1.0 + 0.1 * i, 2.0, 3.0) for i, w in enumerate(THREE) for d in DOFS]
    ranking = [RankRow(w, 0.9 + 0.1 * i, i + 1, {}) for i, w in enumerate(THREE)]
    text = metrics_table_markdown("c172p / steep_turn", rows, ranking, "score")
    assert "bound" not in text.lower() and "ceiling" not in text.lower() and "oracle" not in text.lower()
    rows += [MetricRow("bound", d, 0.5, 0.5, 0.5) for d in DOFS]
    with_bound = metrics_table_markdown("c172p / steep_turn", rows, [*ranking, RankRow("bound", 0.4, 0, {})], "score")
    assert "(the oracle bound, in italics, is a reference)" in with_bound


def test_the_metrics_panel_names_the_felt_error_column_by_its_rule() -> None:
    rows = [MetricRow(w, d, 1.0, 2.0, 3.0) for w in THREE for d in DOFS]
    ranking = [RankRow(w, 0.9 + 0.1 * i, i + 1, {}) for i, w in enumerate(THREE)]
    felt = metrics_table_markdown("c172p / steep_turn", rows, ranking, RankRule().label())
    assert "| rank | washout | felt error |" in felt and "| rank | washout | score |" not in felt
    assert "| rank | washout | score |" in metrics_table_markdown("c172p / steep_turn", rows, ranking,
                                                                  RankRule(by="score").label())  # fmt: skip


def test_a_blank_npc_is_said_to_be_undefined() -> None:
    """A platform standing still gives the simulator pilot no perceived change: NPC (a correlation) is not defined
    (NaN in metrics.csv), its cells are blank, and one line under the NPC table says why."""
    rows = [MetricRow(w, d, 1.0, 2.0, 3.0) for w in THREE for d in DOFS]
    assert "A blank NPC" not in metrics_table_markdown("c172p / steep_turn", rows, [], "felt")
    rows += [MetricRow("still", d, math.nan, 2.0, 3.0) for d in DOFS]
    text = metrics_table_markdown("c172p / steep_turn", rows, [], "felt")
    assert "| still |" + "  |" * len(DOFS) in text
    assert "A blank NPC: not defined" in text and text.index("A blank NPC") < text.index("integral of |error|")


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
            assert set(colours[p]) == {_rgba(FALSE_CUE_COLOR)}
            assert all(set(v.split("+")) <= set(DOFS) for v in values[p])  # the DOFs' names
    assert set(colours[phase_lane_path()]).isdisjoint(washout)
    for p in colours:
        assert set(colours[p]).isdisjoint(washout), p


def _rgba(rgb: tuple[int, int, int]) -> int:
    r, g, b = rgb
    return (r << 24) | (g << 16) | (b << 8) | 0xFF


def test_the_legend_names_every_line_in_its_colour_without_an_empty_plot(recording: tuple[Path, object]) -> None:
    """A legend is the names in their lines' colours in a 2-D view, one for each tab with coloured lines, naming what
    that tab draws: over the perceived tab's right column (over the roll, pitch and yaw panels; the aircraft pilot, the
    washouts, the perception threshold), over the raw tab's (no threshold there), beside the envelope tab's lanes (the
    washouts: the aircraft has no platform). No time-series view is left for a legend (it was an empty plot a quarter
    of the 1920x1080 screen). Each name in a cell of its own inside the view's bounds, the cells as wide as the longest
    name needs (6.6 px a character and 24 px); the motion tabs' legends' rows fit their top row."""
    path, data = recording
    views = _views(path)
    washouts = list(data.washouts)
    lines = read_static(path, "SeriesLines:colors")
    threshold = lines["/perceived/surge/threshold"][0]
    colour = {"aircraft": lines["/perceived/surge"][-1], "perception threshold": threshold}
    colour |= {w: lines["/perceived/surge"][i] for i, w in enumerate(washouts)}  # the lines' own colours
    assert colour["aircraft"] == _rgba(series_color("aircraft"))
    expected = {"/legend/perceived": ["aircraft", *washouts, "perception threshold"],
                "/legend/raw": ["aircraft", *washouts], "/legend/envelope": washouts}  # fmt: skip
    labels, positions = read_static(path, "Points2D:labels"), read_static(path, "Points2D:positions")
    point_colours = read_static(path, "Points2D:colors")
    legend_views = {v["ViewBlueprint:space_origin"][0]: v for v in views.values()
                    if v["ViewBlueprint:class_identifier"] == ["2D"]}  # fmt: skip
    assert set(legend_views) == set(expected)
    assert not any(v["ViewBlueprint:space_origin"][0].startswith("/legend") for v in views.values()
                   if v["ViewBlueprint:class_identifier"] == ["TimeSeries"])  # fmt: skip
    half, quarter = 0.5 * TABS_WIDTH_PX["1920x1080"], 0.25 * TABS_WIDTH_PX["1920x1080"]
    widths = {"/legend/perceived": half, "/legend/raw": half, "/legend/envelope": quarter}
    for origin, view in legend_views.items():
        names = expected[origin]
        assert view["ViewBlueprint:titlebar"] == [False]
        assert labels[origin] == names and point_colours[origin] == [colour[n] for n in names]
        (bounds,) = view["VisualBounds2D:range"]
        (x0, x1), (y0, y1) = bounds["x_range"], bounds["y_range"]
        xy = np.asarray(positions[origin], dtype=float)
        assert np.all((xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] >= y0) & (xy[:, 1] < y1))
        cells = {(round(x, 6), math.floor(y)) for x, y in xy}
        assert len(cells) == len(names)  # a cell each
        columns, rows = len({round(x, 6) for x, _ in xy}), len({math.floor(y) for _, y in xy})
        cell_px = 6.6 * max(len(n) for n in names) + 24
        assert columns * cell_px <= widths[origin] + 1e-6 and y1 - y0 == rows
        if origin != "/legend/envelope":  # the motion tabs' top row holds its rows
            tab = _tab(path, "Perceived" if origin == "/legend/perceived" else "Raw motion")
            assert rows * LEGEND_ROW_PX <= _shares(tab)[0] * TAB_PX["1920x1080"] + 0.5


def _egui_labelled(lo: float, hi: float, plot_px: float) -> list[float]:
    """The y gridlines egui_plot labels whole in a plot ``plot_px`` tall showing [lo, hi] (egui_plot's axis.rs and
    log_grid_spacer(10)): gridlines at multiples of powers of ten; a step's labels drawn when its gridlines are more
    than 20 px apart; a label (about 14 px tall, centred on its line) whole when its line is 7 px inside."""
    out: set[float] = set()
    for e in range(-6, 7):
        step = 10.0**e
        if step * plot_px / (hi - lo) > 20.0:
            inner = (hi - lo) * 7.0 / plot_px
            first, last = math.ceil((lo + inner) / step), math.floor((hi - inner) / step)
            out |= {round(k * step, 9) for k in range(first, last + 1)}
    return sorted(out)


def test_every_motion_and_usage_panel_labels_two_gridlines(recording: tuple[Path, object]) -> None:
    """In the 1920x1080 window each perceived, raw and envelope-usage panel labels two gridlines at least (perceived
    sway, pitch and yaw showed a lone "0": the size of a 6 deg/s cue could not be read). The plot heights from the
    stored shares and the measured chrome; the labelling rule egui_plot's."""
    path, _ = recording
    views = _views(path)
    motion_px = _shares(_tab(path, "Perceived"))[1] / 3 * TAB_PX["1920x1080"] - PANEL_CHROME_PX
    tab = _tab(path, "Atlas envelope")
    grid = _containers(path)[_children(tab)[1]]
    rows = math.ceil(len(grid["ContainerBlueprint:contents"]) / grid["ContainerBlueprint:grid_columns"][0])
    usage_px = _shares(tab)[1] / rows * TAB_PX["1920x1080"] - PANEL_CHROME_PX
    checked = 0
    for v in views.values():
        origin = v["ViewBlueprint:space_origin"][0]
        if not v.get("ScalarAxis:range") or not origin.startswith(("/perceived/", "/raw/", "/envelope/")):
            continue
        (lo, hi), = v["ScalarAxis:range"]
        plot_px = usage_px if origin.startswith("/envelope/") else motion_px
        assert len(_egui_labelled(lo, hi, plot_px)) >= 2, (origin, lo, hi, plot_px)
        checked += 1
    assert checked == 12 + 6  # six perceived, six raw, six usage panels


@pytest.mark.parametrize("span", [(-8.0, 1.7), (-8.4, 7.4), (-6.4, 6.4), (-0.5, 0.3), (-14.5, -5.5), (0.0, 1.15),
                                  (-2.0, 5.5), (-0.05, 0.05), (3.0, 4.0), (-1e-3, 2e-3)])  # fmt: skip
@pytest.mark.parametrize("plot_px", [140.0, 240.0, 400.0])
def test_a_range_is_widened_until_two_gridlines_are_labelled(span: tuple[float, float], plot_px: float) -> None:
    """labelled_range against egui's rule: two labelled gridlines, the data inside, and no more widening than the
    step it labels allows (at most one step and the margins each side); -8 to 1.7 m/s^2 in a 140 px plot labelled
    only 0 before."""
    lo, hi = labelled_range(span, plot_px)
    assert lo <= span[0] and hi >= span[1]
    labelled = _egui_labelled(lo, hi, plot_px)
    assert len(labelled) >= 2, (lo, hi, labelled)
    step = min(np.diff(labelled))
    assert hi - lo <= (span[1] - span[0]) + 2 * step + 4 * 14.0 / plot_px * (hi - lo) + 1e-12


def test_the_envelope_tab_holds_every_lane_and_gives_its_panels_the_room(recording: tuple[Path, object]) -> None:
    """In the 1920x1080 window the lane view is as tall as its lanes (it took 60 % of the tab with eight, half of it
    empty) and the usage panels, in a grid, get the rest: at least 200 px each (they had 170 with eight)."""
    path, data = recording
    views, containers = _views(path), _containers(path)
    tab = _tab(path, "Atlas envelope")
    top_id, grid_id = _children(tab)
    lanes_id, legend_id = _children(containers[top_id])
    shares = _shares(tab)
    lanes_px = shares[0] * TAB_PX["1920x1080"]
    assert views[lanes_id]["ViewContents:query"] == [f"+ {washout_lane_path(data, w)}" for w in data.washouts]
    assert views[legend_id]["ViewBlueprint:space_origin"] == ["/legend/envelope"]
    n = len(data.washouts)
    assert lane_view_px(n) - 0.5 <= lanes_px <= lane_view_px(n) + LANE_PX  # every lane, and no lane's worth empty
    grid = containers[grid_id]
    panels = len(grid["ContainerBlueprint:contents"])
    rows = math.ceil(panels / grid["ContainerBlueprint:grid_columns"][0])
    assert shares[1] * TAB_PX["1920x1080"] / rows >= 200, (panels, rows)


def test_the_events_table_has_no_cut_time_column(recording: tuple[Path, object]) -> None:
    """Every event text starts with its time (right-aligned, monospace): the timeline column, cut to "+3..." in the
    viewer, is hidden."""
    path, _ = recording
    (events,) = [v for v in _views(path).values() if v["ViewBlueprint:class_identifier"] == ["TextLog"]]
    assert events["TextLogColumns:timeline_columns"] == [{"visible": False, "timeline": "time"}]
    assert events["TextLogFormat:monospace_body"] == [True]


def _lab(rgb: tuple[int, int, int]) -> np.ndarray:
    """CIE L*a*b* (D65) of an sRGB colour."""
    c = np.asarray(rgb, dtype=float) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    xyz = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]) @ lin
    xyz /= [0.95047, 1.0, 1.08883]
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16.0 / 116.0)
    return np.array([116.0 * f[1] - 16.0, 500.0 * (f[0] - f[1]), 200.0 * (f[1] - f[2])])


def test_the_threshold_lines_stand_apart_from_the_bound(recording: tuple[Path, object]) -> None:
    """The thresholds' colour (opaque: a translucent grey nearly vanished on the dark theme) far from the bound's grey
    (CIE76 3 before) and from the aircraft's magenta."""
    path, _ = recording
    colours = read_static(path, "SeriesLines:colors")
    threshold = _unpack(colours["/perceived/pitch/threshold"][0])
    for other in ((120, 120, 120), series_color("aircraft")):
        assert np.linalg.norm(_lab(threshold) - _lab(other)) >= 40.0, other


def _unpack(packed: int) -> tuple[int, int, int]:
    assert packed & 0xFF == 0xFF  # opaque
    return (packed >> 24) & 0xFF, (packed >> 16) & 0xFF, (packed >> 8) & 0xFF


def test_lane_bars_join_stretches_closer_than_the_event_gap() -> None:
    """bars(): stretches of a non-zero state, joined where their samples are at most round(0.25 s / dt) samples apart
    (analysis.cues' events: at dt = 0.1 s, two samples: one empty sample between joins, two do not), each with the
    union of what it held (a hand-made mask)."""
    mask = np.array([0, 1, 1, 0, 2, 0, 0, 4, 4, 0, 1], dtype=np.int64)
    assert bars(mask, 0.1) == [(1, 4, 3), (7, 10, 5)]
    assert bars(np.zeros(5, dtype=np.int64), 0.1) == []
    assert bars(mask, 0.01) == [(1, 10, 7)]  # 25 samples
    assert bars(mask, 1.0) == [(1, 2, 1), (4, 4, 2), (7, 8, 4), (10, 10, 1)]  # at least one sample: neighbours only
