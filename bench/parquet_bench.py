"""traces.parquet: write time and file size of codecs and row-group layouts, on a real cue's traces table.

    .venv/bin/python bench/parquet_bench.py [--minutes 30] [--repeat 3]

The table is the traces table ``washbench cue`` writes for a ``--minutes`` 120 Hz synthetic recording (the input of
``bench/cue_bench.py``, three washouts: 149 columns at 30 minutes, 216,000 rows), made once by ``washbench cue
--no-recording --no-figures`` and read back. Each layout writes it from memory, in row groups of ``rows`` rows as
the command streams them (the command's chunk: 8,192), the minimum CPU time of ``--repeat`` writes (on a shared
machine CPU time is the steadier figure), against the command's own layout timed in the same run (zstd,
byte-stream-split floats, dictionary-encoded other columns: :func:`washbench.io.parquet_files.parquet_writer`).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cue_bench import write_input


def layouts(schema: pa.Schema) -> dict[str, dict[str, object]]:
    floats = [f.name for f in schema if pa.types.is_floating(f.type)]
    others = [f.name for f in schema if not pa.types.is_floating(f.type)]
    base = {"use_dictionary": others, "use_byte_stream_split": floats}
    return {
        "zstd (level 1), BSS floats [current]": {**base, "compression": "zstd"},
        "zstd level 3, BSS floats": {**base, "compression": "zstd", "compression_level": 3},
        "lz4, BSS floats": {**base, "compression": "lz4"},
        "snappy, BSS floats": {**base, "compression": "snappy"},
        "zstd, plain floats": {"use_dictionary": others, "compression": "zstd"},
        "none, BSS floats": {**base, "compression": "none"},
    }


def write_cpu(table: pa.Table, path: Path, options: dict[str, object], rows: int, repeat: int) -> tuple[float, int]:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        with pq.ParquetWriter(path, table.schema, **options) as writer:  # type: ignore[arg-type]
            for k in range(0, table.num_rows, rows):
                writer.write_table(table.slice(k, rows))
        best = min(best, time.process_time() - t0)
    return best, path.stat().st_size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="wb-pq-") as tmp:
        root = Path(tmp)
        src = root / "in.csv"
        write_input(src, int(args.minutes * 60 * 120))
        subprocess.run([sys.executable, "-m", "washbench", "cue", str(src), "--out", str(root / "cue"),
                        "--no-recording", "--no-figures"], check=True, stdout=subprocess.DEVNULL)  # fmt: skip
        table = pq.read_table(root / "cue" / "traces.parquet").replace_schema_metadata(None)
        print(f"traces table: {table.num_rows:,} rows x {table.num_columns} columns, "
              f"{sum(c.nbytes for c in table.columns) / 1e6:.0f} MB in memory")  # fmt: skip
        ref = None
        for name, options in layouts(table.schema).items():
            for rows in (8192, 65536):
                cpu, size = write_cpu(table, root / "t.parquet", options, rows, args.repeat)
                if ref is None:
                    ref = (cpu, size)
                print(f"  {name:<38} row groups {rows:>6}: {cpu:6.2f} s CPU ({cpu / ref[0]:4.2f}x), "
                      f"{size / 1e6:7.1f} MB ({size / ref[1]:4.2f}x)")  # fmt: skip
        np.testing.assert_equal(table.num_rows, pq.read_table(root / "t.parquet").num_rows)


if __name__ == "__main__":
    main()
