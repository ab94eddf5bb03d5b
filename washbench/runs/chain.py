"""The chain every command that cues shares: motion in, washout traces, perception, metrics out.

One chain, two ways in (as pvlib's ``ModelChain.run_model`` and ``run_model_from_poa`` enter one chain):

* a flight flown in lockstep (``washbench run``, a suite's runs): :func:`lockstep_blocks` gives JSBSim's step hook
  that feeds each block of samples through the washouts and the Atlas model as it is flown
  (:class:`washbench.cueing.CueingBank`), then :func:`from_lockstep` takes the finished washout traces on, with
  the flight as written to ``flight.parquet`` and read back, through :func:`analyse`;
* a recorded file (``washbench cue``): :func:`cue_motion` (whole traces in memory: ``cueing.cue_trace`` then
  :func:`analyse`) or :func:`stream_cue` (the same in one pass over chunks of :data:`CHUNK_ROWS` samples, writing
  traces.parquet as it goes).

Both end in :class:`CueResult` (perceived motion of every pilot, metrics, the traces.parquet columns) and give
the same bits for the same motion: ``washbench fly`` then ``washbench cue`` equals ``washbench run``.
:func:`write_results` writes traces.parquet and metrics.csv of a result.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Protocol

import numpy as np

from washbench.analysis.best_motion import Scoring
from washbench.analysis.cues import classified_rows
from washbench.analysis.felt import DEFAULT_MEASURE, FeltMeasure, felt_errors, jolt
from washbench.analysis.metrics import dof_metrics
from washbench.analysis.ranking import RankRule
from washbench.cueing.registry import considers
from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path
from washbench.io.columns import (
    AIRCRAFT,
    TIME_COLUMN,
    acc_columns,
    f_columns,
    leg_columns,
    omega_columns,
    omega_platform_columns,
    perceived_f_columns,
    perceived_omega_columns,
    pos_columns,
    q_columns,
    sat_column,
    sp_pos_columns,
    sp_q_columns,
    tilt_rate_column,
    vel_columns,
    wheel_columns,
)
from washbench.io.metrics_csv import MetricRow, write_metrics_csv
from washbench.io.motion import Motion
from washbench.io.parquet_files import write_trace_chunks, write_traces
from washbench.io.progress import Progress
from washbench.io.provenance import parquet_metadata
from washbench.io.result_files import METRICS_FILE, TRACES_FILE
from washbench.perception.sickness import head_msdv
from washbench.perception.svc import SvcStream, head_msi
from washbench.perception.vestibular import Perceived, PerceptionStream, VestibularModel, VestibularParams

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
    themselves; :meth:`columns` the traces.parquet columns (:mod:`washbench.io.columns`) of a range of rows, built
    on demand so the whole table never has to exist at once.
    """

    motion: Motion
    traces: Mapping[str, TraceLike]
    perceived: Mapping[str, Perceived]
    metrics: list[MetricRow]
    arrays: Mapping[str, Mapping[str, np.ndarray]] = field(default_factory=dict, repr=False)
    """washout -> the trace's fields as checked float64 arrays (:func:`analyse`); else read from ``traces``."""
    algorithms: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    """washout -> what a Python washout reports of itself (:meth:`washbench.cueing.CueingBank.algorithm_reports`)."""

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
            tilt = getattr(tr, "tilt_rate_radps", None)  # (not checked finite: NaN where none is known)
            if tilt is not None and len(tilt):
                fields[name]["tilt_rate_radps"] = np.asarray(tilt, dtype=np.float64)[rows]
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
                _put(table, wheel_columns(name), getattr(tr, "wheel_radps", _NONE))
                _put(table, leg_columns(name), getattr(tr, "leg_m", _NONE))
                _put(table, q_columns(name), getattr(tr, "q", _NONE))  # (a rig's angles in its envelope figure)
            for kind, flags in tr.saturated.items():
                table[sat_column(name, kind)] = np.asarray(flags)
        return table

    def column_chunks(self, rows: int = CHUNK_ROWS) -> Iterator[dict[str, np.ndarray]]:
        """:meth:`columns` for consecutive ranges of ``rows`` rows (at least one range, even for no rows)."""
        for a in range(0, max(self.n, 1), rows):
            yield self.columns(a, min(self.n, a + rows))


_NONE = np.zeros((0, 0))

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
    "leg_m": 6,
}
_PLATFORM_FIELDS = {"wheel_radps": "atlas", "leg_m": "hexapod"}
"""Trace fields only one kind of platform has: (N, 0) on the others."""


def _width(attr: str, platform: str) -> int:
    """Columns of trace field ``attr`` on a platform of kind ``platform``."""
    own = _PLATFORM_FIELDS.get(attr)
    return _TRACE_FIELDS[attr] if own is None or own == platform else 0


def _checked_trace(name: str, trace: TraceLike, n: int, first: int = 0) -> dict[str, np.ndarray]:
    """The trace's arrays as float64, checked for shape and finiteness (a non-finite value is an error; ``first``:
    the sample number of the trace's first row, for the message)."""
    out = {}
    for attr, width in _TRACE_FIELDS.items():
        a = np.asarray(getattr(trace, attr, _NONE[:n]) if attr == "leg_m" else getattr(trace, attr), dtype=np.float64)
        if a.shape == (0, 0):
            a = a.reshape(n, 0)
        if a.shape != (n, width) and not (attr in _PLATFORM_FIELDS and a.shape == (n, 0)):
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
    measure: FeltMeasure = DEFAULT_MEASURE,
) -> CueResult:
    """Vestibular models for the aircraft pilot and each simulator pilot, metrics, and the traces table.

    ``traces`` maps washout name -> its trace on the same time grid as ``motion``. Perception
    starts each filter in the steady state of its first sample, or of rest (``filter_start="rest"``;
    see :mod:`washbench.perception`). ``measure``: the felt error's thresholds and terms (the metrics' ``felt_*``
    and ``jolt`` columns, :mod:`washbench.analysis.felt`).
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
    heads = {AIRCRAFT: (motion.f_mps2, motion.omega_radps)}
    heads |= {w: (a["head_f_mps2"], a["head_omega_radps"]) for w, a in checked.items()}
    msi = {p: head_msi(f, w, motion.dt_s, start=filter_start) for p, (f, w) in heads.items()}
    rows = _metric_rows(perceived, motion.dt_s, {p: f for p, (f, _) in heads.items()}, msi, measure)
    result = CueResult(motion=motion, traces=dict(traces), perceived=perceived, metrics=rows, arrays=checked)
    result.columns(0, 0)  # an input column that clashes with a result column fails now, before anything is written
    return result


def _metric_rows(
    perceived: Mapping[str, Perceived],
    dt_s: float,
    head_f: Mapping[str, np.ndarray],
    msi: Mapping[str, float],
    measure: FeltMeasure = DEFAULT_MEASURE,
) -> list[MetricRow]:
    """Six metric rows per washout: each simulator pilot's perceived motion against the aircraft pilot's, the cue
    classification, the felt error's terms (``measure``), and on the heave row the MSDV of each pilot's head
    (``head_f``: pilot -> head specific force (N, 3), body axes, m/s^2) and the predicted incidence (``msi``: pilot
    -> MSI at the end, %)."""
    ac = perceived[AIRCRAFT]
    msdv_ac = head_msdv(head_f[AIRCRAFT][:, 2], dt_s)
    rows: list[MetricRow] = []
    for name, p in perceived.items():
        if name != AIRCRAFT:
            base = dof_metrics(name, ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt_s)
            msdv = head_msdv(head_f[name][:, 2], dt_s)
            felt, false = felt_errors(ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt_s, measure)
            jolts = np.concatenate([jolt(head_f[name], head_f[AIRCRAFT], dt_s, measure), np.full(3, math.nan)])
            classified = classified_rows(base, ac.f_mps2, ac.omega_radps, p.f_mps2, p.omega_radps, dt_s)
            for i, r in enumerate(classified):
                r = dataclasses.replace(r, felt_error=float(felt[i]), felt_false=float(false[i]), jolt=float(jolts[i]))
                if r.dof == "heave":
                    r = dataclasses.replace(r, msdv_mps15=msdv, msdv_aircraft_mps15=msdv_ac, msi_pct=msi[name],
                                            msi_aircraft_pct=msi[AIRCRAFT])  # fmt: skip
                rows.append(r)
    return rows


def _put(table: dict[str, np.ndarray], names: Sequence[str], values: np.ndarray) -> None:
    """The columns of ``values`` under ``names`` (as many as ``values`` has: none for a platform's field of another
    kind of platform)."""
    for i, name in enumerate(names[: values.shape[1]]):
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
        _put(table, leg_columns(name), f["leg_m"])
        _put(table, sp_pos_columns(name), f["sp_pos_m"])
        _put(table, sp_q_columns(name), f["sp_q"])
        # empty (null) where the washout reports none (NaN in the trace; no trace field: none), so the column compares
        # equal to itself as the others do (Arrow's NaN is unequal to NaN); read back as NaN (read_traces)
        tilt = f.get("tilt_rate_radps")
        table[tilt_rate_column(name)] = np.ma.masked_invalid(np.full(len(table[TIME_COLUMN]), np.nan) if tilt is None
                                                             else tilt * _DEG)  # fmt: skip
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
    measure: FeltMeasure = DEFAULT_MEASURE,
    scoring: Scoring | None = None,
) -> CueResult:
    """Run the washouts (names with ``params``, or Washout variants) and the Atlas model over ``motion``
    (``cueing.cue_trace``, one compiled call), then :func:`analyse`.

    ``filter_start``: ``steady`` (every filter in the first sample's steady state) or ``rest``. ``scoring``: how the
    run scores a motion, for a washout that considers the others (the bound; None: the felt error with ``measure``).
    """
    from washbench.cueing import cue_trace  # deferred: numba

    traces = cue_trace(motion.f_mps2, motion.omega_radps, motion.dt_s, washouts, params, limits, filter_start,
                       scoring=scoring if scoring is not None else Scoring(RankRule(measure=measure), vestibular))
    return analyse(motion, traces, vestibular, filter_start, measure)


_REVIEW_FIELDS = ("pos_m", "vel_mps", "acc_mps2", "omega_radps", "wheel_radps", "leg_m")
"""Washout trace fields a streamed cue keeps whole for the report (its envelope figure and time at a limit)."""
_RECORDING_FIELDS = ("head_f_mps2", "head_omega_radps", "q")
"""... and for the recording (the simulator pilot's raw motion, the sphere's attitude in the 3D view)."""
_RELAXATION_FIELDS = ("pos_m", "vel_mps", "acc_mps2", "omega_radps", "q")
"""... and on a platform other than the Atlas, for the ceiling (:func:`washbench.analysis.relaxation.observed`)."""


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
    measure: FeltMeasure = DEFAULT_MEASURE,
    scoring: Scoring | None = None,
) -> CueResult:
    """:func:`cue_motion` and the traces.parquet of :func:`write_results` in one pass, ``chunk_rows`` samples at a
    time (washouts, vestibular models, one Parquet row group per chunk): the same columns and metrics, bit for bit.

    With a washout that considers the others (the bound: it is cued after every other, told their motions and
    ``scoring``), the washouts are cued whole first (:func:`cue_motion`) and the table written from the result in the
    same chunks: the result then holds every trace whole.

    ``washouts``: Washout variants (:func:`washbench.cueing.variants.select_washouts`). ``traces_path`` is written
    (not atomically: the caller's temporary name). Held whole are only the input, every pilot's perceived motion
    (for the metrics and figures) and per washout its saturation flags and the trace fields the report's figures
    (``_REVIEW_FIELDS``, with ``figures`` or ``recording``) and the recording (``_RECORDING_FIELDS``, with
    ``recording``) show: the returned result's ``traces`` hold those, so :meth:`CueResult.columns` is not available
    on it (the table is in the file).
    """
    from washbench.cueing import CueingBank, WashoutTrace  # deferred: numba

    if chunk_rows < 1:
        raise ValueError(f"chunk_rows must be at least 1, got {chunk_rows}")
    n = motion.n
    if n < 1:
        raise WashbenchError("nothing to cue: the input has no rows")
    if any(considers(w.kind, w.source) for w in washouts):
        return _whole_cue(motion, washouts, limits, traces_path, metadata, filter_start, chunk_rows, progress,
                          vestibular, measure, scoring)  # fmt: skip
    bank = CueingBank(washouts, None, limits, motion.dt_s, filter_start, future=(motion.f_mps2, motion.omega_radps))
    names = bank.washouts
    model = VestibularModel(motion.dt_s, vestibular)
    streams = {p: PerceptionStream(model, filter_start) for p in (AIRCRAFT, *names)}
    felt = {p: Perceived(np.empty((n, 3)), np.empty((n, 3))) for p in streams}
    heads = {p: np.empty((n, 3)) for p in names}  # each simulator pilot's head specific force (MSDV, jolts)
    sick = {p: SvcStream(motion.dt_s, start=filter_start) for p in streams}  # predicted incidence (MSI)
    keep = (_REVIEW_FIELDS if figures or recording else ()) + (_RECORDING_FIELDS if recording else ())
    if bank.platform != "atlas":  # the ceiling's relaxation is widened to what each washout did (bound_stage)
        keep = tuple(dict.fromkeys(keep + _RELAXATION_FIELDS))
    kept = {w: {f: np.empty((n, _width(f, bank.platform))) for f in keep} for w in names}
    tilt = CueingBank.FIELDS.index("tilt_rate_radps")
    tilt_rates = {w: np.empty(n) for w in names}  # the tilt rate each commanded (the recording's envelope tab)
    flags: dict[str, dict[str, np.ndarray]] = {w: {} for w in names}
    # two chunk buffers filled in turn: the traces' writer thread still reads the one before (write_trace_chunks)
    bufs = [np.empty((len(names), min(chunk_rows, n), len(CueingBank.FIELDS))) for _ in range(2)]

    def tables() -> Iterator[dict[str, np.ndarray]]:
        """Cue the next chunk, keep what the review needs of it, and yield its traces.parquet rows."""
        for a in range(0, n, chunk_rows):
            b = min(n, a + chunk_rows)
            rows = slice(a, b)
            buf = bufs[(a // chunk_rows) % 2]
            block = bank.steps(motion.f_mps2[rows], motion.omega_radps[rows], buf if b - a == buf.shape[1] else None)
            perceived = {AIRCRAFT: streams[AIRCRAFT].perceive(motion.f_mps2[rows], motion.omega_radps[rows])}
            sick[AIRCRAFT].update(motion.f_mps2[rows], motion.omega_radps[rows])
            fields, saturated = {}, {}
            # one check of the chunk (but the tilt rate, NaN for a washout without one); the failing field named if not
            finite = bool(np.isfinite(block[..., :tilt]).all() and np.isfinite(block[..., tilt + 1 :]).all())
            for i, w in enumerate(names):
                tr = WashoutTrace.from_rows(block[i], copy=False, platform=bank.platform)  # views, used in the chunk
                fields[w] = {f: getattr(tr, f) for f in _TRACE_FIELDS} if finite else _checked_trace(w, tr, b - a, a)
                fields[w]["tilt_rate_radps"] = tr.tilt_rate_radps  # (not checked finite: NaN where none is known)
                saturated[w] = tr.saturated
                perceived[w] = streams[w].perceive(fields[w]["head_f_mps2"], fields[w]["head_omega_radps"])
                heads[w][rows] = fields[w]["head_f_mps2"]
                sick[w].update(fields[w]["head_f_mps2"], fields[w]["head_omega_radps"])
                for f in keep:
                    kept[w][f][rows] = fields[w][f]
                tilt_rates[w][rows] = tr.tilt_rate_radps
                for k, v in tr.saturated.items():
                    flags[w].setdefault(k, np.empty(n, dtype=bool))[rows] = v
            for pilot, per in perceived.items():
                felt[pilot].f_mps2[rows] = per.f_mps2
                felt[pilot].omega_radps[rows] = per.omega_radps
            yield _table_rows(motion, rows, perceived, fields, saturated)
            if progress is not None:
                progress.update(b)

    write_trace_chunks(traces_path, tables(), metadata)
    heads[AIRCRAFT] = motion.f_mps2
    metrics = _metric_rows(felt, motion.dt_s, heads, {p: st.msi_pct for p, st in sick.items()}, measure)
    counts = bank.saturation_counts()
    traces = {w: SimpleNamespace(**kept[w], saturated=flags[w], saturation_counts=counts[w],
                                 tilt_rate_radps=tilt_rates[w]) for w in names}  # fmt: skip
    return CueResult(motion=motion, traces=traces, perceived=felt, metrics=metrics, algorithms=bank.algorithm_reports())


def _whole_cue(motion: Motion, washouts: Sequence[Any], limits: Any, traces_path: Path,
               metadata: Mapping[bytes, bytes] | None, filter_start: str, chunk_rows: int, progress: Progress | None,
               vestibular: VestibularParams | None, measure: FeltMeasure, scoring: Scoring | None) -> CueResult:
    """:func:`stream_cue` with a washout that considers the others: cued whole (:func:`cue_trace` with the washouts'
    reports), analysed, and its table written in chunks."""
    from washbench.cueing import cue_trace  # deferred: numba

    reports: dict[str, dict[str, float | int]] = {}
    traces = cue_trace(motion.f_mps2, motion.omega_radps, motion.dt_s, washouts, None, limits, filter_start,
                       reports=reports,
                       scoring=scoring if scoring is not None else Scoring(RankRule(measure=measure), vestibular))
    result = analyse(motion, traces, vestibular, filter_start, measure)
    write_trace_chunks(traces_path, result.column_chunks(chunk_rows), metadata)
    if progress is not None:
        progress.update(motion.n)
    return dataclasses.replace(result, algorithms=reports)


def write_results(out_dir: Path, result: CueResult, provenance: Mapping[str, Any] | None = None) -> tuple[Path, Path]:
    """Write traces.parquet and metrics.csv into ``out_dir`` (created if missing), both or neither.

    Each file is written to a temporary name and renamed into place only after both are complete.
    ``provenance`` (:mod:`washbench.io.provenance`, no date) goes into the Parquet key-value metadata.
    """
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


def aircraft_attitude(phi_deg: np.ndarray, theta_deg: np.ndarray, psi_deg: np.ndarray) -> np.ndarray:
    """Body->NED quaternions (N, 4), scalar first, from ZYX Euler angles in degrees: q = q_z(psi) q_y(theta) q_x(phi).

    Closed form (what ``scipy.spatial.transform.Rotation.from_euler("ZYX", ...)`` gives, without its import).
    """
    h = 0.5 * np.radians(np.column_stack([phi_deg, theta_deg, psi_deg]))
    c, s = np.cos(h), np.sin(h)
    cf, ct, cp, sf, st, sp = c[:, 0], c[:, 1], c[:, 2], s[:, 0], s[:, 1], s[:, 2]
    return np.column_stack(
        [
            cf * ct * cp + sf * st * sp,
            sf * ct * cp - cf * st * sp,
            cf * st * cp + sf * ct * sp,
            cf * ct * sp - sf * st * cp,
        ]
    )


def lockstep_washouts(
    specs: Sequence[Any], limits: Any, dt_s: float, filter_start: str = "steady"
) -> tuple[list[np.ndarray], Any]:
    """A washout bank (selected :class:`washbench.cueing.variants.Washout` s) run in lockstep with a flight:
    (the rows it fills, the flight's step hook)."""
    from washbench.cueing import CueingBank  # deferred: numba

    rows: list[np.ndarray] = []
    if not specs:  # every washout is cued after the flight (the bound, an MPC with preview): count the samples

        def count(k: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> None:
            rows.append(np.empty((0, len(CueingBank.FIELDS))))

        count.reports = dict  # type: ignore[attr-defined]
        return rows, count
    bank = CueingBank(specs, None, limits, dt_s, filter_start)
    step = bank.step
    omega_deg = np.empty(3)

    def lockstep(k: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> None:
        # The washouts see the angular velocity exactly as flight.parquet stores it (deg/s) and
        # washbench cue reads it back (np.radians), so both paths give the same bits.
        np.degrees(omega_radps, out=omega_deg)
        rows.append(step(f_mps2, np.radians(omega_deg)).copy())

    lockstep.reports = bank.algorithm_reports  # type: ignore[attr-defined]
    return rows, lockstep


#: Samples the washouts take at a time during a flight (1 s at 120 Hz): the same compiled step as one
#: sample at a time, bit for bit, with one call per block instead of one per sample.
LOCKSTEP_BLOCK = 120


def lockstep_blocks(
    specs: Sequence[Any], limits: Any, dt_s: float, filter_start: str = "steady"
) -> tuple[list[np.ndarray], Any]:
    """:func:`lockstep_washouts` for ``fly``'s block hook: the washouts take the flight's samples a block at a
    time (``CueingBank.steps``, one compiled call per block); ``rows`` gets one (washouts, M, fields) block per
    call (:func:`sample_count`, :func:`stacked_rows`)."""
    from washbench.cueing import CueingBank  # deferred: numba

    rows: list[np.ndarray] = []
    done = [0]
    if not specs:  # every washout is cued after the flight (the bound, an MPC with preview): count the samples

        def count(k0: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> None:
            rows.append(np.empty((0, f_mps2.shape[0], len(CueingBank.FIELDS))))
            done[0] += f_mps2.shape[0]

        count.reports = dict  # type: ignore[attr-defined]
        return rows, count
    bank = CueingBank(specs, None, limits, dt_s, filter_start)

    def lockstep(k0: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> None:
        if k0 != done[0]:
            raise RuntimeError(f"lockstep: block starts at sample {k0}, expected {done[0]}")
        # The washouts see the angular velocity exactly as flight.parquet stores it (deg/s) and
        # washbench cue reads it back (np.radians), so both paths give the same bits.
        rows.append(bank.steps(f_mps2, np.radians(np.degrees(omega_radps))))
        done[0] += f_mps2.shape[0]

    lockstep.reports = bank.algorithm_reports  # type: ignore[attr-defined]
    return rows, lockstep


def sample_count(rows: list[np.ndarray]) -> int:
    """Samples in the lockstep's ``rows``: (washouts, fields) rows, one a sample, or (washouts, M, fields) blocks."""
    return sum(r.shape[1] if r.ndim == 3 else 1 for r in rows)


def stacked_rows(rows: list[np.ndarray]) -> np.ndarray:
    """The lockstep's ``rows`` as one (washouts, N, fields) array; ``rows`` is emptied (its blocks freed)."""
    if not rows:
        raise ValueError("no lockstep rows")
    out = np.concatenate(rows, axis=1) if rows[0].ndim == 3 else np.stack(rows, axis=1)
    rows.clear()
    return out




def from_lockstep(
    motion: Motion,
    rows: list[np.ndarray],
    washouts: Sequence[str],
    vestibular: VestibularParams | None = None,
    filter_start: str = "steady",
    platform: str = "atlas",
    measure: FeltMeasure = DEFAULT_MEASURE,
) -> CueResult:
    """The chain entered with a flight flown in lockstep: the washout traces the lockstep filled (``rows`` of
    :func:`lockstep_blocks` or :func:`lockstep_washouts`, emptied here; ``washouts`` their names in order) on
    ``motion`` (the flight as read back from ``flight.parquet``), through :func:`analyse`. ``platform``: the
    platform's kind (:func:`washbench.platform.model.platform_kind`)."""
    from washbench.cueing import WashoutTrace  # deferred: numba

    block = stacked_rows(rows)  # (washouts, N, fields); the lockstep's blocks are freed
    traces = {w: WashoutTrace.from_rows(block[i], platform=platform) for i, w in enumerate(washouts)}  # contiguous
    del block
    return analyse(motion, traces, vestibular, filter_start, measure)
