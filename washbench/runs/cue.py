"""``washbench cue``: washouts, Atlas model, vestibular models and metrics on a recorded trace.

Two layers, so the flight pipeline (which builds washout traces in lockstep with JSBSim) shares
the post-processing:

* :func:`analyse` (motion + finished washout traces -> perception, metrics, tables);
* :func:`cue_motion` = ``cueing.cue_trace`` + :func:`analyse`;
* :func:`run_cue` (the CLI): validate, load, compute, then write ``traces.parquet`` and
  ``metrics.csv`` atomically into the output folder.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import pyarrow as pa

from washbench.analysis.metrics import MetricRow, dof_metrics
from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path
from washbench.io.results import (
    AIRCRAFT,
    TIME_COLUMN,
    Motion,
    acc_columns,
    f_columns,
    omega_columns,
    omega_platform_columns,
    perceived_f_columns,
    perceived_omega_columns,
    pos_columns,
    q_columns,
    read_motion,
    sat_column,
    sp_pos_columns,
    sp_q_columns,
    vel_columns,
    wheel_columns,
    write_metrics_csv,
    write_traces,
)
from washbench.perception.vestibular import Perceived, VestibularModel, VestibularParams

TRACES_FILE = "traces.parquet"
METRICS_FILE = "metrics.csv"

_DEG = 180.0 / math.pi


class TraceLike(Protocol):
    """What :func:`analyse` needs of a washout trace (``washbench.cueing.WashoutTrace``), arrays of N rows."""

    pos_m: np.ndarray  # (N, 3) NED [m]
    vel_mps: np.ndarray  # (N, 3) NED [m/s]
    acc_mps2: np.ndarray  # (N, 3) NED [m/s^2]
    q: np.ndarray  # (N, 4) body -> inertial, scalar first
    omega_radps: np.ndarray  # (N, 3) platform angular velocity, body [rad/s]
    head_f_mps2: np.ndarray  # (N, 3) simulator pilot's specific force, body [m/s^2]
    head_omega_radps: np.ndarray  # (N, 3) simulator pilot's angular velocity, body [rad/s]
    wheel_radps: np.ndarray  # (N, 3)
    sp_pos_m: np.ndarray  # (N, 3) position set point, NED [m]
    sp_q: np.ndarray  # (N, 4) attitude set point, body -> inertial
    saturated: Mapping[str, np.ndarray]  # kind -> bool (N,)
    saturation_counts: Mapping[str, int]


@dataclass(frozen=True, eq=False)
class CueResult:
    """Everything ``washbench cue`` computes for one input trace.

    ``perceived``: pilot name (``"aircraft"`` or a washout name) -> perceived motion;
    ``metrics``: six rows per washout (:mod:`washbench.analysis.metrics`); ``table``: the traces.parquet
    columns in order (:mod:`washbench.io.results`); ``traces``: the washout traces themselves.
    """

    motion: Motion
    traces: Mapping[str, TraceLike]
    perceived: Mapping[str, Perceived]
    metrics: list[MetricRow]
    table: dict[str, np.ndarray]


_TRACE_FIELDS = {
    "pos_m": 3,
    "vel_mps": 3,
    "acc_mps2": 3,
    "q": 4,
    "omega_radps": 3,
    "head_f_mps2": 3,
    "head_omega_radps": 3,
    "wheel_radps": 3,
    "sp_pos_m": 3,
    "sp_q": 4,
}


def _checked_trace(name: str, trace: TraceLike, n: int, first: int = 0) -> dict[str, np.ndarray]:
    """The trace's arrays as float64, checked for shape and finiteness (a non-finite value is an error)."""
    out = {}
    for attr, width in _TRACE_FIELDS.items():
        a = np.asarray(getattr(trace, attr), dtype=np.float64)
        if a.shape != (n, width):
            raise ValueError(f"washout {name!r}: {attr} has shape {a.shape}, expected ({n}, {width})")
        bad = ~np.isfinite(a)
        if bad.any():
            row = first + int(np.argmax(bad.any(axis=1)))
            raise WashbenchError(f"washout {name!r} produced a non-finite {attr} at sample {row} (t index {row})")
        out[attr] = a
    return out


def analyse(motion: Motion, traces: Mapping[str, TraceLike], vestibular: VestibularParams | None = None) -> CueResult:
    """Vestibular models for the aircraft pilot and each simulator pilot, metrics, and the traces table.

    ``traces`` maps washout name -> its trace on the same time grid as ``motion``. Perception
    starts each filter in the steady state of its first sample (see :mod:`washbench.perception`).
    """
    model = VestibularModel(motion.dt_s, vestibular)
    n = motion.n
    arrays = {name: _checked_trace(name, trace, n) for name, trace in traces.items()}
    perceived: dict[str, Perceived] = {AIRCRAFT: model.perceive(motion.f_mps2, motion.omega_radps)}
    for name, arr in arrays.items():
        perceived[name] = model.perceive(arr["head_f_mps2"], arr["head_omega_radps"])
    table = _table(motion.t_s, motion.f_mps2, motion.omega_degps_out(), motion.extra, traces, arrays, perceived)
    return CueResult(motion=motion, traces=dict(traces), perceived=perceived, metrics=_metrics(perceived, motion.dt_s),
                     table=table)  # fmt: skip


def _metrics(perceived: Mapping[str, Perceived], dt_s: float) -> list[MetricRow]:
    ac = perceived[AIRCRAFT]
    rows: list[MetricRow] = []
    for name, p in perceived.items():
        if name != AIRCRAFT:
            rows += dof_metrics(name, ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt_s)
    return rows


def _table(
    t_s: np.ndarray,
    f_mps2: np.ndarray,
    omega_degps: np.ndarray,
    extra: Mapping[str, np.ndarray],
    traces: Mapping[str, TraceLike],
    arrays: Mapping[str, dict[str, np.ndarray]],
    perceived: Mapping[str, Perceived],
) -> dict[str, np.ndarray]:
    """The traces.parquet columns, in order, for the given rows (a whole trace or a chunk of one)."""
    n = t_s.shape[0]
    table: dict[str, np.ndarray] = {TIME_COLUMN: t_s}
    _put(table, f_columns(AIRCRAFT), f_mps2)
    _put(table, omega_columns(AIRCRAFT), omega_degps)
    _put(table, perceived_f_columns(AIRCRAFT), perceived[AIRCRAFT].f_mps2)
    _put(table, perceived_omega_columns(AIRCRAFT), perceived[AIRCRAFT].omega_radps * _DEG)
    for name, trace in traces.items():
        arr, p = arrays[name], perceived[name]
        _put(table, f_columns(name), arr["head_f_mps2"])
        _put(table, omega_columns(name), arr["head_omega_radps"] * _DEG)
        _put(table, perceived_f_columns(name), p.f_mps2)
        _put(table, perceived_omega_columns(name), p.omega_radps * _DEG)
        _put(table, pos_columns(name), arr["pos_m"])
        _put(table, vel_columns(name), arr["vel_mps"])
        _put(table, acc_columns(name), arr["acc_mps2"])
        _put(table, q_columns(name), arr["q"])
        _put(table, omega_platform_columns(name), arr["omega_radps"] * _DEG)
        _put(table, wheel_columns(name), arr["wheel_radps"])
        _put(table, sp_pos_columns(name), arr["sp_pos_m"])
        _put(table, sp_q_columns(name), arr["sp_q"])
        for kind, flags in trace.saturated.items():
            flags = np.asarray(flags)
            if flags.shape != (n,):
                raise ValueError(f"washout {name!r}: saturated[{kind!r}] has shape {flags.shape}, expected ({n},)")
            table[sat_column(name, kind)] = flags.astype(np.int8)
    for col, values in extra.items():
        if col in table:
            raise WashbenchError(f"input column {col!r} clashes with a result column of the same name")
        table[col] = values
    return table


def _put(table: dict[str, np.ndarray], names: Sequence[str], values: np.ndarray) -> None:
    columns = np.ascontiguousarray(values.T)  # one transposing copy, then each column is a contiguous row
    for i, name in enumerate(names):
        table[name] = columns[i]


def cue_motion(
    motion: Motion,
    washouts: Sequence[Any],
    params: Any,
    limits: Any,
    vestibular: VestibularParams | None = None,
) -> CueResult:
    """Run the washouts (names with ``params``, or Washout variants) and the Atlas model over ``motion``
    (``cueing.cue_trace``, one compiled call), then :func:`analyse`."""
    from washbench.cueing import cue_trace

    traces = cue_trace(motion.f_mps2, motion.omega_radps, motion.dt_s, washouts, params, limits)
    return analyse(motion, traces, vestibular)


def check_washout_names(names: Sequence[str] | None) -> tuple[str, ...]:
    """Validated washout names in the order given, duplicates dropped; ``None`` -> all of them."""
    from washbench.cueing import WASHOUT_NAMES, check_washouts

    return check_washouts(dict.fromkeys(names) if names else WASHOUT_NAMES)


def write_results(out_dir: Path, result: CueResult) -> tuple[Path, Path]:
    """Write traces.parquet and metrics.csv into ``out_dir`` (created if missing), both or neither.

    Each file is written to a temporary name and renamed into place only after both are complete.
    """
    out_dir = Path(out_dir)
    traces_path, metrics_path = out_dir / TRACES_FILE, out_dir / METRICS_FILE
    if out_dir.exists() and not out_dir.is_dir():
        raise WashbenchError(located(out_dir, "output path exists and is not a folder"))
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        with atomic_path(traces_path) as tmp_traces, atomic_path(metrics_path) as tmp_metrics:
            write_traces(tmp_traces, result.table)
            write_metrics_csv(tmp_metrics, result.metrics)
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot write results: {exc.strerror or exc}")) from None
    return traces_path, metrics_path


#: Rows ``washbench cue`` works on at a time: memory beyond the input and the perceived signals is bounded by
#: about 2 KB a row of this (65 MB), whatever the length of the recording.
CHUNK_ROWS = 32768


def cue_to_files(
    motion: Motion,
    washouts: Sequence[str],
    params: Any,
    limits: Any,
    out_dir: Path,
    *,
    vestibular: VestibularParams | None = None,
    chunk_rows: int = CHUNK_ROWS,
    progress: bool = False,
) -> tuple[list[MetricRow], dict[str, dict[str, int]], tuple[Path, Path]]:
    """:func:`cue_motion` then :func:`write_results`, ``chunk_rows`` samples at a time; the same files, bit for bit
    in content (only the Parquet row groups differ).

    Held whole are only the input and each pilot's perceived motion (48 bytes a row per pilot, for the metrics);
    the washout traces and the table exist one chunk at a time. Returns the metric rows, the saturation counts per
    washout and the two paths written. ``progress``: a line on stderr every 5 s (in place on a terminal).
    """
    from washbench.cueing import CueingBank, WashoutTrace
    from washbench.io.results import parquet_writer
    from washbench.perception.vestibular import PerceptionStream

    if chunk_rows < 1:
        raise ValueError(f"chunk_rows must be at least 1, got {chunk_rows}")
    n = motion.n
    bank = CueingBank(washouts, params, limits, motion.dt_s)  # names with ``params``, or Washout variants
    names = bank.washouts
    model = VestibularModel(motion.dt_s, vestibular)
    streams = {p: PerceptionStream(model) for p in (AIRCRAFT, *names)}
    felt = {p: (np.empty((n, 3)), np.empty((n, 3))) for p in streams}
    omega_deg = motion.omega_degps_out()
    out_dir = Path(out_dir)
    traces_path, metrics_path = out_dir / TRACES_FILE, out_dir / METRICS_FILE
    if out_dir.exists() and not out_dir.is_dir():
        raise WashbenchError(located(out_dir, "output path exists and is not a folder"))
    reporter = _Progress(n) if progress else None
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        with atomic_path(traces_path) as tmp_traces, atomic_path(metrics_path) as tmp_metrics:
            writer = None
            try:
                for a in range(0, n, chunk_rows):
                    b = min(n, a + chunk_rows)
                    block = bank.steps(motion.f_mps2[a:b], motion.omega_radps[a:b])
                    traces = {w: WashoutTrace.from_rows(block[i]) for i, w in enumerate(names)}
                    arrays = {w: _checked_trace(w, traces[w], b - a, a) for w in names}
                    perceived = {AIRCRAFT: streams[AIRCRAFT].perceive(motion.f_mps2[a:b], motion.omega_radps[a:b])}
                    for w in names:
                        perceived[w] = streams[w].perceive(arrays[w]["head_f_mps2"], arrays[w]["head_omega_radps"])
                    for p, per in perceived.items():
                        felt[p][0][a:b] = per.f_mps2
                        felt[p][1][a:b] = per.omega_radps
                    extra = {c: v[a:b] for c, v in motion.extra.items()}
                    table = _table(motion.t_s[a:b], motion.f_mps2[a:b], omega_deg[a:b], extra, traces, arrays,
                                   perceived)  # fmt: skip
                    arrow = pa.table({c: pa.array(np.asarray(v)) for c, v in table.items()})
                    if writer is None:
                        writer = parquet_writer(tmp_traces, arrow.schema)
                    writer.write_table(arrow)
                    if reporter is not None:
                        reporter.update(b)
            finally:
                if writer is not None:
                    writer.close()
                if reporter is not None:
                    reporter.close()
            rows = _metrics({p: Perceived(f_mps2=f, omega_radps=w) for p, (f, w) in felt.items()}, motion.dt_s)
            write_metrics_csv(tmp_metrics, rows)
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot write results: {exc.strerror or exc}")) from None
    return rows, bank.saturation_counts(), (traces_path, metrics_path)


class _Progress:
    """``cue: 45% (97,000 of 216,000 rows)`` on stderr: in place on a terminal, else a line every 5 s."""

    def __init__(self, total: int) -> None:
        self.total = total
        self.tty = sys.stderr.isatty()
        self.every = 0.5 if self.tty else 5.0
        self.next = time.monotonic() + self.every

    def update(self, done: int) -> None:
        now = time.monotonic()
        if now < self.next or done >= self.total:
            return
        self.next = now + self.every
        line = f"cue: {100 * done // self.total}% ({done:,} of {self.total:,} rows)"
        sys.stderr.write(f"\r\033[K{line}" if self.tty else f"{line}\n")
        sys.stderr.flush()

    def close(self) -> None:
        if self.tty:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()


def run_cue(
    input_path: Path,
    out_dir: Path,
    washouts: Sequence[str] | None = None,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    variants: Sequence[str] = (),
) -> None:
    """The ``washbench cue`` command: read ``input_path``, cue it, write results into ``out_dir``.

    ``washouts``, ``variants`` and ``params_path`` select the washouts
    (:func:`washbench.cueing.variants.select_washouts`).
    Raises WashbenchError (one line) for bad names, parameter files or input; writes nothing then.
    """
    from washbench.cueing.variants import select_washouts
    from washbench.platform import load_platform_limits

    specs = select_washouts(washouts, variants, params_path)
    names = [w.name for w in specs]
    limits = load_platform_limits(platform_path)
    motion = read_motion(input_path)
    _, saturations, (traces_path, metrics_path) = cue_to_files(motion, specs, None, limits, out_dir, progress=True)
    print(
        f"{input_path}: {motion.n} rows, {motion.duration_s:.3f} s at dt = {motion.dt_s:.6g} s "
        f"({1.0 / motion.dt_s:.6g} Hz)"
    )
    for name in names:
        counts = saturations[name]
        sat = ", ".join(f"{k} {v}" for k, v in counts.items() if v) or "none"
        print(f"  {name}: saturated samples: {sat}")
    print(f"wrote {traces_path} and {metrics_path}")
