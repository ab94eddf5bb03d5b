"""``recording.rrd`` of ``washbench track``: the first run of every condition, side by side, on one timeline.

On the timeline ``time`` (seconds since the run's start, k dt to the nanosecond), each entity one line per
condition, in the order flown (the aircraft's own motion first)::

    /track/target        the target's attitude (deg), one line
    /track/attitude      the attitude (bank or pitch from trim, deg)
    /track/error         the displayed error (deg)
    /track/control       the pilot model's control (task units)
    /track/visual        its visual part
    /track/vestibular    its vestibular part
    /track/felt_rate     what the canals report of the simulator pilot's rate about the task's axis (deg/s)
    /track/head_rate     the simulator pilot's rate about the task's axis (deg/s)
    /track/platform      the cockpit's tilt on the task's axis, each washout on its platform (deg)
    /report              report.md as a Markdown document

with a blueprint of one time-series panel per entity. Every sample of the run is logged (float64, as the
signals.parquet columns), sent as whole columns. Written through :class:`washbench.review.rerun_log.RrdFile`
(atomically, no viewer, no network).
"""

from __future__ import annotations

import math
import uuid
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from washbench.cueing.kernel import O_Q
from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path
from washbench.pilot.measure import ConditionResult
from washbench.review.rerun_log import PROPERTIES, TIMELINE, RrdFile
from washbench.review.track_figures import condition_styles

_DEG = 180.0 / math.pi
PANELS: tuple[tuple[str, str, str, float], ...] = (
    ("target", "target (deg)", "target_rad", _DEG),
    ("attitude", "attitude (deg)", "attitude_rad", _DEG),
    ("error", "displayed error (deg)", "error_rad", _DEG),
    ("control", "control (task units)", "control", 1.0),
    ("visual", "visual part of the control", "control_visual", 1.0),
    ("vestibular", "vestibular part of the control", "control_vestibular", 1.0),
    ("felt_rate", "perceived rate (deg/s)", "felt_rate_radps", _DEG),
    ("head_rate", "simulator pilot's rate (deg/s)", "head_rate_radps", _DEG),
)
"""(entity under /track, panel title, RunSignals attribute, factor to the unit shown)."""


def _tilt_deg(q: np.ndarray, axis: str) -> np.ndarray:
    """The roll (or pitch) angle of body->inertial quaternions (N, 4), scalar first, ZYX Euler angles, deg."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    if axis == "pitch":
        return np.degrees(np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0)))
    return np.degrees(np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)))


def _time(t_s: np.ndarray) -> rr.TimeColumn:
    ns = np.round(np.asarray(t_s, dtype=np.float64) * 1e9).astype(np.int64)
    return rr.TimeColumn(TIMELINE, duration=ns.astype("timedelta64[ns]"))


def write_track_recording(path: Path, results: Sequence[ConditionResult], title: str, report_md: str,
                          properties: Mapping[str, str] | None = None, palette: str = "default") -> None:  # fmt: skip
    """Write the recording of the module docstring to ``path`` atomically."""
    flown = [r for r in results if r.runs]
    if not flown:
        raise ValueError("no condition has a run to record")
    rec = rr.RecordingStream("washbench", recording_id=uuid.uuid4(), send_properties=False)
    if not rec.is_enabled():
        raise WashbenchError(located(path, "rerun logging is disabled by the environment (RERUN=off): unset RERUN "
                                     "to write the recording"))  # fmt: skip
    styles = condition_styles([r.name for r in flown], palette)
    n = min(len(r.runs[0].t_s) for r in flown)
    t = flown[0].runs[0].t_s[:n]
    views = []
    for entity, name, attr, factor in PANELS:
        sources = flown[:1] if entity == "target" else flown
        values = np.column_stack([getattr(r.runs[0], attr)[:n] * factor for r in sources])
        views.append((f"/track/{entity}", name, sources, values))
    moved = [r for r in flown if r.runs[0].platform is not None]
    if moved:  # the cockpit's tilt on the task's axis, each washout on its platform
        axis = flown[0].runs[0].axis
        values = np.column_stack([_tilt_deg(r.runs[0].platform[:n, O_Q : O_Q + 4], axis) for r in moved])
        views.append(("/track/platform", "cockpit tilt on the task's axis (deg)", moved, values))
    blueprint = rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(*[rrb.TimeSeriesView(origin=p, name=name) for p, name, _, _ in views[:4]]),
            rrb.Vertical(
                *[rrb.TimeSeriesView(origin=p, name=name) for p, name, _, _ in views[4:]],
                rrb.TextDocumentView(origin="/report", name="report"),
            ),
        ),
        collapse_panels=True,
    )
    with atomic_path(path) as tmp:
        rrd = RrdFile(rec, tmp, blueprint)
        try:
            rec.send_recording_name(title)
            if properties:
                rec.send_property(PROPERTIES, rr.AnyValues(**dict(properties)))
            for entity, _name, sources, values in views:
                names = ["target"] if entity.endswith("/target") else [r.name for r in sources]
                colours = [tuple(int(255 * c) for c in styles[r.name]["color"]) for r in sources]
                rec.log(entity, rr.SeriesLines(colors=colours, names=names, widths=[1.5] * len(names)), static=True,
                        strict=True)  # fmt: skip
                rec.send_columns(entity, indexes=[_time(t)], columns=rr.Scalars.columns(scalars=values), strict=True)
            rec.log("/report", rr.TextDocument(report_md, media_type=rr.MediaType.MARKDOWN), static=True)
            rrd.close()
        except BaseException:
            rrd.abandon()
            raise
