"""Figures of ``washbench track``: the Bode plots of the identified loops, the variance decompositions, the motion
filters the pilot adapted to.

- ``bode.png``: the target and the disturbance open loops at their forcing frequencies (magnitude on log axes,
  phase in degrees), one line per condition (the aircraft's own motion dashed in the aircraft pilot's colour, no
  motion dotted grey), the
  crossover of each marked; a grey line at magnitude 1 and at -180 deg.
- ``variance.png``: the error's and the control's variance per condition, each split into what lies at the
  target's frequencies, at the disturbance's and the remnant; the control's visual and vestibular parts beside.
- ``motion.png``: the motion filter of each condition on the task's axis (simulator over aircraft pilot's rate)
  at the forcing frequencies, as measured in the runs.

Drawn from the files (``track.json``, ``frf.csv``: :func:`read_curves`), so ``washbench report`` draws them again
the same. matplotlib with its Agg back end, imported only when a figure is drawn; written atomically.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from washbench.io.atomic import atomic_path
from washbench.pilot.loop import AIRCRAFT, NO_MOTION
from washbench.review.palette import aircraft_color, mpl, washout_colors

NO_MOTION_COLOR = (150, 150, 150)
_DPI = 100


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Any, path: Path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=_DPI)


@dataclass(frozen=True)
class Curves:
    """What the figures draw of one condition, as ``track.json`` and ``frf.csv`` hold it: the open loops and the
    motion filter at the forcing frequencies (rad/s, complex), the crossovers (rad/s, deg) and the variances."""

    name: str
    target: tuple[np.ndarray, np.ndarray]
    disturbance: tuple[np.ndarray, np.ndarray]
    motion: tuple[np.ndarray, np.ndarray]
    crossovers: Mapping[str, tuple[float, float]]
    measures: Mapping[str, float]


def _value(x: Any) -> float:
    return math.nan if x is None or x == "" else float(x)


def read_curves(summary: Mapping[str, Any], frf_csv: str) -> list[Curves]:
    """The :class:`Curves` of every measured condition of a ``track.json`` summary and its ``frf.csv`` text."""
    rows: dict[tuple[str, str], list[tuple[float, complex, complex]]] = {}
    for r in csv.DictReader(io.StringIO(frf_csv)):
        ol = _value(r["open_loop_gain"]) * np.exp(1j * math.radians(_value(r["open_loop_phase_deg"])))
        mo = _value(r["motion_gain"]) * np.exp(1j * math.radians(_value(r["motion_phase_deg"])))
        rows.setdefault((r["condition"], r["forcing"]), []).append((_value(r["frequency_radps"]), ol, mo))
    out = []
    for c in summary["conditions"]:
        if not c["ok"]:
            continue
        m = {k: _value(v) for k, v in c["measures"].items()}
        t = rows.get((c["name"], "target"), [])
        d = rows.get((c["name"], "disturbance"), [])
        both = sorted(t + d)
        out.append(Curves(
            name=c["name"],
            target=(np.array([x[0] for x in t]), np.array([x[1] for x in t])),
            disturbance=(np.array([x[0] for x in d]), np.array([x[1] for x in d])),
            motion=(np.array([x[0] for x in both]), np.array([x[2] for x in both])),
            crossovers={
                "target": (m.get("target_crossover_radps", math.nan), m.get("target_phase_margin_deg", math.nan)),
                "disturbance": (m.get("disturbance_crossover_radps", math.nan),
                                m.get("disturbance_phase_margin_deg", math.nan)),
            },
            measures=m,
        ))  # fmt: skip
    return out


def condition_styles(names: Sequence[str], palette: str = "default") -> dict[str, dict[str, Any]]:
    """Colour, line style and width of each condition (the aircraft black dashed, no motion grey)."""
    washouts = [n for n in names if n not in (AIRCRAFT, NO_MOTION)]
    colours = washout_colors(washouts, palette)
    out: dict[str, dict[str, Any]] = {}
    for n in names:
        if n == AIRCRAFT:
            out[n] = {"color": mpl(aircraft_color(palette)), "ls": "--", "lw": 2.0, "marker": "o"}
        elif n == NO_MOTION:
            out[n] = {"color": mpl(NO_MOTION_COLOR), "ls": ":", "lw": 2.0, "marker": "s"}
        else:
            out[n] = {"color": mpl(colours[n]), "ls": "-", "lw": 1.4, "marker": "^"}
    return out


def _phase_deg(h: np.ndarray) -> np.ndarray:
    ph = np.degrees(np.unwrap(np.angle(h)))
    if ph[0] > 30.0:
        ph -= 360.0 * math.ceil((ph[0] - 30.0) / 360.0)
    return ph


def bode_figure(path: Path, results: Sequence[Curves], title: str, palette: str = "default") -> None:
    """``bode.png`` (module docstring)."""
    plt = _pyplot()
    styles = condition_styles([r.name for r in results], palette)
    fig, axes = plt.subplots(2, 2, figsize=(11.0, 7.0), sharex="col")
    for col, (label, attr) in enumerate((
        ("target open loop  x / e", "target"),
        ("disturbance open loop  -u / (u + f_d)", "disturbance"),
    )):  # fmt: skip
        ax_m, ax_p = axes[0, col], axes[1, col]
        for r in results:
            w, h = getattr(r, attr)
            if not len(w):
                continue
            st = styles[r.name]
            ax_m.loglog(w, np.abs(h), color=st["color"], ls=st["ls"], lw=st["lw"], marker=st["marker"], ms=4,
                        label=r.name)  # fmt: skip
            ax_p.semilogx(w, _phase_deg(h), color=st["color"], ls=st["ls"], lw=st["lw"], marker=st["marker"], ms=4)
            wc, pm = r.crossovers[attr]
            if math.isfinite(wc) and math.isfinite(pm):
                ax_m.plot([wc], [1.0], marker="x", color=st["color"], ms=9, mew=2)
                ax_p.plot([wc], [pm - 180.0], marker="x", color=st["color"], ms=9, mew=2)
        ax_m.axhline(1.0, color="0.6", lw=0.8)
        ax_p.axhline(-180.0, color="0.6", lw=0.8)
        ax_m.set_title(label)
        ax_m.set_ylabel("magnitude (-)")
        ax_p.set_ylabel("phase (deg)")
        ax_p.set_xlabel("frequency (rad/s)")
        ax_m.grid(True, which="both", alpha=0.3)
        ax_p.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=min(6, len(labels)), frameon=False,
               bbox_to_anchor=(0.5, 0.955))  # fmt: skip
    fig.suptitle(f"{title}: open loops at the forcing frequencies (x: crossover)", y=0.995)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.91))
    _save(fig, path)
    plt.close(fig)


def variance_figure(path: Path, results: Sequence[Curves], title: str, palette: str = "default") -> None:
    """``variance.png`` (module docstring)."""
    plt = _pyplot()
    names = [r.name for r in results]
    x = np.arange(len(names))
    fig, axes = plt.subplots(1, 3, figsize=(13.0, 4.8))
    parts = (("target", "#4878cf"), ("disturbance", "#d65f5f"), ("remnant", "#b0b0b0"))
    for ax, attr, unit in ((axes[0], "error_var_deg2", "deg²"), (axes[1], "control_var", "control²")):
        bottom = np.zeros(len(names))
        stem = attr.removesuffix("_deg2")
        suffix = "_deg2" if attr.endswith("_deg2") else ""
        for part, colour in parts:
            v = np.array([r.measures.get(f"{stem}_{part}{suffix}", math.nan) for r in results])
            ax.bar(x, v, 0.6, bottom=bottom, color=colour, label=f"at the {part}'s frequencies"
                   if part != "remnant" else "remnant")  # fmt: skip
            bottom += np.nan_to_num(v)
        ax.set_title(f"{stem.split('_')[0]} variance")
        ax.set_ylabel(f"variance ({unit})")
    ax = axes[2]
    width = 0.38
    vis = [r.measures.get("control_visual_var", math.nan) for r in results]
    ves = [r.measures.get("control_vestibular_var", math.nan) for r in results]
    ax.bar(x - width / 2, vis, width, color="#6acc65", label="visual channel")
    ax.bar(x + width / 2, ves, width, color="#956cb4", label="vestibular channel")
    ax.set_title("control variance by modality")
    ax.set_ylabel("variance (control²)")
    for a in axes:
        a.set_xticks(x)
        a.set_xticklabels(names, rotation=25, ha="right")
        a.grid(True, axis="y", alpha=0.3)
    h0, l0 = axes[0].get_legend_handles_labels()
    h2, l2 = axes[2].get_legend_handles_labels()
    fig.legend(h0 + h2, l0 + l2, loc="lower center", ncol=5, frameon=False, fontsize=9)
    fig.suptitle(f"{title}: variance decomposition (mean over the runs' measurement windows)")
    fig.tight_layout(rect=(0.0, 0.07, 1.0, 1.0))
    _save(fig, path)
    plt.close(fig)


def motion_figure(path: Path, results: Sequence[Curves], title: str, palette: str = "default") -> None:
    """``motion.png`` (module docstring)."""
    plt = _pyplot()
    styles = condition_styles([r.name for r in results], palette)
    fig, (ax_m, ax_p) = plt.subplots(2, 1, figsize=(8.0, 6.5), sharex=True)
    for r in results:
        if r.name == NO_MOTION:
            continue
        w, h = r.motion
        if not len(w):
            continue
        st = styles[r.name]
        ax_m.semilogx(w, np.abs(h), color=st["color"], ls=st["ls"], lw=st["lw"], marker=st["marker"], ms=4,
                      label=r.name)  # fmt: skip
        ax_p.semilogx(w, np.degrees(np.angle(h)), color=st["color"], ls=st["ls"], lw=st["lw"], marker=st["marker"],
                      ms=4)  # fmt: skip
    ax_m.axvline(1.0, color="0.7", lw=0.8)
    ax_p.axvline(1.0, color="0.7", lw=0.8)
    ax_m.set_ylabel("gain (-)")
    ax_p.set_ylabel("phase (deg)")
    ax_p.set_xlabel("frequency (rad/s)")
    ax_m.grid(True, which="both", alpha=0.3)
    ax_p.grid(True, which="both", alpha=0.3)
    ax_m.legend(fontsize=8)
    fig.suptitle(f"{title}: motion filter on the task's axis (simulator over aircraft pilot's rate)")
    fig.tight_layout()
    _save(fig, path)
    plt.close(fig)


def track_figures(folder: Path, results: Sequence[Curves], title: str,
                  palette: str = "default") -> Mapping[str, Path]:  # fmt: skip
    """Every figure into ``folder`` (created); name -> path."""
    folder.mkdir(parents=True, exist_ok=True)
    out = {"bode": folder / "bode.png", "variance": folder / "variance.png", "motion": folder / "motion.png"}
    bode_figure(out["bode"], results, title, palette)
    variance_figure(out["variance"], results, title, palette)
    motion_figure(out["motion"], results, title, palette)
    return out
