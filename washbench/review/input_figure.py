"""What ``washbench cue`` read: the input after its units, axes and resampling, so a unit or sign mistake is seen.

:func:`input_figure` draws the six signals the washouts receive (specific force f_x, f_y, f_z in m/s^2, angular
velocity omega_x, omega_y, omega_z in deg/s, body axes x forward, y right, z down) against the input's own time,
each panel's legend naming where the signal came from (:func:`input_labels`): the file's column, the unit it was
read in and the sign, with where the sign came from (a ``-`` in the column mapping, the ``--axes`` of the sensor).
Dashed grey guides mark what a level, unaccelerated aircraft would show (f = [0, 0, -g], omega = 0): a specific
force in g, a z axis up or a rate in rad/s is then off its guide at a glance. The figure is ``figures/input.png``
of a cue result (legends and notes kept in run.json, so ``washbench report`` draws it again, with its PDF), and
:func:`input_section` links it first in the report.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from washbench.errors import WashbenchError, located
from washbench.io import collector
from washbench.io.columns import AIRCRAFT, TIME_COLUMN, f_columns, omega_columns
from washbench.io.input_format import ColumnSource
from washbench.io.outfolder import uninterrupted
from washbench.io.result_files import FIGURES_DIR, RUN_FILE, TRACES_FILE
from washbench.io.units import G0_MPS2, axes_matrix, is_identity_axes
from washbench.review.figures import minmax_decimate, save_figure

INPUT_STEM = "input"
"""The figure's file name (``figures/input.png``)."""
FIELDS6 = ("f_x", "f_y", "f_z", "omega_x", "omega_y", "omega_z")
UNITS6 = ("m/s²", "m/s²", "m/s²", "deg/s", "deg/s", "deg/s")
LEVEL_FLIGHT = (0.0, 0.0, -G0_MPS2, 0.0, 0.0, 0.0)
"""Level, unaccelerated flight in washbench's units and axes: the dashed guide of each panel."""
_UNIT_TEXT = {"s": "s", "ms": "ms", "us": "µs", "ns": "ns", "min": "min", "timestamp": "timestamps",
              "mps2": "m/s²", "ftps2": "ft/s²", "g": "g", "degps": "deg/s", "radps": "rad/s"}  # fmt: skip


def input_labels(
    sources: Mapping[str, ColumnSource], axes: str = "frd", mapped: Sequence[str] = (), origin: str = "--columns"
) -> list[str]:
    """Per body field (:data:`FIELDS6`) where it came from: ``f_y ← −'ay' (g): sign from --axes flu (sensor y)``.

    ``sources``: motion field -> its source column, unit and sign as read (before the axes); ``axes``: the sensor
    axes (:func:`washbench.io.units.axes_matrix`: body = M @ sensor); ``mapped``: the fields the user mapped
    (``origin``: where, e.g. ``--columns`` or the input-format file), the others the file kind's own columns.
    """
    m = axes_matrix(axes)
    out = []
    for i, field in enumerate(FIELDS6):
        kind, body = field.split("_")
        j = int(np.flatnonzero(m["xyz".index(body)])[0])  # the sensor axis that became this body axis
        axis_sign = float(m["xyz".index(body), j])
        sensor_field = f"{kind}_{'xyz'[j]}"
        src = sources[sensor_field]
        sign = axis_sign * src.sign
        why = []
        if src.sign < 0:
            why.append(f"'-' in {origin if sensor_field in mapped else 'the mapping'}")
        if not is_identity_axes(axes):
            why.append(f"--axes {axes}: sensor {'xyz'[j]}" + (" reversed" if axis_sign < 0 else ""))
        unit = _UNIT_TEXT.get(src.unit, src.unit)
        label = f"{field} ← {'−' if sign < 0 else '+'}'{src.column}' ({unit})"
        out.append(label + (f"; sign: {', '.join(why)}" if why else "") + f" [{UNITS6[i]}]")
    return out


@uninterrupted
@collector.paused
def input_figure(
    stem: Path,
    title: str,
    t_s: np.ndarray,
    f_mps2: np.ndarray,
    omega_degps: np.ndarray,
    labels: Sequence[str],
    notes: Sequence[str] = (),
    formats: Sequence[str] = ("png",),
) -> Path:
    """Draw the six input signals into ``stem.png`` (and the other ``formats``: ``pdf``), atomically and
    deterministically; return the PNG's path.

    ``t_s`` (N,) [s]; ``f_mps2`` (N, 3) [m/s^2]; ``omega_degps`` (N, 3) [deg/s] as the washouts receive them;
    ``labels``: the six legends (:func:`input_labels`); ``notes``: what the reading did (units, resampling),
    printed under the title.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 8.6))
    FigureCanvasAgg(fig)
    top = 0.90 - 0.018 * min(len(notes), 4)
    fig.subplots_adjust(left=0.07, right=0.985, top=top, bottom=0.06, hspace=0.42, wspace=0.16)
    axs = fig.subplots(3, 2, sharex=True)
    data = np.column_stack([f_mps2, omega_degps])
    for i in range(6):
        ax = axs[i % 3][i // 3]
        tt, yy = minmax_decimate(t_s, data[:, i])
        ax.plot(tt, yy, color=(0.12, 0.30, 0.62), lw=1.0, label=labels[i])
        ax.axhline(LEVEL_FLIGHT[i], color=(0.5, 0.5, 0.5), lw=0.8, ls="--", label="level flight")
        ax.set_ylabel(f"{FIELDS6[i]} [{UNITS6[i]}]", fontsize=9)
        ax.tick_params(labelsize=8)
        ax.grid(True, lw=0.3, alpha=0.5)
        ax.legend(loc="upper left", fontsize=7.5, frameon=True, framealpha=0.85, handlelength=1.6)
        lo, hi = min(float(np.min(yy)), LEVEL_FLIGHT[i]), max(float(np.max(yy)), LEVEL_FLIGHT[i])
        pad = max(0.08 * (hi - lo), 0.5 if i < 3 else 1.0)
        ax.set_ylim(lo - pad, hi + pad + 0.55 * (hi - lo + 2 * pad))  # the top third for the legend
    for col in range(2):
        axs[2][col].set_xlabel("input time [s]", fontsize=9)
    axs[0][0].set_title("specific force (body x fwd, y right, z down)", fontsize=9.5)
    axs[0][1].set_title("angular velocity (body axes)", fontsize=9.5)
    fig.suptitle(f"{title}: the input as the washouts receive it", fontsize=11, y=0.985)
    for k, note in enumerate(notes[:4]):
        fig.text(0.5, 0.955 - 0.018 * k, _short(note, 150), ha="center", fontsize=7.5, color=(0.3, 0.3, 0.3))
    return save_figure(fig, stem, formats)[0]


def _short(text: str, n: int) -> str:
    return text if len(text) <= n else text[: n - 1] + "…"


def input_section(
    folder: Path, pdf: bool, image: Callable[..., list[str]], into: Path | None = None
) -> list[str]:
    """The report's first section when the result has an input figure (a ``cue`` result), else nothing.

    ``pdf`` (``washbench report``): the figure is drawn again, PNG and PDF, from the result's files
    (:func:`redraw`); ``image``: the report's way of embedding a figure and linking its PDF. ``into``: the stage
    folder whose ``figures/`` will replace the result's (the figure is drawn, or copied, there).
    """
    png = folder / FIGURES_DIR / f"{INPUT_STEM}.png"
    if not png.is_file():
        return []
    target = (into or folder) / FIGURES_DIR
    target.mkdir(parents=True, exist_ok=True)
    drawn = redraw(folder, ("png", "pdf"), target) if pdf else None
    if drawn is None and into is not None:
        import shutil

        shutil.copyfile(png, target / png.name)
    return [
        "## Input as read",
        "",
        "The six signals the washouts received, after the units, axes and resampling were applied; each legend "
        "names the column, unit and sign they came from, the dashed line level flight. Check them before the "
        "results: a unit or sign mistake shows here.",
        "",
        *image(png, folder, "input as read", bool(drawn)),
    ]


def redraw(folder: Path, formats: Sequence[str], fig_dir: Path | None = None) -> Path | None:
    """Draw ``folder/figures/input.*`` (or ``fig_dir/input.*``) again from the result's files: the input columns of
    traces.parquet and the legends and notes run.json keeps (``input_labels``, ``conversions``); None when run.json
    has no legends."""
    import json

    import pyarrow.parquet as pq

    try:
        doc = json.loads((folder / RUN_FILE).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict):
        return None
    labels = doc.get("input_labels")
    if not isinstance(labels, list) or len(labels) != 6:
        return None
    notes = doc.get("conversions", [])
    where = folder / RUN_FILE
    for key, value in (("input_labels", labels), ("conversions", notes)):
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise WashbenchError(located(where, f"{key}: not as washbench writes it (a list of texts); edited or "
                                                "damaged? write it again"))  # fmt: skip
    import pyarrow as pa

    cols = [TIME_COLUMN, *f_columns(AIRCRAFT), *omega_columns(AIRCRAFT)]
    traces = folder / TRACES_FILE
    try:
        table = pq.read_table(traces, columns=cols)
    except (OSError, KeyError, ValueError, pa.ArrowException) as exc:
        raise WashbenchError(located(traces, f"cannot read the input columns: {exc}")) from None
    for c in cols:  # what the figure draws must be numbers (a file edited by hand may say otherwise)
        kind = table.schema.field(c).type
        if not (pa.types.is_floating(kind) or pa.types.is_integer(kind)):
            raise WashbenchError(located(traces, f"{c}: not as washbench writes it (numbers, got {kind}); edited or "
                                                 "damaged? write it again"))  # fmt: skip
    arr = np.column_stack([table[c].to_numpy(zero_copy_only=False).astype(np.float64) for c in cols])
    if not np.isfinite(arr).all():
        raise WashbenchError(located(traces, "the input columns hold values that are not finite; edited or damaged? "
                                             "write it again"))  # fmt: skip
    title = f"{Path(str(doc.get('input', 'input'))).name} {doc.get('segment', '')}".strip()
    stem = (fig_dir or folder / FIGURES_DIR) / INPUT_STEM
    return input_figure(stem, title, arr[:, 0], arr[:, 1:4], arr[:, 4:7], labels, notes, formats)


def draw_for_result(folder: Path, title: str, motion: Any, labels: Sequence[str], notes: Sequence[str]) -> Path:
    """``folder/figures/input.png`` of a cued segment (``motion``: :class:`washbench.io.motion.Motion`); a PDF of an
    earlier ``washbench report`` is removed (it would show other data)."""
    fig_dir = folder / FIGURES_DIR
    fig_dir.mkdir(parents=True, exist_ok=True)
    (fig_dir / f"{INPUT_STEM}.pdf").unlink(missing_ok=True)
    w = motion.omega_degps if motion.omega_degps is not None else np.degrees(motion.omega_radps)
    return input_figure(fig_dir / INPUT_STEM, title, motion.t_s, motion.f_mps2, w, labels, notes)
