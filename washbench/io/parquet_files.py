"""Parquet files written the one washbench way, and the traces table (``traces.parquet``) written and read back.

The columns of the traces table are named in :mod:`washbench.io.columns`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from washbench.io.atomic import atomic_path


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


def _arrow(col: np.ndarray) -> pa.Array:
    """One column as Arrow (a masked array's masked values as nulls)."""
    return pa.array(col if isinstance(col, np.ma.MaskedArray) else np.asarray(col))


def write_trace_chunks(
    path: str | Path, chunks: Iterable[Mapping[str, np.ndarray]], metadata: Mapping[bytes, bytes] | None = None
) -> None:
    """Write consecutive row ranges of the traces table (each column name -> 1-D array, the same columns in each; a
    numpy masked array's masked values written empty, null)
    to Parquet at ``path`` (not atomic by itself), one row group each, with :func:`write_parquet`'s settings.

    ``metadata``: the schema's key-value metadata (provenance, :func:`washbench.io.provenance.parquet_metadata`).

    Each chunk is converted to Arrow here (without a copy where a column is contiguous), then encoded, compressed
    and written by a writer thread while ``chunks`` makes the next one: pyarrow releases the GIL while it writes,
    so a second core is not left idle. (The conversion stays here: done in the writer it would take the GIL back
    once per column, waiting each time for this thread to let go of it, and took longer than writing in turn.)
    The file is the same, byte for byte, as written one chunk after another: the row groups are written in
    order, one at a time. So a chunk's arrays must stay as they are until the chunk after the next one is asked
    for (a producer may fill two buffers in turn, not one).
    """
    writer: pq.ParquetWriter | None = None
    try:
        with ThreadPoolExecutor(max_workers=1, thread_name_prefix="washbench-traces") as pool:
            pending: Future[None] | None = None
            for chunk in chunks:  # made here while the writer writes the one before
                arrow = pa.table({name: _arrow(col) for name, col in chunk.items()})
                if writer is None:
                    schema = arrow.schema.with_metadata(dict(metadata)) if metadata else arrow.schema
                    writer = parquet_writer(path, schema)
                arrow = arrow.replace_schema_metadata(schema.metadata)
                if pending is not None:
                    pending.result()  # one chunk in the writer at a time; its error raised here
                pending = pool.submit(writer.write_table, arrow)
            if pending is not None:
                pending.result()
    finally:  # after the pool's end, which waits for a write still under way (an error in ``chunks``)
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
    """Read a traces.parquet back as column name -> numpy array (an empty float value, e.g. ``W.tilt_rate_degps`` of
    a washout that reports no tilt rate, as NaN)."""
    t = pq.read_table(path)
    return {name: t.column(name).to_numpy(zero_copy_only=False) for name in t.column_names}
