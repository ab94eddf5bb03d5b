"""Everything rerun: the data handed to the recorder, entity paths, the blueprint, writing and reading .rrd files.

A recording holds, on one timeline named ``time`` (a duration, seconds since the start of the run):

- ``/perceived/<dof>/<source>``: perceived motion per degree of freedom (surge, sway, heave in m/s^2, roll, pitch,
  yaw in deg/s), for the aircraft pilot (``source = "aircraft"``) and each washout's simulator pilot;
- ``/raw/<dof>/<source>``: the same for the unperceived specific force and angular velocity;
- ``/envelope/<quantity>/<washout>``: platform envelope usage, max over the three axes of |value| / limit
  (``quantity`` in position, velocity, acceleration, wheels), the limit line ``/envelope/<quantity>/limit`` at 1, and
  saturation markers ``/envelope/<panel>/saturation/<washout>/<kind>`` at value 1 at every saturated sample;
- ``/platform/<washout>/<quantity>/axes``: the platform's stage position, velocity, acceleration (NED, SI) and
  omni-wheel speeds (rad/s), three scalars per row, with ``limit_max`` and ``limit_min`` lines;
- ``/world/...``: a 3D scene (NED, x north, y east, z down) with the aircraft's attitude and, per washout, the Atlas
  sphere (``envelope.sphere_diameter_m``, 2.9 m) translated by the stage position and rotated by the simulator
  cockpit's attitude;
- ``/events/phases`` and ``/events/saturation``: text log entries at phase starts and saturation onsets;
- ``/metrics``: the metric table as a Markdown document.

All time-varying data is sent as whole columns (``send_columns``), never one ``log`` call per sample. A blueprint for
review is stored in the same file.
"""

from __future__ import annotations

import uuid
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import rerun as rr
import rerun.blueprint as rrb

from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path

__all__ = [
    "AIRCRAFT",
    "DOFS",
    "ENVELOPE_QUANTITIES",
    "TIMELINE",
    "MotionSeries",
    "PlatformEnvelope",
    "PlatformSeries",
    "RecordingData",
    "build_blueprint",
    "envelope_usage_path",
    "perceived_path",
    "platform_path",
    "quat_wxyz_to_xyzw",
    "raw_path",
    "read_component",
    "read_scalar_series",
    "read_text_documents",
    "series_color",
    "write_recording",
]

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

ENVELOPE_QUANTITIES: tuple[tuple[str, str, str], ...] = (
    ("position", "pos_m", "m"),
    ("velocity", "vel_mps", "m/s"),
    ("acceleration", "acc_mps2", "m/s^2"),
    ("wheels", "wheel_radps", "rad/s"),
)
"""Platform quantities with an envelope: (name in entity paths, field of PlatformSeries / PlatformEnvelope, unit)."""

_SATURATION_PANEL = {"pos": "position", "vel": "velocity", "acc": "acceleration", "wheel": "wheels"}
"""Saturation kind -> envelope panel it is marked in; other kinds go to the panel ``other``."""

_WASHOUT_COLORS: dict[str, tuple[int, int, int]] = {
    "small-angle": (31, 119, 180),  # blue
    "large-angle": (255, 127, 14),  # orange
    "unrestricted": (44, 160, 44),  # green
}
_EXTRA_COLORS: tuple[tuple[int, int, int], ...] = ((214, 39, 40), (148, 103, 189), (140, 86, 75), (227, 119, 194))
_AIRCRAFT_COLOR = (235, 235, 235)  # near white: the viewer's background is dark
_LIMIT_COLOR = (150, 150, 150)
_AXIS_COLORS = ((230, 80, 80), (80, 200, 80), (90, 140, 255))  # x, y, z (or wheel 1, 2, 3) inside one washout panel
_SATURATION_MARKERS = ("Cross", "Diamond", "Square", "Up", "Down", "Plus", "Asterisk", "Left", "Right", "Circle")


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


@dataclass(frozen=True)
class PlatformEnvelope:
    """Symmetric platform limits (+- value), for envelope-usage plots.

    Each limit is one value for all three axes (wheels) or a per-axis triple (x, y, z NED or w1, w2, w3), e.g. the
    Atlas stage's ``position_limit_m`` (1.5, 1.5, 1.0).
    """

    pos_m: float | tuple[float, float, float]
    vel_mps: float | tuple[float, float, float]
    acc_mps2: float | tuple[float, float, float]
    wheel_radps: float | tuple[float, float, float]
    sphere_diameter_m: float = 2.9  # drawn in the 3D view

    def axes(self, fname: str) -> np.ndarray:
        """The limit ``fname`` (e.g. "pos_m") as a per-axis array (3,)."""
        return np.broadcast_to(np.asarray(getattr(self, fname), dtype=np.float64), (3,)).copy()


@dataclass(frozen=True)
class RecordingData:
    """Everything one recording shows; ``washouts`` and ``platforms`` have the same keys.

    A washout's MotionSeries is its simulator pilot's motion; its attitude ``q`` is the Atlas sphere's orientation.
    """

    title: str  # e.g. "c172p / coordinated_turn"
    t_s: np.ndarray  # (N,) = k * dt, seconds
    aircraft: MotionSeries
    washouts: dict[str, MotionSeries]
    platforms: dict[str, PlatformSeries]
    envelope: PlatformEnvelope
    phases: list[tuple[str, float, float]]  # (name, t_start_s, t_end_s)
    metrics_markdown: str


# ---------------------------------------------------------------------------------------------------------------------
# Names and colours


def perceived_path(dof: str, source: str) -> str:
    """Entity path of the perceived motion of ``source`` ("aircraft" or a washout name) in ``dof``."""
    return f"/perceived/{dof}/{source}"


def raw_path(dof: str, source: str) -> str:
    """Entity path of the unperceived motion (specific force or angular velocity) of ``source`` in ``dof``."""
    return f"/raw/{dof}/{source}"


def envelope_usage_path(quantity: str, washout: str) -> str:
    """Entity path of the envelope usage (max |axis| / limit, dimensionless) of ``washout`` for ``quantity``."""
    return f"/envelope/{quantity}/{washout}"


def platform_path(washout: str, quantity: str) -> str:
    """Entity path of a platform quantity: three scalars per row (axes x, y, z, or wheels w1, w2, w3), SI units."""
    return f"/platform/{washout}/{quantity}/axes"


def series_color(source: str, washouts: list[str] | tuple[str, ...] = ()) -> tuple[int, int, int]:
    """Fixed RGB colour of a source: the aircraft near white, each known washout its own colour everywhere.

    An unknown washout name takes a spare colour by its position among the unknown names in ``washouts``.
    """
    if source == AIRCRAFT:
        return _AIRCRAFT_COLOR
    if source in _WASHOUT_COLORS:
        return _WASHOUT_COLORS[source]
    unknown = [w for w in washouts if w not in _WASHOUT_COLORS]
    index = unknown.index(source) if source in unknown else 0
    return _EXTRA_COLORS[index % len(_EXTRA_COLORS)]


def quat_wxyz_to_xyzw(q_wxyz: np.ndarray) -> np.ndarray:
    """Convert scalar-first quaternions (..., 4) [w, x, y, z] to rerun's scalar-last [x, y, z, w].

    The only place in washbench where quaternion order changes.
    """
    q_wxyz = np.asarray(q_wxyz, dtype=np.float64)
    return np.concatenate([q_wxyz[..., 1:4], q_wxyz[..., 0:1]], axis=-1)


def _axis_names(quantity: str) -> tuple[str, str, str]:
    return ("w1", "w2", "w3") if quantity == "wheels" else ("x", "y", "z")


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
        for _, fname, _ in ENVELOPE_QUANTITIES:
            _check_array(f"platforms[{w}].{fname}", getattr(p, fname), (n, 3))
        for kind, flags in p.saturated.items():
            _check_array(f"platforms[{w}].saturated[{kind}]", flags, (n,), "b")
    for fname in [f for _, f, _ in ENVELOPE_QUANTITIES] + ["sphere_diameter_m"]:
        limit = np.asarray(getattr(data.envelope, fname))
        if (
            limit.shape not in ((), (3,))
            or limit.dtype.kind not in "fiu"
            or not np.all(np.isfinite(limit) & (limit > 0))
        ):
            raise ValueError(f"envelope.{fname}: expected a positive number or three, got {limit.tolist()!r}")
    for name, t0, t1 in data.phases:
        if not (isinstance(name, str) and t0 <= t1):
            raise ValueError(f"phase {name!r}: expected a name and t_start_s <= t_end_s, got {t0}, {t1}")
    if not isinstance(data.metrics_markdown, str):
        raise ValueError("metrics_markdown: expected a str")
    return n


# ---------------------------------------------------------------------------------------------------------------------
# Blueprint


def build_blueprint(washouts: list[str] | tuple[str, ...], saturation_kinds: Mapping[str, list[str]]) -> rrb.Blueprint:
    """The review layout: tabs of time-series panels on the left, the 3D scene, metrics and events on the right.

    ``saturation_kinds`` maps each washout to its saturation kinds (to place the "other limits" panel only if needed).
    """
    perceived = [
        rrb.TimeSeriesView(origin=f"/perceived/{dof}", name=f"Perceived {dof} ({unit})") for dof, _, _, unit in DOFS
    ]
    raw = [
        rrb.TimeSeriesView(
            origin=f"/raw/{dof}", name=f"{'Specific force' if sig == 'f' else 'Angular velocity'} {dof} ({unit})"
        )
        for dof, sig, _, unit in DOFS
    ]
    usage = [
        rrb.TimeSeriesView(origin=f"/envelope/{q}", name=f"Envelope: {q} (max |axis| / limit)")
        for q, _, _ in ENVELOPE_QUANTITIES
    ]
    other_kinds = sorted({k for kinds in saturation_kinds.values() for k in kinds if k not in _SATURATION_PANEL})
    if other_kinds:
        usage.append(
            rrb.TimeSeriesView(origin="/envelope/other", name=f"Other limits reached ({', '.join(other_kinds)})")
        )
    per_washout = [
        rrb.Grid(
            *[
                rrb.TimeSeriesView(origin=f"/platform/{w}/{q}", name=f"Atlas {w}: {q} ({unit})")
                for q, _, unit in ENVELOPE_QUANTITIES
            ],
            grid_columns=2,
            name=f"Atlas {w}",
        )
        for w in washouts
    ]
    tabs = rrb.Tabs(
        rrb.Grid(*perceived, grid_columns=3, name="Perceived motion"),
        rrb.Grid(*raw, grid_columns=3, name="Raw motion"),
        rrb.Grid(*usage, grid_columns=2, name="Platform envelope"),
        *per_washout,
        active_tab=0,
    )
    side = rrb.Vertical(
        rrb.Spatial3DView(origin="/world", name="Aircraft attitude and Atlas platforms (NED)"),
        rrb.Tabs(
            rrb.TextDocumentView(origin="/metrics", name="Metrics"),
            rrb.TextLogView(origin="/events", name="Phases and saturation events"),
            active_tab=0,
        ),
        row_shares=[3, 2],
    )
    return rrb.Blueprint(
        rrb.Horizontal(tabs, side, column_shares=[3, 2]),
        rrb.TimePanel(state="expanded"),
        collapse_panels=False,
    )


# ---------------------------------------------------------------------------------------------------------------------
# Writing


def _time_column(t_s: np.ndarray) -> rr.TimeColumn:
    """Times in seconds -> rerun duration column, rounded to the nearest nanosecond."""
    ns = np.round(np.asarray(t_s, dtype=np.float64) * 1e9).astype(np.int64)
    return rr.TimeColumn(TIMELINE, duration=ns.astype("timedelta64[ns]"))


def _series(
    rec: rr.RecordingStream, path: str, time: rr.TimeColumn, values: np.ndarray, name: str, color: tuple[int, int, int]
) -> None:
    rec.log(path, rr.SeriesLines(colors=[color], names=[name], widths=[1.5]), static=True, strict=True)
    rec.send_columns(
        path, indexes=[time], columns=rr.Scalars.columns(scalars=np.asarray(values, np.float64)), strict=True
    )


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
    colors = colors if colors is not None else [_LIMIT_COLOR] * len(values)
    rec.log(path, rr.SeriesLines(colors=colors, names=names, widths=[1.0] * len(values)), static=True, strict=True)
    scalars = np.array([values, values], dtype=np.float64)  # (2, len(values)): one row of len(values) per end
    rec.send_columns(path, indexes=[_time_column(ends)], columns=rr.Scalars.columns(scalars=scalars), strict=True)


def _send_motion(rec: rr.RecordingStream, data: RecordingData, time: rr.TimeColumn) -> None:
    washouts = list(data.washouts)
    sources = {AIRCRAFT: data.aircraft, **data.washouts}
    for dof, sig, axis, unit in DOFS:
        for src, m in sources.items():
            label = "aircraft pilot" if src == AIRCRAFT else f"{src} simulator pilot"
            color = series_color(src, washouts)
            if sig == "f":
                perceived, raw = m.perceived_f_mps2[:, axis], m.f_mps2[:, axis]
            else:
                perceived, raw = np.rad2deg(m.perceived_omega_radps[:, axis]), np.rad2deg(m.omega_radps[:, axis])
            _series(rec, perceived_path(dof, src), time, perceived, f"{label} ({unit})", color)
            _series(rec, raw_path(dof, src), time, raw, f"{label} ({unit})", color)


def _send_platforms(rec: rr.RecordingStream, data: RecordingData, time: rr.TimeColumn) -> None:
    t_s = np.asarray(data.t_s, dtype=np.float64)
    washouts = list(data.washouts)
    for q, fname, unit in ENVELOPE_QUANTITIES:
        limit = data.envelope.axes(fname)
        axes = _axis_names(q)
        uniform = bool(np.all(limit == limit[0]))
        text = f"{limit[0]:g}" if uniform else "/".join(f"{v:g}" for v in limit)
        _limit_line(rec, f"/envelope/{q}/limit", t_s, [1.0], [f"limit (+-{text} {unit})"])
        names = [f"{axis} ({unit})" for axis in axes]
        for w in washouts:
            values = np.asarray(getattr(data.platforms[w], fname), dtype=np.float64)
            ratio = np.abs(values) / limit
            # max over the three axes column by column: np.max(ratio, axis=1) is several times slower on (N, 3)
            usage = np.maximum(np.maximum(ratio[:, 0], ratio[:, 1]), ratio[:, 2])
            _series(rec, envelope_usage_path(q, w), time, usage, f"{w}", series_color(w, washouts))
            axes_path = platform_path(w, q)
            rec.log(axes_path, rr.SeriesLines(colors=list(_AXIS_COLORS), names=names), static=True, strict=True)
            # an (N, 3) array is sent as N rows of three scalars
            rec.send_columns(axes_path, indexes=[time], columns=rr.Scalars.columns(scalars=values), strict=True)
            for sign, end, bound in (("+", "max", limit), ("-", "min", -limit)):
                line_path = f"/platform/{w}/{q}/limit_{end}"
                if uniform:  # one line for all axes
                    _limit_line(rec, line_path, t_s, [bound[0]], [f"{sign}limit ({unit})"])
                else:  # one line per axis, in the axis colours
                    labels = [f"{sign}{a} limit" for a in axes]
                    _limit_line(rec, line_path, t_s, list(bound), labels, list(_AXIS_COLORS))
    onsets: list[tuple[float, str]] = []
    for w in washouts:
        for j, (kind, flags) in enumerate(sorted(data.platforms[w].saturated.items())):
            flags = np.asarray(flags, dtype=bool)
            if not flags.any():
                continue
            panel = _SATURATION_PANEL.get(kind, "other")
            path = f"/envelope/{panel}/saturation/{w}/{kind}"
            rec.log(
                path,
                rr.SeriesPoints(
                    colors=[series_color(w, washouts)],
                    names=[f"{w}: {kind} limit"],
                    markers=[_SATURATION_MARKERS[j % len(_SATURATION_MARKERS)]],
                    marker_sizes=[4.0],
                ),
                static=True,
                strict=True,
            )
            idx = np.flatnonzero(flags)
            rec.send_columns(
                path,
                indexes=[_time_column(t_s[idx])],
                columns=rr.Scalars.columns(scalars=np.ones(idx.size)),
                strict=True,
            )
            starts = np.flatnonzero(flags & ~np.concatenate([[False], flags[:-1]]))
            ends = np.flatnonzero(flags & ~np.concatenate([flags[1:], [False]]))
            onsets.extend(
                (float(t_s[s]), f"{w}: {kind} limit reached for {t_s[e] - t_s[s]:.3f} s")
                for s, e in zip(starts, ends, strict=True)
            )
    if onsets:
        onsets.sort(key=lambda item: item[0])
        rec.send_columns(
            "/events/saturation",
            indexes=[_time_column(np.array([t for t, _ in onsets]))],
            columns=rr.TextLog.columns(text=[s for _, s in onsets], level=["WARN"] * len(onsets)),
            strict=True,
        )


def _send_scene(rec: rr.RecordingStream, data: RecordingData, time: rr.TimeColumn) -> None:
    """3D scene: aircraft attitude triad, and per washout the stage-translated, attitude-rotated Atlas sphere."""
    n = np.asarray(data.t_s).size
    washouts = list(data.washouts)
    travel = data.envelope.axes("pos_m")
    diameter = float(data.envelope.sphere_diameter_m)
    spacing = 2.0 * travel[1] + diameter + 1.0
    rec.log("/world", rr.ViewCoordinates.FRD, static=True, strict=True)  # x north, y east, z down

    def body_triad(path: str, length: float, color: tuple[int, int, int]) -> None:
        rec.log(
            path,
            rr.Arrows3D(
                vectors=[[length, 0, 0], [0, 0.5 * length, 0], [0, 0, 0.5 * length]],
                colors=[color, _AXIS_COLORS[1], _AXIS_COLORS[2]],
                labels=["forward", "right", "down"],
                radii=[0.04 * length],
            ),
            static=True,
            strict=True,
        )

    aircraft_offset = np.array([0.0, -spacing, 0.0])
    rec.send_columns(
        "/world/aircraft",
        indexes=[time],
        columns=rr.Transform3D.columns(
            translation=np.tile(aircraft_offset, (n, 1)), quaternion=quat_wxyz_to_xyzw(data.aircraft.q)
        ),
        strict=True,
    )
    body_triad("/world/aircraft/body", 2.0, _AIRCRAFT_COLOR)
    for i, w in enumerate(washouts):
        offset = np.array([0.0, i * spacing, 0.0])
        color = series_color(w, washouts)
        rec.log(
            f"/world/stage_range/{w}",
            rr.Boxes3D(
                centers=[offset],
                half_sizes=[travel],
                colors=[_LIMIT_COLOR],
                fill_mode="MajorWireframe",
                labels=[f"{w} stage range"],
            ),
            static=True,
            strict=True,
        )
        pos = np.asarray(data.platforms[w].pos_m, dtype=np.float64)
        rec.send_columns(
            f"/world/atlas/{w}",
            indexes=[time],
            columns=rr.Transform3D.columns(translation=pos + offset, quaternion=quat_wxyz_to_xyzw(data.washouts[w].q)),
            strict=True,
        )
        half = diameter / 2.0
        rec.log(
            f"/world/atlas/{w}/sphere",
            rr.Ellipsoids3D(
                half_sizes=[[half, half, half]],
                colors=[(*color, 90)],
                fill_mode="MajorWireframe",
                labels=[f"Atlas {w}"],
            ),
            static=True,
            strict=True,
        )
        body_triad(f"/world/atlas/{w}/cockpit", half, color)


def _send_text(rec: rr.RecordingStream, data: RecordingData) -> None:
    rec.log(
        "/metrics", rr.TextDocument(data.metrics_markdown, media_type=rr.MediaType.MARKDOWN), static=True, strict=True
    )
    if data.phases:
        rec.send_columns(
            "/events/phases",
            indexes=[_time_column(np.array([t0 for _, t0, _ in data.phases], dtype=np.float64))],
            columns=rr.TextLog.columns(
                text=[f"phase {name} ({t0:.2f}-{t1:.2f} s)" for name, t0, t1 in data.phases],
                level=["INFO"] * len(data.phases),
            ),
            strict=True,
        )


def write_recording(path: Path, data: RecordingData) -> None:
    """Write ``data`` to the .rrd file ``path`` atomically (temp file in the same folder, then rename).

    No viewer and no network: the recording stream's only sink is the file. The review blueprint is stored in the same
    file. Raises ValueError on inconsistent shapes, WashbenchError if the environment disables rerun (``RERUN=off``:
    the file would be empty); on any exception no .rrd (and no temp file) is left behind and an
    existing ``path`` is untouched. Byte-for-byte the file differs between runs (rerun stamps row ids and a recording
    id), the logged data does not.
    """
    path = Path(path)
    _check(data)
    saturation_kinds = {w: [k for k, v in p.saturated.items() if np.any(v)] for w, p in data.platforms.items()}
    blueprint = build_blueprint(list(data.washouts), saturation_kinds)
    rec = rr.RecordingStream("washbench", recording_id=uuid.uuid4(), send_properties=False)
    if not rec.is_enabled():
        raise WashbenchError(
            located(
                path, "rerun logging is disabled by the environment (RERUN=off): unset RERUN to write the recording"
            )
        )
    with atomic_path(path) as tmp:
        try:
            rec.save(tmp, default_blueprint=blueprint)
            rec.send_recording_name(data.title)
            time = _time_column(data.t_s)
            _send_motion(rec, data, time)
            _send_platforms(rec, data, time)
            _send_scene(rec, data, time)
            _send_text(rec, data)
        finally:
            rec.flush()
            rec.disconnect()


# ---------------------------------------------------------------------------------------------------------------------
# Reading back (tests, including the pipeline's end-to-end test)


def _time_seconds(col: pa.Array) -> np.ndarray:
    ns = np.asarray(col.cast(pa.int64()).to_numpy(zero_copy_only=False), dtype=np.int64)
    return ns * 1e-9


def _component_values(col: pa.Array) -> np.ndarray:
    """A component column (a list of instances per row) -> array (rows, [instances,] *shape).

    The instance axis is dropped when every row holds one instance; rows of unequal length give an object array.
    """
    lengths = pc.list_value_length(col)
    if col.null_count == 0 and len(col) > 0 and pc.min_max(lengths).as_py()["min"] == pc.max(lengths).as_py():
        per_row = int(lengths[0].as_py())
        inner = col.flatten()
        shape = [len(col)] if per_row == 1 else [len(col), per_row]
        while pa.types.is_fixed_size_list(inner.type):
            shape.append(inner.type.list_size)
            inner = inner.flatten()
        return np.asarray(inner.to_numpy(zero_copy_only=False)).reshape(shape)
    return np.array(col.to_pylist(), dtype=object)


def read_component(path: Path, component: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every entity's time-indexed values of ``component`` (e.g. "Scalars:scalars", "Transform3D:quaternion").

    Returns entity path -> (t_s (M,), values), sorted by time. When each row holds one instance, ``values`` has shape
    (M,) for scalars and (M, k) for k-vectors; with L > 1 instances in every row, (M, L) and (M, L, k). Values keep
    the dtype rerun stores (scalars float64, vectors and quaternions float32); rows of unequal length give an object
    array of per-row lists. Static data is ignored. Reads with
    ``rerun.chunk.RrdReader`` (pyarrow only, no viewer).
    """
    from rerun.chunk import RrdReader

    parts: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    for chunk in RrdReader(str(path)).stream():
        if chunk.is_static or TIMELINE not in chunk.timeline_names:
            continue
        batch = chunk.to_record_batch()
        if component not in batch.schema.names:
            continue
        t = _time_seconds(batch.column(TIMELINE))
        parts.setdefault(chunk.entity_path, []).append((t, _component_values(batch.column(component))))
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for entity, pieces in parts.items():
        t = np.concatenate([p[0] for p in pieces])
        v = np.concatenate([p[1] for p in pieces])
        order = np.argsort(t, kind="stable")
        out[entity] = (t[order], v[order])
    return out


def read_scalar_series(path: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every scalar series in the .rrd file: entity path -> (t_s (M,), values float64).

    ``values`` is (M,) for a single series and (M, 3) for the platform's per-axis entities (:func:`platform_path`).
    """
    return read_component(path, "Scalars:scalars")


def read_text_documents(path: Path) -> dict[str, str]:
    """Every static text document in the .rrd file: entity path -> text."""
    from rerun.chunk import RrdReader

    out: dict[str, str] = {}
    for chunk in RrdReader(str(path)).stream():
        batch = chunk.to_record_batch()
        if "TextDocument:text" in batch.schema.names:
            for row in batch.column("TextDocument:text").to_pylist():
                if row:
                    out[chunk.entity_path] = row[0]
    return out
