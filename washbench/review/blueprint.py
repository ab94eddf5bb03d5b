"""The review layout of a recording, and the colours every view shares.

Laid out for one question: which washout feels most like the aircraft? Sized for a 1920x1080 window and checked at
1280x720 with the pixels measured on the viewer's screenshots (:mod:`washbench.review.viewer_geometry`). The first
tab holds the six perceived-motion panels (surge, sway, heave | roll, pitch, yaw, as the paper's Figures 8-16) in two
columns under one row that holds the phase lane (over the left column, on its time axis) and the legend (over the
right one): all on one linked time axis showing the whole manoeuvre, each panel as tall as what is left a third,
whatever the number of washouts, its y range labelled with two gridlines at least; in every panel the aircraft
pilot's line is drawn last, on top. The false cues (one lane per washout) have a tab of their own; the envelope tab
one lane per washout (the limits it is held at, the view as tall as its lanes) beside the legend, over the usage
panels; the 3D view (aircraft and platform cockpits, labels staggered, the camera fitted to them) a tab of its own;
the events a table whose text starts with its time; the per-washout platform tabs sit inside one tab: seven tabs.
Beside the tabs: the Metrics panel (the ranking with the ceiling first, then washout-by-DOF tables). Titles name the
platform (Atlas, Hexapod, Rig or a plugin's kind). The viewer's own side panels start collapsed.

The legend is a 2-D view of the names in their colours (the lines' own colours: rerun 0.41 draws a time-series
legend only inside a plot, and a plot of its own for it was an empty plot a quarter of the screen).

Colours are fixed and the figures' (:mod:`washbench.review.palette`): the aircraft pilot (the reference) in a strong
magenta, drawn wider, readable on the viewer's light and dark themes; small-angle blue, large-angle orange,
unrestricted green, the oracle bound grey; any other washout name takes the next spare colour in the order the
recording lists it; the perception thresholds the figures' sand.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import rerun.blueprint as rrb

from washbench.review.palette import AIRCRAFT_COLOR as AIRCRAFT_RGB
from washbench.review.palette import EXTRA_COLORS as EXTRA_RGB
from washbench.review.palette import THRESHOLD_COLOR as THRESHOLD_RGB
from washbench.review.palette import WASHOUT_COLORS as FIXED_RGB
from washbench.review.viewer_geometry import (
    LEGEND_ROW_PX,
    PANEL_CHROME_PX,
    TAB_PX,
    TABS_WIDTH_PX,
    lane_view_px,
    legend_grid,
)

__all__ = [
    "AIRCRAFT_COLOR",
    "AIRCRAFT_WIDTH",
    "DESIGN_SIZE",
    "LIMIT_COLOR",
    "THRESHOLD_COLOR",
    "THRESHOLD_NAME",
    "WASHOUT_WIDTH",
    "Layout",
    "LegendView",
    "UsageView",
    "build_blueprint",
    "envelope_shares",
    "legend_views",
    "motion_plot_px",
    "motion_top_share",
    "series_color",
    "source_colors",
    "usage_columns",
    "usage_plot_px",
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
THRESHOLD_COLOR = THRESHOLD_RGB
"""The perception thresholds' lines: the figures' sand, opaque (a translucent grey nearly vanished on the dark theme
and looked like the bound's grey on both)."""
AXIS_COLORS = ((220, 60, 60), (60, 170, 60), (70, 120, 230))
"""x, y, z (or wheel 1, 2, 3) inside one washout's Atlas panels."""

DESIGN_SIZE = "1920x1080"
"""The window the layout is sized for (:mod:`washbench.review.viewer_geometry`)."""
SMALL_SIZE = "1280x720"
"""The smallest window it is checked at."""


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
class LegendView:
    """One legend (a 2-D view of ``names`` in their colours, logged at ``origin``): its grid, ``columns`` x ``rows``
    cells each ``cell`` legend rows wide (:func:`washbench.review.viewer_geometry.legend_positions`)."""

    origin: str
    names: tuple[str, ...]
    columns: int
    rows: int
    cell: float


@dataclass(frozen=True)
class Layout:
    """What the blueprint needs to know about the data (the blueprint is built with the recording).

    ``perceived_ranges`` and ``raw_ranges``: per DOF (in the order of ``dofs``) the y range to show, thresholds and
    all traces inside. ``camera``: (eye, target) in the scene's NED frame, metres. ``usage``: the envelope tab's
    panels. ``platform_quantities``: (name, unit) of each washout's platform panels. ``platform_name``: the word the
    titles use for the platform. Lanes: the phases' (None without phases), one limit lane and one false-cue lane per
    washout, and the key each lane view's title gives to the words on its bars. ``legends``: the perceived tab's,
    the raw tab's and the envelope tab's (:func:`legend_views`).
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
    legends: tuple[LegendView, LegendView, LegendView]
    limit_key: str = ""
    cue_key: str = ""


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
    """A time-series panel on the whole manoeuvre, without legend (the legend has a view of its own)."""
    return rrb.TimeSeriesView(
        origin=origin,
        name=name,
        axis_x=_whole_manoeuvre(layout.t_end_s),
        axis_y=rrb.ScalarAxis(range=y_range) if y_range is not None else None,
        plot_legend=rrb.PlotLegend(visible=False),
        time_ranges=_all_data(),
    )


def _lanes(layout: Layout, name: str, paths: Sequence[str], titlebar: bool = True) -> rrb.StateTimelineView:
    """A lane view of exactly ``paths`` (one lane each), on the whole manoeuvre."""
    return rrb.StateTimelineView(
        origin="/", name=name, contents=[f"+ {p}" for p in paths], time_view=_whole_manoeuvre(layout.t_end_s),
        time_ranges=_all_data(), titlebar=titlebar,
    )  # fmt: skip


def _legend(view: LegendView) -> rrb.Spatial2DView:
    """The legend: the names in their colours, no title bar (the coloured names say what they are)."""
    return rrb.Spatial2DView(
        origin=view.origin,
        name="Legend",
        titlebar=False,
        visual_bounds=rrb.VisualBounds2D(x_range=[0.0, view.columns * view.cell], y_range=[0.0, view.rows]),
    )


MOTION_PANELS = 3
"""Panels in each column of a motion tab."""


def legend_px(view: LegendView) -> float:
    """Height a legend needs, px: its rows and a margin."""
    return LEGEND_ROW_PX * view.rows + 8.0


def motion_top_share(layout: Layout) -> float:
    """The motion tabs' top row (the phase lane beside the legend) as a share of the tab: the phase lane whole in the
    smallest window (its view without title bar: 84 px of 635) and the legend's rows in the design window."""
    phase = lane_view_px(1, title=False) / TAB_PX[SMALL_SIZE] if layout.phase_lane is not None else 0.0
    return max(phase, *(legend_px(v) / TAB_PX[DESIGN_SIZE] for v in layout.legends[:2]))


def motion_plot_px(layout: Layout, size: str = DESIGN_SIZE) -> float:
    """Height of a motion panel's plot area in a window of ``size``, px."""
    return TAB_PX[size] * (1.0 - motion_top_share(layout)) / MOTION_PANELS - PANEL_CHROME_PX


def _motion_tab(layout: Layout, prefix: str, ranges: Sequence[tuple[float, float]], title: str, name: str,
                legend: LegendView) -> rrb.Vertical:  # fmt: skip
    """The top row (the phase lane over the left column, the legend over the right one), then two columns, the
    translational DOFs (surge, sway, heave) and the rotational ones (roll, pitch, yaw), each panel half the tab's width
    (stacked in one column, seven washouts left each panel about 75 px and a single tick). The phase lane once: over
    the left column, on its time axis (the right column's time axis is the same); a lane as wide as both columns
    would run on another time scale."""
    columns = []
    for part in (slice(0, 3), slice(3, 6)):
        panels = [_panel(layout, f"/{prefix}/{dof}", f"{title}{dof} [{unit}]", rng)
                  for (dof, unit), rng in zip(layout.dofs[part], ranges[part], strict=True)]  # fmt: skip
        columns.append(rrb.Vertical(*panels))
    if layout.phase_lane is not None:
        top = rrb.Horizontal(_lanes(layout, "Phases", [layout.phase_lane], titlebar=False), _legend(legend))
    else:
        top = _legend(legend)
    share = motion_top_share(layout)
    return rrb.Vertical(top, rrb.Horizontal(*columns), row_shares=[share, 1.0 - share], name=name)


def usage_columns(n_panels: int) -> int:
    """Columns of the envelope tab's usage grid: four with more than six panels (the Atlas's seven: two rows, as
    tall as its six were before the tilt rate joined them), three with more than four, else two."""
    return 4 if n_panels > 6 else 3 if n_panels > 4 else 2


ENVELOPE_LANES_MAX = 0.5
"""The envelope tab's lane view takes at most this share of the tab (with more lanes than that holds, they scroll)."""


def envelope_shares(layout: Layout) -> tuple[float, float]:
    """(the lanes' row, the usage grid) as shares of the envelope tab: the lanes' view as tall as its lanes (and
    the legend beside it as tall as its rows) in the design window, at most :data:`ENVELOPE_LANES_MAX`; the grid the
    rest (the lane view had 60 % of the tab, half of it empty, the six usage panels 170 px each)."""
    top = max(lane_view_px(len(layout.limit_lanes)), legend_px(layout.legends[2])) / TAB_PX[DESIGN_SIZE]
    top = min(top, ENVELOPE_LANES_MAX)
    return top, 1.0 - top


def usage_plot_px(layout: Layout, size: str = DESIGN_SIZE) -> float:
    """Height of a usage panel's plot area in a window of ``size``, px."""
    rows = max(1, math.ceil(len(layout.usage) / usage_columns(len(layout.usage))))
    return TAB_PX[size] * envelope_shares(layout)[1] / rows - PANEL_CHROME_PX


SIDE_SHARE = 1.3
"""The Metrics panel's width against the tabs' 3: about 390 px in a 1280 px window, as wide as the ranking table with
its recovered column (at 1.1 that column was cut off)."""

ENVELOPE_LEGEND_SHARE = 0.25
"""The envelope tab's legend: this share of the row it shares with the lane view."""


THRESHOLD_NAME = "perception threshold"
"""The legend's name for the perception thresholds' lines."""


def legend_views(washouts: Sequence[str]) -> tuple[LegendView, LegendView, LegendView]:
    """The legends, each naming what its tab draws: the perceived tab's (the aircraft pilot, the washouts, the
    perception threshold) and the raw tab's (no threshold there) over the right column, half the tabs' width; the
    envelope tab's (the washouts: the aircraft has no platform) beside its lanes. Their grids for the design
    window."""
    half = 0.5 * TABS_WIDTH_PX[DESIGN_SIZE]
    side = ENVELOPE_LEGEND_SHARE * TABS_WIDTH_PX[DESIGN_SIZE]
    pilots = ("aircraft", *washouts)

    def view(origin: str, names: tuple[str, ...], width_px: float) -> LegendView:
        return LegendView(origin, names, *legend_grid(names, width_px))

    return (view("/legend/perceived", (*pilots, THRESHOLD_NAME), half), view("/legend/raw", pilots, half),
            view("/legend/envelope", tuple(washouts), side))  # fmt: skip


def build_blueprint(layout: Layout) -> rrb.Blueprint:
    """The review layout (module docstring). Tabs: perceived, false cues, raw motion, envelope, the 3D view, events,
    the platform per washout (one tab per washout inside): seven tabs whatever the number of washouts, the events tab
    in sight in a 1280 px window. Beside them: the Metrics panel (the ranking and the ceiling)."""
    eye, target = layout.camera
    platform = layout.platform_name
    scene = rrb.Spatial3DView(
        origin="/world",
        name=f"Aircraft (from its initial heading) and {platform} cockpits",
        eye_controls=rrb.EyeControls3D(kind="Orbital", position=eye, look_target=target, eye_up=(0.0, 0.0, -1.0)),
        line_grid=rrb.LineGrid3D(visible=False),
    )
    metrics = rrb.TextDocumentView(origin="/metrics", name="Metrics: ranking, ceiling and metrics")
    perceived = _motion_tab(layout, "perceived", layout.perceived_ranges, "perceived ", "Perceived", layout.legends[0])
    raw = _motion_tab(layout, "raw", layout.raw_ranges, "", "Raw motion", layout.legends[1])
    phase = [layout.phase_lane] if layout.phase_lane is not None else []
    cue_view = _lanes(layout, f"False cues, one lane per washout: a bar where its pilot feels false cues "
                              f"({layout.cue_key})", layout.cue_lanes)  # fmt: skip
    phase_share = lane_view_px(1, title=False) / TAB_PX[DESIGN_SIZE]
    false_cues = rrb.Vertical(
        *([_lanes(layout, "Phases", phase, titlebar=False)] if phase else []),
        cue_view,
        row_shares=([phase_share, 1.0 - phase_share] if phase else [1.0]),
        name="False cues",
    )
    usage = [_panel(layout, u.origin, u.title, u.y_range) for u in layout.usage]
    limits = _lanes(layout, f"Limits held, one lane per washout ({layout.limit_key})", layout.limit_lanes)
    top = rrb.Horizontal(limits, _legend(layout.legends[2]),
                         column_shares=[1.0 - ENVELOPE_LEGEND_SHARE, ENVELOPE_LEGEND_SHARE])  # fmt: skip
    envelope = rrb.Vertical(
        top,
        *([rrb.Grid(*usage, grid_columns=usage_columns(len(usage)))] if usage else []),
        row_shares=list(envelope_shares(layout)) if usage else [1.0],
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
            timeline_columns=[enc.TimelineColumn("time", visible=False)],  # each text starts with its time: the
            text_log_columns=[                                              # column was cut to "+3..."
                enc.TextLogColumn("LogLevel"),
                enc.TextLogColumn("Body"),
                enc.TextLogColumn("EntityPath", visible=False),
            ],
        ),
        format_options=rrb.archetypes.TextLogFormat(monospace_body=True),  # the times, right-aligned, line up
    )
    platforms = rrb.Tabs(*per_washout, active_tab=0, name=f"{platform} per washout")
    scene_tab = rrb.Vertical(scene, name="3-D view")  # the view's own title is too long for a tab
    tabs = rrb.Tabs(perceived, false_cues, raw, envelope, scene_tab, events, platforms, active_tab=0)
    return rrb.Blueprint(
        rrb.Horizontal(tabs, metrics, column_shares=[3, SIDE_SHARE]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline="time", play_state="paused"),
    )
