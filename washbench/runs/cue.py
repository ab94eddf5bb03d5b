"""``washbench cue``: washouts, Atlas model, vestibular models and metrics on a recorded trace.

The chain itself (washouts, perception, metrics, the traces table) is :mod:`washbench.runs.chain`, which
``washbench run`` enters with a flight flown in lockstep and ``cue`` with a recorded file. Here is the command,
in stages: :func:`read_input` (reading and conversion to washbench units and axes), :func:`prepare_segments` (time
resets, window, gaps, uniform grid or resampling, plausibility), :func:`write_outputs` (per segment
:func:`washbench.runs.chain.stream_cue` and the other files of a ``run`` result folder, all renamed into place
together), :func:`run_cue` (all of it, the whole set published at once).
"""

from __future__ import annotations

import contextlib
import functools
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from washbench.analysis.best_motion import Scoring
from washbench.analysis.felt import DEFAULT_MEASURE, FeltMeasure
from washbench.analysis.ranking import perceived_motion
from washbench.cueing.variants import tilt_rate_limit_radps
from washbench.errors import WashbenchError, located, printable
from washbench.io.atomic import atomic_path
from washbench.io.columns import AIRCRAFT
from washbench.io.input_format import InputFormat
from washbench.io.metrics_csv import write_metrics_csv
from washbench.io.motion import Motion
from washbench.io.names import check_identifier
from washbench.io.outfolder import check_out_path, result_set
from washbench.io.paths import resolve_manoeuvre
from washbench.io.plausibility import Finding, check_arrays
from washbench.io.progress import Progress
from washbench.io.provenance import file_record, flat_strings, parquet_metadata, read_parquet_provenance, utc_now
from washbench.io.publish import result_path
from washbench.io.readers import Samples, read_samples
from washbench.io.resample import check_gaps, check_step, resample, split_resets, to_motion, window
from washbench.io.result_files import METRICS_FILE, RECORDING_FILE, RUN_FILE, TRACES_FILE
from washbench.review.input_figure import draw_for_result, input_labels
from washbench.runs.beside import beside
from washbench.runs.bound_stage import bound_outputs
from washbench.runs.chain import CueResult, aircraft_attitude, stream_cue
from washbench.runs.options import RunOptions, load_options
from washbench.runs.result_folder import RunSummary, write_run_json, write_run_recording, write_run_review

# --------------------------------------------------------------------------- the cue command, stage by stage


@dataclass(frozen=True)
class CueOptions:
    """What only ``washbench cue`` is told: how to read, cut and put on a grid the recorded input.

    Everything a cue shares with ``run`` (the washouts, parameter and platform files, the filters' start state,
    the optional outputs, the ranking rule, the vestibular model) is the run's options, :class:`RunOptions`
    (:func:`washbench.runs.options.load_options`), given to :func:`run_cue` beside these.
    """

    fmt: InputFormat = field(default_factory=InputFormat)
    resample_hz: float | None = None
    max_gap_s: float | None = None
    split: bool = True
    start_s: float | None = None
    end_s: float | None = None
    strict: bool = False
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


def segment_summary(
    input_path: Path, seg: Segment, result: CueResult, out_dir: Path, measure: FeltMeasure = DEFAULT_MEASURE
) -> RunSummary:
    """The run summary (``run.json``, report) of one cued segment; a crash in the data makes it failed
    (``measure``: the felt error's, for the aircraft pilot's felt motion)."""
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
        motion=perceived_motion(ac.f_mps2, ac.omega_radps, seg.motion.dt_s, measure),
        saturations={w: dict(t.saturation_counts) for w, t in result.traces.items()},
    )


def recorded_attitude(motion: Motion) -> np.ndarray:
    """The aircraft's attitude for the recording: from ``phi_deg``/``theta_deg``/``psi_deg`` when the input
    has them, else level (an attitude is not needed by the cueing and is not invented)."""
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
    run: RunOptions,
    start: float,
    provenance: dict[str, Any] | None = None,
    progress: bool = False,
) -> list[tuple[RunSummary, CueResult]]:
    """Cueing and outputs: per segment (``out_dir`` itself, or ``out_dir/<segment>/`` when there are several) the
    files of a ``run`` result folder: traces.parquet (written as it is cued, :func:`stream_cue`), metrics.csv,
    run.json, ranking.csv, report.md and recording.rrd (unless ``run.outputs`` says not). Every file is written
    under a temporary name and renamed into place once complete: traces.parquet, metrics.csv and run.json
    together, then the recording, while the figures, ranking.csv and report.md are drawn from those beside it (in a
    child process where a core is free, :mod:`washbench.runs.beside`), so a failure leaves no half-written file
    (``out_dir`` is the command's stage, published whole). Returns (summary, result) per segment; ``start``: the
    command's start (``time.perf_counter()``) for run.json's wall time; ``run``: the washouts, the platform, the
    filters' start state, the vestibular model and the optional outputs."""
    recording, figures = run.outputs.recording, run.outputs.figures
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise WashbenchError(located(out_dir, "output path exists and is not a folder"))
    created = utc_now()
    done: list[tuple[RunSummary, CueResult]] = []
    shown = Progress("cue", sum(seg.motion.n for seg in segments)) if progress else None
    try:
        with contextlib.ExitStack() as stack:
            if shown is not None:
                stack.callback(shown.close)
            offset = 0
            for seg in segments:
                folder = result_path(out_dir, seg.name) if seg.name else out_dir
                folder.mkdir(parents=True, exist_ok=True)
                with contextlib.ExitStack() as files:  # renamed into place together when all three are complete
                    if figures and seg.labels:  # the input as read (it needs nothing else), drawn beside the cueing
                        files.enter_context(beside(functools.partial(_input_figure, input_path, seg, folder)))
                    tmp = {name: files.enter_context(atomic_path(folder / name))
                           for name in (TRACES_FILE, METRICS_FILE, RUN_FILE)}  # fmt: skip
                    meta = parquet_metadata(provenance) if provenance else None
                    if shown is not None:
                        shown.offset = offset
                    result = stream_cue(
                        seg.motion, run.washouts, run.limits, tmp[TRACES_FILE], meta,
                        filter_start=run.filter_start, recording=recording, figures=figures, progress=shown,
                        vestibular=run.vestibular_params, measure=run.rank_rule.measure,
                        scoring=Scoring(run.rank_rule, run.vestibular_params),
                    )  # fmt: skip
                    offset += seg.motion.n
                    summary = segment_summary(input_path, seg, result, folder, run.rank_rule.measure)
                    write_metrics_csv(tmp[METRICS_FILE], result.metrics)
                    extra = {
                        "input": str(input_path),
                        "segment": seg.name,
                        "t_start_s": float(seg.motion.t_s[0]),
                        "t_end_s": float(seg.motion.t_s[-1]),
                        "filter_start": run.filter_start,
                        "conversions": list(seg.notes),
                        "input_labels": list(seg.labels),
                        "warnings": [f.text for f in seg.findings],
                        "algorithms": dict(result.algorithms),
                    }

                    bound = bound_outputs(folder, result, run.washouts, run.limits, run.vestibular_params,
                                          run.rank_rule, run.filter_start)  # fmt: skip
                    extra |= {"bound": bound} if bound else {}
                    if provenance:
                        extra |= {"created_utc": created, "provenance": provenance}
                    write_run_json(tmp[RUN_FILE], summary, time.perf_counter() - start, extra)
                if not recording:  # a recording of an earlier set would mislead
                    (folder / RECORDING_FILE).unlink(missing_ok=True)
                review = functools.partial(write_run_review, folder, summary, str(input_path), result.review_table(),
                                           figures, recording)  # fmt: skip
                with beside(review, fork=figures and recording):
                    if recording:
                        with atomic_path(folder / RECORDING_FILE) as rrd:
                            title = f"{summary.aircraft} / {summary.manoeuvre}"
                            q = recorded_attitude(seg.motion)
                            props = flat_strings(provenance, created) if provenance else None
                            write_run_recording(rrd, title, seg.motion, result, run.limits, q, [], props,
                                                run.rank_rule, bound,
                                                {w.name: tilt_rate_limit_radps(w) for w in run.washouts})  # fmt: skip
                done.append((summary, result))
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot write results: {exc.strerror or exc}")) from None
    return done


def _input_figure(input_path: Path, seg: Segment, folder: Path) -> None:
    """A cued segment's figure of the input as read (``figures/input.png``), linked first in its report."""
    title = f"{input_path.name}{f' {seg.name}' if seg.name else ''}"
    draw_for_result(folder, title, seg.motion, seg.labels, seg.notes)


def refuse_manoeuvre(input_path: Path) -> None:
    """WashbenchError (one line) when ``input_path`` is a manoeuvre to fly, not a recorded trace: a YAML manoeuvre
    file, a JSBSim script, or a bundled manoeuvre's name (``c172/takeoff``). ``washbench run`` flies those."""
    text = str(input_path)
    if input_path.suffix.lower() in (".yaml", ".yml", ".xml"):
        what = "a JSBSim script" if input_path.suffix.lower() == ".xml" else "a manoeuvre file"
    elif not input_path.exists() and resolve_manoeuvre(input_path).exists():
        what = "a bundled manoeuvre's name"
    else:
        return
    raise WashbenchError(f"{text}: {what}, which cue does not read (cue takes a recorded trace: CSV, Parquet, "
                         f"X-Plane Data.txt, JSBSim CSV); fly it with the washouts: washbench run {text} "
                         "--out DIR")  # fmt: skip


def run_cue(
    input_path: Path,
    out_dir: Path,
    options: CueOptions | None = None,
    run: RunOptions | None = None,
    adopt: Sequence[str] = (),
) -> int:
    """The ``washbench cue`` command: read, convert, cut and check, cue, write; 0, or 1 if the data holds a crash.

    ``options``: how the input is read and prepared (None: the defaults); ``run``: the run's options, as ``run``
    and ``suite`` are given them (:func:`washbench.runs.options.load_options`: the washouts, the platform, the
    filters' start state, the optional outputs, the ranking rule, the vestibular model; None: the defaults).
    ``adopt``: files already in ``out_dir`` that become part of the published set (``washbench live``'s input).
    Raises WashbenchError (one line) for bad names, parameter files or input; writes nothing then.
    """
    check_out_path(out_dir)
    refuse_manoeuvre(input_path)
    opts = options or CueOptions()
    for flag, value in (("--max-gap-s", opts.max_gap_s), ("--resample", opts.resample_hz)):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise WashbenchError(f"{flag}: expected a positive number, got {value:g}")
    start = time.perf_counter()
    run = run if run is not None else load_options()
    samples = read_input(input_path, opts.fmt)
    segments = prepare_segments(samples, opts)
    with result_set(out_dir, "cue", adopt) as stage:  # the whole set replaces the previous one at once
        for seg in segments:
            for f in seg.findings:
                where = f"{input_path}{f' ({seg.name})' if seg.name else ''}"
                print(f"washbench: warning: {printable(f'{where}: {f.text}')}", file=sys.stderr)
        prov = run.provenance_for()
        prov["input"] = file_record(input_path)
        is_parquet = input_path.suffix.lower() in (".parquet", ".pq")
        input_prov = read_parquet_provenance(input_path) if is_parquet else None
        if input_prov:
            prov["input"]["provenance"] = input_prov
        done = write_outputs(stage, input_path, segments, run, start, prov, progress=opts.progress)
    out_dir = Path(out_dir)
    for seg, (summary, result) in zip(segments, done, strict=True):
        m = seg.motion
        label = f"{input_path}{f' {seg.name}' if seg.name else ''}"
        print(f"{label}: {m.n} rows, {m.duration_s:.3f} s at dt = {m.dt_s:.6g} s ({1.0 / m.dt_s:.6g} Hz)")
        for note in seg.notes:
            print(f"  {note}")
        for name in run.washout_order:
            counts = result.traces[name].saturation_counts
            sat = ", ".join(f"{k} {v}" for k, v in counts.items() if v) or "none"
            print(f"  {name}: saturated samples: {sat}")
        if not summary.ok:
            print(f"  FAILED: {summary.reason}")
        print(f"wrote {printable(str(out_dir / summary.run_dir.relative_to(stage)))}")
    return 0 if all(s.ok for s, _ in done) else 1
