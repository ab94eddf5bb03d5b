"""How an input names its motion columns: the column mapping, its units and axes, the ``--input-format`` file.

``--columns field=[-]COLUMN[:UNIT],...`` and ``--input-format FILE`` (YAML) both give an
:class:`InputFormat`: per motion field (:data:`FIELDS`) its source column, unit and sign, the sensor axes,
the file kind and the delimiter. :mod:`washbench.io.readers` applies it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from pydantic import Field

from washbench.errors import WashbenchError
from washbench.io import units
from washbench.io.columns import INPUT_COLUMNS
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
    decimal: str = "."
    """The decimal mark of a text file's numbers: ``.`` or ``,`` (``--decimal``)."""
    jsbsim_dt_s: float | None = None
    """A JSBSim CSV log's simulation frame time [s] (``--jsbsim-dt``): its pilot accelerations lag one frame."""


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


# --------------------------------------------------------------------------- the input-format file


class InputFormatFile(StrictModel):
    """``--input-format FILE``: the same as the command-line options, in YAML::

    format: csv              # auto (default) | csv | parquet | xplane | jsbsim
    delimiter: ";"           # or comma, semicolon, tab, pipe; default: detected
    axes: flu                # sensor axes (see washbench.io.units); default frd
    decimal: ","             # decimal mark of the numbers, "." (default) or ","
    jsbsim_dt_s: 0.0083333   # JSBSim CSV: the simulation's frame time (the script's <run dt>)
    columns:                 # FIELD: "[-]COLUMN[:UNIT]" (column names may hold commas here)
      t: "Time:ms"
      f_x: "ax:g"
      omega_x: "p:radps"
    """

    format: Literal["auto", "csv", "parquet", "xplane", "jsbsim"] = "auto"
    delimiter: str | None = None
    axes: str = "frd"
    decimal: Literal[".", ","] = "."
    jsbsim_dt_s: float | None = Field(default=None, gt=0.0, allow_inf_nan=False)
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
    if delim == doc.decimal:
        raise WashbenchError(f"{path}:{line_of(lines, ('decimal',)) or 1}: decimal: the delimiter is {delim!r} too")
    return InputFormat(
        kind=doc.format, delimiter=delim, columns=columns, axes=doc.axes, origin=str(path), decimal=doc.decimal,
        jsbsim_dt_s=doc.jsbsim_dt_s,
    )  # fmt: skip


def input_format(
    columns: str | None = None,
    format_file: str | Path | None = None,
    axes: str | None = None,
    delimiter: str | None = None,
    decimal: str | None = None,
    jsbsim_dt_s: float | None = None,
) -> InputFormat:
    """The input format from the command line: ``--input-format FILE`` first, then ``--columns`` (field by
    field), ``--axes``, ``--delimiter``, ``--decimal`` and ``--jsbsim-dt`` over it."""
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
    if decimal is not None and decimal not in (".", ","):
        raise WashbenchError(f"--decimal: expected '.' or ',', got {decimal!r}")
    if jsbsim_dt_s is not None and not (0.0 < jsbsim_dt_s < 1.0):
        raise WashbenchError(f"--jsbsim-dt: expected a frame time in seconds (0 .. 1), got {jsbsim_dt_s!r}")
    delim = check_delimiter(delimiter, "--delimiter") if delimiter is not None else fmt.delimiter
    mark = decimal if decimal is not None else fmt.decimal
    if delim == mark:
        raise WashbenchError(f"--decimal {mark}: the delimiter is {mark!r} too (give --delimiter ';' or tab)")
    return InputFormat(
        kind=fmt.kind,
        delimiter=delim,
        columns=cols,
        axes=axes if axes is not None else fmt.axes,
        origin=origin,
        decimal=mark,
        jsbsim_dt_s=jsbsim_dt_s if jsbsim_dt_s is not None else fmt.jsbsim_dt_s,
    )
