"""On-disk formats: the one place that knows column names.

Input motion (``washbench cue INPUT``) in washbench's own columns, one row per sample, body axes
(x forward, y right, z down), time uniform and increasing (other layouts: :mod:`washbench.io.readers`)::

    t_s, f_x_mps2, f_y_mps2, f_z_mps2, omega_x_degps, omega_y_degps, omega_z_degps

Other columns are ignored by the cueing but kept in :attr:`Motion.extra` and written back
unchanged to ``traces.parquet`` (e.g. the flight pipeline's state columns).

``DIR/traces.parquet`` (see :func:`motion_columns` and :func:`washout_columns`)::

    t_s
    S.f_{x,y,z}_mps2, S.omega_{x,y,z}_degps                  head motion of pilot S
    S.perceived_f_{x,y,z}_mps2, S.perceived_omega_{x,y,z}_degps   vestibular model output
        for S = "aircraft" and for each washout W (its simulator pilot)
    W.pos_{x,y,z}_m, W.vel_{x,y,z}_mps, W.acc_{x,y,z}_mps2   platform centre, NED inertial
    W.q_{w,x,y,z}                                            platform attitude, body -> inertial
    W.omega_platform_{x,y,z}_degps                           platform angular velocity, body axes
    W.wheel_{1,2,3}_radps                                    Atlas omni-wheel speeds
    W.sp_pos_{x,y,z}_m, W.sp_q_{w,x,y,z}                     the washout's set points for the platform
    W.sat_<kind>                                             saturation flags, 0/1 (int8)
    <extra input columns, unchanged>

``DIR/metrics.csv``: ``washout,dof,npc,integral_error,max_error`` then the cue classification
(:mod:`washbench.analysis.cues`) ``cue_correct_frac,cue_scaled_frac,cue_false_frac,cue_missing_frac`` (time
fractions), on the heave row the motion sickness dose values ``msdv_mps15,msdv_aircraft_mps15`` (ISO 2631-1 Wf,
m/s^1.5: the simulator pilot's and the aircraft pilot's, :mod:`washbench.perception.sickness`),
``false_cue_events`` (``start_s-end_s@peak`` joined by ``;``) and on the heave row the predicted motion-sickness
incidence ``msi_pct,msi_aircraft_pct`` (%, subjective vertical conflict, :mod:`washbench.perception.svc`), one row
per washout and DOF
(surge, sway, heave, roll, pitch, yaw). Floats are written with ``repr`` (exact round trip); an
undefined NPC (flat signal) is an empty field; PC = -1 gives ``inf``.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from washbench.analysis.metrics import MetricRow
from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path, write_text_atomic

AXES = ("x", "y", "z")
TIME_COLUMN = "t_s"
F_COLUMNS = tuple(f"f_{a}_mps2" for a in AXES)
OMEGA_COLUMNS = tuple(f"omega_{a}_degps" for a in AXES)
INPUT_COLUMNS = (TIME_COLUMN, *F_COLUMNS, *OMEGA_COLUMNS)
"""The required input columns, in order."""

AIRCRAFT = "aircraft"
"""Source name of the aircraft pilot in traces.parquet."""

METRICS_COLUMNS = (
    "washout", "dof", "npc", "integral_error", "max_error",
    "cue_correct_frac", "cue_scaled_frac", "cue_false_frac", "cue_missing_frac",
    "msdv_mps15", "msdv_aircraft_mps15", "false_cue_events", "msi_pct", "msi_aircraft_pct",
)  # fmt: skip
"""metrics.csv columns; files written before the cue classification have the first five only, before the MSI the
first twelve (both still read)."""
METRICS_TEXT_COLUMNS = ("washout", "dof", "false_cue_events")
N_BASE_METRICS_COLUMNS = 5
N_PRE_MSI_METRICS_COLUMNS = 12

#: Time steps an input motion may have, s: beyond, the filters cannot be discretised (a subnormal step, or one of
#: 8e307 s, overflows them). Wide on purpose: a time column in ms or ns read as seconds still passes, and the
#: plausibility warnings (:mod:`washbench.io.plausibility`) say so.
DT_RANGE_S = (1e-6, 1e7)
#: Largest magnitudes accepted in the motion columns (10,000 g and 100,000 deg/s): no sensor records more, and
#: such numbers only make the platform model meaningless. Crashes and spikes well below are reported by the
#: plausibility checks.
F_MAX_MPS2 = 1e5
OMEGA_MAX_DEGPS = 1e5
MOTION_MAX = {**dict.fromkeys(F_COLUMNS, F_MAX_MPS2), **dict.fromkeys(OMEGA_COLUMNS, OMEGA_MAX_DEGPS)}


# --------------------------------------------------------------------------- column names


def f_columns(source: str) -> tuple[str, str, str]:
    """Head specific force of pilot ``source`` [m/s^2], body x, y, z."""
    return tuple(f"{source}.f_{a}_mps2" for a in AXES)  # type: ignore[return-value]


def omega_columns(source: str) -> tuple[str, str, str]:
    """Head angular velocity of pilot ``source`` [deg/s], body x, y, z."""
    return tuple(f"{source}.omega_{a}_degps" for a in AXES)  # type: ignore[return-value]


def perceived_f_columns(source: str) -> tuple[str, str, str]:
    """Perceived specific force (otolith model output) of pilot ``source`` [m/s^2]."""
    return tuple(f"{source}.perceived_f_{a}_mps2" for a in AXES)  # type: ignore[return-value]


def perceived_omega_columns(source: str) -> tuple[str, str, str]:
    """Perceived angular velocity (canal model output) of pilot ``source`` [deg/s]."""
    return tuple(f"{source}.perceived_omega_{a}_degps" for a in AXES)  # type: ignore[return-value]


def motion_columns(source: str) -> tuple[str, ...]:
    """All 12 head-motion and perception columns of one pilot, in table order."""
    return (
        *f_columns(source),
        *omega_columns(source),
        *perceived_f_columns(source),
        *perceived_omega_columns(source),
    )


def pos_columns(washout: str) -> tuple[str, str, str]:
    """Platform position, NED inertial [m]."""
    return tuple(f"{washout}.pos_{a}_m" for a in AXES)  # type: ignore[return-value]


def vel_columns(washout: str) -> tuple[str, str, str]:
    """Platform velocity, NED inertial [m/s]."""
    return tuple(f"{washout}.vel_{a}_mps" for a in AXES)  # type: ignore[return-value]


def acc_columns(washout: str) -> tuple[str, str, str]:
    """Platform acceleration, NED inertial [m/s^2]."""
    return tuple(f"{washout}.acc_{a}_mps2" for a in AXES)  # type: ignore[return-value]


def q_columns(washout: str) -> tuple[str, str, str, str]:
    """Platform attitude quaternion, scalar first, body -> inertial."""
    return tuple(f"{washout}.q_{c}" for c in ("w", "x", "y", "z"))  # type: ignore[return-value]


def omega_platform_columns(washout: str) -> tuple[str, str, str]:
    """Platform angular velocity, body axes [deg/s]."""
    return tuple(f"{washout}.omega_platform_{a}_degps" for a in AXES)  # type: ignore[return-value]


def wheel_columns(washout: str) -> tuple[str, str, str]:
    """Atlas omni-wheel speeds [rad/s]."""
    return tuple(f"{washout}.wheel_{i}_radps" for i in (1, 2, 3))  # type: ignore[return-value]


def sp_pos_columns(washout: str) -> tuple[str, str, str]:
    """The washout's position set point for the platform, NED inertial [m]."""
    return tuple(f"{washout}.sp_pos_{a}_m" for a in AXES)  # type: ignore[return-value]


def sp_q_columns(washout: str) -> tuple[str, str, str, str]:
    """The washout's attitude set point for the platform, scalar first, body -> inertial."""
    return tuple(f"{washout}.sp_q_{c}" for c in ("w", "x", "y", "z"))  # type: ignore[return-value]


def sat_column(washout: str, kind: str) -> str:
    """Saturation flag column (0/1) of one limit ``kind``."""
    return f"{washout}.sat_{kind}"


def washout_columns(washout: str, sat_kinds: Iterable[str]) -> tuple[str, ...]:
    """All columns of one washout in table order (its pilot's motion, then the platform)."""
    return (
        *motion_columns(washout),
        *pos_columns(washout),
        *vel_columns(washout),
        *acc_columns(washout),
        *q_columns(washout),
        *omega_platform_columns(washout),
        *wheel_columns(washout),
        *sp_pos_columns(washout),
        *sp_q_columns(washout),
        *(sat_column(washout, k) for k in sat_kinds),
    )


# --------------------------------------------------------------------------- input motion


@dataclass(frozen=True, eq=False)
class Motion:
    """A recorded pilot-head motion on a uniform time grid.

    ``t_s`` (N,) [s]; ``dt_s`` the time step [s]; ``f_mps2`` (N, 3) specific force [m/s^2] and
    ``omega_radps`` (N, 3) angular velocity [rad/s], body axes; ``extra`` other columns by name
    (passed through to results). ``omega_degps`` keeps the angular velocity exactly as read
    (deg/s) so it can be written back bit for bit; ``None`` when built in memory.
    """

    t_s: np.ndarray
    dt_s: float
    f_mps2: np.ndarray
    omega_radps: np.ndarray
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    omega_degps: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = self.t_s.shape[0] if self.t_s.ndim == 1 else -1
        if n < 2:
            raise ValueError(f"t_s must be 1-D with at least 2 samples, got shape {self.t_s.shape}")
        for name in ("f_mps2", "omega_radps"):
            shape = getattr(self, name).shape
            if shape != (n, 3):
                raise ValueError(f"{name} must have shape ({n}, 3), got {shape}")
        if self.omega_degps is not None and self.omega_degps.shape != (n, 3):
            raise ValueError(f"omega_degps must have shape ({n}, 3), got {self.omega_degps.shape}")
        for name, col in self.extra.items():
            if len(col) != n:
                raise ValueError(f"extra column {name!r} has {len(col)} rows, expected {n}")
        if not (self.dt_s > 0.0 and math.isfinite(self.dt_s)):
            raise ValueError(f"dt_s must be positive and finite, got {self.dt_s}")

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.t_s.shape[0])

    @property
    def duration_s(self) -> float:
        """Time from the first to the last sample [s]."""
        return float(self.t_s[-1] - self.t_s[0])

    def omega_degps_out(self) -> np.ndarray:
        """Angular velocity in deg/s for output: the values as read if known, else converted."""
        return self.omega_degps if self.omega_degps is not None else np.degrees(self.omega_radps)


def read_motion(path: str | Path) -> Motion:
    """Read a motion trace in washbench's own columns and units (CSV, Parquet, ...) on a uniform grid.

    The plain form of ``washbench cue INPUT`` (no mapping, resampling or splitting; see
    :mod:`washbench.io.readers` and :mod:`washbench.io.resample` for those). Raises WashbenchError with one
    line naming the file (and, for text files, the line) for: a missing, unreadable or empty file, an
    unknown extension, no or one data row, a missing or non-numeric column, missing, NaN or infinite
    values, time that does not increase, jumps back or is not uniform.
    """
    from washbench.io.readers import read_samples
    from washbench.io.resample import split_resets, to_motion

    samples = read_samples(Path(path))
    (only,) = split_resets(samples, split=False)
    return to_motion(only)


# --------------------------------------------------------------------------- writers and readers


def write_parquet(path: str | Path, arrow: pa.Table) -> None:
    """Write a table to Parquet the one way every washbench trace file is written (not atomic by itself).

    zstd throughout; floats byte-stream-split (about 2/3 of the size of dictionary + zstd, and 4x faster),
    other columns dictionary-encoded.
    """
    floats = [f.name for f in arrow.schema if pa.types.is_floating(f.type)]
    others = [name for name in arrow.column_names if name not in set(floats)]
    pq.write_table(arrow, path, compression="zstd", use_dictionary=others, use_byte_stream_split=floats)


def parquet_writer(path: str | Path, schema: pa.Schema) -> pq.ParquetWriter:
    """A writer for tables written a row group at a time, with :func:`write_parquet`'s settings."""
    floats = [f.name for f in schema if pa.types.is_floating(f.type)]
    others = [f.name for f in schema if not pa.types.is_floating(f.type)]
    return pq.ParquetWriter(path, schema, compression="zstd", use_dictionary=others, use_byte_stream_split=floats)


def write_trace_chunks(
    path: str | Path, chunks: Iterable[Mapping[str, np.ndarray]], metadata: Mapping[bytes, bytes] | None = None
) -> None:
    """Write consecutive row ranges of the traces table (each column name -> 1-D array, the same columns in each)
    to Parquet at ``path`` (not atomic by itself), one row group each, with :func:`write_parquet`'s settings.

    ``metadata``: the schema's key-value metadata (provenance, :func:`washbench.io.provenance.parquet_metadata`).
    """
    writer = None
    try:
        for chunk in chunks:
            arrow = pa.table({name: pa.array(np.asarray(col)) for name, col in chunk.items()})
            if writer is None:
                schema = arrow.schema.with_metadata(dict(metadata)) if metadata else arrow.schema
                writer = parquet_writer(path, schema)
            writer.write_table(arrow.replace_schema_metadata(schema.metadata))
    finally:
        if writer is not None:
            writer.close()
    if writer is None:
        raise ValueError("write_trace_chunks: no rows and no columns to write")


def write_traces(
    path: str | Path,
    table: Mapping[str, np.ndarray] | Iterable[Mapping[str, np.ndarray]],
    metadata: Mapping[bytes, bytes] | None = None,
) -> None:
    """Write the traces table to Parquet atomically: the whole table (column name -> 1-D array, all the same
    length) or its consecutive row ranges (:func:`write_trace_chunks`, so the whole table is never in memory)."""
    with atomic_path(path) as tmp:
        write_trace_chunks(tmp, [table] if isinstance(table, Mapping) else table, metadata)


def read_traces(path: str | Path) -> dict[str, np.ndarray]:
    """Read a traces.parquet back as column name -> numpy array."""
    t = pq.read_table(path)
    return {name: t.column(name).to_numpy(zero_copy_only=False) for name in t.column_names}


def csv_number(x: float) -> str:
    """A float for CSV: full precision (repr, so reading back is exact); NaN as an empty field."""
    return "" if math.isnan(x) else repr(float(x))


def metrics_csv_text(rows: Iterable[MetricRow]) -> str:
    """The text of metrics.csv for ``rows`` (header, then one line per row; NaN -> empty field)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(METRICS_COLUMNS)
    for r in rows:
        w.writerow(
            [getattr(r, c) if c in METRICS_TEXT_COLUMNS else csv_number(getattr(r, c)) for c in METRICS_COLUMNS]
        )
    return buf.getvalue()


def write_metrics_csv(path: str | Path, rows: Iterable[MetricRow]) -> None:
    """Write metrics.csv atomically (floats as ``repr``: exact round trip; NaN as an empty field)."""
    write_text_atomic(path, metrics_csv_text(rows))


def read_metrics_csv(path: str | Path) -> list[MetricRow]:
    """Read metrics.csv back (empty fields -> NaN). Raises WashbenchError on a malformed file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise WashbenchError(located(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}")) from None
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    known = (METRICS_COLUMNS, METRICS_COLUMNS[:N_PRE_MSI_METRICS_COLUMNS], METRICS_COLUMNS[:N_BASE_METRICS_COLUMNS])
    if header is None or tuple(header) not in known:
        raise WashbenchError(located(path, f"expected header {','.join(METRICS_COLUMNS)}", line=1))
    ncol = len(header)
    rows = []
    for line, rec in enumerate(reader, start=2):
        if len(rec) != ncol:
            raise WashbenchError(located(path, f"expected {ncol} fields, got {len(rec)}", line=line))
        try:
            values = {c: v if c in METRICS_TEXT_COLUMNS else (math.nan if v == "" else float(v))
                      for c, v in zip(header, rec, strict=True)}  # fmt: skip
        except ValueError as exc:
            raise WashbenchError(located(path, f"not a number: {exc}", line=line)) from None
        rows.append(MetricRow(**values))
    return rows
