"""The cue-classification lane figure of a result: when each washout gave false (and missing) cues.

One lane per washout and DOF (surge .. yaw) on the manoeuvre's time axis: red where the simulator pilot felt a
false cue, grey where a cue the aircraft pilot felt was missing (:mod:`washbench.analysis.cues`, classified again
from the perceived motion in traces.parquet with the rule metrics.csv was written with). matplotlib (Agg) through
:mod:`washbench.review.figures`' helpers; same data, same files.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from washbench.analysis.cues import FALSE, MISSING, classify, dof_thresholds
from washbench.analysis.metrics import DOFS
from washbench.io import collector
from washbench.io.outfolder import uninterrupted
from washbench.review.figures import _new_figure, bars, run_edges, save_figure

FALSE_COLOUR = (0.84, 0.15, 0.16)
MISSING_COLOUR = (0.72, 0.72, 0.72)


def cue_classes(perceived: Mapping[str, np.ndarray], washouts: Sequence[str]) -> dict[str, np.ndarray]:
    """Class per sample (6, N) int8 of each washout from perceived (N, 6) motion (m/s^2, deg/s) per pilot."""
    thresholds, rest = dof_thresholds()
    ac = perceived["aircraft"]
    return {
        w: np.vstack([classify(ac[:, j], perceived[w][:, j], thresholds[j], rest[j]) for j in range(len(DOFS))])
        for w in washouts
    }


@uninterrupted
@collector.paused
def cue_lane_figure(
    stem: Path,
    title: str,
    t_s: np.ndarray,
    classes: Mapping[str, np.ndarray],
    formats: Sequence[str] = ("png",),
) -> list[Path]:
    """Write the lane figure (``stem.png``, and PDF if asked); ``classes``: washout -> (6, N) from cue_classes."""
    from matplotlib.patches import Patch

    washouts = list(classes)
    n_lanes = len(washouts) * len(DOFS)
    fig = _new_figure(9.0, 1.2 + 0.16 * n_lanes + 0.25 * len(washouts))
    ax = fig.add_subplot(1, 1, 1)
    labels, ticks = [], []
    y = 0.0
    t = np.asarray(t_s, dtype=np.float64)
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    for i, w in enumerate(washouts):
        if i:  # a rule between two washouts' lanes
            y += 0.6
            ax.axhline(y - 0.3, color="0.6", lw=0.6)
        for j, d in enumerate(DOFS):
            row = classes[w][j]
            for cls, colour in ((MISSING, MISSING_COLOUR), (FALSE, FALSE_COLOUR)):
                a, b = run_edges(row == cls)
                if a.size:
                    bars(ax, t[a], (t[b - 1] - t[a]) + dt, y + 0.1, 0.8, facecolors=[colour], linewidth=0)
            labels.append(f"{w}  {d}" if j == 0 else d)
            ticks.append(y + 0.5)
            y += 1.0
    ax.set_yticks(ticks, labels, fontsize=7)
    ax.set_ylim(y, -0.2)
    ax.set_xlim(t[0], t[-1] + dt)
    ax.set_xlabel("time (s)")
    ax.set_title(f"{title}: false and missing cues per washout and DOF", fontsize=10, loc="left")
    ax.grid(True, axis="x", alpha=0.3)
    ax.legend(handles=[Patch(color=FALSE_COLOUR, label="false cue"), Patch(color=MISSING_COLOUR, label="missing cue")],
              loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=7, ncol=2, frameon=False)  # fmt: skip
    return save_figure(fig, stem, formats)
