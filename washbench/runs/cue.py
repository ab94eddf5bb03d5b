"""``washbench cue``: washouts, Atlas model, vestibular models and metrics on a recorded trace.

Two layers, so the flight pipeline (which builds washout traces in lockstep with JSBSim) shares
the post-processing:

* :func:`analyse` (motion + finished washout traces -> perception, metrics, tables);
* :func:`cue_motion` = ``cueing.cue_trace`` + :func:`analyse` (whole traces in memory);
* :func:`stream_cue`: the same in one pass over chunks of :data:`CHUNK_ROWS` samples, writing traces.parquet as it
  goes, the same bits; memory beyond the input is what the review needs of each row (see its docstring);
* :func:`run_cue` (the CLI), in stages: :func:`read_input` (reading and conversion to washbench units
  and axes), :func:`prepare_segments` (time resets, window, gaps, uniform grid or resampling,
  plausibility), :func:`write_outputs` (per segment :func:`stream_cue` and the other files of a
  ``run`` result folder, all renamed into place together).
"""

from __future__ import annotations

import contextlib
import math
import sys
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Protocol

import numpy as np

from washbench.analysis.metrics import MetricRow, dof_metrics
from washbench.errors import WashbenchError, located, printable
from washbench.io.atomic import atomic_path
from washbench.io.input_format import InputFormat
from washbench.io.names import check_identifier
from washbench.io.plausibility import Finding, check_arrays
from washbench.io.progress import Progress
from washbench.io.publish import result_path
from washbench.io.readers import Samples, read_samples
from washbench.io.resample import check_gaps, check_step, resample, split_resets, to_motion, window
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
    sat_column,
    sp_pos_columns,
    sp_q_columns,
    vel_columns,
    wheel_columns,
    write_metrics_csv,
    write_traces,
)
from washbench.perception.vestibular import Perceived, VestibularModel, VestibularParams, model_params

TRACES_FILE = "traces.parquet"
METRICS_FILE = "metrics.csv"
RECORDING_FILE = "recording.rrd"

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


CHUNK_ROWS = 8192
"""Rows of traces.parquet built and written at a time (one Parquet row group each): the table is never whole in
memory, whatever the length of the input."""


@dataclass(frozen=True, eq=False)
class CueResult:
    """Everything ``washbench cue`` computes for one input trace.

    ``perceived``: pilot name (``"aircraft"`` or a washout name) -> perceived motion;
    ``metrics``: six rows per washout (:mod:`washbench.analysis.metrics`); ``traces``: the washout traces
    themselves; :meth:`columns` the traces.parquet columns (:mod:`washbench.io.results`) of a range of rows, built
    on demand so the whole table never has to exist at once.
    """

    motion: Motion
    traces: Mapping[str, TraceLike]
    perceived: Mapping[str, Perceived]
    metrics: list[MetricRow]
    arrays: Mapping[str, Mapping[str, np.ndarray]] = field(default_factory=dict, repr=False)
    """washout -> the trace's fields as checked float64 arrays (:func:`analyse`); else read from ``traces``."""

    @property
    def n(self) -> int:
        """Number of samples."""
        return self.motion.n

    def columns(self, start: int = 0, stop: int | None = None) -> dict[str, np.ndarray]:
        """The traces.parquet columns, in order, for rows ``start:stop`` (views where no unit changes)."""
        rows = slice(start, self.n if stop is None else stop)
        perceived = {p: Perceived(v.f_mps2[rows], v.omega_radps[rows]) for p, v in self.perceived.items()}
        fields = {}
        for name, tr in self.traces.items():
            arr = self.arrays.get(name) or {f: getattr(tr, f) for f in _TRACE_FIELDS}
            fields[name] = {f: a[rows] for f, a in arr.items()}
        saturated = {w: {k: np.asarray(v)[rows] for k, v in tr.saturated.items()} for w, tr in self.traces.items()}
        return _table_rows(self.motion, rows, perceived, fields, saturated)

    def review_table(self) -> dict[str, np.ndarray]:
        """What the report reads of traces.parquet (:func:`washbench.review.result_data.load_result`), whole:
        time, every pilot's perceived motion, the platform's envelope fields and the saturation flags."""
        m = self.motion
        table: dict[str, np.ndarray] = {TIME_COLUMN: m.t_s}
        for name, p in self.perceived.items():
            _put(table, perceived_f_columns(name), p.f_mps2)
            _put(table, perceived_omega_columns(name), p.omega_radps * _DEG)
        for name, tr in self.traces.items():
            if hasattr(tr, "pos_m"):  # (a streamed cue without figures keeps no platform fields)
                _put(table, pos_columns(name), tr.pos_m)
                _put(table, vel_columns(name), tr.vel_mps)
                _put(table, acc_columns(name), tr.acc_mps2)
                _put(table, omega_platform_columns(name), tr.omega_radps * _DEG)
                _put(table, wheel_columns(name), tr.wheel_radps)
            for kind, flags in tr.saturated.items():
                table[sat_column(name, kind)] = np.asarray(flags)
        return table

    def column_chunks(self, rows: int = CHUNK_ROWS) -> Iterator[dict[str, np.ndarray]]:
        """:meth:`columns` for consecutive ranges of ``rows`` rows (at least one range, even for no rows)."""
        for a in range(0, max(self.n, 1), rows):
            yield self.columns(a, min(self.n, a + rows))


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
    """The trace's arrays as float64, checked for shape and finiteness (a non-finite value is an error; ``first``:
    the sample number of the trace's first row, for the message)."""
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


def analyse(
    motion: Motion,
    traces: Mapping[str, TraceLike],
    vestibular: VestibularParams | None = None,
    filter_start: str = "steady",
) -> CueResult:
    """Vestibular models for the aircraft pilot and each simulator pilot, metrics, and the traces table.

    ``traces`` maps washout name -> its trace on the same time grid as ``motion``. Perception
    starts each filter in the steady state of its first sample, or of rest (``filter_start="rest"``;
    see :mod:`washbench.perception`).
    """
    model = VestibularModel(motion.dt_s, vestibular)
    n = motion.n
    perceived: dict[str, Perceived] = {AIRCRAFT: model.perceive(motion.f_mps2, motion.omega_radps, filter_start)}
    checked: dict[str, dict[str, np.ndarray]] = {}
    for name, trace in traces.items():
        arr = _checked_trace(name, trace, n)
        for kind, flags in trace.saturated.items():
            if np.shape(flags) != (n,):
                raise ValueError(f"washout {name!r}: saturated[{kind!r}] has shape {np.shape(flags)}, expected ({n},)")
        perceived[name] = model.perceive(arr["head_f_mps2"], arr["head_omega_radps"], filter_start)
        checked[name] = arr
    vertical = {AIRCRAFT: motion.f_mps2[:, 2], **{w: a["head_f_mps2"][:, 2] for w, a in checked.items()}}
    rows = _metric_rows(perceived, motion.dt_s, vertical)
    result = CueResult(motion=motion, traces=dict(traces), perceived=perceived, metrics=rows, arrays=checked)
    result.columns(0, 0)  # an input column that clashes with a result column fails now, before anything is written
    return result


def _metric_rows(
    perceived: Mapping[str, Perceived], dt_s: float, vertical: Mapping[str, np.ndarray]
) -> list[MetricRow]:
    """Six metric rows per washout: each simulator pilot's perceived motion against the aircraft pilot's, the cue
    classification, and on the heave row the MSDV of each pilot's head (``vertical``: pilot -> body-z specific
    force (N,), m/s^2)."""
    import dataclasses

    from washbench.analysis.cues import classified_rows
    from washbench.perception.sickness import head_msdv

    ac = perceived[AIRCRAFT]
    msdv_ac = head_msdv(vertical[AIRCRAFT], dt_s)
    rows: list[MetricRow] = []
    for name, p in perceived.items():
        if name != AIRCRAFT:
            base = dof_metrics(name, ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt_s)
            msdv = head_msdv(vertical[name], dt_s)
            rows += [
                dataclasses.replace(r, msdv_mps15=msdv, msdv_aircraft_mps15=msdv_ac) if r.dof == "heave" else r
                for r in classified_rows(base, ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt_s)
            ]
    return rows


def _put(table: dict[str, np.ndarray], names: Sequence[str], values: np.ndarray) -> None:
    for i, name in enumerate(names):
        table[name] = values[:, i]


def _table_rows(
    motion: Motion,
    rows: slice,
    perceived: Mapping[str, Perceived],
    fields: Mapping[str, Mapping[str, np.ndarray]],
    saturated: Mapping[str, Mapping[str, np.ndarray]],
) -> dict[str, np.ndarray]:
    """The traces.parquet columns, in order, of the input rows ``rows``: ``perceived`` (every pilot), ``fields``
    (washout -> trace field -> array) and ``saturated`` (washout -> kind -> flags) hold those rows only."""
    m = motion
    table: dict[str, np.ndarray] = {TIME_COLUMN: m.t_s[rows]}
    _put(table, f_columns(AIRCRAFT), m.f_mps2[rows])
    omega_deg = m.omega_degps[rows] if m.omega_degps is not None else np.degrees(m.omega_radps[rows])
    _put(table, omega_columns(AIRCRAFT), omega_deg)
    ac = perceived[AIRCRAFT]
    _put(table, perceived_f_columns(AIRCRAFT), ac.f_mps2)
    _put(table, perceived_omega_columns(AIRCRAFT), ac.omega_radps * _DEG)
    for name, f in fields.items():
        p = perceived[name]
        _put(table, f_columns(name), f["head_f_mps2"])
        _put(table, omega_columns(name), f["head_omega_radps"] * _DEG)
        _put(table, perceived_f_columns(name), p.f_mps2)
        _put(table, perceived_omega_columns(name), p.omega_radps * _DEG)
        _put(table, pos_columns(name), f["pos_m"])
        _put(table, vel_columns(name), f["vel_mps"])
        _put(table, acc_columns(name), f["acc_mps2"])
        _put(table, q_columns(name), f["q"])
        _put(table, omega_platform_columns(name), f["omega_radps"] * _DEG)
        _put(table, wheel_columns(name), f["wheel_radps"])
        _put(table, sp_pos_columns(name), f["sp_pos_m"])
        _put(table, sp_q_columns(name), f["sp_q"])
        for kind, flags in saturated[name].items():
            table[sat_column(name, kind)] = flags.astype(np.int8)
    for col, values in m.extra.items():
        if col in table:
            raise WashbenchError(f"input column {col!r} clashes with a result column of the same name")
        table[col] = values[rows]
    return table


def cue_motion(
    motion: Motion,
    washouts: Sequence[Any],
    params: Any,
    limits: Any,
    vestibular: VestibularParams | None = None,
    filter_start: str = "steady",
) -> CueResult:
    """Run the washouts (names with ``params``, or Washout variants) and the Atlas model over ``motion``
    (``cueing.cue_trace``, one compiled call), then :func:`analyse`.

    ``filter_start``: ``steady`` (every filter in the first sample's steady state) or ``rest``.
    """
    from washbench.cueing import cue_trace

    traces = cue_trace(motion.f_mps2, motion.omega_radps, motion.dt_s, washouts, params, limits, filter_start)
    return analyse(motion, traces, vestibular, filter_start)


_REVIEW_FIELDS = ("pos_m", "vel_mps", "acc_mps2", "omega_radps", "wheel_radps")
"""Washout trace fields a streamed cue keeps whole for the report (its envelope figure and time at a limit)."""
_RECORDING_FIELDS = ("head_f_mps2", "head_omega_radps", "q")
"""... and for the recording (the simulator pilot's raw motion, the sphere's attitude in the 3D view)."""


def stream_cue(
    motion: Motion,
    washouts: Sequence[Any],
    limits: Any,
    traces_path: Path,
    metadata: Mapping[bytes, bytes] | None = None,
    *,
    filter_start: str = "steady",
    recording: bool = True,
    figures: bool = True,
    chunk_rows: int = CHUNK_ROWS,
    progress: Progress | None = None,
    vestibular: VestibularParams | None = None,
) -> CueResult:
    """:func:`cue_motion` and the traces.parquet of :func:`write_results` in one pass, ``chunk_rows`` samples at a
    time (washouts, vestibular models, one Parquet row group per chunk): the same columns and metrics, bit for bit.

    ``washouts``: Washout variants (:func:`washbench.cueing.variants.select_washouts`). ``traces_path`` is written
    (not atomically: the caller's temporary name). Held whole are only the input, every pilot's perceived motion
    (for the metrics and figures) and per washout its saturation flags and the trace fields the report's figures
    (``_REVIEW_FIELDS``, with ``figures`` or ``recording``) and the recording (``_RECORDING_FIELDS``, with
    ``recording``) show: the returned result's ``traces`` hold those, so :meth:`CueResult.columns` is not available
    on it (the table is in the file).
    """
    from washbench.cueing import CueingBank, WashoutTrace
    from washbench.io.results import write_trace_chunks
    from washbench.perception.vestibular import PerceptionStream

    if chunk_rows < 1:
        raise ValueError(f"chunk_rows must be at least 1, got {chunk_rows}")
    n = motion.n
    if n < 1:
        raise WashbenchError("nothing to cue: the input has no rows")
    bank = CueingBank(washouts, None, limits, motion.dt_s, filter_start)
    names = bank.washouts
    model = VestibularModel(motion.dt_s, vestibular)
    streams = {p: PerceptionStream(model, filter_start) for p in (AIRCRAFT, *names)}
    felt = {p: Perceived(np.empty((n, 3)), np.empty((n, 3))) for p in streams}
    vertical = {p: np.empty(n) for p in streams}  # body-z specific force at each pilot's head (MSDV)
    keep = (_REVIEW_FIELDS if figures or recording else ()) + (_RECORDING_FIELDS if recording else ())
    kept = {w: {f: np.empty((n, _TRACE_FIELDS[f])) for f in keep} for w in names}
    flags: dict[str, dict[str, np.ndarray]] = {w: {} for w in names}
    buf = np.empty((len(names), min(chunk_rows, n), len(CueingBank.FIELDS)))

    def tables() -> Iterator[dict[str, np.ndarray]]:
        """Cue the next chunk, keep what the review needs of it, and yield its traces.parquet rows."""
        for a in range(0, n, chunk_rows):
            b = min(n, a + chunk_rows)
            rows = slice(a, b)
            block = bank.steps(motion.f_mps2[rows], motion.omega_radps[rows], buf if b - a == buf.shape[1] else None)
            perceived = {AIRCRAFT: streams[AIRCRAFT].perceive(motion.f_mps2[rows], motion.omega_radps[rows])}
            fields, saturated = {}, {}
            finite = bool(np.isfinite(block).all())  # one check of the chunk; the failing field named if not
            for i, w in enumerate(names):
                tr = WashoutTrace.from_rows(block[i], copy=False)  # views into the reused buffer, used in the chunk
                fields[w] = {f: getattr(tr, f) for f in _TRACE_FIELDS} if finite else _checked_trace(w, tr, b - a, a)
                saturated[w] = tr.saturated
                perceived[w] = streams[w].perceive(fields[w]["head_f_mps2"], fields[w]["head_omega_radps"])
                vertical[w][rows] = fields[w]["head_f_mps2"][:, 2]
                for f in keep:
                    kept[w][f][rows] = fields[w][f]
                for k, v in tr.saturated.items():
                    flags[w].setdefault(k, np.empty(n, dtype=bool))[rows] = v
            for pilot, per in perceived.items():
                felt[pilot].f_mps2[rows] = per.f_mps2
                felt[pilot].omega_radps[rows] = per.omega_radps
            yield _table_rows(motion, rows, perceived, fields, saturated)
            if progress is not None:
                progress.update(b)

    write_trace_chunks(traces_path, tables(), metadata)
    vertical[AIRCRAFT][:] = motion.f_mps2[:, 2]
    metrics = _metric_rows(felt, motion.dt_s, vertical)
    counts = bank.saturation_counts()
    traces = {w: SimpleNamespace(**kept[w], saturated=flags[w], saturation_counts=counts[w]) for w in names}
    return CueResult(motion=motion, traces=traces, perceived=felt, metrics=metrics)


def write_results(out_dir: Path, result: CueResult, provenance: Mapping[str, Any] | None = None) -> tuple[Path, Path]:
    """Write traces.parquet and metrics.csv into ``out_dir`` (created if missing), both or neither.

    Each file is written to a temporary name and renamed into place only after both are complete.
    ``provenance`` (:mod:`washbench.io.provenance`, no date) goes into the Parquet key-value metadata.
    """
    from washbench.io.provenance import parquet_metadata

    out_dir = Path(out_dir)
    traces_path, metrics_path = out_dir / TRACES_FILE, out_dir / METRICS_FILE
    if out_dir.exists() and not out_dir.is_dir():
        raise WashbenchError(located(out_dir, "output path exists and is not a folder"))
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        with atomic_path(traces_path) as tmp_traces, atomic_path(metrics_path) as tmp_metrics:
            write_traces(tmp_traces, result.column_chunks(), parquet_metadata(provenance) if provenance else None)
            write_metrics_csv(tmp_metrics, result.metrics)
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot write results: {exc.strerror or exc}")) from None
    return traces_path, metrics_path


# --------------------------------------------------------------------------- the cue command, stage by stage


@dataclass(frozen=True)
class CueOptions:
    """Everything ``washbench cue`` is told besides the input, washouts and parameter files."""

    fmt: InputFormat = field(default_factory=InputFormat)
    resample_hz: float | None = None
    max_gap_s: float | None = None
    split: bool = True
    start_s: float | None = None
    end_s: float | None = None
    filter_start: str = "steady"
    strict: bool = False
    recording: bool = True
    figures: bool = True
    rank_by: str | None = None  # the ranking rule (--rank-by; None: the parameter file's)
    vestibular: str | None = None  # the vestibular model (--vestibular; None: young-meiry)
    progress: bool = True
    force: bool = False
    """Resample even when that makes more than :data:`MAX_GROWTH` times the input's rows."""


MAX_GROWTH = 100
"""``--resample`` refuses (without ``--force``) to make more than this many times the input's rows: such a factor
is a time column in the wrong unit far more often than a wish (a 0.1 Hz 'log' at 100 Hz: 1000 times)."""


@dataclass(frozen=True, eq=False)
class Segment:
    """One part of the input between time resets, ready to cue: its name (a plain identifier, its
    subfolder when there are several), the motion on its uniform grid, what was done to it and what
    looks implausible."""

    name: str
    motion: Motion
    notes: tuple[str, ...]
    findings: tuple[Finding, ...]
    labels: tuple[str, ...] = ()
    """Where each of the six signals came from (:func:`washbench.review.input_figure.input_labels`)."""


def check_segment_name(name: str) -> str:
    """``name`` if it is a plain identifier (:mod:`washbench.io.names`: it names a folder)."""
    return check_identifier(name, "segment name")


def read_input(path: Path, fmt: InputFormat) -> Samples:
    """Reading and conversion: the file, in washbench units and axes (:func:`washbench.io.readers.read_samples`)."""
    return read_samples(path, fmt)


def prepare_segments(samples: Samples, opts: CueOptions) -> list[Segment]:
    """Window and segments: split at time resets, cut the window, check gaps, the plausibility checks on the data
    as read (errors with ``--strict``), then put on a uniform grid (``--resample``, else the grid check).

    Resampling is held to what the grid check holds the data to (a step of 1 Hz .. 10 kHz, the median step
    here), and to at most :data:`MAX_GROWTH` times the rows read unless ``opts.force``.
    """
    from washbench.review.input_figure import input_labels

    parts = split_resets(samples, split=opts.split)
    fmt = opts.fmt
    labels = tuple(input_labels(samples.sources, fmt.axes, tuple(fmt.columns), fmt.origin)) if samples.sources else ()
    out = []
    for i, part in enumerate(parts):
        name = check_segment_name(f"segment_{i + 1}") if len(parts) > 1 else ""
        part = window(part, opts.start_s, opts.end_s)
        check_gaps(part, opts.max_gap_s)
        notes = list(part.notes)
        step = float(np.median(np.diff(part.t_s)))
        findings = tuple(check_arrays(part.t_s, step, part.f_mps2, part.omega_degps, part.declared))
        if opts.strict and findings:
            where = f" ({name})" if name else ""
            raise WashbenchError(located(samples.path, f"{findings[0].text}{where} [--strict]"))
        if opts.resample_hz is not None:
            check_step(part, step)
            rows = math.floor((part.t_s[-1] - part.t_s[0]) * opts.resample_hz + 1e-9) + 1
            if rows > MAX_GROWTH * part.n and not opts.force:
                why = next((f.text for f in findings if f.text.startswith("sample rate")), "")
                why = why or f"the data's own rate is {1.0 / step:.4g} Hz: is the time in another unit?"
                raise WashbenchError(
                    located(
                        samples.path,
                        f"--resample {opts.resample_hz:g} would make {rows:,} rows of {part.n:,} ({rows / part.n:.0f} "
                        f"times): {why}; --force resamples anyway",
                        field=part.time_column,
                    )
                )
            motion, note = resample(part, opts.resample_hz)
            notes.append(note)
        else:
            motion = to_motion(part)
        out.append(Segment(name=name, motion=motion, notes=tuple(notes), findings=findings, labels=labels))
    return out


def segment_summary(input_path: Path, seg: Segment, result: CueResult, out_dir: Path) -> Any:
    """The run summary (``run.json``, report) of one cued segment; a crash in the data makes it failed."""
    from washbench.runs.pipeline import RunSummary, perceived_motion

    crash = [f.text for f in seg.findings if f.crash]
    ac = result.perceived[AIRCRAFT]
    return RunSummary(
        ok=not crash,
        reason="the data holds a crash or spike: " + crash[0] if crash else "",
        aircraft="recorded",
        manoeuvre=input_path.name.split(".")[0] + (f"/{seg.name}" if seg.name else ""),
        run_dir=out_dir,
        steps=seg.motion.n,
        dt_s=seg.motion.dt_s,
        metrics=list(result.metrics),
        motion=perceived_motion(ac.f_mps2, ac.omega_radps, seg.motion.dt_s),
        saturations={w: dict(t.saturation_counts) for w, t in result.traces.items()},
    )


def recorded_attitude(motion: Motion) -> np.ndarray:
    """The aircraft's attitude for the recording: from ``phi_deg``/``theta_deg``/``psi_deg`` when the input
    has them, else level (an attitude is not needed by the cueing and is not invented)."""
    from washbench.runs.pipeline import aircraft_attitude

    cols = [motion.extra.get(c) for c in ("phi_deg", "theta_deg", "psi_deg")]
    if all(c is not None and c.dtype.kind == "f" for c in cols):
        return aircraft_attitude(*cols)  # type: ignore[arg-type]
    q = np.zeros((motion.n, 4))
    q[:, 0] = 1.0
    return q


def write_outputs(
    out_dir: Path,
    input_path: Path,
    segments: Sequence[Segment],
    washouts: Sequence[Any],
    limits: Any,
    opts: CueOptions,
    start: float,
    provenance: dict[str, Any] | None = None,
    progress: bool = False,
) -> list[tuple[Any, CueResult]]:
    """Cueing and outputs: per segment (``out_dir`` itself, or ``out_dir/<segment>/`` when there are several) the
    files of a ``run`` result folder: traces.parquet (written as it is cued, :func:`stream_cue`), metrics.csv,
    run.json, ranking.csv, report.md and recording.rrd (unless ``opts.recording`` is False). Every file is written
    under a temporary name and all are renamed into place together, then ranking.csv and report.md are written
    (atomically) last, so a failure leaves no half-written file. Returns (summary, result) per segment;
    ``start``: the command's start (``time.perf_counter()``) for run.json's wall time."""
    from washbench.io.provenance import flat_strings, parquet_metadata, utc_now
    from washbench.runs.pipeline import write_run_json, write_run_recording
    from washbench.runs.suite import write_run_review

    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise WashbenchError(located(out_dir, "output path exists and is not a folder"))
    created = utc_now()
    done: list[tuple[Any, CueResult]] = []
    shown = Progress("cue", sum(seg.motion.n for seg in segments)) if progress else None
    try:
        with contextlib.ExitStack() as stack:
            if shown is not None:
                stack.callback(shown.close)
            offset = 0
            for seg in segments:
                folder = result_path(out_dir, seg.name) if seg.name else out_dir
                folder.mkdir(parents=True, exist_ok=True)
                names = (TRACES_FILE, METRICS_FILE, "run.json") + ((RECORDING_FILE,) if opts.recording else ())
                tmp = {name: stack.enter_context(atomic_path(folder / name)) for name in names}
                meta = parquet_metadata(provenance) if provenance else None
                if shown is not None:
                    shown.offset = offset
                result = stream_cue(
                    seg.motion, washouts, limits, tmp[TRACES_FILE], meta,
                    filter_start=opts.filter_start, recording=opts.recording, figures=opts.figures, progress=shown,
                    vestibular=model_params(opts.vestibular),
                )  # fmt: skip
                offset += seg.motion.n
                summary = segment_summary(input_path, seg, result, folder)
                write_metrics_csv(tmp[METRICS_FILE], result.metrics)
                extra = {
                    "input": str(input_path),
                    "segment": seg.name,
                    "t_start_s": float(seg.motion.t_s[0]),
                    "t_end_s": float(seg.motion.t_s[-1]),
                    "filter_start": opts.filter_start,
                    "conversions": list(seg.notes),
                    "input_labels": list(seg.labels),
                    "warnings": [f.text for f in seg.findings],
                }
                if provenance:
                    extra |= {"created_utc": created, "provenance": provenance}
                write_run_json(tmp["run.json"], summary, time.perf_counter() - start, extra)
                if opts.recording:
                    title = f"{summary.aircraft} / {summary.manoeuvre}"
                    q = recorded_attitude(seg.motion)
                    props = flat_strings(provenance, created) if provenance else None
                    write_run_recording(tmp[RECORDING_FILE], title, seg.motion, result, limits, q, [], props)
                done.append((summary, result))
        for seg, (summary, result) in zip(segments, done, strict=True):  # last, as a suite's report: each written
            if not opts.recording:  # atomically once the rest is in place; an earlier recording would mislead
                (summary.run_dir / RECORDING_FILE).unlink(missing_ok=True)
            if opts.figures and seg.labels:  # what was read, linked first in the report
                from washbench.review.input_figure import draw_for_result

                title = f"{input_path.name}{f' {seg.name}' if seg.name else ''}"
                draw_for_result(summary.run_dir, title, seg.motion, seg.labels, seg.notes)
            write_run_review(summary.run_dir, summary, str(input_path), result.review_table(), opts.figures)
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot write results: {exc.strerror or exc}")) from None
    return done


def run_cue(
    input_path: Path,
    out_dir: Path,
    washouts: Sequence[str] | None = None,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    variants: Sequence[str] = (),
    options: CueOptions | None = None,
    adopt: Sequence[str] = (),
) -> int:
    """The ``washbench cue`` command: read, convert, cut and check, cue, write; 0, or 1 if the data holds a crash.

    ``adopt``: files already in ``out_dir`` that become part of the published set (``washbench live``'s input).

    ``washouts``, ``variants`` and ``params_path`` select the washouts
    (:func:`washbench.cueing.variants.select_washouts`).
    Raises WashbenchError (one line) for bad names, parameter files or input; writes nothing then.
    """
    from washbench.cueing.params import check_filter_start
    from washbench.cueing.variants import select_washouts
    from washbench.io.outfolder import check_out_path, result_set
    from washbench.platform import load_platform_limits

    check_out_path(out_dir)
    opts = options or CueOptions()
    for flag, value in (("--max-gap-s", opts.max_gap_s), ("--resample", opts.resample_hz)):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise WashbenchError(f"{flag}: expected a positive number, got {value:g}")
    start = time.perf_counter()
    specs = select_washouts(washouts, variants, params_path)
    names = [w.name for w in specs]
    check_filter_start(opts.filter_start)
    limits = load_platform_limits(platform_path)
    samples = read_input(input_path, opts.fmt)
    segments = prepare_segments(samples, opts)
    with result_set(out_dir, "cue", adopt) as stage:  # the whole set replaces the previous one at once
        for seg in segments:
            for f in seg.findings:
                where = f"{input_path}{f' ({seg.name})' if seg.name else ''}"
                print(f"washbench: warning: {printable(f'{where}: {f.text}')}", file=sys.stderr)
        from washbench.io.provenance import file_record, read_parquet_provenance
        from washbench.runs.pipeline import run_provenance

        prov = run_provenance(params_path, platform_path, specs, limits, rank_by=opts.rank_by,
                              vestibular=opts.vestibular)  # fmt: skip
        prov["input"] = file_record(input_path)
        is_parquet = input_path.suffix.lower() in (".parquet", ".pq")
        input_prov = read_parquet_provenance(input_path) if is_parquet else None
        if input_prov:
            prov["input"]["provenance"] = input_prov
        done = write_outputs(stage, input_path, segments, specs, limits, opts, start, prov, progress=opts.progress)
    out_dir = Path(out_dir)
    for seg, (summary, result) in zip(segments, done, strict=True):
        m = seg.motion
        label = f"{input_path}{f' {seg.name}' if seg.name else ''}"
        print(f"{label}: {m.n} rows, {m.duration_s:.3f} s at dt = {m.dt_s:.6g} s ({1.0 / m.dt_s:.6g} Hz)")
        for note in seg.notes:
            print(f"  {note}")
        for name in names:
            counts = result.traces[name].saturation_counts
            sat = ", ".join(f"{k} {v}" for k, v in counts.items() if v) or "none"
            print(f"  {name}: saturated samples: {sat}")
        if not summary.ok:
            print(f"  FAILED: {summary.reason}")
        print(f"wrote {out_dir / summary.run_dir.relative_to(stage)}")
    return 0 if all(s.ok for s, _ in done) else 1
