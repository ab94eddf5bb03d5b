"""Figures of the studies: score against each swept key (``sweep.png``), tuning convergence (``convergence.png``).

matplotlib with its non-interactive Agg back end, imported only when a figure is drawn. Scores are the ranking
rule's (lower is better; 1 is no better than a simulator that stands still, drawn as a grey line).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from washbench.analysis.sweep import SweepRow, format_value
from washbench.io.atomic import atomic_path
from washbench.io.outfolder import uninterrupted


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)


UNIT_SUFFIXES: tuple[tuple[str, str], ...] = (
    ("_radps", "rad/s"),
    ("_degps2", "deg/s²"),
    ("_degps", "deg/s"),
    ("_deg", "deg"),
    ("_mps2", "m/s²"),
    ("_mps", "m/s"),
    ("_per_s", "1/s"),
    ("_m", "m"),
    ("_s", "s"),
)
"""Unit suffixes of parameter names (SI inside, the unit in the name: ``lowpass_wn_radps``) and how they read."""


def key_label(key: str) -> str:
    """A swept key with its unit, from the unit in its dotted name: ``tilt.lowpass_wn_radps.x`` ->
    ``tilt.lowpass_wn_radps.x (rad/s)``; a scale factor is ``(-)``; a key whose name carries no unit stays as it is."""
    parts = key.split(".")
    for part in reversed(parts):
        for suffix, unit in UNIT_SUFFIXES:
            if part.endswith(suffix):
                return f"{key} ({unit})"
    if parts[0] == "scale":
        return f"{key} (-)"
    return key


@uninterrupted
def sweep_figure(path: Path, keys: Sequence[str], rows: Sequence[SweepRow]) -> None:
    """Mean score over the manoeuvres against each swept key, one line per washout.

    With more than one key, each panel shows for every value of its key the best mean score over the other keys'
    values (the profile), so each panel reads on its own.
    """
    plt = _pyplot()
    mean: dict[tuple[str, tuple[str, ...]], list[float]] = defaultdict(list)
    for r in rows:
        mean[(r.washout, tuple(format_value(r.point[k]) for k in keys))].append(float(r.evaluation.score[r.index]))
    washouts = list(dict.fromkeys(r.washout for r in rows))
    fig, axes = plt.subplots(1, len(keys), figsize=(5.2 * len(keys), 3.8), squeeze=False)
    for ax, (j, key) in zip(axes[0], enumerate(keys), strict=True):
        values = list(dict.fromkeys(format_value(r.point[key]) for r in rows))
        try:
            xs = [float(v) for v in values]
            numeric = True
        except ValueError:
            xs, numeric = list(range(len(values))), False
        for w in washouts:
            ys = []
            for v in values:
                scores = [np.mean(s) for (ww, pt), s in mean.items() if ww == w and pt[j] == v]
                ys.append(min(scores) if scores else np.nan)
            ax.plot(xs, ys, marker="o", label=w)
        if numeric and min(xs) > 0 and max(xs) / min(xs) >= 10:
            ax.set_xscale("log")
        if not numeric:
            ax.set_xticks(xs, values)
        elif len(values) <= 8:
            ax.set_xticks(xs, values)
            ax.minorticks_off()
        ax.axhline(1.0, color="0.6", lw=0.8, ls="--")
        ax.set_xlabel(key_label(key))
        ax.set_ylabel("mean score (lower is better)" + (", best over other keys" if len(keys) > 1 else ""))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    n_man = len({(r.aircraft, r.manoeuvre) for r in rows})
    fig.suptitle(f"Sweep: mean score over {n_man} manoeuvre(s)")
    fig.tight_layout()
    _save(fig, path)
    plt.close(fig)


@uninterrupted
def convergence_figure(path: Path, objective: np.ndarray, baseline: float, label: str) -> None:
    """Every evaluation's objective (dots) and the best so far (a step at each improvement) against the evaluation
    number (integer ticks)."""
    from matplotlib.ticker import MaxNLocator

    plt = _pyplot()
    obj = np.asarray(objective, dtype=float)
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    idx = np.arange(1, len(obj) + 1)  # evaluations counted from 1
    ax.plot(idx, obj, ".", ms=3, color="0.6", label="each evaluation")
    ax.step(idx, np.fmin.accumulate(obj), where="post", color="C0", lw=1.8, label="best so far")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.axhline(baseline, color="C3", ls="--", lw=1.0, label=label)
    finite = obj[np.isfinite(obj)]
    if finite.size:
        lo, hi = float(finite.min()), float(np.percentile(finite, 95))
        ax.set_ylim(lo - 0.05 * (hi - lo + 1e-9), max(hi, baseline) + 0.05 * (hi - lo + 1e-9))
    ax.set_xlabel("evaluation")
    ax.set_ylabel("objective (lower is better)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, path)
    plt.close(fig)
