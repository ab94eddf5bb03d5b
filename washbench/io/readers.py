"""Reading recorded pilot-head motion from any of the supported files into :class:`Samples`.

Files (chosen by extension, then by the header):

- CSV text, ``.csv``/``.tsv``/``.txt``, optionally gzip-compressed (``.gz``): the delimiter (comma,
  semicolon, tab or ``|``) is detected from the header line or given; lines starting with ``#`` are
  comments (skipped); header names are trimmed of surrounding whitespace. Read with pyarrow's CSV reader.
- Parquet (``.parquet``, ``.pq``): float32, float64 or integer columns.
- X-Plane's Data Output file ``Data.txt`` (:mod:`washbench.io.xplane`): pipe-separated, padded headers.
- JSBSim's own CSV output (header ``Time, ..., accelerations/a-pilot-x-ft_sec2, ...``): the eyepoint
  specific force (ft/s^2) and the body rates (``velocities/p-rad_sec`` ... or the ``<rates>`` group's
  ``P (deg/s)``); JSBSim's pilot accelerations lag its other outputs by one simulation frame, so they are
  shifted back by one frame (:func:`shift_jsbsim_lag`: one row of a log written every frame, interpolated in a
  log written every few frames, not at all where the frame time cannot be known).

Every reader ends in the same conversion (:func:`convert`): the format's column mapping, overridden
field by field by the user's (``--columns`` or ``--input-format FILE``), picks one source column per
motion field with its unit and sign; :mod:`washbench.io.units` turns them into s, m/s^2 and deg/s and the
sensor axes into body axes. A column already in washbench's units and axes is passed through untouched,
so a ``washbench fly`` trace is read back bit for bit.
"""

from __future__ import annotations

import re
import stat
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from washbench.errors import WashbenchError, located
from washbench.io import units, xplane
from washbench.io.input_format import CANONICAL, FIELDS, QUANTITY, ColumnSource, InputFormat
from washbench.io.jsbsim_csv import is_jsbsim_header, jsbsim_mapping
from washbench.io.tables import SourceTable, file_kind, header, read_parquet_table, read_text_table


@dataclass(frozen=True, eq=False)
class Samples:
    """Recorded motion in washbench units, time not yet checked: as read, one row per sample.

    ``t_s`` (N,) [s]; ``f_mps2`` (N, 3) [m/s^2]; ``omega_degps`` (N, 3) [deg/s], body axes x forward,
    y right, z down; ``extra``: other columns by name. ``lines`` (N,) the file line of each row (text
    files) or ``None`` (Parquet: rows are counted from 1). ``kind`` the file kind read; ``notes``: what the
    conversion did (units, axes, lag shift, time origin), one line each.
    """

    path: Path
    kind: str
    t_s: np.ndarray
    f_mps2: np.ndarray
    omega_degps: np.ndarray
    extra: dict[str, np.ndarray]
    lines: np.ndarray | None
    notes: tuple[str, ...] = ()
    time_column: str = "t_s"
    declared: Mapping[str, str] = field(default_factory=dict)
    """The units the columns were read in: ``t`` (time), ``f`` (specific force), ``omega`` (angular velocity)."""
    sources: Mapping[str, ColumnSource] = field(default_factory=dict)
    """Per motion field (``t``, ``f_x`` ...) the source column, unit and sign it came from."""

    @property
    def n(self) -> int:
        return int(self.t_s.shape[0])

    def where(self, i: int) -> tuple[int | None, str]:
        """(line for :func:`located`, row text) of sample ``i`` (0-based)."""
        if self.lines is not None:
            return int(self.lines[i]), ""
        return None, f"row {i + 1}: "

    def take(self, index: slice | np.ndarray, notes: tuple[str, ...] = ()) -> Samples:
        """The samples at ``index`` (a slice or an index array), with ``notes`` added."""
        return Samples(
            path=self.path,
            kind=self.kind,
            t_s=self.t_s[index],
            f_mps2=self.f_mps2[index],
            omega_degps=self.omega_degps[index],
            extra={k: v[index] for k, v in self.extra.items()},
            lines=None if self.lines is None else self.lines[index],
            notes=self.notes + notes,
            time_column=self.time_column,
            declared=self.declared,
            sources=self.sources,
        )


# --------------------------------------------------------------------------- format defaults


def default_mapping(kind: str, names: list[str]) -> dict[str, ColumnSource]:
    """The column mapping a file kind implies (washbench's own names for CSV and Parquet)."""
    if kind == "xplane":
        return xplane.default_mapping(names)
    if kind == "jsbsim":
        return jsbsim_mapping(names)
    return {f: ColumnSource(CANONICAL[f], units.CANONICAL_UNIT[QUANTITY[f]]) for f in FIELDS}


def detect_kind(path: Path, fmt: InputFormat) -> tuple[str, str | None]:
    """(kind, delimiter) of ``path`` under ``fmt`` (``auto`` looks at the extension, then the header)."""
    base = file_kind(path)
    if fmt.kind == "parquet" or (fmt.kind == "auto" and base == "parquet"):
        if base != "parquet":
            raise WashbenchError(located(path, "--input-format says parquet but the file is text"))
        return "parquet", None
    if base == "parquet":
        raise WashbenchError(located(path, f"--input-format says {fmt.kind} but the file is Parquet"))
    if fmt.kind != "auto":
        delim = fmt.delimiter or ("|" if fmt.kind == "xplane" else None)
        return fmt.kind, delim
    _, names, delim = header(path, fmt.delimiter)
    if xplane.is_xplane_header(names, delim):
        return "xplane", delim
    if is_jsbsim_header(names):
        return "jsbsim", delim
    return "csv", delim


# --------------------------------------------------------------------------- reading and conversion


def read_samples(path: str | Path, fmt: InputFormat | None = None) -> Samples:
    """Read ``path`` and convert it to washbench units and axes (time not yet checked for uniformity)."""
    path = Path(path)
    fmt = fmt or InputFormat()
    file_kind(path)
    if not path.exists():
        raise WashbenchError(located(path, "no such file"))
    if path.is_dir():
        raise WashbenchError(located(path, "is a folder, not a file"))
    mode = path.stat().st_mode  # (stat opens nothing: opening a FIFO with no writer waits for one for ever)
    if not stat.S_ISREG(mode):
        what = "a FIFO (named pipe)" if stat.S_ISFIFO(mode) else "a device or socket"
        raise WashbenchError(located(path, f"is {what}, not a regular file: washbench reads an input more than once "
                                           "(its header, then its rows); write it to a file first"))  # fmt: skip
    kind, delim = detect_kind(path, fmt)
    if kind == "parquet":
        src = read_parquet_table(path)
    else:
        _, names, delim = header(path, delim)
        mapping = default_mapping(kind, names) | dict(fmt.columns)
        src = read_text_table(path, delim, {s.column for s in mapping.values()}, fmt.decimal)
        src = SourceTable(path=src.path, kind=kind, table=src.table, lines=src.lines, decimal=src.decimal)
    return convert(src, fmt)


def _resolve(src: SourceTable, fmt: InputFormat) -> dict[str, ColumnSource]:
    names = src.table.column_names
    mapping = default_mapping(src.kind, names) | dict(fmt.columns)
    for f in FIELDS:
        if f not in mapping:
            raise WashbenchError(
                located(src.path, f"{src.kind} file: no column for {f} (give it with --columns {f}=COLUMN:UNIT)")
            )
        col = mapping[f].column
        if col not in names:
            hint = "" if f not in fmt.columns else f" (from {fmt.origin})"
            shown = ", ".join(names) if len(names) <= 40 else ", ".join(names[:40]) + ", ..."
            raise WashbenchError(located(src.path, f"missing column {col!r}{hint} (found: {shown or 'none'})"))
    used = [mapping[f].column for f in FIELDS]
    dup = sorted({c for c in used if used.count(c) > 1})
    if dup:
        raise WashbenchError(located(src.path, f"column {dup[0]!r} is mapped to two fields"))
    return mapping


def convert(src: SourceTable, fmt: InputFormat) -> Samples:
    """The one conversion every reader ends in: mapping, units, signs, axes, JSBSim's lag, extra columns."""
    table = src.table
    mapping = _resolve(src, fmt)
    if table.num_rows == 0:
        raise WashbenchError(located(src.path, "no data rows"))
    if table.num_rows < 2:
        raise WashbenchError(located(src.path, "only one data row: need at least 2 samples"))
    notes: list[str] = []
    t_src = mapping["t"]
    t = _time_column(src, t_src, notes)
    cols = {}
    for f in FIELDS[1:]:
        s = mapping[f]
        x = numeric_column(src, s.column, f if s.column == CANONICAL[f] else None)
        factor = units.unit_factor(QUANTITY[f], s.unit) * s.sign
        if factor != 1.0:
            x = x * factor
        cols[f] = x
    changed = [f"{f}={s.describe()}" for f, s in mapping.items() if s.column != CANONICAL[f] or s.sign != 1.0]
    if changed:
        notes.append("columns: " + ", ".join(changed))
    f_mps2 = np.column_stack([cols[f"f_{a}"] for a in "xyz"])
    w_degps = np.column_stack([cols[f"omega_{a}"] for a in "xyz"])
    if not units.is_identity_axes(fmt.axes):
        try:
            m = units.axes_matrix(fmt.axes)
        except ValueError as exc:
            raise WashbenchError(f"--axes: {exc}") from None
        f_mps2 = f_mps2 @ m.T
        w_degps = w_degps @ m.T
        notes.append(f"axes: sensor {fmt.axes} turned into body x forward, y right, z down")
    used = {s.column for s in mapping.values()}
    extra = {n: table.column(n).to_numpy(zero_copy_only=False) for n in table.column_names if n not in used}
    samples = Samples(
        path=src.path,
        kind=src.kind,
        t_s=t,
        f_mps2=np.ascontiguousarray(f_mps2),
        omega_degps=np.ascontiguousarray(w_degps),
        extra=extra,
        lines=src.lines,
        notes=tuple(notes),
        time_column=t_src.column,
        declared={"t": units.normalise_unit(t_src.unit), "f": mapping["f_x"].unit, "omega": mapping["omega_x"].unit},
        sources=dict(mapping),
    )
    if src.kind == "jsbsim":
        samples = shift_jsbsim_lag(samples, fmt.jsbsim_dt_s)
    return samples


JSBSIM_DEFAULT_DT_S = 1.0 / 120.0
"""JSBSim's frame time when a script's ``<run>`` gives no ``dt`` [s]."""
JSBSIM_DT_COLUMNS = ("simulation/dt", "/fdm/jsbsim/simulation/dt")
"""A logged ``simulation/dt`` property: the frame time, read from the log itself."""


def jsbsim_frame_s(s: Samples, given_s: float | None) -> tuple[float | None, str]:
    """(the simulation frame time of a JSBSim log [s] or None where it cannot be known; where it came from).

    Given (``--jsbsim-dt``), or a logged ``simulation/dt`` column, or, for a log whose rows are JSBSim's default
    frame (1/120 s) apart, that frame: a script that sets no ``dt`` and logs every frame (a log at 120 Hz of a
    240 Hz simulation is told apart only by ``--jsbsim-dt``).
    """
    if given_s is not None:
        return float(given_s), "--jsbsim-dt"
    for c in JSBSIM_DT_COLUMNS:
        if c in s.extra and s.extra[c].dtype.kind in "fi" and np.ptp(s.extra[c]) == 0.0:
            return float(s.extra[c][0]), f"its {c} column"
    steps = np.diff(s.t_s)
    if steps.size and np.all(np.abs(steps - JSBSIM_DEFAULT_DT_S) <= 1e-3 * JSBSIM_DEFAULT_DT_S):
        return JSBSIM_DEFAULT_DT_S, "JSBSim's default, one row per frame at 120 Hz"
    return None, ""


def shift_jsbsim_lag(s: Samples, frame_s: float | None = None) -> Samples:
    """JSBSim logs ``a-pilot`` one simulation frame late: the value logged at time t is the one of t - frame.

    The accelerations are moved back by one frame, ``f(t_k) = f_logged(t_k + frame)``: for a log with a row per
    frame that is the next row exactly; for a log written every few frames (``<output rate>`` below the
    simulation's) it is interpolated linearly between the rows around ``t_k + frame``. Rows with no logged value
    one frame later (the last) are dropped. Where the frame time cannot be known (:func:`jsbsim_frame_s`) nothing
    is shifted and the note says so: shifting by a row of a sub-sampled log would move the accelerations by a
    whole row, many frames.
    """
    frame, origin = jsbsim_frame_s(s, frame_s)
    n = s.n
    t = s.t_s
    steps = np.diff(t)
    if frame is None:
        note = (
            f"JSBSim's pilot accelerations lag the other columns by one simulation frame, but the log's rows are "
            f"{float(np.median(steps)):.6g} s apart and its frame time is not in the file: NOT shifted (give the "
            "script's <run dt> with --jsbsim-dt S, or log simulation/dt)"
        )
        return s.take(slice(0, n), (note,))
    if np.all(np.abs(steps - frame) <= 1e-3 * frame):
        f = np.ascontiguousarray(s.f_mps2[1:])
        note = f"JSBSim's pilot accelerations shifted back one frame of {frame:.6g} s = one row (frame from {origin})"
        out = s.take(slice(0, n - 1), (note,))
    else:
        if not np.all(steps > 0.0):
            raise WashbenchError(located(s.path, "JSBSim log: time does not increase, cannot undo the one-frame lag"))
        if np.any(steps < frame * (1.0 - 1e-3)):
            raise WashbenchError(
                located(s.path, f"JSBSim log: rows closer than the frame time {frame:.6g} s (from {origin})")
            )
        keep = int(np.searchsorted(t, t[-1] - frame, side="right"))
        f = np.column_stack([np.interp(t[:keep] + frame, t, s.f_mps2[:, j]) for j in range(3)])
        note = (
            f"JSBSim's pilot accelerations shifted back one frame of {frame:.6g} s (frame from {origin}), "
            f"interpolated between rows {float(np.median(steps)):.6g} s apart"
        )
        out = s.take(slice(0, keep), (note,))
    return replace(out, f_mps2=f)


def _time_column(src: SourceTable, s: ColumnSource, notes: list[str]) -> np.ndarray:
    """Time in seconds. Seconds are kept as given; other units and timestamps count from the first sample."""
    col = src.table.column(s.column)
    unit = units.normalise_unit(s.unit)
    if pa.types.is_timestamp(col.type) or pa.types.is_date(col.type) or unit == "timestamp":
        ns = _timestamp_ns(src, s.column, col)
        notes.append(f"time: {s.column} timestamps, measured from the first one")
        return (ns - ns[0]).astype(np.float64) * 1e-9
    if pa.types.is_integer(col.type) and unit != "s":
        _check_nulls(src, s.column, col)
        raw = col.to_numpy().astype(np.int64)
        notes.append(f"time: {s.column} in {unit}, measured from the first sample ({raw[0]} {unit})")
        return (raw - raw[0]).astype(np.float64) * units.unit_factor(units.TIME, unit) * s.sign
    x = numeric_column(src, s.column, "t" if s.column == CANONICAL["t"] else None)
    if unit == "s" and s.sign == 1.0:
        return x
    notes.append(f"time: {s.column} in {unit}, measured from the first sample")
    return (x - x[0]) * units.unit_factor(units.TIME, unit) * s.sign


def _timestamp_ns(src: SourceTable, name: str, col: pa.ChunkedArray) -> np.ndarray:
    _check_nulls(src, name, col)
    if pa.types.is_string(col.type) or pa.types.is_large_string(col.type):
        try:
            col = pc.cast(pc.utf8_trim_whitespace(col), pa.timestamp("ns"))
        except pa.ArrowInvalid:
            values = col.to_pylist()
            for i, v in enumerate(values):
                try:
                    pc.cast(pa.array([v.strip()]), pa.timestamp("ns"))
                except pa.ArrowInvalid:
                    line, row = _where(src, i)
                    raise WashbenchError(
                        located(src.path, f"{row}not a timestamp: {v!r}", line=line, field=name)
                    ) from None
            raise WashbenchError(located(src.path, "column is not a timestamp", field=name)) from None
    elif pa.types.is_timestamp(col.type) and col.type.tz is not None:
        col = col.cast(pa.timestamp(col.type.unit))
    return col.cast(pa.timestamp("ns")).cast(pa.int64()).to_numpy()


def _where(src: SourceTable, i: int) -> tuple[int | None, str]:
    if src.lines is not None:
        return int(src.lines[i]), ""
    return None, f"row {i + 1}: "


def _check_nulls(src: SourceTable, name: str, col: pa.ChunkedArray) -> None:
    nulls = col.is_null().to_numpy(zero_copy_only=False)
    if nulls.any():
        line, row = _where(src, int(np.argmax(nulls)))
        raise WashbenchError(located(src.path, f"{row}missing value", line=line, field=name))


_DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$")
"""A number written with a decimal comma (``0,000000``, ``-1,5e-3``)."""


def numeric_column(src: SourceTable, name: str, label: str | None = None) -> np.ndarray:
    """Column ``name`` as float64, checked: no missing, non-numeric, NaN or infinite values."""
    col = src.table.column(name)
    _check_nulls(src, name, col)
    if pa.types.is_string(col.type) or pa.types.is_large_string(col.type):
        stripped = pc.utf8_trim_whitespace(col)
        if src.decimal == ",":
            stripped = pc.replace_substring(stripped, ",", ".")
        try:
            col = pc.cast(stripped, pa.float64())
        except pa.ArrowInvalid:
            for i, v in enumerate(stripped.to_pylist()):
                try:
                    float(v)
                except ValueError:
                    line, row = _where(src, i)
                    hint = ""
                    if src.decimal == "." and _DECIMAL_COMMA.match(v):
                        hint = " (a decimal comma? read the file with --decimal ,)"
                    raise WashbenchError(
                        located(src.path, f"{row}not a number: {v!r}{hint}", line=line, field=name)
                    ) from None
            raise WashbenchError(located(src.path, "column is not numeric", field=name)) from None
    elif pa.types.is_integer(col.type) or pa.types.is_floating(col.type):
        col = pc.cast(col, pa.float64())
    else:
        raise WashbenchError(located(src.path, f"column is not numeric (type {col.type})", field=name))
    arr = col.to_numpy()
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.argmax(bad))
        line, row = _where(src, i)
        what = "NaN" if np.isnan(arr[i]) else "infinite"
        raise WashbenchError(located(src.path, f"{row}value is {what}", line=line, field=name))
    return np.ascontiguousarray(arr, dtype=np.float64)
