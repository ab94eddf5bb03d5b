"""Figures of the report, drawn with matplotlib (Agg, no display, no pyplot state): PNG for report.md, PDF for papers.

Per manoeuvre (one result folder):

- :func:`perceived_figure`: the six perceived-motion panels stacked on one time axis, as the paper's Figures 8, 10,
  14 and 16: surge, sway, heave (m/s^2), roll, pitch, yaw (deg/s); the aircraft pilot in magenta (drawn wider), each
  washout's simulator pilot in its fixed colour (:mod:`washbench.review.palette`); the phases as a lane on top
  and shaded alternately in every panel; the perception thresholds (Zacharias, :mod:`washbench.perception.thresholds`)
  as a sand-coloured band +- threshold around the resting value (0, or -g for heave: the values the cue
  classification and the recording use), so what lies inside it is not felt.
- :func:`envelope_figure`: platform envelope usage against time, max over the axes of |value| / limit for stage
  position, velocity, acceleration, sphere angular rate and wheel speed, the limit at 1, and one lane per washout
  and limit kind showing when a limit was active.

Per suite:

- :func:`score_heatmap`: the ranking score (:mod:`washbench.analysis.ranking`) per manoeuvre and washout; green
  below 1, red above (worse than a simulator that stands still), the best per row framed.
- :func:`table4_figure`: the paper's Table 4 as a figure: per manoeuvre, DOF and metric, how much better than
  small-angle each other washout is, in percent of the small-angle value (green better, red worse).

matplotlib is imported inside the functions, so commands that draw nothing do not load it. Long traces are drawn
through a min/max decimation (:func:`minmax_decimate`) that keeps every peak at the figure's resolution. Same data,
same files: no dates or random ids are written into the PNG or PDF.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from washbench.io import collector
from washbench.io.atomic import atomic_path, write_bytes_atomic
from washbench.io.outfolder import uninterrupted
from washbench.review.numbers import SCORE_FLAG, sig
from washbench.review.palette import THRESHOLD_COLOR, aircraft_color, mpl, palette_name, washout_colors, washout_dashes
from washbench.review.png import png_bytes

FIGURE_FORMATS = ("png", "pdf")
"""The formats a figure can be written in: STEM.png (embedded in report.md) and STEM.pdf (vector, for papers).
``washbench run``/``cue``/``suite`` write the PNG only (a PDF costs as much again); ``washbench report`` both."""

PNG_DPI = 110

PERCEIVED_PANELS: tuple[tuple[str, str], ...] = (
    ("surge", "m/s²"),
    ("sway", "m/s²"),
    ("heave", "m/s²"),
    ("roll", "deg/s"),
    ("pitch", "deg/s"),
    ("yaw", "deg/s"),
)
"""The six panels of :func:`perceived_figure`: (DOF, unit)."""

SATURATION_LABELS = {
    "pos": "stage position",
    "vel": "stage velocity",
    "acc": "stage acceleration",
    "rate": "sphere rate",
    "angacc": "sphere ang. acceleration",
    "tilt_rate": "tilt-rate limit",
    "rot_rate": "rotational saturation",
}
"""Readable names of the saturation kinds (``W.sat_<kind>`` columns) on the Atlas."""

PLATFORM_SATURATION_LABELS = {
    "hexapod": {"pos": "workspace / leg stroke", "vel": "leg velocity", "acc": "leg acceleration"},
    "rig": {"pos": "axis stop (angle, heave)", "vel": "heave velocity", "acc": "heave acceleration",
            "rate": "axis rate", "angacc": "axis ang. acceleration"},
}  # fmt: skip
"""What the platform's own saturation kinds mean on another platform than the Atlas (docs/platforms.md)."""


def saturation_labels(platform: str = "atlas") -> dict[str, str]:
    """:data:`SATURATION_LABELS` for a platform of kind ``platform`` (a plugin's: the kinds' own names)."""
    if platform == "atlas":
        return dict(SATURATION_LABELS)
    plugin = {k: f"platform {k}" for k in ("pos", "vel", "acc", "rate", "angacc")}
    own = PLATFORM_SATURATION_LABELS.get(platform, plugin)
    return {**SATURATION_LABELS, **own}

METRIC_LABELS = {"npc": "NPC", "integral_error": "integral of |error|", "max_error": "maximum |error|"}

_THRESHOLD_COLOR = mpl(THRESHOLD_COLOR)
"""The edges of the not-felt band: a warm sand, apart from the phases' blue-grey and every washout's colour."""
_THRESHOLD_FILL = (0.93, 0.78, 0.40, 0.30)
_PHASE_SHADE = (0.82, 0.86, 0.92, 0.45)
"""Every other phase in the panels: the phase lane's own blue-grey (not the not-felt band's colour)."""
_CHAR_IN = 7.5 * 0.56 / 72.0  # mean width of a phase-label character (DejaVu Sans at 7.5 pt) [in]
_LAYOUT_CACHE: dict[tuple[str, int], tuple[Any, Any]] = {}
_LAYOUT_CACHE_SIZE = 6

PERCEIVED_SIZE_IN = (8.6, 11.0)
PERCEIVED_MARGINS_IN = (0.85, 0.12, 0.62, 0.45)


def _new_figure(
    width_in: float, height_in: float, margins_in: tuple[float, float, float, float] | None = None
) -> Any:
    """A matplotlib Figure on an Agg canvas (no pyplot, no global backend change).

    ``margins_in`` (left, right, top, bottom) [in]: fixed margins for a figure of stacked panels whose labels are
    known (the per-result figures, drawn for every run: the constrained layout engine measures every label and
    costs about as much as the drawing); else the constrained layout.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if margins_in is None:
        fig = Figure(figsize=(width_in, height_in), layout="constrained")
    else:
        fig = Figure(figsize=(width_in, height_in))
        fig.subplots_adjust(**_subplot_fractions((width_in, height_in), margins_in))
    FigureCanvasAgg(fig)
    return fig


def _stacked_layout(
    kind: str, size_in: tuple[float, float], margins_in: tuple[float, float, float, float],
    ratios: Sequence[float],
) -> tuple[Any, Any, bool]:  # fmt: skip
    """A figure of panels stacked on one shared time axis, laid out once per process and reused; and whether it is
    new (then the caller styles its ticks and grid, which a reused one keeps).

    Building the axes and their ticks costs more than drawing the data; a worker that draws many results reuses the
    layout it already built for the same ``kind`` of figure and number of panels, emptied of the previous data:
    lines, patches, texts, collections, titles, tick choices and data limits (the legend stays while it is the same,
    :func:`_top_legend`), and refitted to this figure's size, margins and panel ratios when they differ (the
    envelope figure's height and left margin follow its limit lanes). Same data, same pixels.
    """
    key = (kind, len(ratios))
    cached = _LAYOUT_CACHE.pop(key, None)
    if cached is None:
        fig = _new_figure(size_in[0], size_in[1], margins_in)
        axes = fig.subplots(len(ratios), 1, sharex=True, gridspec_kw={"height_ratios": list(ratios)})
        _label_places(axes, size_in, margins_in)
        if len(_LAYOUT_CACHE) >= _LAYOUT_CACHE_SIZE:
            _LAYOUT_CACHE.pop(next(iter(_LAYOUT_CACHE)))
    else:
        fig, axes = cached
        for ax in axes:
            for artist in [*ax.lines, *ax.patches, *ax.texts, *ax.collections]:
                artist.remove()
            ax.set_title("")
            ax.set_ylabel("")
            ax.set_xlabel("")
            ax.relim()
            ax.ignore_existing_data_limits = True
            ax.set_xlim(0.0, 1.0)  # a fresh axes' view: a panel without data keeps it (spines end on the view)
            ax.set_ylim(0.0, 1.0)
            ax.set_autoscale_on(True)
            ax.yaxis.set_major_locator(_auto_locator())
            ax.yaxis.set_major_formatter(_auto_formatter())
        if fig._washbench_geometry != (size_in, margins_in, tuple(ratios)):
            fig.set_size_inches(size_in, forward=False)
            axes[0].get_subplotspec().get_gridspec().set_height_ratios(list(ratios))
            fig.subplots_adjust(**_subplot_fractions(size_in, margins_in))  # places every panel again
            _label_places(axes, size_in, margins_in)
    fig._washbench_geometry = (size_in, margins_in, tuple(ratios))
    _LAYOUT_CACHE[key] = (fig, axes)
    return fig, axes, cached is None


def _subplot_fractions(size_in: tuple[float, float], margins_in: tuple[float, float, float, float]) -> dict[str, float]:
    """``Figure.subplots_adjust`` arguments for fixed margins (left, right, top, bottom) [in] on a figure of
    ``size_in`` (width, height) [in]."""
    (width_in, height_in), (left, right, top, bottom) = size_in, margins_in
    return {"left": left / width_in, "right": 1.0 - right / width_in, "top": 1.0 - top / height_in,
            "bottom": bottom / height_in, "hspace": 0.16}  # fmt: skip


def _label_places(axes: Any, size_in: tuple[float, float], margins_in: tuple[float, float, float, float]) -> None:
    """Axis labels at fixed places (y: ending 0.32 in inside the figure's left edge, x: 0.24 in under the axis)
    instead of matplotlib measuring every tick label of every shared panel before each drawing to place them."""
    for ax in axes:
        box = ax.get_position()
        width_in, height_in = box.width * size_in[0], box.height * size_in[1]
        ax.yaxis.set_label_coords(-(margins_in[0] - 0.32) / width_in, 0.5)
        ax.xaxis.set_label_coords(0.5, -0.24 / height_in)


def _auto_locator() -> Any:
    from matplotlib.ticker import AutoLocator

    return AutoLocator()


def _auto_formatter() -> Any:
    from matplotlib.ticker import ScalarFormatter

    return ScalarFormatter()


def _plot_width_px(size_in: tuple[float, float], margins_in: tuple[float, float, float, float]) -> int:
    """Width of the panels in PNG pixels (the resolution a trace is drawn at)."""
    return max(math.ceil((size_in[0] - margins_in[0] - margins_in[1]) * PNG_DPI), 16)


_LEGEND_ROW = 6
"""Entries in one legend row; more (the aircraft and six or more washouts) go on two rows in a smaller font."""


def _top_legend(fig: Any, handles: Callable[[], list[Any]], key: tuple[Any, ...]) -> None:
    """The legend above the panels (under the figure's top edge): one row, or two when there are more than
    :data:`_LEGEND_ROW` entries (so that every name stays inside the picture). ``handles`` makes the entries;
    ``key`` says all they depend on: a reused figure keeps its legend while the key is the same (laying a legend out
    costs a tenth of the figure)."""
    key = (*key, fig.get_figheight())  # the legend's anchor is placed in figure fractions
    if fig.legends and getattr(fig, "_washbench_legend", None) == key:
        return
    for legend in list(fig.legends):
        legend.remove()
    fig._washbench_legend = key
    handles = handles()
    two = len(handles) > _LEGEND_ROW
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 1.0 - 0.02 / fig.get_figheight()),
               ncol=math.ceil(len(handles) / 2) if two else len(handles), fontsize=7.0 if two else 8.5,
               frameon=False, handlelength=3.2, borderaxespad=0.0,
               labelspacing=0.15, columnspacing=1.2)  # fmt: skip


def save_figure(fig: Any, stem: Path, formats: Sequence[str] = ("png",)) -> list[Path]:
    """Write ``stem.<format>`` for each of ``formats`` (:data:`FIGURE_FORMATS`), PNG first, atomically and
    deterministically (no date, no software stamp); return the paths in that order."""

    unknown = [f for f in formats if f not in FIGURE_FORMATS]
    if unknown or "png" not in formats:
        raise ValueError(f"figure formats must include png and be among {FIGURE_FORMATS}, got {tuple(formats)}")
    paths = []
    for fmt in sorted(formats, key=FIGURE_FORMATS.index):
        path = stem.with_suffix(f".{fmt}")
        if fmt == "png":  # drawn at PNG_DPI as savefig draws it, encoded by png_bytes (4x faster than Pillow)
            if fig.dpi != PNG_DPI:
                fig.set_dpi(PNG_DPI)
            fig.canvas.draw()
            write_bytes_atomic(path, png_bytes(np.asarray(fig.canvas.buffer_rgba()), PNG_DPI))
        else:
            meta = {"Creator": None, "Producer": None, "CreationDate": None}
            with atomic_path(path) as tmp:
                fig.savefig(tmp, format=fmt, dpi=PNG_DPI, metadata=meta)
        paths.append(path)
    return paths


def minmax_decimate(t: np.ndarray, y: np.ndarray, buckets: int = 1500) -> tuple[np.ndarray, np.ndarray]:
    """At most ``2 * buckets`` points that draw like ``(t, y)``: each bucket's minimum and maximum, in time order.

    The figures pass one bucket per pixel column of the panel, so every peak stays where the full trace puts it.
    Shorter traces are returned unchanged. NaNs are kept out of the min/max (a bucket of NaNs stays NaN).
    """
    n = t.shape[0]
    if n <= 2 * buckets:
        return t, y
    size = math.ceil(n / buckets)
    buckets = math.ceil(n / size)
    if np.isfinite(y).all():  # the usual case: argmin/argmax on a view of the samples, no copies
        full = n // size
        yb = y[: full * size].reshape(full, size)
        lo, hi = yb.argmin(axis=1), yb.argmax(axis=1)
        if full < buckets:  # the last, shorter bucket
            rest = y[full * size :]
            lo = np.append(lo, rest.argmin())
            hi = np.append(hi, rest.argmax())
        start = np.arange(buckets) * size
        idx = np.column_stack([start + np.minimum(lo, hi), start + np.maximum(lo, hi)]).ravel()
        return t[idx], y[idx]
    pad = size * buckets - n
    yp = np.concatenate([y, np.full(pad, y[-1])]).reshape(buckets, size)
    tp = np.concatenate([t, np.full(pad, t[-1])]).reshape(buckets, size)
    finite = np.isfinite(yp)
    lo = np.where(finite, yp, np.inf).argmin(axis=1)
    hi = np.where(finite, yp, -np.inf).argmax(axis=1)
    first, second = np.minimum(lo, hi), np.maximum(lo, hi)
    rows = np.arange(buckets)
    idx_t = np.column_stack([tp[rows, first], tp[rows, second]]).ravel()
    idx_y = np.column_stack([yp[rows, first], yp[rows, second]]).ravel()
    return idx_t, idx_y


def phase_label(name: str, width_in: float) -> str:
    """``name`` as it fits a phase box ``width_in`` inches wide: on one line, else wrapped at spaces onto two,
    else shortened with an ellipsis (or dropped where not even four characters fit)."""
    chars = int(width_in / _CHAR_IN)
    if len(name) <= chars:
        return name
    words = name.split()
    if len(words) > 1:
        for cut in range(len(words) - 1, 0, -1):
            first, second = " ".join(words[:cut]), " ".join(words[cut:])
            if len(first) <= chars and len(second) <= chars:
                return f"{first}\n{second}"
    return name[: max(chars - 1, 0)] + "…" if chars >= 4 else ""


@dataclass(frozen=True)
class PlacedLabel:
    """A phase name placed on the phase lane: ``text`` centred at ``x_in`` inches from the lane's left edge, on
    ``row`` (0: the whole lane height, inside its box; 1: the upper half; 2: the lower half)."""

    text: str
    x_in: float
    row: int


def place_phase_labels(boxes: Sequence[tuple[str, float, float]], width_in: float,
                       gap_in: float = 2 * _CHAR_IN) -> list[PlacedLabel]:  # fmt: skip
    """Where each phase name goes on a lane ``width_in`` inches wide; ``boxes``: (name, left, right) in inches.

    A name that fits its box (on one line or wrapped onto two, :func:`phase_label`) stays centred in it. A name
    that does not is written on one line in the upper or lower half of the lane, centred on its box as far as the
    lane allows and free to run over its neighbours' boxes, wherever it keeps ``gap_in`` from every other name;
    only where neither half has the room is it shortened to its box (or dropped) as before.
    """
    placed: list[PlacedLabel | None] = [None] * len(boxes)
    taken: dict[int, list[tuple[float, float]]] = {1: [], 2: []}

    def extent(text: str, x: float) -> tuple[float, float]:
        half = 0.5 * max(len(line) for line in text.split("\n")) * _CHAR_IN
        return x - half, x + half

    for i, (name, a, b) in enumerate(boxes):
        text = phase_label(name, b - a)
        if text == name or text.replace("\n", " ") == name:
            x = 0.5 * (a + b)
            placed[i] = PlacedLabel(text, x, 0)
            for row in taken.values():
                row.append(extent(text, x))
    for i, (name, a, b) in enumerate(boxes):
        if placed[i] is not None:
            continue
        half = 0.5 * len(name) * _CHAR_IN
        x = min(max(0.5 * (a + b), half), width_in - half)
        lo, hi = x - half - gap_in, x + half + gap_in
        for row in (1, 2) if 2 * half <= width_in else ():
            if all(hi <= left or lo >= right for left, right in taken[row]):
                placed[i] = PlacedLabel(name, x, row)
                taken[row].append((x - half, x + half))
                break
        else:
            short = phase_label(name, b - a)
            placed[i] = PlacedLabel(short, 0.5 * (a + b), 0) if short else None
    return [p for p in placed if p is not None]


def _phase_lane(ax: Any, phases: Sequence[tuple[str, float, float]], t0_s: float, t1_s: float,
                width_in: float) -> None:  # fmt: skip
    """Phases as labelled boxes on a lane axis (names that do not fit their box staggered above and below,
    :func:`place_phase_labels`)."""
    ax.set_ylim(0, 1)
    ax.set_yticks([])
    for side in ("top", "right", "left"):
        ax.spines[side].set_visible(False)
    span = max(t1_s - t0_s, 1e-9)
    boxes = []
    for i, (name, a, b) in enumerate(phases):
        shade = (0.82, 0.86, 0.92) if i % 2 == 0 else (0.90, 0.92, 0.96)
        _span(ax, a, b, color=shade, lw=0)
        boxes.append((name, (max(a, t0_s) - t0_s) / span * width_in, (min(b, t1_s) - t0_s) / span * width_in))
    for label in place_phase_labels(boxes, width_in):
        ax.text(t0_s + label.x_in / width_in * span, (0.5, 0.75, 0.25)[label.row], label.text, ha="center",
                va="center", fontsize=7.5, clip_on=True, linespacing=1.0)  # fmt: skip
    ax.set_ylabel("phase", rotation=0, ha="right", va="center", fontsize=8)
    ax.yaxis.set_label_coords(-0.01, 0.5)


def _shade_phases(ax: Any, phases: Sequence[tuple[str, float, float]]) -> None:
    """Every other phase shaded and a thin line at each phase start (one collection each: fewer artists to draw)."""
    from matplotlib.collections import LineCollection, PolyCollection

    if not phases:
        return
    trans = ax.get_xaxis_transform()  # x in data, y in axes fraction
    boxes = [[(t0, 0.0), (t1, 0.0), (t1, 1.0), (t0, 1.0)] for i, (_, t0, t1) in enumerate(phases) if i % 2 == 1]
    if boxes:
        ax.add_collection(PolyCollection(boxes, facecolors=[_PHASE_SHADE], linewidths=0, zorder=0, transform=trans),
                          autolim=False)  # fmt: skip
    starts = [[(t0, 0.0), (t0, 1.0)] for _, t0, _ in phases]
    ax.add_collection(LineCollection(starts, colors=[(0.6, 0.6, 0.6)], linewidths=0.5, zorder=0.5, transform=trans),
                      autolim=False)  # fmt: skip


def _line(ax: Any, x: Any, y: Any, **style: Any) -> None:
    """A data line, as ``ax.plot(x, y, **style)`` draws it (Line2D, data limits updated) without plot()'s argument
    parsing, which cost a tenth of a reused figure; the caller asks for the autoscaling it needs."""
    from matplotlib.lines import Line2D

    ax.add_line(Line2D(x, y, **style))


def _span(ax: Any, t0_s: float, t1_s: float, **style: Any) -> None:
    """A box over the whole height of a panel from ``t0_s`` to ``t1_s``, drawn as ``axvspan`` draws it, without its
    data-limit update (the panels' time limits are set, never autoscaled)."""
    from matplotlib.axis import GRIDLINE_INTERPOLATION_STEPS
    from matplotlib.patches import Rectangle

    box = Rectangle((t0_s, 0.0), t1_s - t0_s, 1.0, **style)
    box.set_transform(ax.get_xaxis_transform(which="grid"))
    box.get_path()._interpolation_steps = GRIDLINE_INTERPOLATION_STEPS
    ax.add_artist(box)


def _band(ax: Any, lo: float, hi: float) -> None:
    """The not-felt band ``lo..hi`` across the panel, drawn as ``axhspan`` draws it, without its data-limit update
    (the threshold lines drawn with it span the same values; the update cost as much as drawing the band)."""
    from matplotlib.axis import GRIDLINE_INTERPOLATION_STEPS
    from matplotlib.patches import Rectangle

    band = Rectangle((0.0, lo), 1.0, hi - lo, facecolor=_THRESHOLD_FILL, edgecolor="none", zorder=1)
    band.set_transform(ax.get_yaxis_transform(which="grid"))
    band.get_path()._interpolation_steps = GRIDLINE_INTERPOLATION_STEPS
    ax.add_artist(band)


@uninterrupted
@collector.paused
def perceived_figure(
    stem: Path,
    title: str,
    t_s: np.ndarray,
    perceived: Mapping[str, np.ndarray],
    *,
    phases: Sequence[tuple[str, float, float]] = (),
    thresholds: Sequence[float] | None = None,
    rest: Sequence[float] = (0.0, 0.0, -9.80665, 0.0, 0.0, 0.0),
    formats: Sequence[str] = ("png",),
    palette: str | None = None,
) -> list[Path]:
    """The six stacked perceived-motion panels (module docstring); returns the paths (PNG first).

    ``perceived``: ``"aircraft"`` and each washout -> (N, 6) array, columns surge, sway, heave [m/s^2], roll, pitch,
    yaw [deg/s]; the washouts are drawn in the mapping's order. ``thresholds`` (6,) in the same units, drawn as a
    band ``rest +- threshold`` (``rest``: the pilot's resting value per DOF, same units); ``phases``:
    (name, t_start_s, t_end_s); ``palette``: :data:`washbench.review.palette.PALETTES` (None: the environment's).
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    pal = palette_name(palette)
    washouts = [s for s in perceived if s != "aircraft"]
    colors, dashes = washout_colors(washouts, pal), washout_dashes(washouts)
    ac_color = mpl(aircraft_color(pal))
    ratios = (0.35, *[1.0] * 6) if phases else (1.0,) * 6
    fig, axes, new = _stacked_layout("perceived", PERCEIVED_SIZE_IN, PERCEIVED_MARGINS_IN, ratios)
    width_px = _plot_width_px(PERCEIVED_SIZE_IN, PERCEIVED_MARGINS_IN)
    t0, t1 = float(t_s[0]), float(t_s[-1])
    if phases:
        width_in = PERCEIVED_SIZE_IN[0] - PERCEIVED_MARGINS_IN[0] - PERCEIVED_MARGINS_IN[1]
        _phase_lane(axes[0], phases, t0, t1, width_in)
        panels = axes[1:]
    else:
        panels = axes
    for i, (ax, (dof, unit)) in enumerate(zip(panels, PERCEIVED_PANELS, strict=True)):
        _shade_phases(ax, phases)
        if thresholds is not None:
            lo, hi = rest[i] - thresholds[i], rest[i] + thresholds[i]
            _band(ax, lo, hi)
            _line(ax, [t0, t1, np.nan, t0, t1], [lo, lo, np.nan, hi, hi], color=_THRESHOLD_COLOR, lw=0.6, zorder=1)
        for w in washouts:
            tt, yy = minmax_decimate(t_s, perceived[w][:, i], width_px)
            _line(ax, tt, yy, color=mpl(colors[w]), lw=1.0, ls=dashes[w], zorder=2)
        tt, yy = minmax_decimate(t_s, perceived["aircraft"][:, i], width_px)
        _line(ax, tt, yy, color=ac_color, lw=1.7, zorder=3)
        ax.autoscale(axis="y")  # the y limits from the lines' data, at drawing (as plot() asks)
        ax.set_ylabel(f"{dof}\n({unit})", fontsize=9)
        if new:  # a reused layout keeps its tick and grid style
            ax.tick_params(labelsize=8)
            ax.grid(True, color=(0.9, 0.9, 0.9), lw=0.5)
        ax.margins(x=0)
    panels[-1].set_xlabel("time (s)", fontsize=9)
    panels[-1].set_xlim(t0, t1)

    def handles() -> list[Any]:
        out = [Line2D([], [], color=ac_color, lw=1.7, label="aircraft pilot")]
        out += [Line2D([], [], color=mpl(colors[w]), lw=1.2, ls=dashes[w], label=w) for w in washouts]
        if thresholds is not None:
            out.append(Patch(facecolor=_THRESHOLD_FILL, edgecolor=_THRESHOLD_COLOR, lw=0.6, label="not felt"))
        return out

    _top_legend(fig, handles, (pal, tuple(washouts), thresholds is not None))
    axes[0].set_title(f"{title}: perceived motion", fontsize=11)
    return save_figure(fig, stem, formats)


def run_edges(flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start and end indices (end exclusive) of the runs of True in a boolean array, as two int arrays."""
    f = np.concatenate([[False], np.asarray(flags, dtype=bool), [False]])
    edges = np.flatnonzero(np.diff(f.astype(np.int8)))
    return edges[::2], edges[1::2]


def bars(ax: Any, x0: np.ndarray, width: np.ndarray, y0: float, height: float, **style: Any) -> None:
    """Boxes ``x0 .. x0 + width`` by ``y0 .. y0 + height`` (data units) as one collection, drawn as ``broken_barh``
    draws them, built from arrays (broken_barh converts every box's two numbers one by one: a tenth of a second
    for a 30-minute trace's runs) and without a data-limit update (the lane panels' limits are set)."""
    from matplotlib.collections import PolyCollection

    x0 = np.asarray(x0, dtype=np.float64)
    x1 = x0 + np.asarray(width, dtype=np.float64)
    y1 = y0 + height
    verts = np.empty((x0.shape[0], 4, 2))
    verts[:, 0, 0] = verts[:, 1, 0] = x0
    verts[:, 2, 0] = verts[:, 3, 0] = x1
    verts[:, 0, 1] = verts[:, 3, 1] = y0
    verts[:, 1, 1] = verts[:, 2, 1] = y1
    ax.add_collection(PolyCollection(verts, **style), autolim=False)


@uninterrupted
@collector.paused
def envelope_figure(
    stem: Path,
    title: str,
    t_s: np.ndarray,
    usage: Mapping[str, Mapping[str, np.ndarray]],
    saturated: Mapping[str, Mapping[str, np.ndarray]],
    *,
    phases: Sequence[tuple[str, float, float]] = (),
    formats: Sequence[str] = ("png",),
    palette: str | None = None,
    labels: Mapping[str, str] | None = None,
) -> list[Path]:
    """Platform envelope usage and saturation lanes (module docstring); returns the paths (PNG first).

    ``usage``: panel label (e.g. "position") -> washout -> (N,) |value| / limit (dimensionless, 1 = at the limit);
    ``saturated``: washout -> limit kind -> bool (N,) (kinds without any True are left out of the lanes);
    ``labels``: the lanes' names per kind (default :data:`SATURATION_LABELS`, the Atlas's: :func:`saturation_labels`).
    """
    from matplotlib.lines import Line2D

    pal = palette_name(palette)
    washouts = list(dict.fromkeys(w for per in usage.values() for w in per))
    colors, dashes = washout_colors(washouts, pal), washout_dashes(washouts)
    lanes = [(w, k, flags) for w in washouts for k, flags in saturated.get(w, {}).items() if np.any(flags)]
    n_lanes = max(len(lanes), 1)
    # the lane labels (7.5 pt, about 0.06 in a character) and the "limit active" label set the left margin
    names = labels if labels is not None else SATURATION_LABELS
    label_in = max([len(names.get(k, k)) for _, k, _ in lanes] + [8]) * 0.062
    size_in = (8.6, 1.55 * len(usage) + 0.9 + 0.2 * n_lanes)
    margins_in = (max(0.85, label_in + 0.45), 0.12, 0.62, 0.45)
    ratios = (*[1.0] * len(usage), 0.12 * n_lanes + 0.25)
    fig, axes, new = _stacked_layout("envelope", size_in, margins_in, ratios)
    width_px = _plot_width_px(size_in, margins_in)
    dt = float(t_s[1] - t_s[0]) if t_s.shape[0] > 1 else 0.0
    for ax, (label, per) in zip(axes, usage.items(), strict=False):
        _shade_phases(ax, phases)
        ax.axhline(1.0, color=(0.3, 0.3, 0.3), lw=0.9, ls=(0, (2.0, 2.0)), zorder=1)
        top = 1.0
        for w, u in per.items():
            tt, yy = minmax_decimate(t_s, u, width_px)
            _line(ax, tt, yy, color=mpl(colors[w]), lw=1.0, ls=dashes[w], zorder=2)
            if u.size and np.isfinite(u).any():
                top = max(top, float(np.nanmax(u)))
        ax.set_ylim(0.0, 1.08 * top)
        ax.set_ylabel(f"{label}\n(of limit)", fontsize=9)
        if new:  # a reused layout keeps its tick and grid style
            ax.tick_params(labelsize=8)
            ax.grid(True, color=(0.9, 0.9, 0.9), lw=0.5)
    lane_ax = axes[-1]
    if lanes:
        # a limit active for a few samples is still drawn visibly wide (0.3 % of the manoeuvre)
        min_width = max(dt, 0.003 * float(t_s[-1] - t_s[0]))
        for j, (w, _, flags) in enumerate(lanes):
            y = len(lanes) - 1 - j
            a, b = run_edges(flags)
            bars(lane_ax, t_s[a], np.maximum((b - a) * dt, min_width), y - 0.35, 0.7, color=mpl(colors[w]), lw=0)
        lane_ax.set_yticks(range(len(lanes)))
        lane_ax.set_yticklabels([names.get(k, k) for _, k, _ in reversed(lanes)], fontsize=7.5)
        for tick, (w, _, _) in zip(lane_ax.get_yticklabels(), reversed(lanes), strict=True):
            tick.set_color(mpl(colors[w]))
        lane_ax.set_ylim(-0.6, len(lanes) - 0.4)
    else:
        lane_ax.set_yticks([])
        lane_ax.text(0.5, 0.5, "no limit reached", transform=lane_ax.transAxes, ha="center", va="center", fontsize=8)
    lane_ax.set_ylabel("limit\nactive", fontsize=9)
    if new:
        lane_ax.tick_params(axis="x", labelsize=8)
    lane_ax.set_xlabel("time (s)", fontsize=9)
    lane_ax.set_xlim(float(t_s[0]), float(t_s[-1]))

    def handles() -> list[Any]:
        out = [Line2D([], [], color=mpl(colors[w]), lw=1.2, ls=dashes[w], label=w) for w in washouts]
        return [*out, Line2D([], [], color=(0.3, 0.3, 0.3), lw=0.9, ls=(0, (2.0, 2.0)), label="limit")]

    _top_legend(fig, handles, (pal, tuple(washouts)))
    axes[0].set_title(f"{title}: platform envelope", fontsize=11)
    return save_figure(fig, stem, formats)


def _sig(x: float, digits: int = 3) -> str:
    return sig(x, digits)


@uninterrupted
def score_heatmap(
    stem: Path,
    rows: Sequence[str],
    washouts: Sequence[str],
    scores: np.ndarray,
    title: str = "ranking score",
    formats: Sequence[str] = ("png",),
    firsts: Sequence[Sequence[str]] | None = None,
) -> list[Path]:
    """Score per manoeuvre (row) and washout (column), lower is better; the first place per row framed (each of a
    tie), above 1 in red; the bound's replay (``bound``: knows the future, not ranked) in italics, never framed.

    ``scores`` (R, W), NaN where a washout did not run; ``firsts``: per row the washouts ranked first (None: the
    lowest score of the ranked washouts). Returns the paths (PNG first).
    """
    from matplotlib.colors import LinearSegmentedColormap, TwoSlopeNorm
    from matplotlib.font_manager import FontProperties
    from matplotlib.patches import Rectangle

    from washbench.review.cell_text import CellTexts  # deferred: matplotlib

    scores = np.asarray(scores, dtype=np.float64).reshape(len(rows), len(washouts))
    finite = scores[np.isfinite(scores)]
    vmax = max(2.0, float(finite.max()) if finite.size else 2.0)
    colors = [(0.10, 0.60, 0.32), (1.0, 1.0, 0.85), (0.84, 0.19, 0.15)]
    cmap = LinearSegmentedColormap.from_list("score", colors).with_extremes(bad=(0.85, 0.85, 0.85))
    norm = TwoSlopeNorm(vmin=0.0, vcenter=1.0, vmax=vmax)
    fig = _new_figure(1.6 + 1.35 * len(washouts), 1.3 + 0.32 * len(rows))
    ax = fig.subplots()
    image = ax.imshow(np.ma.masked_invalid(scores), cmap=cmap, norm=norm, aspect="auto")
    normal, bold = FontProperties(size=8), FontProperties(size=8, weight="bold")
    italic = FontProperties(size=8, style="italic")
    ranked = [c for c, w in enumerate(washouts) if w != "bound"]
    cells, texts, fonts = [], [], []
    for r in range(len(rows)):
        row = scores[r]
        if firsts is not None:
            top = set(firsts[r])
        else:
            vals = [row[c] for c in ranked if math.isfinite(row[c])]
            top = {washouts[c] for c in ranked if vals and row[c] == min(vals)}
        for c in range(len(washouts)):
            v = row[c]
            is_best = math.isfinite(v) and washouts[c] in top and washouts[c] != "bound"
            cells.append((c, r))
            texts.append("-" if not math.isfinite(v) else _sig(v) + (f" {SCORE_FLAG}" if v > 1.0 else ""))
            fonts.append(bold if is_best else italic if washouts[c] == "bound" else normal)
            if is_best:
                ax.add_patch(Rectangle((c - 0.5, r - 0.5), 1, 1, fill=False, lw=1.6, ec="black"))
    ax.add_artist(CellTexts(cells, texts, fonts))
    labels = [f"{w} (replay)" if w == "bound" else w for w in washouts]
    # many columns: the names slanted, so that long ones (adaptive-large-angle) do not run into each other
    slant = {"rotation": 20, "ha": "left", "rotation_mode": "anchor"} if len(washouts) > 6 else {}
    ax.set_xticks(range(len(washouts)), labels, fontsize=8.5, **slant)
    ax.xaxis.tick_top()
    ax.set_yticks(range(len(rows)), rows, fontsize=8)
    bar = fig.colorbar(image, ax=ax, shrink=0.8, pad=0.02)
    bar.set_label("score (lower is better)", fontsize=7.5)
    bar.ax.tick_params(labelsize=7)
    replay = "; bound (replay, knows the future): italics, not ranked" if "bound" in washouts else ""
    ax.set_title(f"{title}: first place per manoeuvre framed (each of a tie){replay};\n{SCORE_FLAG} above 1 = worse "
                 "than a simulator standing still", fontsize=9)  # fmt: skip
    return save_figure(fig, stem, formats)


@uninterrupted
def table4_figure(
    stem: Path,
    rows: Sequence[str],
    reference: str,
    better_pct: Mapping[str, np.ndarray],
    dofs: Sequence[str],
    metrics: Sequence[str],
    formats: Sequence[str] = ("png",),
) -> list[Path]:
    """The paper's Table 4 as a figure: one panel per washout other than ``reference``.

    ``better_pct``: washout -> (R, len(metrics) * len(dofs)) array of 100 * (reference - washout) / reference, columns
    grouped by metric, then DOF; positive means better than the reference. NaN where undefined. Returns the paths.

    The colours follow a symmetric logarithmic scale (linear within +-10 %, then one step per decade) up to the
    largest magnitude in the table, so -1273 % is redder than -150 %, which is redder than -20 %; every cell prints
    its value.
    """
    from matplotlib.colors import SymLogNorm
    from matplotlib.font_manager import FontProperties

    from washbench.review.cell_text import CellTexts  # deferred: matplotlib

    others = list(better_pct)
    ncol = len(metrics) * len(dofs)
    fig = _new_figure(2.2 + 0.42 * ncol, 0.9 + len(others) * (0.85 + 0.3 * len(rows)))
    axes = np.atleast_1d(fig.subplots(len(others), 1, squeeze=False)[:, 0])
    cmap = _diverging_cmap()
    values_of = {w: np.asarray(better_pct[w], dtype=np.float64).reshape(len(rows), ncol) for w in others}
    finite = np.concatenate([np.abs(v[np.isfinite(v)]) for v in values_of.values()] + [np.zeros(1)])
    vmax = max(100.0, float(finite.max()))
    norm = SymLogNorm(linthresh=10.0, linscale=1.0, vmin=-vmax, vmax=vmax, base=10)
    image = None
    font = FontProperties(size=6.5)
    for ax, w in zip(axes, others, strict=True):
        values = values_of[w]
        image = ax.imshow(np.ma.masked_invalid(values), cmap=cmap, norm=norm, aspect="auto")
        cells = [(c, r) for r in range(len(rows)) for c in range(ncol)]
        texts = ["-" if not math.isfinite(v) else f"{v:+.0f}" if abs(v) >= 0.5 else "0" for v in values.ravel()]
        ax.add_artist(CellTexts(cells, texts, font))
        ax.set_xticks(range(ncol), [d for _ in metrics for d in dofs], fontsize=7, rotation=90)
        ax.set_yticks(range(len(rows)), rows, fontsize=7.5)
        for g in range(1, len(metrics)):
            ax.axvline(g * len(dofs) - 0.5, color="black", lw=1.2)
        sec = ax.secondary_xaxis("top")
        names = [METRIC_LABELS.get(m, m) for m in metrics]
        sec.set_xticks([(g + 0.5) * len(dofs) - 0.5 for g in range(len(metrics))], names, fontsize=8)
        sec.tick_params(length=0)
        ax.set_title(f"{w} better than {reference} (% of {reference}'s value)", fontsize=9)
    if image is not None:
        bar = fig.colorbar(image, ax=list(axes), shrink=0.6, pad=0.01)
        decades = [10.0**k for k in range(1, math.floor(math.log10(vmax)) + 1)]
        ticks = [-d for d in reversed(decades)] + [0.0] + decades
        bar.set_ticks(ticks, labels=[f"{t:+.0f}" if t else "0" for t in ticks])
        bar.set_label("% better (green) / worse (red), log scale beyond +-10", fontsize=7.5)
        bar.ax.tick_params(labelsize=7)
    return save_figure(fig, stem, formats)


def _diverging_cmap() -> Any:
    from matplotlib.colors import LinearSegmentedColormap

    colors = [(0.84, 0.19, 0.15), (1.0, 1.0, 0.92), (0.10, 0.60, 0.32)]
    return LinearSegmentedColormap.from_list("better", colors).with_extremes(bad=(0.88, 0.88, 0.88))
