"""The review layout of a recording, and the colours every view shares.

Laid out for one question: which washout feels most like the aircraft? The first tab holds the six perceived-motion
panels (surge, sway, heave | roll, pitch, yaw, as the paper's Figures 8-16) in two columns, each under the phase lane,
all on one linked time axis showing the whole manoeuvre: each panel as tall as a third of the tab, whatever the number
of washouts; in every panel the aircraft pilot's line is drawn last, on top. The false cues (one lane per washout)
have a tab of their own; the envelope tab one lane per washout (the limits it is held at) over the usage panels; the
3D view (aircraft and platform cockpits, labels staggered) a tab of its own, as wide as the plots; the per-washout
platform tabs sit inside one tab: seven tabs, the events tab in sight with ten washouts. Beside the tabs: the legend
(as tall as its lines) and the Metrics panel (the ranking with the ceiling first, then washout-by-DOF tables). Titles
name the platform (Atlas, Hexapod, Rig or a plugin's kind). The viewer's own side panels start collapsed.

Colours are fixed and the figures' (:mod:`washbench.review.palette`): the aircraft pilot (the reference) in a strong
magenta, drawn wider, readable on the viewer's light and dark themes; small-angle blue, large-angle orange,
unrestricted green, the oracle bound grey; any other washout name takes the next spare colour in the order the
recording lists it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import rerun.blueprint as rrb

from washbench.review.palette import AIRCRAFT_COLOR as AIRCRAFT_RGB
from washbench.review.palette import EXTRA_COLORS as EXTRA_RGB
from washbench.review.palette import WASHOUT_COLORS as FIXED_RGB

__all__ = [
    "AIRCRAFT_COLOR",
    "AIRCRAFT_WIDTH",
    "LIMIT_COLOR",
    "THRESHOLD_COLOR",
    "WASHOUT_WIDTH",
    "Layout",
    "UsageView",
    "build_blueprint",
    "series_color",
    "source_colors",
]

AIRCRAFT_COLOR = AIRCRAFT_RGB
"""The aircraft pilot's colour (magenta): visible on white and on the viewer's near-black background."""
AIRCRAFT_WIDTH = 2.5
WASHOUT_WIDTH = 1.5
WASHOUT_COLORS: dict[str, tuple[int, int, int]] = dict(FIXED_RGB)
"""The fixed colours (small-angle blue, large-angle orange, unrestricted green, the bound grey): the figures'
default palette (:mod:`washbench.review.palette`), one set of colours for the recording and the figures."""
EXTRA_COLORS: tuple[tuple[int, int, int], ...] = EXTRA_RGB
"""Colours for the other washout names, taken in the order the recording lists them."""
LIMIT_COLOR = (128, 128, 128)
THRESHOLD_COLOR = (128, 128, 128, 100)
"""The perception thresholds' lines: a faint (translucent) grey, thin, apart from the oracle bound's solid grey."""
AXIS_COLORS = ((220, 60, 60), (60, 170, 60), (70, 120, 230))
"""x, y, z (or wheel 1, 2, 3) inside one washout's Atlas panels."""


def series_color(source: str, washouts: Sequence[str] = ()) -> tuple[int, int, int]:
    """Fixed RGB colour of ``"aircraft"`` or a washout name.

    The named washouts have their own colours; any other name takes a spare colour by its position among the
    other names in ``washouts`` (cycling after :data:`EXTRA_COLORS`).
    """
    if source == "aircraft":
        return AIRCRAFT_COLOR
    if source in WASHOUT_COLORS:
        return WASHOUT_COLORS[source]
    others = [w for w in washouts if w not in WASHOUT_COLORS]
    index = others.index(source) if source in others else 0
    return EXTRA_COLORS[index % len(EXTRA_COLORS)]


def source_colors(washouts: Sequence[str]) -> list[tuple[int, int, int]]:
    """Colours of ``["aircraft", *washouts]`` in that order."""
    return [AIRCRAFT_COLOR] + [series_color(w, washouts) for w in washouts]


@dataclass(frozen=True)
class UsageView:
    """One panel of the envelope tab: its entity, title and y range."""

    origin: str
    title: str
    y_range: tuple[float, float]


@dataclass(frozen=True)
class Layout:
    """What the blueprint needs to know about the data (the blueprint is built with the recording).

    ``perceived_ranges`` and ``raw_ranges``: per DOF (in the order of ``dofs``) the y range to show, thresholds and
    all traces inside. ``camera``: (eye, target) in the scene's NED frame, metres. ``usage``: the envelope tab's
    panels. ``platform_quantities``: (name, unit) of each washout's platform panels. ``platform_name``: the word the
    titles use for the platform. Lanes: the phases' (None without phases), one limit lane and one false-cue lane per
    washout.
    """

    washouts: tuple[str, ...]
    dofs: tuple[tuple[str, str], ...]  # (name, unit)
    t_end_s: float
    perceived_ranges: tuple[tuple[float, float], ...]
    raw_ranges: tuple[tuple[float, float], ...]
    camera: tuple[tuple[float, float, float], tuple[float, float, float]]
    usage: tuple[UsageView, ...]
    platform_quantities: tuple[tuple[str, str], ...]
    platform_name: str
    phase_lane: str | None
    limit_lanes: tuple[str, ...]
    cue_lanes: tuple[str, ...]


def _whole_manoeuvre(t_end_s: float) -> rrb.TimeAxis:
    """Time axis linked across views, opening on the whole manoeuvre (0 to ``t_end_s``)."""
    return rrb.TimeAxis(
        link="Independent",
        view_range=rrb.TimeRange(
            start=rrb.TimeRangeBoundary.absolute(nanos=0),
            end=rrb.TimeRangeBoundary.absolute(nanos=round(t_end_s * 1e9)),  # as the time column rounds
        ),
    )


def _all_data() -> rrb.VisibleTimeRange:
    return rrb.VisibleTimeRange("time", start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.infinite())


def _panel(layout: Layout, origin: str, name: str, y_range: tuple[float, float] | None) -> rrb.TimeSeriesView:
    """A time-series panel on the whole manoeuvre, without legend (the one legend has a panel of its own)."""
    return rrb.TimeSeriesView(
        origin=origin,
        name=name,
        axis_x=_whole_manoeuvre(layout.t_end_s),
        axis_y=rrb.ScalarAxis(range=y_range) if y_range is not None else None,
        plot_legend=rrb.PlotLegend(visible=False),
        time_ranges=_all_data(),
    )


def _lanes(layout: Layout, name: str, paths: Sequence[str]) -> rrb.StateTimelineView:
    """A lane view of exactly ``paths`` (one lane each), on the whole manoeuvre."""
    return rrb.StateTimelineView(
        origin="/", name=name, contents=[f"+ {p}" for p in paths], time_view=_whole_manoeuvre(layout.t_end_s),
        time_ranges=_all_data(),
    )  # fmt: skip


PANEL_SHARE = 2.0
LANE_SHARE = 0.8
"""Height of one state lane (its label above it) against a motion panel's 2.0 (measured on screenshots: a lane
with its label takes about 40 px of the window; a motion panel needs about 110 px to show its ticks)."""
LANE_VIEW_SHARE = 1.2
"""A lane view's title bar and time axis, against a motion panel's 2.0."""
PHASE_VIEW_SHARE = 1.0
"""The phase lane's view above three motion panels (2.0 each): about 85 px in a 720 px window, the lane whole
(screenshots at 1280x720 and 1920x1080)."""


def lane_share(n_lanes: int) -> float:
    """The row share of a lane view of ``n_lanes`` lanes (its title bar and time axis included)."""
    return LANE_VIEW_SHARE + LANE_SHARE * n_lanes


def _motion_tab(layout: Layout, prefix: str, ranges: Sequence[tuple[float, float]], title: str, name: str
                ) -> rrb.Horizontal:  # fmt: skip
    """Two columns, the translational DOFs (surge, sway, heave) and the rotational ones (roll, pitch, yaw), each under
    the phase lane: each of the six panels gets half the tab's width and twice the height it had in one column of
    six (with seven washouts those panels got about 75 px and showed a single tick)."""
    columns = []
    for part in (slice(0, 3), slice(3, 6)):
        panels = [_panel(layout, f"/{prefix}/{dof}", f"{title}{dof} [{unit}]", rng)
                  for (dof, unit), rng in zip(layout.dofs[part], ranges[part], strict=True)]  # fmt: skip
        if layout.phase_lane is not None:
            columns.append(rrb.Vertical(_lanes(layout, "Phases", [layout.phase_lane]), *panels,
                                        row_shares=[PHASE_VIEW_SHARE] + [PANEL_SHARE] * len(panels)))  # fmt: skip
        else:
            columns.append(rrb.Vertical(*panels))
    return rrb.Horizontal(*columns, name=name)


def legend_share(n_washouts: int) -> float:
    """The legend's share of the side column (the Metrics panel has 1 - it): its title bar, axes and margins (about
    120 px: the legend's box ends some 80 px above the panel's bottom) and 23 px a line (aircraft, every washout, the
    threshold), for the 620 px side column of a 720 px window (measured on screenshots at 1280x720: sized for a
    900 px window the last two of nine lines were cut off, with 90 px for the frame the last of eleven), at most 0.65:
    the legend is as tall as its lines, the rest is the ranking's."""
    return min(0.65, (120.0 + 23.0 * (n_washouts + 2)) / 620.0)


def usage_columns(n_washouts: int, n_panels: int) -> int:
    """Columns of the envelope tab's usage grid: two, three with more than six washouts and more than four panels
    (their lanes need the height: at 1280x720 ten lanes need about 445 px of the tab's 610)."""
    return 3 if n_washouts > 6 and n_panels > 4 else 2


SIDE_SHARE = 1.3
"""The side column's width against the tabs' 3: about 390 px in a 1280 px window, as wide as the ranking table with
its recovered column (at 1.1 that column was cut off)."""


def build_blueprint(layout: Layout) -> rrb.Blueprint:
    """The review layout (module docstring). Tabs: perceived, false cues, raw motion, envelope, the 3D view, events,
    the platform per washout (one tab per washout inside): seven tabs whatever the number of washouts, the events tab
    in sight in a 1280 px window. Beside them: the legend and the Metrics panel (the ranking and the ceiling)."""
    eye, target = layout.camera
    platform = layout.platform_name
    scene = rrb.Spatial3DView(
        origin="/world",
        name=f"Aircraft (from its initial heading) and {platform} cockpits",
        eye_controls=rrb.EyeControls3D(kind="Orbital", position=eye, look_target=target, eye_up=(0.0, 0.0, -1.0)),
        line_grid=rrb.LineGrid3D(visible=False),
    )
    legend_part = legend_share(len(layout.washouts))
    side = rrb.Vertical(
        rrb.TimeSeriesView(
            origin="/legend",
            name="Legend",
            axis_x=_whole_manoeuvre(layout.t_end_s),
            axis_y=rrb.ScalarAxis(range=(1.0, 2.0)),  # its lines lie at 0: only the legend shows
            plot_legend=rrb.PlotLegend(corner="LeftTop", visible=True),
            time_ranges=_all_data(),
        ),
        rrb.TextDocumentView(origin="/metrics", name="Metrics: ranking, ceiling and metrics"),
        row_shares=[legend_part, 1.0 - legend_part],
    )
    perceived = _motion_tab(layout, "perceived", layout.perceived_ranges, "perceived ", "Perceived")
    raw = _motion_tab(layout, "raw", layout.raw_ranges, "", "Raw motion")
    phase = [layout.phase_lane] if layout.phase_lane is not None else []
    false_cues = rrb.Vertical(
        *([_lanes(layout, "Phases", phase)] if phase else []),
        _lanes(layout, "False cues (one lane per washout: the DOFs felt falsely)", layout.cue_lanes),
        row_shares=([PHASE_VIEW_SHARE] if phase else []) + [lane_share(len(layout.cue_lanes))],
        name="False cues",
    )
    usage = [_panel(layout, u.origin, u.title, u.y_range) for u in layout.usage]
    columns = usage_columns(len(layout.washouts), len(usage))
    rows = -(-len(usage) // columns)
    envelope = rrb.Vertical(
        _lanes(layout, "Limits held (one lane per washout)", layout.limit_lanes),
        *([rrb.Grid(*usage, grid_columns=columns)] if usage else []),
        row_shares=[lane_share(len(layout.limit_lanes))] + ([PANEL_SHARE * rows] if usage else []),
        name=f"{platform} envelope",
    )
    per_washout = [
        rrb.Grid(
            *[
                _panel(layout, f"/platform/{w}/{q}", f"{w}: {q} [{unit}] ({axes})", None)
                for q, unit in layout.platform_quantities
                for axes in ["w1 red, w2 green, w3 blue" if q == "wheels" else "x red, y green, z blue"]
            ],
            grid_columns=2,
            name=f"{platform} {w}",
        )
        for w in layout.washouts
    ]
    enc = rrb.encodings
    events = rrb.TextLogView(
        origin="/events",
        name="Events",
        columns=rrb.archetypes.TextLogColumns(
            timeline_columns=[enc.TimelineColumn("time")],
            text_log_columns=[
                enc.TextLogColumn("LogLevel"),
                enc.TextLogColumn("Body"),
                enc.TextLogColumn("EntityPath", visible=False),
            ],
        ),
    )
    platforms = rrb.Tabs(*per_washout, active_tab=0, name=f"{platform} per washout")
    scene_tab = rrb.Vertical(scene, name="3-D view")  # the view's own title is too long for a tab
    tabs = rrb.Tabs(perceived, false_cues, raw, envelope, scene_tab, events, platforms, active_tab=0)
    return rrb.Blueprint(
        rrb.Horizontal(tabs, side, column_shares=[3, SIDE_SHARE]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline="time", play_state="paused"),
    )
