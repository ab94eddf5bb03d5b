"""What the rerun viewer (0.41, native, scale 1) draws where, measured on its screenshots: the pixels the recording's
layout (:mod:`washbench.review.blueprint`) is sized with, the rule by which a time-series panel labels its y axis,
and the grid of the legend. Pure functions, no rerun import.

Sizes are measured at the two window sizes the layout is made for, 1920x1080 (the one it is sized for) and
1280x720 (the smallest it is checked at): a tab's content (under the tab bar, over the collapsed time panel) is
:data:`TAB_PX` tall and :data:`TABS_WIDTH_PX` wide; a time-series panel spends :data:`PANEL_CHROME_PX` on its title
bar and time axis; a state-lane view spends :data:`LANE_VIEW_PX` on its title bar, time ruler and margins and
:data:`LANE_PX` on each lane (rerun's ``re_view_state_timeline``: a 14 px label, a 22 px band, a 4 px gap).

The y axis of a time-series panel (egui_plot's ``log_grid_spacer(10)`` and ``AxisHints::new_y``): gridlines at the
multiples of powers of ten only (no 2s or 5s), a step's labels drawn only where its gridlines are more than
:data:`LABEL_GAP_PX` apart (faint up to 30 px). A panel from -8.4 to 7.4 deg/s 140 px tall therefore labels only
the multiples of 10 (1 deg/s is 9 px), and of those only 0 lies inside: a lone "0" tick, the size of a 6 deg/s cue
unreadable. :func:`labelled_range` widens a range until two labelled gridlines lie inside it, clear of its edges.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = [
    "LABEL_EDGE_PX",
    "LABEL_GAP_PX",
    "LANE_PX",
    "LANE_VIEW_PX",
    "LEGEND_ROW_PX",
    "PANEL_CHROME_PX",
    "TABS_WIDTH_PX",
    "TAB_PX",
    "labelled_range",
    "labelled_step",
    "lane_view_px",
    "legend_grid",
    "legend_positions",
]

TAB_PX = {"1920x1080": 988.0, "1280x720": 628.0}
"""Height of a tab's content, px (measured: the window less the top bar, the tab bar and the collapsed time panel)."""

TABS_WIDTH_PX = {"1920x1080": 1340.0, "1280x720": 893.0}
"""Width of the tabs beside the Metrics panel, px (the tabs' column share 3 against the Metrics panel's
:data:`washbench.review.blueprint.SIDE_SHARE`)."""

PANEL_CHROME_PX = 44.0
"""A time-series panel's title bar and time axis, px: its plot area is the panel's height less this."""

LANE_VIEW_PX = 64.0
"""A state-lane view's title bar (24 px), time ruler and margins, px (without its title bar 24 px less)."""

TITLE_PX = 24.0
"""A view's title bar, px."""

LANE_PX = 40.0
"""One lane of a state-lane view: its label (14 px), its band (22 px) and the gap to the next (4 px)."""

LABEL_GAP_PX = 24.0
"""A y step's labels show when its gridlines are more than 20 px apart (egui_plot's ``label_spacing`` 20..30 px for
the y axis: invisible at 20, full strength at 30): counted from 24 px, where they have 40 % of their strength."""

LABEL_EDGE_PX = 14.0
"""A tick label (about 14 px tall, centred on its gridline) stands clear of the plot's edge (and of the time axis's
labels under it) when its gridline is this far inside."""

LEGEND_ROW_PX = 26.0
"""One line of the legend: a label (about 18 px tall with its box) and the gap to the next."""

LEGEND_CHAR_PX = 6.6
"""Width of one character of a legend label (the viewer's proportional font, measured: 6.4 px on average)."""

LEGEND_PAD_PX = 24.0
"""A legend label's box padding and the gap to the next column, px."""

LEGEND_LABEL_DROP_PX = 12.0
"""The viewer draws a point's label under the point, centred: the label's middle is this far below it, px."""


def lane_view_px(n_lanes: int, title: bool = True) -> float:
    """Height a state-lane view of ``n_lanes`` lanes needs to show them all, px (4 px of slack)."""
    return LANE_VIEW_PX - (0.0 if title else TITLE_PX) + LANE_PX * n_lanes + 4.0


def labelled_step(height: float, plot_px: float) -> float:
    """The smallest power of ten whose gridlines a panel ``plot_px`` tall showing ``height`` (y units) labels: more
    than :data:`LABEL_GAP_PX` apart."""
    return 10.0 ** math.ceil(math.log10(height * LABEL_GAP_PX / plot_px) + 1e-12)


def _inside(lo: float, hi: float, step: float, plot_px: float) -> int:
    """How many multiples of ``step`` lie in [lo, hi], each at least :data:`LABEL_EDGE_PX` inside its edges."""
    margin = (hi - lo) * LABEL_EDGE_PX / plot_px
    return max(0, math.floor((hi - margin) / step + 1e-9) - math.ceil((lo + margin) / step - 1e-9) + 1)


def labelled_range(span: tuple[float, float], plot_px: float) -> tuple[float, float]:
    """``span`` (lo, hi), widened as little as need be so that a panel ``plot_px`` tall showing it labels two
    gridlines at least, each whole (:data:`LABEL_EDGE_PX` inside the edges): the viewer labels only multiples of the
    power of ten :func:`labelled_step` gives (a panel from -8.4 to 7.4 deg/s, 140 px tall, labels the multiples of
    10, of which only 0 is inside: it showed a lone "0").

    Widened outward to a pair of neighbouring multiples of a power of ten plus the edge margin, the pair and the power
    of ten that widen least while that power is still labelled at the new height."""
    lo, hi = span
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo and plot_px > 2.0 * LABEL_EDGE_PX):
        return span
    if _inside(lo, hi, labelled_step(hi - lo, plot_px), plot_px) >= 2:
        return span
    edge = LABEL_EDGE_PX / plot_px  # the margin as a share of the final height
    best: tuple[float, float] | None = None
    step = labelled_step(hi - lo, plot_px)
    for _ in range(4):  # this step, then coarser ones
        for k in range(math.floor(lo / step) - 1, math.ceil(hi / step) + 1):
            a, b = lo, hi
            for _ in range(60):  # a = min(lo, k s - e H), b = max(hi, (k + 1) s + e H), H = b - a: a contraction
                height = b - a
                a, b = min(lo, k * step - edge * height), max(hi, (k + 1) * step + edge * height)
            if labelled_step(b - a, plot_px) <= step * (1 + 1e-9) and (best is None or b - a < best[1] - best[0]):
                best = (a, b)
        if best is not None:
            return best
        step *= 10.0
    return span


def legend_grid(names: Sequence[str], width_px: float) -> tuple[int, int, float]:
    """(columns, rows, cell width in rows) of a legend of ``names`` in a view ``width_px`` wide: as many columns as
    the longest label leaves room for, filled row by row."""
    cell_px = LEGEND_CHAR_PX * max((len(n) for n in names), default=1) + LEGEND_PAD_PX
    columns = max(1, min(len(names), math.floor(width_px / cell_px)))
    rows = max(1, math.ceil(len(names) / columns))
    return columns, rows, cell_px / LEGEND_ROW_PX


def legend_positions(n: int, columns: int, cell: float) -> list[tuple[float, float]]:
    """The point of each of ``n`` legend labels, in units of one legend row: column by column in a row, rows downward
    (a 2-D view's y points down), the label (drawn under its point) in the middle of its cell."""
    drop = LEGEND_LABEL_DROP_PX / LEGEND_ROW_PX
    return [((i % columns + 0.5) * cell, i // columns + 0.5 - drop) for i in range(n)]
