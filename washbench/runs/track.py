"""``washbench track TASK --out DIR``: the pilot model flies a tracking task in every motion condition.

The conditions, side by side: the aircraft's own motion (what a pilot feels in flight), no motion, and each washout
chosen (``--washout``, ``--variant``; default: the run's default set) on the chosen platform. The loop is
calibrated once (:func:`washbench.pilot.measure.calibrate`), then each condition is adapted, flown ``runs`` times
and measured (:func:`washbench.pilot.measure.measure_condition`); :mod:`washbench.pilot.compare` puts them side by
side and gives the verdict. A condition whose run fails (the monitor stopped the flight) is reported as failed; the
others go on. Published as one result set (:func:`washbench.io.outfolder.result_set`)::

    OUT/
        report.md         the verdict first, the measures, the pilot model, the figures
        track.json        everything the report says, machine-readable, with the provenance
        measures.csv      one row per condition: every measure and its difference from the aircraft's motion
        frf.csv           per condition and forcing frequency: controlled element, open loop, motion filter
        signals.parquet   every run of every condition, every sample (forcing functions, error, control, motion)
        recording.rrd     the first run of each condition in the rerun viewer (unless --no-recording)
        figures/          bode.png, variance.png, motion.png (unless --no-figures)
"""

from __future__ import annotations

import csv
import io
import json
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from washbench.cueing.registry import REFERENCE_KINDS
from washbench.errors import WashbenchError, printable
from washbench.io.atomic import atomic_path, write_text_atomic
from washbench.io.csv_numbers import csv_number
from washbench.io.outfolder import result_set
from washbench.io.parquet_files import write_parquet
from washbench.io.provenance import file_record, flat_strings, merge_provenance, parquet_metadata, utc_now
from washbench.io.result_files import (
    RECORDING_FILE,
    REPORT_FILE,
    TRACK_FILE,
    TRACK_FRF_FILE,
    TRACK_MEASURES_FILE,
    TRACK_SIGNALS_FILE,
)
from washbench.perception.vestibular import model_params, model_record
from washbench.pilot.compare import differences, distance, measures, verdict
from washbench.pilot.loop import AIRCRAFT, NO_MOTION, Condition
from washbench.pilot.measure import ConditionResult, calibrate, measure_condition, motion_filter
from washbench.pilot.params import MultimodalParams
from washbench.pilot.plugins import load_pilot_plugin
from washbench.pilot.senses import DEFAULT_VESTIBULAR
from washbench.pilot.task import Task, load_task, pilot_params
from washbench.review.track_report import write_track_report
from washbench.runs.bound_stage import split_whole
from washbench.runs.options import RunOptions
from washbench.runs.outputs import DEFAULT_OUTPUTS, Outputs


@dataclass(frozen=True)
class TrackOptions:
    """``track``'s own options: ``runs`` (None: the task's), what is written, progress lines, a pilot plugin."""

    runs: int | None = None
    outputs: Outputs = DEFAULT_OUTPUTS
    progress: bool = True
    pilot_plugin: str | None = None


def _say(text: str, progress: bool) -> None:
    if progress:
        print(f"track: {text}", file=sys.stderr, flush=True)


def conditions(options: RunOptions) -> list[Condition]:
    """The aircraft's own motion, no motion, then every washout of ``options`` that runs sample by sample (a washout
    that needs the whole recording, the bound, cannot close a loop: refused). The default set's naive references are
    left out: the aircraft's own motion and no motion are their conditions in the loop (named with ``--washout``,
    they fly)."""
    stepped, whole = split_whole(list(options.washouts))
    if options.washout_names is None and not options.variants:
        stepped = [w for w in stepped if w.kind not in REFERENCE_KINDS]
    if whole:
        raise WashbenchError(f"washout {whole[0].name} needs the whole recording in advance: it cannot fly in the "
                             "loop with a pilot (washbench track)")  # fmt: skip
    return [Condition(AIRCRAFT), Condition(NO_MOTION)] + [Condition(w.name, w, options.limits) for w in stepped]


def run_track(task_path: Path, out_dir: Path, options: RunOptions, track: TrackOptions | None = None) -> dict[str, Any]:
    """Fly, measure and write (module docstring); return the summary (``track.json``'s content)."""
    track = track if track is not None else TrackOptions()
    task, manoeuvre = load_task(task_path, options.aircraft_dirs)
    if track.runs is not None:
        task = _with_runs(task, track.runs)
    vest_name = options.vestibular or DEFAULT_VESTIBULAR
    vestibular = model_params(vest_name)
    plugin = load_pilot_plugin(track.pilot_plugin) if track.pilot_plugin else None
    params = pilot_params(task, MultimodalParams if plugin is None else plugin.params_model)
    conds = conditions(options)
    prov = merge_provenance(
        options.provenance_for(task_path, task.environment.turbulence, manoeuvre.aircraft_files),
        {"vestibular": model_record(vest_name), "task": file_record(task_path, task.name)},
    )
    with result_set(out_dir, "track") as stage:
        started = time.perf_counter()
        _say(f"{task.aircraft}/{task.name}: calibrating the loop", track.progress)
        base = params if plugin is None else MultimodalParams()
        calib, _ = calibrate(task, manoeuvre, base, vestibular, task.adaptation)
        results: list[ConditionResult] = []
        failed: dict[str, str] = {}
        aircraft_runs: list[Any] = []
        for c in conds:
            _say(f"{c.name}: adapting and flying {task.runs} run(s)", track.progress)
            try:
                motion = motion_filter(c, aircraft_runs, task, options.filter_start) if c.name != AIRCRAFT else \
                    motion_filter(c, [], task)  # fmt: skip
                r = measure_condition(
                    task, manoeuvre, c, calib, vestibular, motion,
                    params=params if plugin is None else None,
                    factory=None if plugin is None else plugin.make, plugin_params=params if plugin else None,
                    keep_platform=options.outputs.recording,
                )  # fmt: skip
            except WashbenchError as exc:
                if c.name == AIRCRAFT:
                    raise
                failed[c.name] = str(exc)
                continue
            if c.name == AIRCRAFT:
                aircraft_runs = r.runs
            results.append(r)
        summary = _summary(task, task_path, results, failed, calib, vest_name, plugin, prov, conds)
        summary["wall_s"] = round(time.perf_counter() - started, 3)
        _write(stage, task, results, summary, options.outputs, prov)
    return summary


def _with_runs(task: Task, runs: int) -> Task:
    """``task`` with ``runs`` runs (checked like the file's value)."""
    if not 1 <= runs <= 50:
        raise WashbenchError(f"--runs: expected 1 to 50 runs, got {runs}")
    copy = task.model_copy(update={"runs": runs})
    copy._source, copy._lines, copy._aircraft_dirs = task._source, task._lines, task._aircraft_dirs
    return copy


def _num(x: Any) -> Any:
    """A JSON-safe number (NaN and infinities as null), rounded to 9 significant digits."""
    if isinstance(x, (float, np.floating)):
        x = float(x)
        return None if not math.isfinite(x) else float(f"{x:.9g}")
    if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
        return int(x)
    return x


def _clean(d: Any) -> Any:
    if isinstance(d, dict):
        return {str(k): _clean(v) for k, v in d.items()}
    if isinstance(d, (list, tuple)):
        return [_clean(v) for v in d]
    return _num(d)


def _summary(
    task: Task,
    task_path: Path,
    results: Sequence[ConditionResult],
    failed: dict[str, str],
    calib: Any,
    vest_name: str,
    plugin: Any,
    prov: dict[str, Any],
    conds: Sequence[Condition],
) -> dict[str, Any]:
    """``track.json``'s content: the task, the conditions (measures, differences, distance, parameters,
    prediction), the verdict, the calibration, the provenance."""
    table = {r.name: measures(r, task) for r in results}
    ref = table[AIRCRAFT]
    by_name = {r.name: r for r in results}
    rows = []
    for c in conds:
        r = by_name.get(c.name)
        entry: dict[str, Any] = {
            "name": c.name,
            "kind": c.kind,
            "washout_kind": c.washout.kind if c.washout is not None else None,
            "ok": r is not None,
            "reason": failed.get(c.name, ""),
        }
        if r is not None:
            m = table[c.name]
            entry["measures"] = m
            entry["differences_pct"] = differences(m, ref)
            entry["distance_pct"] = distance(m, ref)
            entry["params"] = r.params
            if r.prediction is not None:
                p = r.prediction
                entry["prediction"] = {
                    "error_var_deg2": p.error_variance * (180.0 / math.pi) ** 2,
                    "control_var": p.control_variance,
                    "target_crossover_radps": p.target.frequency_radps,
                    "target_phase_margin_deg": p.target.phase_margin_deg,
                    "disturbance_crossover_radps": p.disturbance.frequency_radps,
                    "disturbance_phase_margin_deg": p.disturbance.phase_margin_deg,
                    "stable": p.stable,
                }
        rows.append(entry)
    washouts = [c.name for c in conds if c.kind == "washout" and c.name in table]
    no_verdict = {"order": [], "distance_pct": {}, "closest": None}
    w, h = calib.plant.w, calib.plant.h
    summary = {
        "task": {
            "name": task.name, "aircraft": task.aircraft, "axis": task.axis, "file": str(task_path),
            "runs": task.runs, "measurement_s": task.measurement_s, "run_in_s": task.run_in_s,
            "rate_hz": task.rate_hz, "seed": task.seed,
        },
        "vestibular": model_record(vest_name),
        "pilot": {
            "model": "multimodal" if plugin is None else "plugin",
            "plugin": plugin.record() if plugin is not None else None,
            "adaptation": task.adaptation.model_dump(mode="json"),
        },
        "conditions": rows,
        "verdict": verdict(table, washouts, task.runs) if washouts else no_verdict,
        "calibration": {
            "frequencies_radps": list(w), "gain": list(np.abs(h)),
            "phase_deg": list(np.degrees(np.unwrap(np.angle(h)))),
            "disturbance_amplitudes": list(calib.disturbance.amplitudes),
        },
        "created_utc": utc_now(),
        "provenance": prov,
    }  # fmt: skip
    return _clean(summary)


def _cell(x: Any) -> str:
    """A CSV cell: a number at full precision, empty when missing (NaN, null)."""
    return "" if x is None else csv_number(float(x))


def _measures_csv(summary: dict[str, Any]) -> str:
    rows = [c for c in summary["conditions"] if c["ok"]]
    keys: list[str] = []
    for c in rows:
        keys += [k for k in c["measures"] if k not in keys]
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["condition", "kind", "distance_pct", *keys, *(f"{k}_diff_pct" for k in keys)])
    for c in rows:
        m, d = c["measures"], c["differences_pct"]
        writer.writerow([c["name"], c["kind"], _cell(c["distance_pct"]), *(_cell(m.get(k)) for k in keys),
                         *(_cell(d.get(k)) for k in keys)])  # fmt: skip
    return buf.getvalue()


def _frf_csv(results: Sequence[ConditionResult]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["condition", "forcing", "frequency_radps", "plant_gain", "plant_phase_deg", "open_loop_gain",
                     "open_loop_phase_deg", "motion_gain", "motion_phase_deg"])  # fmt: skip
    for r in results:
        idf = r.identified
        for which in ("target", "disturbance"):
            w = getattr(idf, f"w_{which}")
            for i in range(len(w)):
                hp = getattr(idf, f"plant_{which}")[i]
                ho = getattr(idf, f"open_loop_{which}")[i]
                hm = getattr(idf, f"motion_{which}")[i]
                writer.writerow(
                    [
                        r.name,
                        which,
                        csv_number(w[i]),
                        *(v for h in (hp, ho, hm) for v in (csv_number(abs(h)), csv_number(math.degrees(np.angle(h))))),
                    ]
                )
    return buf.getvalue()


def _signals_parquet(path: Path, results: Sequence[ConditionResult], prov: dict[str, Any]) -> None:
    import pyarrow as pa

    cols: dict[str, list[np.ndarray]] = {}
    deg = 180.0 / math.pi
    spec = (("t_s", "t_s", 1.0), ("target_deg", "target_rad", deg), ("disturbance", "disturbance", 1.0),
            ("error_deg", "error_rad", deg), ("control", "control", 1.0), ("control_visual", "control_visual", 1.0),
            ("control_vestibular", "control_vestibular", 1.0), ("attitude_deg", "attitude_rad", deg),
            ("aircraft_rate_degps", "aircraft_rate_radps", deg), ("head_rate_degps", "head_rate_radps", deg),
            ("felt_rate_degps", "felt_rate_radps", deg), ("head_force_mps2", "head_force_mps2", 1.0),
            ("felt_force_mps2", "felt_force_mps2", 1.0))  # fmt: skip
    names: list[str] = []
    runs: list[np.ndarray] = []
    for r in results:
        for i, run in enumerate(r.runs):
            n = len(run.t_s)
            names += [r.name] * n
            runs.append(np.full(n, i + 1, dtype=np.int16))
            for col, attr, f in spec:
                cols.setdefault(col, []).append(np.asarray(getattr(run, attr)) * f)
    table = pa.table({"condition": pa.array(names, pa.string()), "run": np.concatenate(runs),
                      **{k: np.concatenate(v) for k, v in cols.items()}})  # fmt: skip
    table = table.replace_schema_metadata(parquet_metadata(prov))
    with atomic_path(path) as tmp:
        write_parquet(tmp, table)


def _write(stage: Path, task: Task, results: Sequence[ConditionResult], summary: dict[str, Any], outputs: Outputs,
           prov: dict[str, Any]) -> None:  # fmt: skip
    title = f"{task.aircraft} / {task.name} ({task.axis})"
    write_text_atomic(stage / TRACK_FILE, json.dumps(summary, indent=1, allow_nan=False) + "\n")
    write_text_atomic(stage / TRACK_MEASURES_FILE, _measures_csv(summary))
    write_text_atomic(stage / TRACK_FRF_FILE, _frf_csv(results))
    _signals_parquet(stage / TRACK_SIGNALS_FILE, results, prov)
    report = write_track_report(stage, figures=outputs.figures).read_text(encoding="utf-8")
    if outputs.recording:
        from washbench.review.track_recording import write_track_recording  # deferred: rerun

        props = flat_strings(prov, summary.get("created_utc"))
        write_track_recording(stage / RECORDING_FILE, results, title, report, props)


def track_command(task_path: Path, out_dir: Path, options: RunOptions, track: TrackOptions) -> int:
    """CLI entry: 0 when every condition was measured, 1 when one failed (the report says which)."""
    summary = run_track(task_path, out_dir, options, track)
    v = summary["verdict"]
    for c in summary["conditions"]:
        if not c["ok"]:
            print(f"  {c['name']}: FAILED ({printable(c['reason'])})")
            continue
        m = c["measures"]
        d = c.get("distance_pct")
        print(f"  {c['name']}: error {_fmt(math.sqrt(m['error_var_deg2']) if m['error_var_deg2'] else None)} deg RMS,"
              f" disturbance crossover {_fmt(m['disturbance_crossover_radps'])} rad/s, "
              f"K_v {_fmt(m.get('visual_gain'))}, K_m {_fmt(m.get('vestibular_gain'))}"
              + (f", distance from flight {_fmt(d)} %" if c["kind"] != "aircraft" else ""))  # fmt: skip
    closest = v.get("closest")
    task = summary["task"]
    line = f"{task['aircraft']}/{task['name']}: {len(summary['conditions'])} conditions in {summary['wall_s']:.1f} s"
    if closest:
        line += f"; closest to flight: {closest}"
    print(f"{line}; report: {printable(str(out_dir / REPORT_FILE))}")
    return 0 if all(c["ok"] for c in summary["conditions"]) else 1


def _fmt(x: Any) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.3g}"
