"""Text and Parquet files read as pyarrow tables, with the file line of every row (for error messages).

Text (``.csv``, ``.tsv``, ``.txt``, each optionally ``.gz``): the header line and the delimiter are sniffed
from the first lines (comment lines start with ``#``), the header names trimmed, then pyarrow's CSV reader
reads the rest with those names (comment lines in the data are skipped and counted, so line numbers stay
right). Parquet: ``pyarrow.parquet``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from washbench.errors import WashbenchError, located
from washbench.io.budget import MAX_SAMPLES, MAX_TEXT_BYTES
from washbench.io.input_format import DELIMITERS

TEXT_SUFFIXES = (".csv", ".tsv", ".txt")
PARQUET_SUFFIXES = (".parquet", ".pq")


@dataclass(frozen=True)
class SourceTable:
    """A file read as a table: its kind, the table, and the file line of each row (text files)."""

    path: Path
    kind: str
    table: pa.Table
    lines: np.ndarray | None
    decimal: str = "."


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
        text = raw.decode("utf-8-sig")  # a byte-order mark (Excel's "CSV UTF-8") is dropped
    except UnicodeDecodeError as exc:
        if exc.start < len(raw) - 4:  # not just a multi-byte character cut at the end of the block
            raise WashbenchError(located(path, "not a readable CSV file: it is not UTF-8 text")) from None
        text = raw[: exc.start].decode("utf-8-sig")
    lines = text.splitlines()
    return lines[:-1] if len(raw) == limit and len(lines) > 1 else lines


def header(path: Path, delimiter: str | None) -> tuple[int, list[str], str]:
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


def _check_text_size(path: Path) -> None:
    """Stream the (decompressed) text once, refusing it beyond the allocation bound before it is parsed: a small
    gzip file expanding to gigabytes, or millions of blank lines, costs a second and no memory."""

    size = lines = 0
    try:
        with pa.input_stream(str(path), compression="detect") as f:
            while block := f.read(1 << 22):
                size += len(block)
                lines += block.count(b"\n")
                if size > MAX_TEXT_BYTES or lines > MAX_SAMPLES + 10_000:
                    what = f"more than {MAX_TEXT_BYTES // 2**30} GiB" if size > MAX_TEXT_BYTES else f"{lines:,}+ lines"
                    raise WashbenchError(located(path, f"{what} of text (decompressed): more than washbench reads "
                                                       f"for one time series ({MAX_SAMPLES:,} rows)"))  # fmt: skip
    except (OSError, pa.ArrowException) as exc:
        raise WashbenchError(located(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}")) from None


def read_text_table(path: Path, delimiter: str | None, string_columns: set[str], decimal: str = ".") -> SourceTable:
    """A CSV-like text file with pyarrow: header and delimiter sniffed, ``#`` lines skipped, names trimmed.

    ``string_columns`` are read as text (converted later with errors that name the line and value); the other
    numbers are read with the decimal mark ``decimal``.
    """
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot read: {exc.strerror or exc}")) from None
    if size == 0:
        raise WashbenchError(located(path, "the file is empty"))
    header_line, names, delim = header(path, delimiter)
    _check_text_size(path)
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

    convert = pacsv.ConvertOptions(
        null_values=[""],
        strings_can_be_null=True,
        decimal_point=decimal,
        column_types={c: pa.string() for c in names if c in string_columns},
    )
    table = _threaded_read(path, header_line, names, delim, convert)
    if table is not None:  # every line a data row: their numbers follow from the header's
        return _source(path, table, header_line, [], decimal)
    read = pacsv.ReadOptions(
        use_threads=False,
        block_size=int(min(max(size + 1, 1 << 20), (1 << 31) - 1)),
        skip_rows=header_line,
        column_names=names,
    )
    parse = pacsv.ParseOptions(delimiter=delim, ignore_empty_lines=False, invalid_row_handler=on_invalid)
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
    return _source(path, table, header_line, skipped, decimal)


def _threaded_read(
    path: Path, header_line: int, names: list[str], delim: str, convert: pacsv.ConvertOptions
) -> pa.Table | None:
    """The file read in blocks on pyarrow's threads, or None where any line is not a data row (a comment, an empty
    line, a wrong number of fields) or the read fails: the one-block read (:func:`read_text_table`) then reads it
    again, on one thread, which knows each row's line number for the skip or the error. A read in blocks gives the
    columns the one-block read gives (pyarrow promotes a column's type across blocks: integers then decimals are
    decimals, as read whole). The 31 MB of a 30-minute 120 Hz log: 0.16-0.25 s in a cue instead of 0.5-0.65 s."""
    read = pacsv.ReadOptions(use_threads=True, skip_rows=header_line, column_names=names)
    parse = pacsv.ParseOptions(delimiter=delim, ignore_empty_lines=False, invalid_row_handler=lambda row: "error")
    try:
        return pacsv.read_csv(path, read_options=read, parse_options=parse, convert_options=convert)
    except (pa.ArrowException, OSError, UnicodeDecodeError, ValueError):
        return None


def _source(path: Path, table: pa.Table, header_line: int, skipped: list[int], decimal: str) -> SourceTable:
    """The table read, its trailing empty rows dropped, with each row's line number (1-based; ``skipped``: the comment
    lines skipped, each moving the data lines after it down by one)."""
    table = _drop_trailing_empty_rows(table)
    if "_trailing" in table.column_names and table.column("_trailing").null_count == table.num_rows:
        table = table.drop_columns(["_trailing"])
    lines = header_line + 1 + np.arange(table.num_rows, dtype=np.int64)
    if skipped:  # every data line after a skipped comment moves down by one
        skip = np.asarray(sorted(skipped), dtype=np.int64)
        for s in skip:
            lines[lines >= s] += 1
    return SourceTable(path=path, kind="csv", table=table, lines=lines, decimal=decimal)


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
