"""Reading recorded pilot-head motion from any of the supported files into :class:`Samples`.

Files (chosen by extension, then by the header):

- CSV text, ``.csv``/``.tsv``/``.txt``, optionally gzip-compressed (``.gz``): the delimiter (comma,
  semicolon, tab or ``|``) is detected from the header line or given; lines starting with ``#`` are
  comments (skipped); header names are trimmed of surrounding whitespace. Read with pyarrow's CSV reader.
- Parquet (``.parquet``, ``.pq``): float32, float64 or integer columns.
- X-Plane's Data Output file ``Data.txt`` (:mod:`washbench.io.xplane`): pipe-separated, padded headers.
- JSBSim's own CSV output (header ``Time, ..., accelerations/a-pilot-x-ft_sec2, ...``): the eyepoint
  specific force (ft/s^2) and the body rates (``velocities/p-rad_sec`` ... or the ``<rates>`` group's
  ``P (deg/s)``); JSBSim's pilot accelerations lag its other outputs by one frame, so they are shifted
  back by one row (the last row, which has none, is dropped).

Every reader ends in the same conversion (:func:`convert`): the format's column mapping, overridden
field by field by the user's (``--columns`` or ``--input-format FILE``), picks one source column per
motion field with its unit and sign; :mod:`washbench.io.units` turns them into s, m/s^2 and deg/s and the
sensor axes into body axes. A column already in washbench's units and axes is passed through untouched,
so a ``washbench fly`` trace is read back bit for bit.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv
import pyarrow.parquet as pq
from pydantic import Field

from washbench.errors import WashbenchError, located
from washbench.io import units
from washbench.io.results import INPUT_COLUMNS
from washbench.io.yamlio import StrictModel, line_of, read_yaml, validate_data

FIELDS = ("t", "f_x", "f_y", "f_z", "omega_x", "omega_y", "omega_z")
"""The motion fields a mapping names (``t`` time, ``f_*`` specific force, ``omega_*`` angular velocity)."""

QUANTITY = {"t": units.TIME} | {f"f_{a}": units.FORCE for a in "xyz"} | {f"omega_{a}": units.RATE for a in "xyz"}
CANONICAL = dict(zip(FIELDS, INPUT_COLUMNS, strict=True))

KINDS = ("auto", "csv", "parquet", "xplane", "jsbsim")
TEXT_SUFFIXES = (".csv", ".tsv", ".txt")
PARQUET_SUFFIXES = (".parquet", ".pq")
DELIMITERS = {",": "comma", ";": "semicolon", "\t": "tab", "|": "pipe"}


@dataclass(frozen=True)
class ColumnSource:
    """Where one motion field comes from: a source column, its unit and a sign (+1 or -1)."""

    column: str
    unit: str
    sign: float = 1.0

    def describe(self) -> str:
        return f"{'-' if self.sign < 0 else ''}{self.column}:{self.unit}"


@dataclass(frozen=True)
class InputFormat:
    """How to read an input: file kind, delimiter, column mapping overrides and sensor axes.

    ``columns`` maps motion fields (:data:`FIELDS`) to their sources; fields not named keep the
    file kind's default (washbench's own column names for CSV and Parquet). ``origin`` names where the
    mapping came from, for error messages (``--columns`` or the YAML file).
    """

    kind: str = "auto"
    delimiter: str | None = None
    columns: Mapping[str, ColumnSource] = field(default_factory=dict)
    axes: str = "frd"
    origin: str = "--columns"


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
        )


# --------------------------------------------------------------------------- the mapping option


_SPEC = re.compile(r"^\s*(-?)\s*(.+?)\s*$")


def parse_column_source(field_name: str, text: str, where: str) -> ColumnSource:
    """``[-]COLUMN[:UNIT]`` for motion field ``field_name``; the unit defaults to washbench's own."""
    m = _SPEC.match(text)
    if not m or not m.group(2):
        raise WashbenchError(f"{where}: {field_name}: expected [-]COLUMN[:UNIT], got {text!r}")
    sign = -1.0 if m.group(1) else 1.0
    column, unit = m.group(2), units.CANONICAL_UNIT[QUANTITY[field_name]]
    if ":" in column:
        head, tail = column.rsplit(":", 1)
        column, unit = head.strip(), tail.strip()
    try:
        units.unit_factor(QUANTITY[field_name], unit)
    except ValueError as exc:
        raise WashbenchError(f"{where}: {field_name}: {exc}") from None
    if not column:
        raise WashbenchError(f"{where}: {field_name}: no column name in {text!r}")
    return ColumnSource(column=column, unit=units.normalise_unit(unit), sign=sign)


def field_name_of(key: str, where: str) -> str:
    """The motion field for a mapping key (``t``, ``f_x`` ... or washbench's column names ``t_s``, ``f_x_mps2``)."""
    k = key.strip()
    for name, canonical in CANONICAL.items():
        if k in (name, canonical):
            return name
    raise WashbenchError(f"{where}: unknown field {key!r} (valid: {', '.join(FIELDS)})")


def parse_columns_option(text: str) -> dict[str, ColumnSource]:
    """``--columns t=Time:ms,f_x=ax:g,...`` into a mapping (commas separate fields; use a YAML file for
    column names that contain commas)."""
    out: dict[str, ColumnSource] = {}
    for item in (s for s in text.split(",") if s.strip()):
        if "=" not in item:
            raise WashbenchError(f"--columns: expected FIELD=COLUMN[:UNIT], got {item.strip()!r}")
        key, spec = item.split("=", 1)
        name = field_name_of(key, "--columns")
        if name in out:
            raise WashbenchError(f"--columns: {name} is given twice")
        out[name] = parse_column_source(name, spec, "--columns")
    return out


def check_delimiter(text: str | None, where: str) -> str | None:
    """A delimiter option: one character, or the names comma, semicolon, tab, pipe."""
    if text is None:
        return None
    names = {v: k for k, v in DELIMITERS.items()}
    d = names.get(text.lower(), text.replace("\\t", "\t"))
    if len(d) != 1 or d in '"\n\r#':
        raise WashbenchError(f"{where}: delimiter must be one character or one of {', '.join(names)}, got {text!r}")
    return d


# --------------------------------------------------------------------------- tables


@dataclass(frozen=True)
class SourceTable:
    """A file read as a table: its kind, the table, and the file line of each row (text files)."""

    path: Path
    kind: str
    table: pa.Table
    lines: np.ndarray | None


def file_kind(path: Path) -> str:
    """``"text"`` or ``"parquet"`` from the extension (``.gz`` stripped); WashbenchError otherwise."""
    suffixes = [s.lower() for s in path.suffixes]
    if suffixes and suffixes[-1] == ".gz":
        suffixes = suffixes[:-1]
        if suffixes and suffixes[-1] in PARQUET_SUFFIXES:
            raise WashbenchError(located(path, "gzip-compressed Parquet is not supported: Parquet compresses itself"))
    last = suffixes[-1] if suffixes else ""
    if last in TEXT_SUFFIXES:
        return "text"
    if last in PARQUET_SUFFIXES:
        return "parquet"
    shown = "".join(path.suffixes[-2:]) if path.suffixes else "(no extension)"
    raise WashbenchError(
        located(path, f"unknown file type {shown!r}: expected .csv, .tsv, .txt (optionally .gz) or .parquet")
    )


def _head_lines(path: Path, limit: int = 1 << 16) -> list[str]:
    """The first lines of a text file (decompressed), for sniffing the header and delimiter."""
    try:
        with pa.input_stream(str(path), compression="detect") as f:
            raw = f.read(limit)
    except (OSError, pa.ArrowException) as exc:
        raise WashbenchError(located(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}")) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(raw) - 4:  # not just a multi-byte character cut at the end of the block
            raise WashbenchError(located(path, "not a readable CSV file: it is not UTF-8 text")) from None
        text = raw[: exc.start].decode("utf-8")
    lines = text.splitlines()
    return lines[:-1] if len(raw) == limit and len(lines) > 1 else lines


def _header(path: Path, delimiter: str | None) -> tuple[int, list[str], str]:
    """(line number of the header, 1-based; trimmed column names; delimiter) of a text file."""
    lines = _head_lines(path)
    for i, line in enumerate(lines):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        if delimiter is None:  # the one found as often in the header as in the first data line (X-Plane's
            # header holds as many commas as pipes), the most frequent one if none is
            data = next((x for x in lines[i + 1 :] if x.strip() and not x.lstrip().startswith("#")), line)
            counts = {d: (min(line.count(d), data.count(d)), line.count(d)) for d in DELIMITERS}
            best = max(counts, key=lambda d: counts[d])
            delimiter = best if counts[best][1] > 0 else ","
        names = [n.strip().strip('"').strip() for n in line.split(delimiter)]
        if names and names[-1] == "" and len(names) > 1:  # a trailing delimiter (X-Plane writes one)
            names[-1] = "_trailing"
        return i + 1, names, delimiter
    raise WashbenchError(located(path, "the file is empty" if not lines else "no header line (only comments)"))


def read_text_table(path: Path, delimiter: str | None, string_columns: set[str]) -> SourceTable:
    """A CSV-like text file with pyarrow: header and delimiter sniffed, ``#`` lines skipped, names trimmed.

    ``string_columns`` are read as text (converted later with errors that name the line and value).
    """
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot read: {exc.strerror or exc}")) from None
    if size == 0:
        raise WashbenchError(located(path, "the file is empty"))
    header_line, names, delim = _header(path, delimiter)
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise WashbenchError(located(path, f"column {dup[0]!r} appears more than once", line=header_line))
    skipped: list[int] = []
    wrong: list[tuple[int, str]] = []

    def on_invalid(row: pacsv.InvalidRow) -> str:
        if row.text.lstrip().startswith("#"):
            skipped.append(row.number)
            return "skip"
        wrong.append((row.number, f"expected {row.expected_columns} fields, got {row.actual_columns}"))
        return "error"

    read = pacsv.ReadOptions(
        use_threads=False,
        block_size=int(min(max(size + 1, 1 << 20), (1 << 31) - 1)),
        skip_rows=header_line,
        column_names=names,
    )
    parse = pacsv.ParseOptions(delimiter=delim, ignore_empty_lines=False, invalid_row_handler=on_invalid)
    convert = pacsv.ConvertOptions(
        null_values=[""],
        strings_can_be_null=True,
        column_types={c: pa.string() for c in names if c in string_columns},
    )
    try:
        table = pacsv.read_csv(path, read_options=read, parse_options=parse, convert_options=convert)
    except pa.ArrowInvalid as exc:
        if wrong:
            raise WashbenchError(located(path, f"wrong number of fields ({wrong[0][1]})", line=wrong[0][0])) from None
        text = str(exc)
        if "Empty CSV" in text:
            raise WashbenchError(located(path, "no data rows")) from None
        if "UTF8" in text or "utf8" in text.lower():
            raise WashbenchError(located(path, "not a readable CSV file: it is not UTF-8 text")) from None
        raise WashbenchError(located(path, f"not a readable CSV file: {text}")) from None
    except UnicodeDecodeError:
        raise WashbenchError(located(path, "not a readable CSV file: it is not UTF-8 text")) from None
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}")) from None
    table = _drop_trailing_empty_rows(table)
    if "_trailing" in table.column_names and table.column("_trailing").null_count == table.num_rows:
        table = table.drop_columns(["_trailing"])
    lines = header_line + 1 + np.arange(table.num_rows, dtype=np.int64)
    if skipped:  # every data line after a skipped comment moves down by one
        skip = np.asarray(sorted(skipped), dtype=np.int64)
        for s in skip:
            lines[lines >= s] += 1
    return SourceTable(path=path, kind="csv", table=table, lines=lines)


def read_parquet_table(path: Path) -> SourceTable:
    try:
        table = pq.read_table(path)
    except FileNotFoundError:
        raise WashbenchError(located(path, "no such file")) from None
    except IsADirectoryError:
        raise WashbenchError(located(path, "is a folder, not a file")) from None
    except PermissionError as exc:
        raise WashbenchError(located(path, f"cannot read: {exc.strerror}")) from None
    except (pa.ArrowException, OSError) as exc:
        if path.is_file() and path.stat().st_size == 0:
            raise WashbenchError(located(path, "the file is empty")) from None
        raise WashbenchError(located(path, f"not a readable Parquet file ({exc})")) from None
    return SourceTable(path=path, kind="parquet", table=table, lines=None)


def _drop_trailing_empty_rows(table: pa.Table) -> pa.Table:
    """Blank lines at the end of a CSV file read as all-null rows: drop them."""
    n = table.num_rows
    if n == 0 or table.num_columns == 0:
        return table
    all_null = np.ones(n, dtype=bool)
    for col in table.columns:
        all_null &= col.is_null().to_numpy(zero_copy_only=False)
    end = n
    while end > 0 and all_null[end - 1]:
        end -= 1
    return table.slice(0, end) if end < n else table


# --------------------------------------------------------------------------- format defaults


def default_mapping(kind: str, names: list[str]) -> dict[str, ColumnSource]:
    """The column mapping a file kind implies (washbench's own names for CSV and Parquet)."""
    from washbench.io import xplane

    if kind == "xplane":
        return xplane.default_mapping(names)
    if kind == "jsbsim":
        return jsbsim_mapping(names)
    return {f: ColumnSource(CANONICAL[f], units.CANONICAL_UNIT[QUANTITY[f]]) for f in FIELDS}


JSBSIM_F = tuple(f"accelerations/a-pilot-{a}-ft_sec2" for a in "xyz")
_JSBSIM_RATES = (
    (tuple(f"velocities/{r}-rad_sec" for r in "pqr"), "radps"),
    (("P (deg/s)", "Q (deg/s)", "R (deg/s)"), "degps"),
    (("P_{Body} (deg/s)", "Q_{Body} (deg/s)", "R_{Body} (deg/s)"), "degps"),
)


def _jsbsim_column(names: list[str], prop: str) -> str | None:
    """The header of property ``prop`` in a JSBSim CSV (written as given or with the ``/fdm/jsbsim/`` prefix)."""
    for n in (prop, f"/fdm/jsbsim/{prop}"):
        if n in names:
            return n
    return None


def is_jsbsim_header(names: list[str]) -> bool:
    return "Time" in names and all(_jsbsim_column(names, c) for c in JSBSIM_F)


def jsbsim_mapping(names: list[str]) -> dict[str, ColumnSource]:
    """JSBSim CSV output: ``Time`` [s], the pilot accelerations [ft/s^2] and the body rates."""
    out = {"t": ColumnSource("Time", "s")}
    for a, prop in zip("xyz", JSBSIM_F, strict=True):
        col = _jsbsim_column(names, prop)
        if col is not None:
            out[f"f_{a}"] = ColumnSource(col, "ftps2")
    for cols, unit in _JSBSIM_RATES:
        found = [_jsbsim_column(names, c) for c in cols]
        if all(found):
            out |= {f"omega_{a}": ColumnSource(str(c), unit) for a, c in zip("xyz", found, strict=True)}
            break
    return out


def detect_kind(path: Path, fmt: InputFormat) -> tuple[str, str | None]:
    """(kind, delimiter) of ``path`` under ``fmt`` (``auto`` looks at the extension, then the header)."""
    from washbench.io import xplane

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
    _, names, delim = _header(path, fmt.delimiter)
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
    kind, delim = detect_kind(path, fmt)
    if kind == "parquet":
        src = read_parquet_table(path)
    else:
        _, names, delim = _header(path, delim)
        mapping = default_mapping(kind, names) | dict(fmt.columns)
        src = read_text_table(path, delim, {s.column for s in mapping.values()})
        src = SourceTable(path=src.path, kind=kind, table=src.table, lines=src.lines)
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
    )
    if src.kind == "jsbsim":
        samples = shift_jsbsim_lag(samples)
    return samples


def shift_jsbsim_lag(s: Samples) -> Samples:
    """JSBSim logs ``a-pilot`` one frame late: row k + 1 holds sample k's value. Shift it back, drop the last row."""
    n = s.n
    f = np.ascontiguousarray(s.f_mps2[1:])
    out = s.take(slice(0, n - 1), ("JSBSim's pilot accelerations shifted back one row (their one-frame lag)",))
    return Samples(out.path, out.kind, out.t_s, f, out.omega_degps, out.extra, out.lines, out.notes, out.time_column)


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


def numeric_column(src: SourceTable, name: str, label: str | None = None) -> np.ndarray:
    """Column ``name`` as float64, checked: no missing, non-numeric, NaN or infinite values."""
    col = src.table.column(name)
    _check_nulls(src, name, col)
    if pa.types.is_string(col.type) or pa.types.is_large_string(col.type):
        stripped = pc.utf8_trim_whitespace(col)
        try:
            col = pc.cast(stripped, pa.float64())
        except pa.ArrowInvalid:
            for i, v in enumerate(stripped.to_pylist()):
                try:
                    float(v)
                except ValueError:
                    line, row = _where(src, i)
                    raise WashbenchError(
                        located(src.path, f"{row}not a number: {v!r}", line=line, field=name)
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


# --------------------------------------------------------------------------- the input-format file


class InputFormatFile(StrictModel):
    """``--input-format FILE``: the same as the command-line options, in YAML::

    format: csv              # auto (default) | csv | parquet | xplane | jsbsim
    delimiter: ";"           # or comma, semicolon, tab, pipe; default: detected
    axes: flu                # sensor axes (see washbench.io.units); default frd
    columns:                 # FIELD: "[-]COLUMN[:UNIT]" (column names may hold commas here)
      t: "Time:ms"
      f_x: "ax:g"
      omega_x: "p:radps"
    """

    format: Literal["auto", "csv", "parquet", "xplane", "jsbsim"] = "auto"
    delimiter: str | None = None
    axes: str = "frd"
    columns: dict[str, str] = Field(default_factory=dict)


def load_input_format(path: str | Path) -> InputFormat:
    """Read an ``--input-format`` YAML file; errors name the file, line and key."""
    path = Path(path)
    data, lines = read_yaml(path)
    doc = validate_data(path, data, lines, InputFormatFile)
    columns: dict[str, ColumnSource] = {}
    for key, spec in doc.columns.items():
        where = f"{path}:{line_of(lines, ('columns', key)) or 1}: columns.{key}"
        name = field_name_of(key, where)
        columns[name] = parse_column_source(name, spec, where)
    where = f"{path}:{line_of(lines, ('axes',)) or 1}: axes"
    try:
        units.axes_matrix(doc.axes)
    except ValueError as exc:
        raise WashbenchError(f"{where}: {exc}") from None
    delim = check_delimiter(doc.delimiter, f"{path}:{line_of(lines, ('delimiter',)) or 1}: delimiter")
    return InputFormat(kind=doc.format, delimiter=delim, columns=columns, axes=doc.axes, origin=str(path))


def input_format(
    columns: str | None = None,
    format_file: str | Path | None = None,
    axes: str | None = None,
    delimiter: str | None = None,
) -> InputFormat:
    """The input format from the command line: ``--input-format FILE`` first, then ``--columns`` (field by
    field), ``--axes`` and ``--delimiter`` over it."""
    fmt = load_input_format(format_file) if format_file is not None else InputFormat()
    cols = dict(fmt.columns)
    origin = fmt.origin
    if columns:
        cols |= parse_columns_option(columns)
        origin = "--columns" if format_file is None else f"{fmt.origin} and --columns"
    if axes is not None:
        try:
            units.axes_matrix(axes)
        except ValueError as exc:
            raise WashbenchError(f"--axes: {exc}") from None
    return InputFormat(
        kind=fmt.kind,
        delimiter=check_delimiter(delimiter, "--delimiter") if delimiter is not None else fmt.delimiter,
        columns=cols,
        axes=axes if axes is not None else fmt.axes,
        origin=origin,
    )
