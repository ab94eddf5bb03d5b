"""The review layout of a recording, and the colours every view shares.

Laid out for one question: which washout feels most like the aircraft? The first tab stacks the six perceived-motion
panels (surge, sway, heave, roll, pitch, yaw, as the paper's Figures 8-16) under the phase lane, all on one linked
time axis showing the whole manoeuvre, and gives them the height; the false cues (one lane per washout) have a tab
of their own, the per-washout Atlas tabs sit inside one tab, so the events tab stays in sight with ten washouts.
Beside them the 3D scene (aircraft and Atlas cockpits, labels staggered), the legend (as tall as its lines) and the
Metrics panel (the ranking first, then washout-by-DOF tables). The viewer's own side panels start collapsed.

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
THRESHOLD_COLOR = (128, 128, 128)
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
class Layout:
    """What the blueprint needs to know about the data (the blueprint is built with the recording).

    ``perceived_ranges`` and ``raw_ranges``: per DOF (in the order of ``dofs``) the y range to show, thresholds and
    all traces inside.
    ``limit_lanes``: (washout, kind) pairs that reach a limit at least once. ``camera``: (eye, target) in the scene's
    NED frame, metres.
    """

    washouts: tuple[str, ...]
    dofs: tuple[tuple[str, str], ...]  # (name, unit)
    t_end_s: float
    perceived_ranges: tuple[tuple[float, float], ...]
    raw_ranges: tuple[tuple[float, float], ...]
    limit_lanes: tuple[tuple[str, str], ...]
    camera: tuple[tuple[float, float, float], tuple[float, float, float]]
    envelope_quantities: tuple[tuple[str, str], ...]  # (name, unit)
    limits_text: tuple[str, ...]  # per envelope quantity, e.g. "+-1.5/1.5/1 m"
    hidden_lanes: tuple[str, ...] = ()
    """Lanes under ``/lanes`` no tab shows: each washout's limits joined (the envelope tab shows the limits, one lane
    per washout and kind)."""
    cue_lanes: tuple[str, ...] = ()
    """The false-cue lanes (one per washout): a tab of their own, left out of the motion tabs, whose six panels get
    the room (with seven washouts the lanes above them left each panel about 55 px)."""


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


def _stack(layout: Layout, prefix: str, ranges: Sequence[tuple[float, float]], title: str) -> list[rrb.TimeSeriesView]:
    """Six stacked panels (one per DOF) without legends, y ranges fixed to hold all the data and the thresholds."""
    views = []
    for (dof, unit), (lo, hi) in zip(layout.dofs, ranges, strict=True):
        legend = rrb.PlotLegend(visible=False)  # the one legend has a panel of its own
        views.append(
            rrb.TimeSeriesView(
                origin=f"/{prefix}/{dof}",
                name=f"{title}{dof} [{unit}]",
                axis_x=_whole_manoeuvre(layout.t_end_s),
                axis_y=rrb.ScalarAxis(range=(lo, hi)),
                plot_legend=legend,
                time_ranges=_all_data(),
            )
        )
    return views


def _lanes(layout: Layout, origin: str, name: str, hidden: Sequence[str] = ()) -> rrb.StateTimelineView:
    contents = [f"+ {origin}/**", *(f"- {path}" for path in hidden)]
    return rrb.StateTimelineView(
        origin=origin, name=name, contents=contents, time_view=_whole_manoeuvre(layout.t_end_s),
        time_ranges=_all_data(),
    )  # fmt: skip


LANE_SHARE = 0.7
"""Height of one state lane (with its name above it) against a motion panel's 2.0 (measured on screenshots: a lane
takes about 40 px of the 1080 px window, a motion panel needs about 110 px to show its ticks)."""
PANEL_SHARE = 2.0


LANE_VIEW_SHARE = 1.2
"""A lane view's title bar and time axis, against a motion panel's 2.0: with it one lane shows whole in a 720 px
window (screenshots of the Columbia aerobatics at 1280x720: with 0.7 only the axis showed)."""


def lane_share(n_lanes: int) -> float:
    """The row share of a lane view of ``n_lanes`` lanes (its title bar and time axis included)."""
    return LANE_VIEW_SHARE + LANE_SHARE * n_lanes





def build_blueprint(layout: Layout) -> rrb.Blueprint:
    """The review layout (see the module docstring); tabs: perceived, raw, envelope, events, Atlas (one tab per
    washout inside): the events tab stays in sight with ten washouts."""
    eye, target = layout.camera
    n_legend = len(layout.washouts) + 2  # the aircraft, every washout, the threshold
    side = rrb.Vertical(
        rrb.Spatial3DView(
            origin="/world",
            name="Aircraft (from its initial heading) and Atlas cockpits",
            eye_controls=rrb.EyeControls3D(kind="Orbital", position=eye, look_target=target, eye_up=(0.0, 0.0, -1.0)),
            line_grid=rrb.LineGrid3D(visible=False),
        ),
        rrb.TimeSeriesView(
            origin="/legend",
            name="Legend",
            axis_x=_whole_manoeuvre(layout.t_end_s),
            axis_y=rrb.ScalarAxis(range=(1.0, 2.0)),  # its lines lie at 0: only the legend shows
            plot_legend=rrb.PlotLegend(corner="LeftTop", visible=True),
            time_ranges=_all_data(),
        ),
        rrb.TextDocumentView(origin="/metrics", name="Metrics: ranking and metrics"),
        row_shares=[2.2, 0.9 + 0.26 * n_legend, 3.6],  # the legend as tall as its lines, the rest for the tables
    )
    phase_only = [*layout.hidden_lanes, *layout.cue_lanes]  # the motion tabs: the phase lane, the panels the room
    perceived = rrb.Vertical(
        _lanes(layout, "/lanes", "Phases", phase_only),
        *_stack(layout, "perceived", layout.perceived_ranges, "perceived "),
        row_shares=[lane_share(1)] + [PANEL_SHARE] * len(layout.dofs),
        name="Perceived",
    )
    false_cues = _lanes(layout, "/lanes", "False cues", layout.hidden_lanes)  # phases, a lane per washout
    raw = rrb.Vertical(
        _lanes(layout, "/lanes", "Phases", phase_only),
        *_stack(layout, "raw", layout.raw_ranges, ""),
        row_shares=[lane_share(1)] + [PANEL_SHARE] * len(layout.dofs),
        name="Raw motion",
    )
    usage = [
        rrb.TimeSeriesView(
            origin=f"/envelope/{q}",
            name=f"{q}: max |axis| / limit ({limit})",
            axis_x=_whole_manoeuvre(layout.t_end_s),
            axis_y=rrb.ScalarAxis(range=(0.0, 1.15)),
            plot_legend=rrb.PlotLegend(visible=False),  # the colours are those of the one legend
            time_ranges=_all_data(),
        )
        for (q, _), limit in zip(layout.envelope_quantities, layout.limits_text, strict=True)
    ]
    envelope = rrb.Vertical(
        _lanes(layout, "/limits", "Limits reached (one lane per washout and limit kind)"),
        *usage,
        row_shares=[1.0 + 0.45 * len(layout.limit_lanes) + 0.4 * len(layout.washouts)] + [PANEL_SHARE] * len(usage),
        name="Platform envelope",
    )
    per_washout = [
        rrb.Grid(
            *[
                rrb.TimeSeriesView(
                    origin=f"/platform/{w}/{q}",
                    name=f"{w}: {q} [{unit}] ({axes})",
                    axis_x=_whole_manoeuvre(layout.t_end_s),
                    plot_legend=rrb.PlotLegend(visible=False),
                    time_ranges=_all_data(),
                )
                for q, unit in layout.envelope_quantities
                for axes in ["w1 red, w2 green, w3 blue" if q == "wheels" else "x red, y green, z blue"]
            ],
            grid_columns=2,
            name=f"Atlas {w}",
        )
        for w in layout.washouts
    ]
    enc = rrb.encodings
    events = rrb.TextLogView(
        origin="/events",
        name="Phases, limit and false-cue events",
        columns=rrb.archetypes.TextLogColumns(
            timeline_columns=[enc.TimelineColumn("time")],
            text_log_columns=[
                enc.TextLogColumn("LogLevel"),
                enc.TextLogColumn("Body"),
                enc.TextLogColumn("EntityPath", visible=False),
            ],
        ),
    )
    atlas = rrb.Tabs(*per_washout, active_tab=0, name="Atlas per washout")
    tabs = rrb.Tabs(perceived, false_cues, raw, envelope, events, atlas, active_tab=0)
    return rrb.Blueprint(
        rrb.Horizontal(tabs, side, column_shares=[3, 1.4]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline="time", play_state="paused"),
    )
