"""Bode plots of the OMCT (``washbench omct``): one PNG per test, every washout overlaid.

Left column: the simulator's motion at the pilot's head, measured on the platform's own state (gain on a log axis,
absolute, as the OMCT literature plots it; phase in degrees), with the boundaries if given (dashed, the band between
them shaded). Where the head-motion estimate of ``washbench cue`` (the paper's Eq. 8 estimator for the small-angle
washout, the quaternion difference of Eqs. 18-19 otherwise) differs from it, that estimate is drawn as a thin
dotted line of the washout's colour, labelled "cue head estimate": a separate curve, not the test's result. Right
column: what the pilot perceives through the vestibular models, each simulator pilot against the aircraft pilot
(black, dashed) for the same input. Non-linear points are drawn as crosses, points outside the boundaries get a red
ring. matplotlib is imported lazily with the Agg backend (no display needed).

One legend for both columns, outside every axes, in a strip between the suptitle and the panels' titles: each entry
once (each washout's line style with its marker, its cue head estimate, the aircraft pilot), read row by row, in as
many columns as fit the figure's width; the strip is as tall as the legend's rows and the panels' tops come
down by as much, so the legend never covers a curve or a red ring, whatever the number of washouts.

Layout: fixed for every test but for the legend's height. The left column's y-labels ("gain (-)", "phase (deg)")
stand at one fixed distance from the figure's left edge (``_YLABEL_X``, a figure fraction), so they are always
inside the figure and above one another; the axes start at ``_LEFT``, which leaves room between the labels and the axes
for the widest tick labels these axes get: a log gain axis spanning less than a decade labels its minor ticks
(``6x10^-1``, 53 px wide at the PNGs' 90 dpi), which matplotlib's own label placement would push off the figure.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from washbench.analysis.omct import TESTS, Bounds, bounds_at
from washbench.io.atomic import atomic_path
from washbench.io.outfolder import uninterrupted

_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive")
_STYLES = (("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"))  # washouts that coincide stay visible
_SIZE_IN = (11.0, 7.0)  # figure width, height [in]
_DPI = 90  # of the figure and its PNG [pixels per inch]
# The left column's y-labels: their right edge (the text's bottom, turned) at this fraction of the figure's width
# from its left edge, 17.8 px; the label (10 pt) is 13 px wide turned, so it spans 4.8 to 17.8 px. The axes begin
# at _LEFT, 87.1 px; the tick labels end 7 px before it. Measured gaps between a label and the left end of its
# tick labels: 9 px for the widest minor label of gains in [1e-9, 10) (``2x10^-1``, 53 px), 3 px for gains below
# 1e-9 (``2x10^-10``, 59 px), 18 px for a phase axis labelled ``-1000`` (42 px) (tests/test_omct.py checks one).
_YLABEL_X = 0.018
_LEFT = 0.088
_GAP_PX = 5.0  # between the suptitle, the legend and the panels' titles, and the legend's margin to the sides [px]


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _boundary_lines(ax_gain: Any, ax_phase: Any, b: Bounds) -> bool:
    """Draw the boundaries ``b``; whether a gain boundary was drawn (a value the log gain axis shows)."""
    w = np.geomspace(b.frequency_radps[0], b.frequency_radps[-1], 200)
    vals = np.array([[np.nan if v is None else v for v in bounds_at(b, x)] for x in w], dtype=float)
    for ax, lo, hi in ((ax_gain, vals[:, 0], vals[:, 1]), (ax_phase, vals[:, 2], vals[:, 3])):
        for line in (lo, hi):
            if np.isfinite(line).any():
                ax.plot(w, line, "k--", lw=1.0, label="_bound")
        if np.isfinite(lo).any() and np.isfinite(hi).any():
            ax.fill_between(w, lo, hi, color="0.85", zorder=0)
    return bool(np.any(vals[:, :2] > 0))


def _series(
    ax_gain: Any, ax_phase: Any, w: np.ndarray, g: np.ndarray, ph: np.ndarray, lin: np.ndarray, i: int, **kw: Any
) -> tuple[Any, Any]:
    """Draw one washout's response (the ``i``-th washout's line style and marker) on a gain and a phase panel; the
    gain panel's line and its markers, which the legend shows together."""
    line, marker = _STYLES[i % len(_STYLES)]
    (test_line,) = ax_gain.plot(w, g, line, **kw)
    ax_phase.plot(w, ph, line, **kw)
    (markers,) = ax_gain.plot(w[lin], g[lin], marker, ms=4, fillstyle="none", **kw)
    ax_phase.plot(w[lin], ph[lin], marker, ms=4, fillstyle="none", **kw)
    ax_gain.plot(w[~lin], g[~lin], "x", ms=7, mew=2, **kw)
    ax_phase.plot(w[~lin], ph[~lin], "x", ms=7, mew=2, **kw)
    return test_line, markers


def write_bode_plots(
    out_dir: Path, points: Sequence[Any], bounds: dict[str, Bounds], washouts: Sequence[str]
) -> dict[str, str]:
    """Write ``bode_<test>.png`` for every test in ``points`` (OmctPoint); return test -> file name."""
    by_test = {t.name: [p for p in points if p.test == t.name] for t in TESTS}
    tests = [t for t in TESTS if by_test[t.name]]
    if not tests:
        return {}
    plt = _pyplot()
    fig_axes = new_figure()  # one figure, emptied for each next test
    files: dict[str, str] = {}
    try:
        for k, test in enumerate(tests):
            if k:
                _empty(fig_axes[1])
            files[test.name] = _bode_plot(fig_axes, Path(out_dir), test, by_test[test.name], bounds, washouts)
    finally:
        plt.close(fig_axes[0])
    return files


def new_figure() -> tuple[Any, Any]:
    """A new empty figure and its 2 x 2 axes (gain above phase; platform motion left, perceived right) for
    :func:`_bode_plot`: the figure's size and resolution are those of the PNG."""
    return _pyplot().subplots(2, 2, figsize=_SIZE_IN, dpi=_DPI, sharex=True)


def _empty(axes: Any) -> None:
    """Empty the figure of the previous test of its data (lines, shading, texts, its legend, titles, labels, scales,
    data limits), to draw the next test in: the same bytes as a new figure (tested), without a new figure's axes
    creating their tick marks again, the larger part of a Bode plot's drawing (``washbench omct`` of four washouts and
    ten tests with boundaries: 11.5 s of CPU before, 7.9 s after)."""
    for legend in list(axes.flat[0].figure.legends):  # the figure's legend (_figure_legend)
        legend.remove()
    for ax in axes.flat:
        for artist in [*ax.lines, *ax.patches, *ax.texts, *ax.collections]:
            artist.remove()
        ax.set_title("")
        ax.set_xlabel("")
        ax.set_ylabel("")
        ax.set_xscale("linear")
        ax.set_yscale("linear")
        ax.relim()
        ax.ignore_existing_data_limits = True
        ax.autoscale(True)


def _row_major(items: Sequence[Any], ncols: int) -> list[Any]:
    """``items`` reordered so that a legend of ``ncols`` columns, which matplotlib fills column by column (the first
    ``len(items) % ncols`` columns one row longer), reads them row by row, left to right."""
    return [items[k] for j in range(ncols) for k in range(j, len(items), ncols)]


def _figure_legend(fig: Any, ax_top_left: Any, suptitle: Any, entries: dict[str, Any]) -> None:
    """Put one legend of ``entries`` (label -> handle; a tuple handle is drawn overlaid) for all panels in a strip
    between the suptitle and the panels' titles, outside every axes, in as many columns as fit the figure's width
    (entries read row by row); then set the figure's margins: the axes' tops come down by the legend's height, so
    the legend never covers a curve or a marker, whatever the number of washouts. Measured by matplotlib's renderer
    at the PNG's resolution: deterministic, the same for the same entries."""
    renderer = fig.canvas.get_renderer()
    height_px = fig.bbox.height
    labels = list(entries)
    # the strip: from _GAP_PX under the suptitle down to the panels' titles
    legend_top_px = suptitle.get_window_extent(renderer).y0 - _GAP_PX
    legend = None
    for ncols in range(len(labels), 0, -1):
        if legend is not None:
            legend.remove()
        legend = fig.legend(
            _row_major([entries[k] for k in labels], ncols), _row_major(labels, ncols), ncols=ncols, fontsize=8,
            loc="upper center", bbox_to_anchor=(0.5, legend_top_px / height_px), bbox_transform=fig.transFigure,
            borderaxespad=0.0, columnspacing=1.5, handlelength=2.5,
        )  # fmt: skip
        if legend.get_window_extent(renderer).width <= fig.bbox.width - 2.0 * _GAP_PX:
            break
    legend_bottom_px = legend.get_window_extent(renderer).y0 if legend is not None else legend_top_px + _GAP_PX
    # the titles stand above the axes by the title's pad and text height, whatever the axes' position
    title_px = ax_top_left.title.get_window_extent(renderer).y1 - ax_top_left.bbox.y1
    top_px = legend_bottom_px - _GAP_PX - title_px
    fig.subplots_adjust(left=_LEFT, right=0.985, bottom=0.075, top=top_px / height_px, wspace=0.16, hspace=0.07)


def _differs(gain: np.ndarray, phase_deg: np.ndarray, ref_gain: np.ndarray, ref_phase_deg: np.ndarray) -> bool:
    """Whether the response ``gain``, ``phase_deg`` differs from ``ref_gain``, ``ref_phase_deg`` by more than 0.1 %
    at some frequency (complex ratio); a point whose ratio is undefined (0/0, NaN) is left out, one where only the
    reference is 0 differs. No warning either way (a washout that passes nothing on gives such points)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(gain * np.exp(1j * np.radians(phase_deg)) / (ref_gain * np.exp(1j * np.radians(ref_phase_deg)))
                       - 1.0)  # fmt: skip
    defined = ratio[~np.isnan(ratio)]
    return bool(defined.size) and bool(defined.max() > 1e-3)


@uninterrupted
def _bode_plot(
    fig_axes: tuple[Any, Any], out_dir: Path, test: Any, pts: Sequence[Any], bounds: dict[str, Bounds],
    washouts: Sequence[str],
) -> str:
    """Draw one test's Bode plot into the empty 2 x 2 figure ``fig_axes`` and write it (a Ctrl-C waits until it is
    written); its file name."""
    fig, axes = fig_axes
    (ag, apg), (aph, app) = axes
    positive = {ag: False, apg: False}  # whether the gain panel has a value a log axis can show
    if test.name in bounds:
        positive[ag] = _boundary_lines(ag, aph, bounds[test.name])
    aircraft_entry: tuple[str, Any] | None = None  # the aircraft pilot's legend entry, once drawn
    entries: dict[str, Any] = {}  # the figure legend's label -> handle, in drawing order, each label once
    for i, name in enumerate(washouts):
        mine = sorted((p for p in pts if p.washout == name), key=lambda p: p.frequency_radps)
        if not mine:
            continue
        w = np.array([p.frequency_radps for p in mine])
        lin = np.array([p.linear for p in mine])
        colour = _COLOURS[i % len(_COLOURS)]
        g_meas = np.array([p.gain for p in mine])
        g_perc = np.array([p.perceived_gain for p in mine])
        positive[ag] |= bool(np.any(g_meas > 0))
        positive[apg] |= bool(np.any(g_perc > 0))
        # a washout that passes nothing of this test on has no point a log axis can show: its legend entry says so
        handle = _series(ag, aph, w, g_meas, np.array([p.phase_deg for p in mine]), lin, i, color=colour)
        entries.setdefault(name if np.any(g_meas > 0) else f"{name}: no platform motion (gain 0)", handle)
        g_est = np.array([p.estimator_gain for p in mine])
        ph_est = np.array([p.estimator_phase_deg for p in mine])
        if _differs(g_est, ph_est, g_meas, np.array([p.phase_deg for p in mine])):
            (estimate,) = ag.plot(w, g_est, ":", lw=1.0, color=colour)
            aph.plot(w, ph_est, ":", lw=1.0, color=colour)
            entries.setdefault(f"{name}: cue head estimate (not the test)", estimate)
        handle = _series(apg, app, w, g_perc, np.array([p.perceived_phase_deg for p in mine]), lin, i, color=colour)
        entries.setdefault(name if np.any(g_perc > 0) else f"{name}: nothing perceived (gain 0)", handle)
        for p in mine:  # outside the boundaries: a red ring
            if p.gain_inside is False:
                ag.plot(p.frequency_radps, p.gain, "o", ms=11, mfc="none", mec="red", mew=1.5)
            if p.phase_inside is False:
                aph.plot(p.frequency_radps, p.phase_deg, "o", ms=11, mfc="none", mec="red", mew=1.5)
        if aircraft_entry is None:
            ga = np.array([p.aircraft_perceived_gain for p in mine])
            pa = np.array([p.aircraft_perceived_phase_deg for p in mine])
            if np.any(ga > 0):
                positive[apg] = True
                (aircraft,) = apg.plot(w, ga, "k--", lw=1.5)
                app.plot(w, pa, "k--", lw=1.5)
                aircraft_entry = ("aircraft pilot", aircraft)
            else:  # nothing drawn: the legend's entry says why (a line of the same style, in no axes)
                from matplotlib.lines import Line2D

                aircraft_entry = ("aircraft pilot: no rotation (gain 0)", Line2D([], [], color="k", ls="--", lw=1.5))
    if aircraft_entry is not None:
        entries.setdefault(*aircraft_entry)
    for ax in (ag, apg):
        ax.set_xscale("log")
        if positive[ax]:  # else a log axis has nothing to show (and matplotlib warns): left linear, at 0
            ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
    for ax in (aph, app):
        ax.set_xscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlabel("frequency (rad/s)")
    from matplotlib.transforms import blended_transform_factory

    for ax, label in ((ag, "gain (-)"), (aph, "phase (deg)")):  # at a fixed place, not pushed by the tick labels
        ax.set_ylabel(label)
        ax.yaxis.set_label_coords(_YLABEL_X, 0.5, transform=blended_transform_factory(fig.transFigure, ax.transAxes))
    ag.set_title(f"{test.input_axis} -> {test.output_axis}: platform motion at the pilot's head")
    apg.set_title("perceived (vestibular models)")
    suptitle = fig.suptitle(f"OMCT {test.name}  (x: non-linear point; red ring: outside the boundaries)", fontsize=11)
    _figure_legend(fig, ag, suptitle, entries)
    name = f"bode_{test.name}.png"
    with atomic_path(Path(out_dir) / name) as tmp:
        fig.savefig(tmp, format="png", dpi=_DPI)
    return name
