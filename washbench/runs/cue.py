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
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

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


def _checked_trace(name: str, trace: TraceLike, n: int) -> dict[str, np.ndarray]:
    """The trace's arrays as float64, checked for shape and finiteness (a non-finite value is an error)."""
    out = {}
    for attr, width in _TRACE_FIELDS.items():
        a = np.asarray(getattr(trace, attr), dtype=np.float64)
        if a.shape != (n, width):
            raise ValueError(f"washout {name!r}: {attr} has shape {a.shape}, expected ({n}, {width})")
        bad = ~np.isfinite(a)
        if bad.any():
            row = int(np.argmax(bad.any(axis=1)))
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
    perceived: dict[str, Perceived] = {AIRCRAFT: model.perceive(motion.f_mps2, motion.omega_radps)}
    table: dict[str, np.ndarray] = {TIME_COLUMN: motion.t_s}
    _put(table, f_columns(AIRCRAFT), motion.f_mps2)
    _put(table, omega_columns(AIRCRAFT), motion.omega_degps_out())
    _put(table, perceived_f_columns(AIRCRAFT), perceived[AIRCRAFT].f_mps2)
    _put(table, perceived_omega_columns(AIRCRAFT), perceived[AIRCRAFT].omega_radps * _DEG)
    rows: list[MetricRow] = []
    ac = perceived[AIRCRAFT]
    for name, trace in traces.items():
        arr = _checked_trace(name, trace, n)
        p = model.perceive(arr["head_f_mps2"], arr["head_omega_radps"])
        perceived[name] = p
        rows += dof_metrics(name, ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, motion.dt_s)
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
    for col, values in motion.extra.items():
        if col in table:
            raise WashbenchError(f"input column {col!r} clashes with a result column of the same name")
        table[col] = values
    return CueResult(motion=motion, traces=dict(traces), perceived=perceived, metrics=rows, table=table)


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
    from washbench.io.lock import output_lock
    from washbench.platform import load_platform_limits

    specs = select_washouts(washouts, variants, params_path)
    names = [w.name for w in specs]
    limits = load_platform_limits(platform_path)
    motion = read_motion(input_path)
    with output_lock(out_dir):
        result = cue_motion(motion, specs, None, limits)
        traces_path, metrics_path = write_results(out_dir, result)
    print(
        f"{input_path}: {motion.n} rows, {motion.duration_s:.3f} s at dt = {motion.dt_s:.6g} s "
        f"({1.0 / motion.dt_s:.6g} Hz)"
    )
    for name in names:
        counts = result.traces[name].saturation_counts
        sat = ", ".join(f"{k} {v}" for k, v in counts.items() if v) or "none"
        print(f"  {name}: saturated samples: {sat}")
    print(f"wrote {traces_path} and {metrics_path}")
