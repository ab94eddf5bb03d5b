"""``washbench run``: fly a manoeuvre with the three washouts in lockstep, then perceive, measure, record.

At every JSBSim step the scripted pilot's flight gives one sample of pilot-head motion; the
sample goes straight through the three washouts and the kinematic Atlas model
(:class:`washbench.cueing.CueingBank`, the streaming form), as a real simulator would run them.
After the flight the vestibular models, the metrics and the tables are the same code as
``washbench cue`` (:func:`washbench.runs.cue.analyse`), on the flight as written to
``flight.parquet`` and read back, so ``washbench fly`` then ``washbench cue`` gives the same
numbers bit for bit.

Output, published as a whole folder (built under a temporary name, then renamed into place, so
an interrupted run never leaves a half-written folder that looks complete)::

    OUT/<aircraft>/<manoeuvre>/
        flight.json      manoeuvre, phases, checks (as from washbench fly)
        flight.parquet   the flown trace (washbench cue input columns + flight state)
        traces.parquet   washbench cue columns + flight-state columns
        metrics.csv      washout,dof,npc,integral_error,max_error
        recording.rrd    rerun recording with its blueprint
        run.json         summary used by washbench suite (status, motion per DOF, saturations)
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import shutil
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from washbench.analysis.metrics import MetricRow
from washbench.analysis.ranking import DOFS, perceived_motion
from washbench.errors import WashbenchError, located
from washbench.io.atomic import write_text_atomic
from washbench.io.provenance import build_provenance, flat_strings, utc_now
from washbench.io.publish import (
    check_replaceable,
    clean_partials,
    partial_dir,
    publish_dir,
    remove_if_empty,
    result_path,
)
from washbench.runs.outputs import DEFAULT_OUTPUTS, Outputs

if TYPE_CHECKING:
    from washbench.io.results import Motion
    from washbench.platform import PlatformLimits
    from washbench.review.rerun_log import PlatformEnvelope
    from washbench.runs.cue import CueResult

RUN_FILES = (
    *("flight.json", "flight.parquet", "traces.parquet", "metrics.csv", "recording.rrd", "run.json"),
    *("ranking.csv", "report.md", "figures"),
)


@dataclass(frozen=True)
class RunSummary:
    """What one ``washbench run`` gave: status, where, and what the suite needs to compare.

    A run that could not start (bad file) or broke has only ``ok`` False and the ``reason``.
    """

    ok: bool
    reason: str = ""
    aircraft: str = ""
    manoeuvre: str = ""
    run_dir: Path | None = None
    steps: int = 0
    dt_s: float = 0.0
    checks_passed: int = 0
    checks_total: int = 0
    metrics: list[MetricRow] = field(default_factory=list)
    motion: dict[str, float] = field(default_factory=dict)  # DOF -> aircraft pilot's perceived motion
    saturations: dict[str, dict[str, int]] = field(default_factory=dict)


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


def metrics_markdown(title: str, rows: list[MetricRow]) -> str:
    """The metric table of one run as Markdown, DOF by washout (for the recording)."""
    from washbench.review.metrics_table import metrics_table_markdown

    return metrics_table_markdown(title, rows)


#: The file that marks a folder as a ``washbench run`` result (only such a folder is ever replaced).
RUN_MARKER = "run.json"


def run_dir(out_root: Path, aircraft: str, manoeuvre: str) -> Path:
    """``OUT/<aircraft>/<manoeuvre>``, proven inside ``out_root`` (both names are identifiers)."""
    return result_path(out_root, aircraft, manoeuvre)


def _marker(aircraft: str, manoeuvre: str) -> dict[str, object]:
    return {"aircraft": aircraft, "manoeuvre": manoeuvre}


def run_manoeuvre(
    manoeuvre_path: Path,
    out_root: Path,
    *,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    progress: bool = False,
    washouts: Sequence[str] | None = None,
    variants: Sequence[str] = (),
    filter_start: str = "steady",
    aircraft_dirs: Sequence[Path] = (),
    outputs: Outputs = DEFAULT_OUTPUTS,
    rank_by: str | None = None,
    vestibular: str | None = None,
) -> RunSummary:
    """Fly one manoeuvre with the washouts in lockstep and write its results folder.

    ``outputs``: whether ``recording.rrd`` and the figures are written (:class:`washbench.runs.outputs.Outputs`);
    every other file is.

    ``washouts`` (built-in names), ``variants`` (``--variant`` texts) and the parameter file's ``variants:``
    select the washouts (:func:`washbench.cueing.variants.select_washouts`; default the three built-in ones).
    ``filter_start``: the washouts' and vestibular models' start state (``steady`` or ``rest``).

    Raises WashbenchError for a bad manoeuvre, parameter or platform file, or a result place that
    cannot be used (all checked before flying; nothing written). A flight that crashes or fails a check
    still writes its results (what was flown), with ``ok`` False and the reason. The result folder
    replaces only a previous ``washbench run`` result of the same manoeuvre (recognised by its run.json).
    """
    from washbench.cueing.variants import select_washouts
    from washbench.flight.manoeuvre import load_manoeuvre
    from washbench.platform.limits import load_platform_limits

    # every input and the result place first: a bad one fails before anything is flown
    manoeuvre = load_manoeuvre(manoeuvre_path, aircraft_dirs)
    specs = select_washouts(washouts, variants, params_path)
    limits = load_platform_limits(platform_path)
    turbulence = manoeuvre.environment.turbulence
    ac_files = manoeuvre.aircraft_files
    flight_prov = build_provenance(manoeuvre_path=manoeuvre_path, turbulence=turbulence, aircraft_files=ac_files)
    prov = run_provenance(params_path, platform_path, specs, limits, manoeuvre_path, turbulence, ac_files, rank_by,
                          vestibular)  # fmt: skip
    final = run_dir(Path(out_root), manoeuvre.aircraft, manoeuvre.name)
    marker = _marker(manoeuvre.aircraft, manoeuvre.name)
    check_replaceable(final, RUN_MARKER, marker)  # before flying: a folder in the way fails now, not after
    clean_partials(final.parent)

    from washbench.flight.fly import fly, write_flight

    washouts = tuple(w.name for w in specs)
    rows, lockstep = lockstep_blocks(specs, limits, manoeuvre.dt_s, filter_start)
    partial = partial_dir(final)  # before flying: a file in the way of OUT/<aircraft>/ fails now
    published = False
    try:
        start = time.perf_counter()
        created = utc_now()
        flight = fly(manoeuvre, block_hook=lockstep, block_size=LOCKSTEP_BLOCK, progress=progress)
        n = len(flight.t_s)
        if sample_count(rows) != n:
            raise RuntimeError(f"washouts ran {sample_count(rows)} steps for {n} recorded samples")
        write_flight(partial, flight, str(manoeuvre_path), flight_prov)
        if n < 2:
            raise WashbenchError(located(manoeuvre_path, f"the flight recorded {n} sample(s): nothing to cue"))
        cols = flight.columns
        # the flight is "failed" when the monitor stopped it or a check failed, with the reason
        summary = RunSummary(
            ok=flight.ok,
            reason=flight.reason,
            aircraft=manoeuvre.aircraft,
            manoeuvre=manoeuvre.name,
            run_dir=final,
            checks_passed=sum(1 for c in flight.checks if c[3]),
            checks_total=len(flight.checks),
        )
        ac_q = aircraft_attitude(cols["phi_deg"], cols["theta_deg"], cols["psi_deg"])
        extra = {"created_utc": created, "provenance": prov}
        summary = write_cued_folder(
            partial, summary, rows, washouts, limits, ac_q, flight.phases, start, filter_start, extra, prov,
            outputs=outputs,
        )  # fmt: skip
        publish_dir(partial, final, RUN_MARKER, marker)
        published = True
    finally:
        with contextlib.suppress(FileNotFoundError):
            shutil.rmtree(partial)
        if not published:
            remove_if_empty(final.parent)
    return summary


def run_provenance(
    params_path: Path | None,
    platform_path: Path | None,
    specs: Sequence[Any],
    limits: Any,
    manoeuvre_path: Path | None = None,
    turbulence: Any = None,
    aircraft_files: Any = None,
    rank_by: str | None = None,
    vestibular: str | None = None,
) -> dict[str, Any]:
    """The provenance of a run (:mod:`washbench.io.provenance`): the files actually used, the washouts, versions,
    the ranking rule (:func:`washbench.runs.rank_rule.load_rank_rule`)."""
    from washbench.cueing import load_washout_params
    from washbench.cueing.params import DEFAULT_PARAMS_PATH
    from washbench.perception.vestibular import model_record
    from washbench.platform.limits import DEFAULT_LIMITS_PATH
    from washbench.runs.rank_rule import load_rank_rule

    return build_provenance(
        manoeuvre_path=manoeuvre_path,
        turbulence=turbulence,
        aircraft_files=aircraft_files,
        params_path=params_path or DEFAULT_PARAMS_PATH,
        params=load_washout_params(params_path),
        washouts=specs,
        platform_path=platform_path or DEFAULT_LIMITS_PATH,
        platform=limits,
        ranking=load_rank_rule(params_path, rank_by).record(),
        vestibular=model_record(vestibular),
    )


def check_max_time(max_time_s: float | None) -> None:
    """``--max-time-s``: None or a positive, finite number of seconds (WashbenchError otherwise)."""
    if max_time_s is not None and not (math.isfinite(max_time_s) and max_time_s > 0.0):
        raise WashbenchError(f"--max-time-s: expected a positive number of seconds, got {max_time_s:g}")


def lockstep_washouts(
    specs: Sequence[Any], limits: Any, dt_s: float, filter_start: str = "steady"
) -> tuple[list[np.ndarray], Any]:
    """A washout bank (selected :class:`washbench.cueing.variants.Washout` s) run in lockstep with a flight:
    (the rows it fills, the flight's step hook)."""
    from washbench.cueing import CueingBank

    bank = CueingBank(specs, None, limits, dt_s, filter_start)
    rows: list[np.ndarray] = []
    step = bank.step
    omega_deg = np.empty(3)

    def lockstep(k: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> None:
        # The washouts see the angular velocity exactly as flight.parquet stores it (deg/s) and
        # washbench cue reads it back (np.radians), so both paths give the same bits.
        np.degrees(omega_radps, out=omega_deg)
        rows.append(step(f_mps2, np.radians(omega_deg)).copy())

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
    from washbench.cueing import CueingBank

    bank = CueingBank(specs, None, limits, dt_s, filter_start)
    rows: list[np.ndarray] = []
    done = [0]

    def lockstep(k0: int, f_mps2: np.ndarray, omega_radps: np.ndarray) -> None:
        if k0 != done[0]:
            raise RuntimeError(f"lockstep: block starts at sample {k0}, expected {done[0]}")
        # The washouts see the angular velocity exactly as flight.parquet stores it (deg/s) and
        # washbench cue reads it back (np.radians), so both paths give the same bits.
        rows.append(bank.steps(f_mps2, np.radians(np.degrees(omega_radps))))
        done[0] += f_mps2.shape[0]

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


def write_cued_folder(
    folder: Path,
    summary: RunSummary,
    rows: list[np.ndarray],
    washouts: tuple[str, ...],
    limits: Any,
    aircraft_q: np.ndarray,
    phases: list[tuple[str, float, float]],
    start: float,
    filter_start: str = "steady",
    extra: dict[str, object] | None = None,
    provenance: dict[str, Any] | None = None,
    outputs: Outputs = DEFAULT_OUTPUTS,
) -> RunSummary:
    """Everything after the flight, into ``folder`` (which already holds ``flight.parquet``): perception and
    metrics on the flight read back (as ``washbench cue`` reads it), traces.parquet, metrics.csv, recording.rrd,
    run.json, ranking.csv, report.md and figures/. Returns ``summary`` completed with the steps, metrics and
    saturations. ``provenance`` (no date) goes into traces.parquet's metadata; ``extra`` into run.json. The
    vestibular model is the one the provenance records (``vestibular``; the default without)."""
    from washbench.cueing import WashoutTrace
    from washbench.io.results import read_motion
    from washbench.runs.cue import analyse, write_results
    from washbench.runs.suite import write_run_review

    motion = read_motion(folder / "flight.parquet")
    block = stacked_rows(rows)  # (washouts, N, fields); the lockstep's blocks are freed
    traces = {w: WashoutTrace.from_rows(block[i]) for i, w in enumerate(washouts)}  # contiguous columns
    del block
    from washbench.perception.vestibular import model_params

    vest = (provenance or {}).get("vestibular") or {}
    result = analyse(motion, traces, model_params(vest.get("model")), filter_start=filter_start)
    write_results(folder, result, provenance)
    if outputs.recording:
        title = f"{summary.aircraft} / {summary.manoeuvre}"
        props = flat_strings(provenance, str((extra or {}).get("created_utc") or "")) if provenance else None
        write_run_recording(folder / "recording.rrd", title, motion, result, limits, aircraft_q, phases, props)
    ac = result.perceived["aircraft"]
    summary = dataclasses.replace(
        summary,
        steps=motion.n,
        dt_s=motion.dt_s,
        metrics=list(result.metrics),
        motion=perceived_motion(ac.f_mps2, ac.omega_radps, motion.dt_s),
        saturations={w: dict(traces[w].saturation_counts) for w in washouts},
    )
    write_run_json(folder / "run.json", summary, time.perf_counter() - start, extra)
    write_run_review(folder, dataclasses.replace(summary, run_dir=folder), table=result.columns(),
                     figures=outputs.figures)
    return summary


def run_script(
    script_path: Path,
    out_root: Path,
    *,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    max_time_s: float | None = None,
    filter_start: str = "steady",
    aircraft_dirs: Sequence[Path] = (),
    washouts: Sequence[str] | None = None,
    variants: Sequence[str] = (),
    outputs: Outputs = DEFAULT_OUTPUTS,
    rank_by: str | None = None,
    vestibular: str | None = None,
) -> list[RunSummary]:
    """Fly a JSBSim script (:mod:`washbench.flight.scripts`) with the washouts in lockstep, one result per run.

    Writes ``OUT/<aircraft>/<script>/`` (one run) or ``OUT/<aircraft>/<script>/<run_i>/`` (a script that
    resets), published as one folder. A crash still writes what was flown, with ``ok`` False and the reason.
    """
    from washbench.cueing.params import check_filter_start
    from washbench.cueing.variants import select_washouts
    from washbench.flight.scripts import DEFAULT_MAX_TIME_S, fly_script, load_script_info, write_script_flight
    from washbench.platform import load_platform_limits

    info = load_script_info(script_path, aircraft_dirs)
    check_filter_start(filter_start)
    check_max_time(max_time_s)
    if max_time_s is None and info.end_s > DEFAULT_MAX_TIME_S:  # announced by the commands (script_plan)
        max_time_s = DEFAULT_MAX_TIME_S
    specs = select_washouts(washouts, variants, params_path)
    limits = load_platform_limits(platform_path)
    prov = run_provenance(params_path, platform_path, specs, limits, script_path, rank_by=rank_by,
                          vestibular=vestibular)  # fmt: skip
    created = utc_now()
    final = run_dir(Path(out_root), info.aircraft, info.name)
    marker = {"aircraft": info.aircraft}  # one run.json, or one per run of a script that resets
    check_replaceable(final, RUN_MARKER, marker, nested=True)
    clean_partials(final.parent)
    names = tuple(w.name for w in specs)
    banks: list[list[np.ndarray]] = []

    def segment_hook(i: int, dt_s: float) -> Any:
        rows, hook = lockstep_washouts(specs, limits, dt_s, filter_start)
        banks.append(rows)
        return hook

    start = time.perf_counter()
    flight = fly_script(script_path, max_time_s=max_time_s, segment_hook=segment_hook, aircraft_dirs=aircraft_dirs)
    partial = partial_dir(final)
    several = len(flight.segments) > 1
    summaries = []
    try:
        for seg, rows in zip(flight.segments, banks, strict=True):
            folder = partial / seg.name if several else partial
            folder.mkdir(exist_ok=True)
            write_script_flight(folder, flight, seg)
            summary = RunSummary(
                ok=seg.ok,
                reason=seg.reason,
                aircraft=info.aircraft,
                manoeuvre=f"{info.name}/{seg.name}" if several else info.name,
                run_dir=final / seg.name if several else final,
            )
            if seg.n < 2:
                summaries.append(dataclasses.replace(summary, ok=False, reason=seg.reason or "nothing recorded"))
                continue
            cols = seg.columns
            ac_q = aircraft_attitude(cols["phi_deg"], cols["theta_deg"], cols["psi_deg"])
            extra = {"script": str(info.path), "segment": seg.name, "stopped_by_time_limit": flight.stopped_by_limit}
            extra |= {"created_utc": created, "provenance": prov}
            summaries.append(
                write_cued_folder(folder, summary, rows, names, limits, ac_q, [], start, filter_start, extra, prov,
                                  outputs=outputs)
            )
        publish_dir(partial, final, RUN_MARKER, marker, nested=True)
    finally:
        with contextlib.suppress(FileNotFoundError):
            shutil.rmtree(partial)
        remove_if_empty(final.parent)
    return summaries


def write_run_json(path: Path, s: RunSummary, wall_s: float, extra: dict[str, object] | None = None) -> None:
    """``run.json``: the summary of one result folder (``extra``: more keys, e.g. what ``cue`` read)."""
    doc: dict[str, object] = {
        "aircraft": s.aircraft,
        "manoeuvre": s.manoeuvre,
        "ok": s.ok,
        "reason": s.reason,
        "steps": s.steps,
        "dt_s": s.dt_s,
        "wall_s": round(wall_s, 3),
        "checks_passed": s.checks_passed,
        "checks_total": s.checks_total,
        "perceived_motion": {
            d: {"value": v, "unit": "m/s^2*s" if d in DOFS[:3] else "deg"} for d, v in s.motion.items()
        },
        "saturations": s.saturations,
    }
    doc |= extra or {}
    write_text_atomic(path, json.dumps(doc, indent=2) + "\n")


def write_run_recording(
    path: Path,
    title: str,
    motion: Motion,
    result: CueResult,
    limits: PlatformLimits,
    aircraft_q: np.ndarray,
    phases: list[tuple[str, float, float]],
    properties: dict[str, str] | None = None,
) -> None:
    """The recording of one result folder (``run`` and ``cue`` alike): the one call of the recording writer.

    ``aircraft_q`` (N, 4) the aircraft's attitude, body -> NED, scalar first; ``phases`` (name, start, end) [s];
    ``properties``: the provenance as flat strings (:func:`washbench.io.provenance.flat_strings`).
    """
    from washbench.review.rerun_log import MotionSeries, PlatformSeries, RecordingData, write_recording

    ac = result.perceived["aircraft"]
    washouts: dict[str, MotionSeries] = {}
    platforms: dict[str, PlatformSeries] = {}
    for name, tr in result.traces.items():
        p = result.perceived[name]
        washouts[name] = MotionSeries(
            f_mps2=tr.head_f_mps2,
            omega_radps=tr.head_omega_radps,
            perceived_f_mps2=p.f_mps2,
            perceived_omega_radps=p.omega_radps,
            q=tr.q,
        )
        platforms[name] = PlatformSeries(
            pos_m=tr.pos_m, vel_mps=tr.vel_mps, acc_mps2=tr.acc_mps2, wheel_radps=tr.wheel_radps, saturated=tr.saturated
        )
    data = RecordingData(
        title=title,
        t_s=motion.t_s,
        aircraft=MotionSeries(
            f_mps2=motion.f_mps2,
            omega_radps=motion.omega_radps,
            perceived_f_mps2=ac.f_mps2,
            perceived_omega_radps=ac.omega_radps,
            q=aircraft_q,
        ),
        washouts=washouts,
        platforms=platforms,
        envelope=platform_envelope(limits),
        phases=[(p[0], float(p[1]), float(p[2])) for p in phases],
        metrics_markdown=metrics_markdown(title, list(result.metrics)),
    )
    write_recording(path, data, properties)


def platform_envelope(limits: PlatformLimits) -> PlatformEnvelope:
    """The recording's envelope lines from the platform limits (wheel limit from the rate limit)."""
    from washbench.platform.limits import wheel_jacobian
    from washbench.review.rerun_log import PlatformEnvelope

    t = limits.translation
    jac = wheel_jacobian(limits)
    # the fastest any wheel can turn with the sphere at its angular-rate limit
    wheel_max = float(np.max(np.linalg.norm(jac, axis=1)) * math.radians(limits.rotation.rate_limit_degps))
    return PlatformEnvelope(
        pos_m=t.position_limit_m.xyz,
        vel_mps=t.velocity_limit_mps.xyz,
        acc_mps2=t.acceleration_limit_mps2.xyz,
        wheel_radps=wheel_max,
        sphere_diameter_m=limits.sphere_diameter_m,
    )


def announce_script(
    path: Path,
    max_time_s: float | None,
    aircraft_dirs: Sequence[Path],
    washouts: Sequence[str] | None,
    variants: Sequence[str],
    params_path: Path | None,
    outputs: Outputs,
) -> None:
    """Before a long JSBSim script run (or one the default cap cuts short): one line on standard error with the
    simulated time, the steps, the expected size and wall time, and the cap (:func:`washbench.flight.scripts.
    script_plan`)."""
    from washbench.cueing.variants import select_washouts
    from washbench.flight.scripts import load_script_info, plan_limit_s, script_plan
    from washbench.io.budget import check_samples

    n = len(select_washouts(washouts, variants, params_path))
    info = load_script_info(path, aircraft_dirs)
    plan = script_plan(info, max_time_s, n, outputs.recording)
    span_s = min(info.end_s, plan_limit_s(max_time_s))
    # beyond what washbench allocates for one time series: refused (one line) before anything is announced
    check_samples(span_s / info.dt_s, f"<run end={info.end_s:g} dt={info.dt_s:g}> (give --max-time-s)", info.path)
    if plan.long:
        print(f"washbench: {plan.text()}", file=sys.stderr, flush=True)


def run_command(
    manoeuvre_path: Path,
    out_root: Path,
    *,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    progress: bool = True,
    max_time_s: float | None = None,
    filter_start: str = "steady",
    washouts: Sequence[str] | None = None,
    variants: Sequence[str] = (),
    aircraft_dirs: Sequence[Path] = (),
    outputs: Outputs = DEFAULT_OUTPUTS,
    rank_by: str | None = None,
    vestibular: str | None = None,
) -> int:
    """CLI entry of ``washbench run`` (a YAML manoeuvre or a JSBSim script): 0 if every run was ok, else 1.

    Holds the lock of ``out_root`` (:func:`washbench.io.lock.output_lock`) while it runs.
    """
    from washbench.cueing.params import check_filter_start
    from washbench.flight.scripts import is_script
    from washbench.io.lock import output_lock
    from washbench.review.numbers import pct, sig

    check_filter_start(filter_start)
    check_max_time(max_time_s)
    start = time.perf_counter()
    with output_lock(out_root):  # held while it runs: a second writer gets one line at once
        if is_script(manoeuvre_path):
            announce_script(manoeuvre_path, max_time_s, aircraft_dirs, washouts, variants, params_path, outputs)
            runs = run_script(
                manoeuvre_path,
                out_root,
                params_path=params_path,
                platform_path=platform_path,
                max_time_s=max_time_s,
                filter_start=filter_start,
                aircraft_dirs=aircraft_dirs,
                washouts=washouts,
                variants=variants,
                outputs=outputs,
                rank_by=rank_by,
                vestibular=vestibular,
            )
        else:
            if max_time_s is not None:
                raise WashbenchError(
                    "--max-time-s applies to JSBSim scripts only (a manoeuvre's phases set its length)"
                )
            runs = [
                run_manoeuvre(
                    manoeuvre_path,
                    out_root,
                    params_path=params_path,
                    platform_path=platform_path,
                    progress=progress,
                    filter_start=filter_start,
                    aircraft_dirs=aircraft_dirs,
                    washouts=washouts,
                    variants=variants,
                    outputs=outputs,
                    rank_by=rank_by,
                    vestibular=vestibular,
                )
            ]
    wall = time.perf_counter() - start
    for s in runs:
        state = "ok" if s.ok else f"FAILED ({s.reason})"
        checks = f"; checks {s.checks_passed}/{s.checks_total}" if s.checks_total else ""
        print(
            f"{s.aircraft}/{s.manoeuvre}: {state}{checks}; {s.steps * s.dt_s:.1f} s flown in {wall:.1f} s; "
            f"results in {s.run_dir}" + (f"; report: {s.run_dir / 'report.md'}" if s.run_dir and s.steps else "")
        )
        for w, kinds in s.saturations.items():
            sat = ", ".join(
                f"{k} {sig(v * s.dt_s)} s ({pct(100.0 * v / s.steps, False)})" for k, v in kinds.items() if v
            )
            print(f"  {w}: time at a limit: {sat or 'none'}", file=sys.stdout)
    return 0 if all(s.ok for s in runs) else 1
