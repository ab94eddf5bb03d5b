"""A pilot-head motion file in the input format of ``washbench cue`` (CSV or Parquet, by the extension): read, written.

Columns :data:`washbench.io.columns.INPUT_COLUMNS`: ``t_s``, ``f_{x,y,z}_mps2`` (body specific force),
``omega_{x,y,z}_degps`` (body angular velocity, deg/s). CSV numbers are written in full precision (``repr``),
so ``read_motion`` gets back exactly what was written. The file is written atomically.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path, write_text_atomic
from washbench.io.columns import INPUT_COLUMNS
from washbench.io.motion import Motion
from washbench.io.readers import read_samples
from washbench.io.resample import split_resets, to_motion

SUFFIXES = {".csv": "csv", ".parquet": "parquet", ".pq": "parquet"}  # what this writer writes


def write_motion(path: str | Path, t_s: np.ndarray, f_mps2: np.ndarray, omega_radps: np.ndarray) -> Path:
    """Write t_s (N,) [s], f_mps2 (N, 3) [m/s^2], omega_radps (N, 3) [rad/s] to ``path`` (.csv or .parquet).

    Raises WashbenchError (one line naming the file) for an unknown extension, a folder, or a write error.
    """
    path = Path(path)
    kind = SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise WashbenchError(located(path, f"unknown extension {path.suffix!r} (use {', '.join(SUFFIXES)})"))
    if path.is_dir():
        raise WashbenchError(located(path, "is a folder, not a file"))
    cols = np.column_stack([t_s, f_mps2, np.degrees(omega_radps)])
    try:
        if kind == "csv":
            buf = io.StringIO()
            buf.write(",".join(INPUT_COLUMNS) + "\n")
            for row in cols.tolist():
                buf.write(",".join(repr(v) if math.isfinite(v) else "nan" for v in row) + "\n")
            write_text_atomic(path, buf.getvalue())
        else:
            table = pa.table({name: pa.array(cols[:, i]) for i, name in enumerate(INPUT_COLUMNS)})
            with atomic_path(path) as tmp:
                pq.write_table(table, tmp)
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot write: {exc.strerror or exc}")) from None
    return path


def read_motion(path: str | Path) -> Motion:
    """Read a motion trace in washbench's own columns and units (CSV, Parquet, ...) on a uniform grid.

    The plain form of ``washbench cue INPUT`` (no mapping, resampling or splitting; see
    :mod:`washbench.io.readers` and :mod:`washbench.io.resample` for those). Raises WashbenchError with one
    line naming the file (and, for text files, the line) for: a missing, unreadable or empty file, an
    unknown extension, no or one data row, a missing or non-numeric column, missing, NaN or infinite
    values, time that does not increase, jumps back or is not uniform.
    """
    samples = read_samples(Path(path))
    (only,) = split_resets(samples, split=False)
    return to_motion(only)
