"""Everything rerun: the data handed to the recorder, entity paths, writing and reading .rrd files.

A recording holds, on one timeline named ``time`` (a duration, seconds since the start of the run, k * dt rounded to
the nanosecond):

- ``/perceived/<dof>``: perceived motion in one degree of freedom (surge, sway, heave in m/s^2; roll, pitch, yaw in
  deg/s), one row per recorded step with one scalar per source: each washout's simulator pilot in the order of
  ``RecordingData.washouts``, then the aircraft pilot (:func:`sources`: the viewer draws a panel's lines in that order,
  so the reference lies on top of a washout that follows it); ``/perceived/<dof>/threshold`` the
  perception threshold as two lines (+-threshold around 0, around -g for heave);
- ``/raw/<dof>``: the same layout for the unperceived specific force and angular velocity;
- ``/envelope/<quantity>``: platform envelope usage, one scalar per washout, drawn with Max aggregation, and the
  limit line ``/envelope/<quantity>/limit`` at 1 (:func:`usage_panels`): max over the three axes of |value| / limit
  for position, velocity, acceleration and wheels, the cockpit's |omega| / rate limit (``rate``, the Atlas), a rig's
  angles / its stops (``angle``); ``/envelope/tilt_rate``: the tilt-coordination rate each washout with one
  commanded (deg/s, after its tilt-rate limit, measured as the limit measures it: the norm, or the largest axis),
  one scalar per such washout, and ``/envelope/tilt_rate/limit`` a line at each tilt-rate limit (deg/s);
  ``/envelope/tilt_rate_held``: the seconds each washout has been held at its tilt-rate limit so far (no limit
  line);
- ``/platform/<washout>/<quantity>/axes``: the platform's stage position, velocity, acceleration (NED, SI) and
  omni-wheel speeds (rad/s), three scalars per row, with ``limit_max`` and ``limit_min`` lines where the platform has
  that limit;
- state lanes, each labelled by the viewer with its path: ``/phase`` (flight phases), ``/limits/<i>_<washout>`` (a
  state per stretch a washout is held at limits: the kinds joined by "+") and ``/false_cues/<i>_<washout>`` (a state
  per stretch of false cues: the DOFs joined by "+", shown in two-letter words); stretches less than
  :data:`washbench.analysis.cues.MERGE_GAP_S` apart joined (:mod:`washbench.review.lane_bars`); i = 1, 2, ... in
  washout order, as the viewer sorts lanes by name;
- ``/legend/perceived``, ``/legend/raw``, ``/legend/envelope``: the legends, static ``Points2D`` whose labels are the
  names in their lines' colours, in the grids of :func:`washbench.review.blueprint.legend_views`;
- ``/world/...``: the 3D scene (:mod:`washbench.review.scene3d`);
- ``/events/phases``, ``/events/saturation`` and ``/events/false_cues``: text log entries at phase starts, limit
  onsets and false-cue events, each text starting with its time, right-aligned (the events table hides the viewer's
  time column, which it cut to "+3...");
- ``/metrics``: the metric table as a Markdown document; the recording properties ``provenance`` (strings).

Precision: every time-varying scalar is rounded to float32 (:data:`VALUE_DTYPE`; rerun stores it as float64) after
the angular rates are converted to deg/s once (``np.rad2deg``), and only the steps that linear interpolation needs are
recorded (:func:`washbench.review.thinning.keep_samples`, at least one every :data:`MAX_GAP_S`): at each recorded step
the value is float32(trace value) exactly, and interpolating between recorded steps reproduces every step within
:data:`THRESHOLD_FRACTION` (1 %) of the DOF's perception threshold or :data:`PANEL_FRACTION` (0.2 %) of its panel's
height, whichever is smaller, for perceived and raw motion,
:data:`ENVELOPE_TOLERANCE` (0.002) for envelope usage and :data:`PLATFORM_DETAIL_TOLERANCE` (0.2 %) of each axis's
limit for the platform traces; the tolerance is stored with each entity (static component ``interpolation_tolerance``,
one per line). Where signals move fast every step is kept. Times are k * dt to the nanosecond; 3D poses float32
(rerun's type), at most at 30 Hz and held within 0.1 deg and 1 mm (:mod:`washbench.review.scene3d`). Exact values are
in traces.parquet. All time-varying data is sent as whole columns (``send_columns``), never one ``log`` call per
sample; the sources of one panel share one row (one time and one row id for all of them). The review blueprint
(:mod:`washbench.review.blueprint`) is stored in the same file.
"""

from __future__ import annotations

import contextlib
import os
import uuid
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import rerun as rr

from washbench.analysis.cues import FALSE, classify, dof_thresholds, false_events
from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path
from washbench.perception.thresholds import STANDARD_GRAVITY_MPS2, ZACHARIAS, Thresholds
from washbench.review import scene3d
from washbench.review.blueprint import (
    AIRCRAFT_COLOR,
    AIRCRAFT_WIDTH,
    AXIS_COLORS,
    LIMIT_COLOR,
    THRESHOLD_COLOR,
    THRESHOLD_NAME,
    WASHOUT_WIDTH,
    Layout,
    LegendView,
    UsageView,
    build_blueprint,
    legend_views,
    motion_plot_px,
    series_color,
    source_colors,
    usage_plot_px,
)
from washbench.review.figures import saturation_labels
from washbench.review.lane_bars import DOF_CODES, bars, code_text
from washbench.review.rrd_read import read_component, read_properties, read_scalar_series, read_text_documents
from washbench.review.thinning import keep_samples
from washbench.review.viewer_geometry import labelled_range, legend_positions

__all__ = [
    "AIRCRAFT",
    "DOFS",
    "ENVELOPE_QUANTITIES",
    "TIMELINE",
    "HexapodDrawing",
    "MotionSeries",
    "PlatformEnvelope",
    "PlatformSeries",
    "RecordingData",
    "envelope_usage_path",
    "motion_tolerance",
    "perceived_path",
    "phase_lane_path",
    "platform_path",
    "quat_wxyz_to_xyzw",
    "raw_path",
    "read_component",
    "read_properties",
    "read_scalar_series",
    "read_text_documents",
    "series_color",
    "sources",
    "washout_lane_path",
    "write_recording",
]

quat_wxyz_to_xyzw = scene3d.quat_wxyz_to_xyzw

TIMELINE = "time"
"""Name of the rerun timeline: a duration in seconds since the start of the run."""

AIRCRAFT = "aircraft"
"""Source name of the aircraft pilot in entity paths."""

DOFS: tuple[tuple[str, str, int, str], ...] = (
    ("surge", "f", 0, "m/s^2"),
    ("sway", "f", 1, "m/s^2"),
    ("heave", "f", 2, "m/s^2"),
    ("roll", "omega", 0, "deg/s"),
    ("pitch", "omega", 1, "deg/s"),
    ("yaw", "omega", 2, "deg/s"),
)
"""Degrees of freedom: (name, signal "f" or "omega", body axis index, unit shown in the recording)."""
DOF_NAMES: tuple[str, ...] = tuple(d[0] for d in DOFS)

ENVELOPE_QUANTITIES: tuple[tuple[str, str, str], ...] = (
    ("position", "pos_m", "m"),
    ("velocity", "vel_mps", "m/s"),
    ("acceleration", "acc_mps2", "m/s^2"),
    ("wheels", "wheel_radps", "rad/s"),
)
"""Platform quantities with an envelope: (name in entity paths, field of PlatformSeries / PlatformEnvelope, unit)."""

VALUE_DTYPE = np.float32
"""Every time-varying scalar is rounded to this type before it is recorded (rerun stores it as float64): 24 bits,
seven significant digits, more than a plot or a tooltip shows; exact values stay in traces.parquet."""

THRESHOLD_FRACTION = 0.01
"""Perceived and raw motion: interpolation tolerance at most this fraction of the DOF's perception threshold..."""

PANEL_FRACTION = 0.002
"""...and at most this fraction of the height (y range) of the panel that shows it: 0.2 pixels in a panel 100 pixels
tall, one pixel in a panel 500 pixels tall."""

ENVELOPE_TOLERANCE = 0.002
"""Envelope usage (dimensionless, limit at 1): interpolation tolerance."""

PLATFORM_DETAIL_TOLERANCE = 0.002
"""Per-axis platform traces: interpolation tolerance as a fraction of the axis's limit."""

MAX_GAP_S = 1.0
"""Recorded samples of one series are at most this far apart, s (a tooltip in the viewer is never far from one)."""

PROPERTIES = "provenance"
"""Name of the recording property that holds the caller's provenance strings."""


@dataclass(frozen=True)
class MotionSeries:
    """Pilot-head motion of one source: the aircraft pilot, or one washout's simulator pilot.

    All arrays have N rows (one per time step); vectors are in body axes (x forward, y right, z down).
    """

    f_mps2: np.ndarray  # (N,3) specific force at the pilot's head, m/s^2
    omega_radps: np.ndarray  # (N,3) angular velocity, rad/s
    perceived_f_mps2: np.ndarray  # (N,3) vestibular (otolith) output, m/s^2
    perceived_omega_radps: np.ndarray  # (N,3) vestibular (canal) output, rad/s
    q: np.ndarray  # (N,4) attitude body->inertial (NED), scalar-first [w, x, y, z]


@dataclass(frozen=True)
class PlatformSeries:
    """One washout's Atlas platform: translational stage (NED, SI) and omni-wheel speeds, N rows each."""

    pos_m: np.ndarray  # (N,3) stage position, NED, m
    vel_mps: np.ndarray  # (N,3) m/s
    acc_mps2: np.ndarray  # (N,3) m/s^2
    wheel_radps: np.ndarray  # (N,3) omni-wheel speeds, rad/s
    saturated: dict[str, np.ndarray] = field(default_factory=dict)  # limit kind -> bool (N,)
    # the tilt-coordination rate the washout commanded, after its tilt-rate limit, rad/s (N,); None (or all NaN): a
    # washout without tilt coordination, or one whose tilt rate the bench does not know (no line)
    tilt_rate_radps: np.ndarray | None = None
    tilt_rate_limit_radps: float | None = None  # its tilt-rate limit, rad/s; None: none (no limit line)


@dataclass(frozen=True)
class PlatformEnvelope:
    """Symmetric platform limits (+- value), for envelope-usage plots; None: the platform has no such limit (no panel
    and no limit line).

    Each translational limit is one value for all three axes (wheels) or a per-axis triple (x, y, z NED or w1, w2,
    w3), e.g. the Atlas stage's ``position_limit_m`` (1.5, 1.5, 1.0). ``rate_radps``: the limit on the cockpit's
    |angular velocity| (the Atlas sphere's rate limit), rad/s. ``angle_rad``: a rig's angle limits (roll, pitch,
    yaw about level; ``math.inf`` for an axis it lacks), rad.
    """

    pos_m: float | tuple[float, float, float] | None
    vel_mps: float | tuple[float, float, float] | None
    acc_mps2: float | tuple[float, float, float] | None
    wheel_radps: float | tuple[float, float, float] | None  # None: a platform without wheels (no wheels panel)
    sphere_diameter_m: float = 2.9  # drawn in the 3D view (a hexapod: its base's diameter, for the spacing)
    rate_radps: float | None = None
    angle_rad: tuple[float, float, float] | None = None

    def axes(self, fname: str) -> np.ndarray:
        """The limit ``fname`` (e.g. "pos_m") as a per-axis array (3,); zeros where the platform has none."""
        value = getattr(self, fname)
        if value is None:
            return np.zeros(3)
        return np.broadcast_to(np.asarray(value, dtype=np.float64), (3,)).copy()


@dataclass(frozen=True)
class RecordingData:
    """Everything one recording shows; ``washouts`` and ``platforms`` have the same keys, in the same order.

    Washout names are any identifiers except ``"aircraft"``; their order is the order of every panel and legend. A
    washout's MotionSeries is its simulator pilot's motion; its attitude ``q`` is the Atlas sphere's orientation.
    ``thresholds``: the perception thresholds drawn as +- lines (default Zacharias 1978).
    """

    title: str  # e.g. "c172p / coordinated_turn"
    t_s: np.ndarray  # (N,) = k * dt, seconds
    aircraft: MotionSeries
    washouts: dict[str, MotionSeries]
    platforms: dict[str, PlatformSeries]
    envelope: PlatformEnvelope
    phases: list[tuple[str, float, float]]  # (name, t_start_s, t_end_s)
    metrics_markdown: str
    thresholds: Thresholds = ZACHARIAS
    hexapod: HexapodDrawing | None = None  # a hexapod's joints: drawn with its legs instead of the Atlas
    platform: str = "atlas"  # the platform's kind: atlas, hexapod, rig or a plugin's (the 3D drawing, limit names)
    platform_name: str = "Atlas"  # the word the tab and view titles use ("Atlas", "Hexapod", "Rig", a plugin's kind)


@dataclass(frozen=True)
class HexapodDrawing:
    """What the 3D view needs to draw a hexapod (docs/platforms.md), m: base joints (6, 3) in the base frame (NED,
    origin at the base centre), platform joints (6, 3) in the cockpit's body axes (origin at the motion reference
    point), the motion reference point at neutral (3,) in the base frame."""

    base_joints_m: np.ndarray
    platform_joints_m: np.ndarray
    neutral_m: np.ndarray


def envelope_quantities(data: RecordingData) -> tuple[tuple[str, str, str], ...]:
    """The :data:`ENVELOPE_QUANTITIES` this recording's platform has a limit on (no wheels on a hexapod, no stage on a
    rig without heave or a plugin without an envelope)."""
    return tuple(q for q in ENVELOPE_QUANTITIES if getattr(data.envelope, q[1]) is not None)


def platform_quantities(data: RecordingData) -> tuple[tuple[str, str, str], ...]:
    """The quantities of each washout's platform tab: position, velocity and acceleration whatever the platform (a
    limit line where it has one), the wheels on the Atlas."""
    return tuple(q for q in ENVELOPE_QUANTITIES if q[1] != "wheel_radps" or data.envelope.wheel_radps is not None)


# ---------------------------------------------------------------------------------------------------------------------
# Names


def perceived_path(dof: str) -> str:
    """Entity path of the perceived motion in ``dof``: one scalar per source per row, in :func:`sources` order."""
    return f"/perceived/{dof}"


def raw_path(dof: str) -> str:
    """Entity path of the unperceived motion (specific force or angular velocity) in ``dof``, as perceived_path."""
    return f"/raw/{dof}"


def envelope_usage_path(quantity: str) -> str:
    """Entity path of the envelope usage (max |axis| / limit, dimensionless), one scalar per washout per row."""
    return f"/envelope/{quantity}"


def platform_path(washout: str, quantity: str) -> str:
    """Entity path of a platform quantity: three scalars per row (axes x, y, z, or wheels w1, w2, w3), SI units."""
    return f"/platform/{washout}/{quantity}/axes"


def _lane_name(data: RecordingData, washout: str) -> str:
    """``<i>_<washout>``, i = 1, 2, ... in data order, zero-padded: the viewer sorts lanes by name and labels each with
    its entity path, so a lane's path is a group word and this name (``/false_cues/1_small-angle``)."""
    names = list(data.washouts)
    width = len(str(len(names)))
    return f"{names.index(washout) + 1:0{width}d}_{washout}"


def phase_lane_path() -> str:
    """State lane of the flight phases (its own view above the others: the viewer labels it ``/phase``)."""
    return "/phase"


def washout_lane_path(data: RecordingData, washout: str) -> str:
    """State lane of the limits ``washout`` is held at (the kinds joined by "+"), ordered as the washouts."""
    return f"/limits/{_lane_name(data, washout)}"


def sources(data: RecordingData) -> list[str]:
    """The instance order of the perceived and raw entities: ``[*washouts, "aircraft"]``. The viewer draws the lines
    of a panel in instance order: the aircraft pilot's, the reference every washout is compared with, last, on top
    (drawn first, a washout that followed it hid it)."""
    return [*data.washouts, AIRCRAFT]


def _axis_names(quantity: str) -> tuple[str, str, str]:
    return ("w1", "w2", "w3") if quantity == "wheels" else ("x", "y", "z")


def _threshold_lines(th: Thresholds) -> list[tuple[float, float]]:
    """Per DOF: (centre, threshold) in the recording's units; heave's dead band is around -g (thresholds.py)."""
    f = th.f_mps2()
    w = np.degrees(th.omega_radps())
    centres = (0.0, 0.0, -STANDARD_GRAVITY_MPS2, 0.0, 0.0, 0.0)
    return [(c, float(v)) for c, v in zip(centres, [*f, *w], strict=True)]


# ---------------------------------------------------------------------------------------------------------------------
# Input checks (programming errors of the caller: ValueError)


def _check_array(name: str, a: object, shape: tuple[int, ...], dtype_kind: str = "f") -> np.ndarray:
    arr = np.asarray(a)
    if arr.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {arr.shape}")
    if dtype_kind == "f" and arr.dtype.kind not in "fiu":
        raise ValueError(f"{name}: expected numbers, got dtype {arr.dtype}")
    if dtype_kind == "b" and arr.dtype.kind != "b":
        raise ValueError(f"{name}: expected booleans, got dtype {arr.dtype}")
    return arr


def _check(data: RecordingData) -> int:
    t = np.asarray(data.t_s)
    if t.ndim != 1 or t.size < 1:
        raise ValueError(f"t_s: expected a non-empty 1-D array, got shape {t.shape}")
    n = t.size
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ValueError("t_s: expected finite, strictly increasing times")
    if set(data.washouts) != set(data.platforms):
        raise ValueError(
            f"washouts {sorted(data.washouts)} and platforms {sorted(data.platforms)} must have the same keys"
        )
    sources = {AIRCRAFT: data.aircraft, **data.washouts}
    if AIRCRAFT in data.washouts:
        raise ValueError(f"washout name {AIRCRAFT!r} is reserved for the aircraft pilot")
    for src, m in sources.items():
        for fname in ("f_mps2", "omega_radps", "perceived_f_mps2", "perceived_omega_radps"):
            _check_array(f"{src}.{fname}", getattr(m, fname), (n, 3))
        _check_array(f"{src}.q", m.q, (n, 4))
    for w, p in data.platforms.items():
        for _, fname, _ in platform_quantities(data):
            _check_array(f"platforms[{w}].{fname}", getattr(p, fname), (n, 3))
        for kind, flags in p.saturated.items():
            _check_array(f"platforms[{w}].saturated[{kind}]", flags, (n,), "b")
        if p.tilt_rate_radps is not None:
            _check_array(f"platforms[{w}].tilt_rate_radps", p.tilt_rate_radps, (n,))
        lim = p.tilt_rate_limit_radps
        if lim is not None and not (isinstance(lim, int | float) and np.isfinite(lim) and lim > 0):
            raise ValueError(f"platforms[{w}].tilt_rate_limit_radps: expected a positive number or None, got {lim!r}")
    extra = [f for f in ("rate_radps", "angle_rad") if getattr(data.envelope, f) is not None]
    for fname in [f for _, f, _ in envelope_quantities(data)] + ["sphere_diameter_m", *extra]:
        limit = np.asarray(getattr(data.envelope, fname))
        if (
            limit.shape not in ((), (3,))
            or limit.dtype.kind not in "fiu"
            or not np.all((np.isfinite(limit) | (fname == "angle_rad")) & (limit > 0))
        ):
            raise ValueError(f"envelope.{fname}: expected a positive number or three, got {limit.tolist()!r}")
    for name, t0, t1 in data.phases:
        if not (isinstance(name, str) and t0 <= t1):
            raise ValueError(f"phase {name!r}: expected a name and t_start_s <= t_end_s, got {t0}, {t1}")
    if not isinstance(data.metrics_markdown, str):
        raise ValueError("metrics_markdown: expected a str")
    return n


# ---------------------------------------------------------------------------------------------------------------------
# Writing


def _time_column(t_s: np.ndarray) -> rr.TimeColumn:
    """Times in seconds -> rerun duration column, rounded to the nearest nanosecond."""
    ns = np.round(np.asarray(t_s, dtype=np.float64) * 1e9).astype(np.int64)
    return rr.TimeColumn(TIMELINE, duration=ns.astype("timedelta64[ns]"))


def _series(
    rec: rr.RecordingStream,
    path: str,
    t_s: np.ndarray,
    values: np.ndarray,
    names: list[str],
    colors: list[tuple[int, int, int]],
    widths: list[float],
    tolerance: np.ndarray | float,
    aggregation: str | None = None,
) -> None:
    """One entity, one row per recorded time, one scalar per named line: ``values`` (N,) or (N, len(names)).

    Values are rounded to float32 (:data:`VALUE_DTYPE`), then thinned (:func:`thinning.keep_samples`): the rows kept
    interpolate linearly to every step within ``tolerance`` (a number or one per line), at most :data:`MAX_GAP_S`
    apart. The tolerance is stored with the entity (static component ``interpolation_tolerance``, one per line).
    """
    v = np.asarray(values, dtype=VALUE_DTYPE).astype(np.float64)
    lines = 1 if v.ndim == 1 else v.shape[1]
    tol = np.broadcast_to(np.asarray(tolerance, dtype=np.float64), (lines,))
    idx = keep_samples(t_s, v, tol, MAX_GAP_S + 1e-9)
    style = rr.SeriesLines(colors=colors, names=names, widths=widths, aggregation_policy=aggregation)
    rec.log(path, style, rr.AnyValues(interpolation_tolerance=tol), static=True, strict=True)
    rec.send_columns(path, indexes=[_time_column(t_s[idx])], columns=rr.Scalars.columns(scalars=v[idx]), strict=True)


def _limit_line(
    rec: rr.RecordingStream,
    path: str,
    t_s: np.ndarray,
    values: list[float],
    names: list[str],
    colors: list[tuple[int, int, int]] | None = None,
) -> None:
    """Horizontal lines (one per value) from the first to the last time (two samples each)."""
    ends = np.array([t_s[0], t_s[-1]], dtype=np.float64)
    colors = colors if colors is not None else [LIMIT_COLOR] * len(values)
    rec.log(path, rr.SeriesLines(colors=colors, names=names, widths=[1.0] * len(values)), static=True, strict=True)
    scalars = np.array([values, values], dtype=np.float64)  # (2, len(values)): one row of len(values) per end
    rec.send_columns(path, indexes=[_time_column(ends)], columns=rr.Scalars.columns(scalars=scalars), strict=True)


def _span(values: list[np.ndarray], extra: tuple[float, ...] = ()) -> tuple[float, float]:
    """y range holding every finite value and ``extra``, 6 % margin each side (at least +-0.05 around a flat line)."""
    finite = [v[np.isfinite(v)] for v in values]
    lo = min([float(v.min()) for v in finite if v.size] + list(extra) + [np.inf])
    hi = max([float(v.max()) for v in finite if v.size] + list(extra) + [-np.inf])
    if not np.isfinite(lo) or not np.isfinite(hi):
        return (-1.0, 1.0)
    pad = max(0.06 * (hi - lo), 0.05)
    return (lo - pad, hi + pad)


def _dof_columns(data: RecordingData) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per DOF, (N, sources) arrays of perceived and raw motion in the recording's units."""
    every = [*data.washouts.values(), data.aircraft]  # in sources() order
    perceived, raw = [], []
    for _dof, sig, axis, _unit in DOFS:
        if sig == "f":
            perceived.append(np.column_stack([m.perceived_f_mps2[:, axis] for m in every]))
            raw.append(np.column_stack([m.f_mps2[:, axis] for m in every]))
        else:
            perceived.append(np.rad2deg(np.column_stack([m.perceived_omega_radps[:, axis] for m in every])))
            raw.append(np.rad2deg(np.column_stack([m.omega_radps[:, axis] for m in every])))
    return perceived, raw


def motion_tolerance(thresholds: Thresholds, ranges: Sequence[tuple[float, float]]) -> list[float]:
    """Per DOF (in :data:`DOFS` order, recording units): the interpolation tolerance of a motion panel with the y
    ``ranges`` (lo, hi) per DOF: :data:`THRESHOLD_FRACTION` of the DOF's perception threshold or
    :data:`PANEL_FRACTION` of the panel's height, whichever is smaller."""
    lines = _threshold_lines(thresholds)
    pairs = zip(lines, ranges, strict=True)
    return [min(THRESHOLD_FRACTION * th, PANEL_FRACTION * (hi - lo)) for (_, th), (lo, hi) in pairs]


def _send_motion(
    rec: rr.RecordingStream,
    data: RecordingData,
    perceived: list[np.ndarray],
    raw: list[np.ndarray],
    layout: Layout,
) -> None:
    names = sources(data)
    colors = [*source_colors(list(data.washouts))[1:], AIRCRAFT_COLOR]
    widths = [WASHOUT_WIDTH] * len(data.washouts) + [AIRCRAFT_WIDTH]
    t_s = np.asarray(data.t_s, dtype=np.float64)
    lines = _threshold_lines(data.thresholds)
    tol_p = motion_tolerance(data.thresholds, layout.perceived_ranges)
    tol_r = motion_tolerance(data.thresholds, layout.raw_ranges)
    for (dof, _, _, _), p, r, (centre, th), tp, tr in zip(DOFS, perceived, raw, lines, tol_p, tol_r, strict=True):
        _series(rec, perceived_path(dof), t_s, p, names, colors, widths, tp)
        _series(rec, raw_path(dof), t_s, r, names, colors, widths, tr)
        _limit_line(
            rec,
            f"/perceived/{dof}/threshold",
            t_s,
            [centre + th, centre - th],
            [THRESHOLD_NAME, THRESHOLD_NAME],
            [THRESHOLD_COLOR, THRESHOLD_COLOR],
        )


@dataclass(frozen=True)
class UsagePanel:
    """One panel of the envelope tab: ``values`` (N, washouts) at ``/envelope/<key>``; ``limit``: the line at 1 (a
    usage against a limit) or None (a time held, s). A panel of a quantity in its own unit (the tilt rate) names
    the washouts it has lines for (``names``; None: every washout), its limit ``lines`` (values of ``values``) and
    the ``tolerance`` its lines are thinned with (None: the usage's or the time held's)."""

    key: str
    title: str
    values: np.ndarray
    limit: str | None
    names: tuple[str, ...] | None = None
    lines: tuple[float, ...] = (1.0,)
    tolerance: float | None = None

    def span(self) -> tuple[float, float]:
        """The y range before its gridlines are fitted: 0 to 15 % above the highest limit line (and above every
        value) for a quantity against a limit, the values' own range for a time held."""
        if self.limit is None:
            return _span([self.values], (0.0,))
        finite = self.values[np.isfinite(self.values)]
        top = max([*self.lines, float(finite.max()) if finite.size else 0.0])
        return (0.0, 1.15 * top)


def _max_ratio(values: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """max over the three axes of |value| / limit, column by column (np.max(axis=1) is several times slower)."""
    ratio = np.abs(np.asarray(values, dtype=np.float64)) / limit
    return np.maximum(np.maximum(ratio[:, 0], ratio[:, 1]), ratio[:, 2])


def _zyx_angles(q: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (ZYX Euler angles, rad) of body -> NED quaternions (N, 4), scalar first: a rig's gimbals."""
    w, x, y, z = (np.asarray(q, dtype=np.float64)[:, i] for i in range(4))
    roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return np.column_stack([roll, pitch, yaw])


def usage_panels(data: RecordingData) -> list[UsagePanel]:
    """The envelope tab's panels (short titles: with nine washouts a panel is a third of the tab wide), each one line
    per washout: the stage's position, velocity and acceleration and the wheel speeds against their limits (max over
    the axes of |value| / limit); the cockpit's rate against its limit
    (the Atlas sphere: |omega| / rate limit); a rig's angles against its stops; the tilt-coordination rate each
    washout that has one commanded against its tilt-rate limit (deg/s: a rate inside the washout, not a platform
    quantity; :func:`tilt_rate_panel`); and the time each washout has been held at its tilt-rate limit so far (the
    limit washouts reach most, from the ``tilt_rate`` flags)."""
    env, washouts = data.envelope, list(data.washouts)
    t_s = np.asarray(data.t_s, dtype=np.float64)
    panels = []
    for q, fname, unit in envelope_quantities(data):
        limit = env.axes(fname)
        values = np.column_stack([_max_ratio(getattr(data.platforms[w], fname), limit) for w in washouts])
        panels.append(UsagePanel(q, f"{q} / limit", values, f"+-{_limit_text(limit)} {unit}"))
    if env.rate_radps is not None:
        rate = float(env.rate_radps)
        values = np.column_stack([np.linalg.norm(np.asarray(data.washouts[w].omega_radps, dtype=np.float64), axis=1)
                                  / rate for w in washouts])  # fmt: skip
        panels.append(UsagePanel("rate", "cockpit rate / limit", values, f"{np.degrees(rate):.3g} deg/s"))
    if env.angle_rad is not None:
        limit = np.asarray(env.angle_rad, dtype=np.float64)
        values = np.column_stack([_max_ratio(_zyx_angles(data.washouts[w].q), limit) for w in washouts])
        shown = "/".join("-" if not np.isfinite(v) else f"{np.degrees(v):.3g}" for v in limit)
        panels.append(UsagePanel("angle", "rig angles / stops", values, f"{shown} deg"))
    tilt = tilt_rate_panel(data)
    if tilt is not None:
        panels.append(tilt)
    if any("tilt_rate" in data.platforms[w].saturated for w in washouts):
        dt = float(t_s[1] - t_s[0]) if t_s.size > 1 else 0.0
        held = [np.cumsum(np.asarray(data.platforms[w].saturated.get("tilt_rate", np.zeros(t_s.size, bool)),
                                     dtype=np.float64)) * dt for w in washouts]  # fmt: skip
        panels.append(UsagePanel("tilt_rate_held", "time at tilt-rate limit [s]",
                                 np.column_stack(held), None))  # fmt: skip
    return panels


def tilt_rate_panel(data: RecordingData) -> UsagePanel | None:
    """The tilt-coordination rate each washout commanded (deg/s; a washout whose tilt rate is unknown or NaN
    throughout has no line), against its tilt-rate limit: one line at each limit the washouts drawn have (one for
    all when they share it). None when no washout has a tilt rate."""
    names, columns, limits = [], [], []
    for w in data.washouts:
        p = data.platforms[w]
        rate = None if p.tilt_rate_radps is None else np.asarray(p.tilt_rate_radps, dtype=np.float64)
        if rate is None or not np.isfinite(rate).any():
            continue
        names.append(w)
        columns.append(np.degrees(rate))
        if p.tilt_rate_limit_radps is not None:
            limits.append(float(np.degrees(p.tilt_rate_limit_radps)))
    if not names:
        return None
    lines = tuple(sorted(set(limits)))
    text = "limit " + "/".join(f"{v:.3g}" for v in lines) + " deg/s" if lines else None
    top = max(lines) if lines else max(float(np.nanmax(c)) for c in columns)
    return UsagePanel("tilt_rate", "tilt rate [deg/s]", np.column_stack(columns), text, tuple(names), lines,
                      ENVELOPE_TOLERANCE * max(top, 1e-3))  # fmt: skip


def _send_platforms(rec: rr.RecordingStream, data: RecordingData, panels: list[UsagePanel]) -> None:
    t_s = np.asarray(data.t_s, dtype=np.float64)
    washouts = list(data.washouts)
    colors = [series_color(w, washouts) for w in washouts]
    widths = [WASHOUT_WIDTH] * len(washouts)
    for panel in panels:
        path = envelope_usage_path(panel.key)
        if panel.names is not None:  # a quantity in its own unit, lines for some washouts, a line at each limit
            if panel.lines:
                _limit_line(rec, f"{path}/limit", t_s, list(panel.lines), [f"limit ({v:.3g})" for v in panel.lines])
            shown = list(panel.names)
            _series(rec, path, t_s, panel.values, shown, [series_color(w, washouts) for w in shown],
                    [WASHOUT_WIDTH] * len(shown), panel.tolerance, "Max")  # fmt: skip
        elif panel.limit is not None:
            _limit_line(rec, f"{path}/limit", t_s, [1.0], [f"limit ({panel.limit})"])
            _series(rec, path, t_s, panel.values, washouts, colors, widths, ENVELOPE_TOLERANCE, "Max")
        else:  # a time held: tolerance a tenth of a step
            dt = float(t_s[1] - t_s[0]) if t_s.size > 1 else 1.0
            _series(rec, path, t_s, panel.values, washouts, colors, widths, 0.1 * dt, "Max")
    for q, fname, _unit in platform_quantities(data):
        has_limit = getattr(data.envelope, fname) is not None
        limit = data.envelope.axes(fname)
        axes = _axis_names(q)
        uniform = bool(np.all(limit == limit[0]))
        for w in washouts:
            values = getattr(data.platforms[w], fname)  # (N, 3): N rows of three scalars
            scale = limit if has_limit else np.maximum(np.max(np.abs(np.asarray(values, dtype=np.float64)), axis=0),
                                                       1e-3)  # fmt: skip
            tol = PLATFORM_DETAIL_TOLERANCE * scale
            _series(rec, platform_path(w, q), t_s, values, list(axes), list(AXIS_COLORS), [1.5] * 3, tol)
            if not has_limit:
                continue
            for sign, end, bound in (("+", "max", limit), ("-", "min", -limit)):
                line_path = f"/platform/{w}/{q}/limit_{end}"
                if uniform:  # one line for all axes
                    _limit_line(rec, line_path, t_s, [bound[0]], [f"{sign}limit"])
                else:  # one line per axis, in the axis colours
                    _limit_line(rec, line_path, t_s, list(bound), [f"{sign}{a} limit" for a in axes], list(AXIS_COLORS))


def _limit_text(limit: np.ndarray) -> str:
    """ "2" for one limit on all axes, "1.5/1.5/1" for per-axis limits."""
    return f"{limit[0]:.3g}" if bool(np.all(limit == limit[0])) else "/".join(f"{v:.3g}" for v in limit)


def _runs(flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start and end indices (inclusive) of the runs of True in ``flags``."""
    starts = np.flatnonzero(flags & ~np.concatenate([[False], flags[:-1]]))
    ends = np.flatnonzero(flags & ~np.concatenate([flags[1:], [False]]))
    return starts, ends


def _send_states(rec: rr.RecordingStream, path: str, t_s: np.ndarray, states: list[str], changes: np.ndarray) -> None:
    """A state lane: ``states[i]`` from ``t_s[changes[i]]`` on; "" is a gap."""
    rec.send_columns(
        path,
        indexes=[_time_column(t_s[changes])],
        columns=rr.StateChange.columns(state=states),
        strict=True,
    )


LIMIT_LANE_COLOR = (150, 150, 150)
"""Every limit bar (position, tilt_rate ...): one neutral grey, the kind written on it; rerun's own colours by label
looked like washout colours."""
FALSE_CUE_COLOR = (214, 39, 40)
"""Every false-cue bar: the red of the report's cue figure (:mod:`washbench.review.cue_figures`)."""
PHASE_COLORS = ((105, 125, 155), (140, 158, 185))
"""The phase lane's bars, alternating: blue-greys (as the figures' phase lane), apart from every washout colour."""


def _rgba(rgb: tuple[int, int, int]) -> int:
    return (rgb[0] << 24) | (rgb[1] << 16) | (rgb[2] << 8) | 0xFF


def _lane_style(
    rec: rr.RecordingStream,
    path: str,
    values: Sequence[str],
    colors: Sequence[tuple[int, int, int]],
    labels: Sequence[str] | None = None,
) -> None:
    """The colour (and the text shown, ``labels``) of each state value of a lane (static ``StateConfiguration``);
    "" (a gap) is left out."""
    shown = list(labels) if labels is not None else list(values)
    triples = [(v, c, t) for v, c, t in zip(values, colors, shown, strict=True) if v]
    if triples:
        colors = np.array([_rgba(c) for _, c, _ in triples], dtype=np.uint32)  # 0xRRGGBBAA (a list of 3: ambiguous)
        rec.log(path, rr.StateConfiguration(values=[v for v, _, _ in triples], colors=colors,
                                            labels=[t for _, _, t in triples]), static=True, strict=True)  # fmt: skip


def _send_bars(rec: rr.RecordingStream, path: str, t_s: np.ndarray, found: list[tuple[int, int, int]],
               values: Sequence[str], texts: Sequence[str], color: tuple[int, int, int]) -> None:  # fmt: skip
    """A lane of ``found`` bars (:func:`washbench.review.lane_bars.bars`): the bar's state ``values[i]`` from its first
    sample to its last (a gap after it), its bar drawn in ``color`` with ``texts[i]`` on it; an empty lane (one gap)
    without bars."""
    if not found:
        _send_states(rec, path, t_s, [""], np.array([0]))
        return
    states: list[str] = []
    changes: list[int] = []
    for (start, end, _), value in zip(found, values, strict=True):
        states.append(value)
        changes.append(start)
        if end + 1 < t_s.size:
            states.append("")
            changes.append(end + 1)
    _send_states(rec, path, t_s, states, np.array(changes))
    shown = dict(zip(values, texts, strict=True))
    _lane_style(rec, path, list(shown), [color] * len(shown), list(shown.values()))


def _send_lanes(rec: rr.RecordingStream, data: RecordingData) -> None:
    """Phase lane; one lane per washout, a bar while it is held at a limit (gaps under MERGE_GAP_S joined, its state
    the kinds held at inside it joined by "+", as the console's and the report's kind names: one lane per washout and
    kind ran off a 720 px window, a bar per change of kinds was cut to a few pixels); limit onset events."""
    t_s = np.asarray(data.t_s, dtype=np.float64)
    n = t_s.size
    dt = float(t_s[1] - t_s[0]) if n > 1 else 0.0
    if data.phases:
        starts = [t0 for _, t0, _ in data.phases]
        names = [name for name, _, _ in data.phases]
        idx = np.searchsorted(t_s, np.array(starts) - 0.5e-9)
        if data.phases[-1][2] < t_s[-1]:
            idx = np.append(idx, np.searchsorted(t_s, data.phases[-1][2] - 0.5e-9))
            names.append("")
        _send_states(rec, phase_lane_path(), t_s, names, np.minimum(idx, n - 1))
        unique = list(dict.fromkeys(name for name in names if name))
        _lane_style(rec, phase_lane_path(), unique, [PHASE_COLORS[i % 2] for i in range(len(unique))])
    onsets: list[tuple[float, str]] = []
    for w in data.washouts:
        kinds = [(k, np.asarray(v, dtype=bool)) for k, v in data.platforms[w].saturated.items() if np.any(v)]
        code = np.zeros(n, dtype=np.int64)
        for j, (kind, flags) in enumerate(kinds):
            code |= flags.astype(np.int64) << j
            starts, ends = _runs(flags)
            onsets.extend(
                (float(t_s[s]), f"{_time_text(t_s[s])}  {w}: {kind} limit reached for {t_s[e] - t_s[s] + dt:.3f} s")
                for s, e in zip(starts, ends, strict=True)
            )
        found = bars(code, dt)
        values = [code_text(m, [k for k, _ in kinds], "+") for _, _, m in found]
        _send_bars(rec, washout_lane_path(data, w), t_s, found, values, values, LIMIT_LANE_COLOR)
    if onsets:
        onsets.sort(key=lambda item: item[0])
        rec.send_columns(
            "/events/saturation",
            indexes=[_time_column(np.array([t for t, _ in onsets]))],
            columns=rr.TextLog.columns(text=[s for _, s in onsets], level=["WARN"] * len(onsets)),
            strict=True,
        )


def _time_text(t_s: float) -> str:
    """The time an event line starts with, right-aligned for the events table's monospace text ("  5.83 s")."""
    return f"{t_s:7.2f} s"


def cue_lane_path(data: RecordingData, washout: str) -> str:
    """State lane of the DOFs in which ``washout``'s simulator pilot feels a false cue (joined by "+")."""
    return f"/false_cues/{_lane_name(data, washout)}"


def _send_cues(rec: rr.RecordingStream, data: RecordingData) -> None:
    """Per washout a lane with a bar where its simulator pilot feels false cues (:mod:`washbench.analysis.cues`;
    gaps under MERGE_GAP_S joined, as the events), its state the DOFs felt falsely inside it ("sway+heave"), its
    text their short words ("Sw He", :data:`washbench.review.lane_bars.DOF_CODES`: whole words were cut to "sw",
    "sur" on the narrow bars); and one ``/events/false_cues`` line per false-cue event (start, end, DOF, peak)."""

    t_s = np.asarray(data.t_s, dtype=np.float64)
    dt = float(t_s[1] - t_s[0]) if t_s.size > 1 else 1.0
    thresholds, rest = dof_thresholds()

    def dof_cols(m: MotionSeries) -> np.ndarray:
        return np.column_stack([m.perceived_f_mps2, np.rad2deg(m.perceived_omega_radps)])

    ac = dof_cols(data.aircraft)
    lines: list[tuple[float, str]] = []
    codes = [DOF_CODES[d] for d in DOF_NAMES]
    for w, series in data.washouts.items():
        sim = dof_cols(series)
        code = np.zeros(t_s.size, dtype=np.int64)
        for j, dof in enumerate(DOF_NAMES):
            cls = classify(ac[:, j], sim[:, j], thresholds[j], rest[j])
            code |= (cls == FALSE).astype(np.int64) << j
            for e in false_events(cls, sim[:, j] - rest[j], dt, dof, float(t_s[0])):
                unit = "m/s^2" if j < 3 else "deg/s"
                lines.append((e.start_s, f"{_time_text(e.start_s)}  {w}: false {dof} cue until {e.end_s:.2f} s, "
                                         f"peak {e.peak:.3g} {unit}"))  # fmt: skip
        found = bars(code, dt)
        values = [code_text(m, list(DOF_NAMES), "+") for _, _, m in found]
        texts = [code_text(m, codes, " ") for _, _, m in found]
        _send_bars(rec, cue_lane_path(data, w), t_s, found, values, texts, FALSE_CUE_COLOR)
    if lines:
        lines.sort(key=lambda item: item[0])
        rec.send_columns(
            "/events/false_cues",
            indexes=[_time_column(np.array([t for t, _ in lines]))],
            columns=rr.TextLog.columns(text=[s for _, s in lines], level=["WARN"] * len(lines)),
            strict=True,
        )


def _send_text(rec: rr.RecordingStream, data: RecordingData) -> None:
    rec.log(
        "/metrics", rr.TextDocument(data.metrics_markdown, media_type=rr.MediaType.MARKDOWN), static=True, strict=True
    )
    if data.phases:
        rec.send_columns(
            "/events/phases",
            indexes=[_time_column(np.array([t0 for _, t0, _ in data.phases], dtype=np.float64))],
            columns=rr.TextLog.columns(
                text=[f"{_time_text(t0)}  phase {name} ({t0:.2f}-{t1:.2f} s)" for name, t0, t1 in data.phases],
                level=["INFO"] * len(data.phases),
            ),
            strict=True,
        )


def _send_legend(rec: rr.RecordingStream, data: RecordingData, views: Sequence[LegendView]) -> None:
    """The legends: each name in its line's colour (the viewer draws a point's label under it, in the point's
    colour), in each legend view's grid; the points themselves too small to see."""
    colour = {AIRCRAFT: AIRCRAFT_COLOR, THRESHOLD_NAME: THRESHOLD_COLOR}
    colour |= {w: series_color(w, list(data.washouts)) for w in data.washouts}
    for view in views:
        rec.log(
            view.origin,
            rr.Points2D(legend_positions(len(view.names), view.columns, view.cell), labels=list(view.names),
                        colors=[colour[n] for n in view.names], radii=rr.Radius.ui_points(0.1), show_labels=True),
            static=True,
            strict=True,
        )  # fmt: skip


def _layout(data: RecordingData, perceived: list[np.ndarray], raw: list[np.ndarray], panels: list[UsagePanel]
            ) -> Layout:  # fmt: skip
    """The blueprint's data: the panels' y ranges each labelled with two gridlines at least at the plot height the
    layout gives them in the design window (:func:`washbench.review.viewer_geometry.labelled_range`)."""
    offsets = scene3d.object_offsets(len(data.washouts), data.envelope.axes("pos_m"), data.envelope.sphere_diameter_m)
    usage_spans = [(0.0, 1.15) if p.limit is not None and p.names is None else p.span() for p in panels]
    kinds = [k for k in saturation_labels(data.platform)
             if any(np.any(data.platforms[w].saturated.get(k, False)) for w in data.washouts)]  # fmt: skip
    labels = saturation_labels(data.platform)
    draft = Layout(
        washouts=tuple(data.washouts),
        dofs=tuple((dof, unit) for dof, _, _, unit in DOFS),
        t_end_s=float(data.t_s[-1]),
        perceived_ranges=(),
        raw_ranges=(),
        camera=scene3d.camera(offsets, data.envelope.axes("pos_m"), data.envelope.sphere_diameter_m),
        usage=tuple(
            UsageView(envelope_usage_path(p.key), p.title if p.limit is None else f"{p.title} ({p.limit})", span)
            for p, span in zip(panels, usage_spans, strict=True)
        ),
        platform_quantities=tuple((q, unit) for q, _, unit in platform_quantities(data)),
        platform_name=data.platform_name,
        phase_lane=phase_lane_path() if data.phases else None,
        limit_lanes=tuple(washout_lane_path(data, w) for w in data.washouts),
        cue_lanes=tuple(cue_lane_path(data, w) for w in data.washouts),
        legends=legend_views(list(data.washouts)),
        limit_key=", ".join(f"{k} {labels[k]}" for k in kinds) or "none reached",
        cue_key=", ".join(f"{code} {dof}" for dof, code in DOF_CODES.items()),
    )
    plot_px, usage_px = motion_plot_px(draft), usage_plot_px(draft)
    lines = _threshold_lines(data.thresholds)
    spans = [_span([p], (c - th, c + th)) for p, (c, th) in zip(perceived, lines, strict=True)]
    return replace(
        draft,
        perceived_ranges=tuple(labelled_range(sp, plot_px) for sp in spans),
        raw_ranges=tuple(labelled_range(_span([r]), plot_px) for r in raw),
        usage=tuple(replace(u, y_range=labelled_range(u.y_range, usage_px)) for u in draft.usage),
    )


#: Longest wait (s) for the rerun SDK to encode what was logged (in memory: no disk involved).
ENCODE_DEADLINE_S = 300.0


class RrdFile:
    """A recording stream whose bytes washbench writes to the file itself (one way for every .rrd it writes).

    The stream's only sink is an in-memory binary stream (:func:`rerun.binary_stream`), written into ``tmp``
    by Python when the recording is complete (:meth:`close`; the stream is read once: a stream read in parts
    fails the file's checksum): a full disk or any file error is an ``OSError`` at once (one line through
    :func:`washbench.io.atomic.atomic_path`), never a hang of the SDK's file sink (which blocks for ever when
    its writes fail). The encoded recording is held in memory until then (about the size of the .rrd file).
    ``blueprint`` is sent as the recording's default blueprint (what ``save(default_blueprint=...)`` stores).
    """

    def __init__(self, rec: rr.RecordingStream, tmp: Path, blueprint: object | None = None) -> None:
        self.rec = rec
        self.stream = rr.binary_stream(recording=rec)
        self.fh = open(tmp, "wb")  # noqa: SIM115 - closed in close()
        if blueprint is not None:
            rec.send_blueprint(blueprint, make_active=False, make_default=True)  # type: ignore[arg-type]

    def _drain(self, flush: bool = True) -> None:
        """Write what was logged to the file (``flush``: everything logged, encoded first)."""
        try:
            data = self.stream.read(flush=flush, flush_timeout_sec=ENCODE_DEADLINE_S)
        except Exception as exc:  # the rerun SDK: encoding did not finish within the deadline
            problem = f"the rerun SDK did not encode the recording within {ENCODE_DEADLINE_S:g} s ({exc})"
            raise OSError(problem) from None
        if data:
            self.fh.write(data)

    def close(self) -> None:
        """Drain everything, end the stream and close the file (errors as OSError)."""
        try:
            self._drain()
            self.rec.disconnect()
            self._drain(flush=False)
            self.fh.flush()
            os.fsync(self.fh.fileno())
        finally:
            self.fh.close()

    def abandon(self) -> None:
        """Stop without writing more (after an error)."""
        with contextlib.suppress(Exception):
            self.rec.disconnect()
        self.fh.close()


def write_recording(path: Path, data: RecordingData, properties: Mapping[str, str] | None = None) -> None:
    """Write ``data`` to the .rrd file ``path`` atomically (temp file in the same folder, then rename).

    ``properties``: provenance strings (e.g. software versions, file hashes), stored as the recording property
    ``provenance`` (shown in the viewer's recording properties; :func:`read_properties` reads them back).

    No viewer and no network: the recording stream's only sink is the file. The review blueprint is stored in the same
    file. Raises ValueError on inconsistent shapes, WashbenchError if the environment disables rerun (``RERUN=off``:
    the file would be empty); on any exception no .rrd (and no temp file) is left behind and an
    existing ``path`` is untouched. Byte-for-byte the file differs between runs (rerun stamps row ids and a recording
    id), the logged data does not.
    """
    path = Path(path)
    _check(data)
    props = dict(properties or {})
    bad = [k for k, v in props.items() if not (isinstance(k, str) and k and isinstance(v, str))]
    if bad:
        raise ValueError(f"properties: expected non-empty str keys and str values, got {bad[:3]!r}")
    rec = rr.RecordingStream("washbench", recording_id=uuid.uuid4(), send_properties=False)
    if not rec.is_enabled():
        raise WashbenchError(
            located(
                path, "rerun logging is disabled by the environment (RERUN=off): unset RERUN to write the recording"
            )
        )
    perceived, raw = _dof_columns(data)
    panels = usage_panels(data)
    layout = _layout(data, perceived, raw, panels)
    blueprint = build_blueprint(layout)
    with atomic_path(path) as tmp:
        rrd = RrdFile(rec, tmp, blueprint)
        try:
            rec.send_recording_name(data.title)
            if props:
                rec.send_property(PROPERTIES, rr.AnyValues(**props))
            _send_motion(rec, data, perceived, raw, layout)
            _send_platforms(rec, data, panels)
            _send_lanes(rec, data)
            _send_cues(rec, data)
            scene3d.send_scene(
                rec,
                _time_column,
                np.asarray(data.t_s, dtype=np.float64),
                data.aircraft.q,
                {w: m.q for w, m in data.washouts.items()},
                {w: p.pos_m for w, p in data.platforms.items()},
                data.envelope.axes("pos_m"),
                float(data.envelope.sphere_diameter_m),
                data.hexapod,
                data.platform,
            )
            _send_text(rec, data)
            _send_legend(rec, data, layout.legends)
            rrd.close()
        except BaseException:
            rrd.abandon()
            raise
