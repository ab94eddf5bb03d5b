"""``washbench run``: fly a manoeuvre with the three washouts in lockstep, then perceive, measure, record.

At every JSBSim step the scripted pilot's flight gives one sample of pilot-head motion; the
sample goes straight through the three washouts and the kinematic Atlas model
(:class:`washbench.cueing.CueingBank`, the streaming form), as a real simulator would run them.
After the flight the vestibular models, the metrics and the tables are the same code as
``washbench cue`` (:func:`washbench.runs.chain.from_lockstep`), on the flight as written to
``flight.parquet`` and read back, so ``washbench fly`` then ``washbench cue`` gives the same
numbers bit for bit.

Output, one result entry of ``OUT`` published whole (:func:`washbench.io.outfolder.result_entry`: built in a
hidden stage beside its place, then swapped in, so an interrupted run never leaves a half-written folder that
looks complete; it replaces only a previous ``washbench run`` result of the same manoeuvre)::

    OUT/<aircraft>/<manoeuvre>/
        flight.json      manoeuvre, phases, checks (as from washbench fly)
        flight.parquet   the flown trace (washbench cue input columns + flight state)
        traces.parquet   washbench cue columns + flight-state columns
        metrics.csv      washout,dof,npc,integral_error,max_error
        recording.rrd    rerun recording with its blueprint
        run.json         summary used by washbench suite (status, motion per DOF, saturations)
"""

from __future__ import annotations

import dataclasses
import functools
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from washbench.analysis.ranking import perceived_motion
from washbench.cueing.variants import tilt_rate_limit_radps
from washbench.errors import WashbenchError, located, printable
from washbench.flight.fly import fly, write_flight
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.flight.scripts import (
    fly_script,
    is_script,
    load_script_info,
    plan_limit_s,
    script_plan,
    write_script_flight,
)
from washbench.io.budget import check_samples
from washbench.io.lock import output_lock
from washbench.io.motion_file import read_motion
from washbench.io.outfolder import refuse_other_owner, result_entry
from washbench.io.owners import announce, refuse_nested, suite_holding
from washbench.io.provenance import flat_strings, utc_now
from washbench.io.publish import check_replaceable
from washbench.io.result_files import FLIGHT_FILE, RANKING_FILE, RECORDING_FILE, REPORT_FILE, RUN_FILE, SUITE_FILE
from washbench.review.numbers import pct, sig
from washbench.runs.beside import beside
from washbench.runs.bound_stage import bound_outputs, lockstep_result, split_whole
from washbench.runs.chain import (
    LOCKSTEP_BLOCK,
    aircraft_attitude,
    lockstep_blocks,
    lockstep_washouts,
    sample_count,
    write_results,
)
from washbench.runs.options import RunOptions, load_options
from washbench.runs.result_folder import (
    RUN_MARKER,
    RunSummary,
    run_dir,
    run_marker,
    write_run_json,
    write_run_recording,
    write_run_review,
)


def run_place_check(marker: dict[str, str], nested: bool = False) -> Callable[[Path], None]:
    """What may stand where a run's result folder goes (``OUT/<aircraft>/<manoeuvre>``), checked before flying and
    again before publishing (:mod:`washbench.io.owners`): nothing, or an earlier washbench run of the same thing
    (``marker``; ``nested``: a JSBSim script's runs), which is replaced and said so once; never a result of a suite
    in ``OUT`` (refused: the suite's report would describe a result that is gone). A run added beside a suite says
    that the suite's report does not include it."""
    said: list[bool] = []

    def check(place: Path) -> None:
        check_replaceable(place, RUN_MARKER, marker, nested)
        suite = suite_holding(place)
        if suite is not None:
            raise WashbenchError(located(place, (
                f"a result of the suite in {suite.parent} ({suite.name}): a run here would leave the suite's "
                f"{REPORT_FILE}, {RANKING_FILE} and {suite.name} describing a result that is gone; not replaced; "
                f"choose another --out, or run the suite again")))  # fmt: skip
        if said:
            return
        said.append(True)
        if place.exists():
            announce(f"{place} holds an earlier run of {place.parent.name}/{place.name}: replaced when this one is "
                     "complete (until then, and after a failure or Ctrl-C, it stays as it is)")  # fmt: skip
        elif (place.parent.parent / SUITE_FILE).is_file():
            announce(f"{place} is added beside the suite in {place.parent.parent}, whose report does not include "
                     "it")  # fmt: skip

    return check


def run_manoeuvre(
    manoeuvre_path: Path, out_root: Path, options: RunOptions | None = None, *, progress: bool = False
) -> RunSummary:
    """Fly one manoeuvre with the washouts in lockstep and write its results folder.

    ``options`` (:func:`washbench.runs.options.load_options`; None: the defaults): the washouts, the platform,
    the filters' start state (``filter_start``), what optional files are written (``outputs``), the ranking rule
    and the vestibular model.

    Raises WashbenchError for a bad manoeuvre file or a result place that cannot be used (all checked before
    flying; nothing written). A flight that crashes or fails a check still writes its results (what was flown),
    with ``ok`` False and the reason. The result folder replaces only a previous ``washbench run`` result of the
    same manoeuvre (recognised by its run.json).
    """

    opts = options if options is not None else load_options()
    # every input and the result place first: a bad one fails before anything is flown
    manoeuvre = load_manoeuvre(manoeuvre_path, opts.aircraft_dirs)
    prov = opts.provenance_for(manoeuvre_path, manoeuvre.environment.turbulence, manoeuvre.aircraft_files)
    final = run_dir(Path(out_root), manoeuvre.aircraft, manoeuvre.name)
    marker = run_marker(manoeuvre.aircraft, manoeuvre.name)

    stepped = split_whole(opts.washouts)[0]  # a whole-only washout (the bound) is cued after the flight
    # entered before flying: a folder or file in the way fails now, not after
    with result_entry(final, run_place_check(marker)) as folder:
        rows, lockstep = lockstep_blocks(stepped, opts.limits, manoeuvre.dt_s, opts.filter_start)
        start = time.perf_counter()
        created = utc_now()
        flight = fly(manoeuvre, block_hook=lockstep, block_size=LOCKSTEP_BLOCK, progress=progress)
        n = len(flight.t_s)
        if sample_count(rows) != n:
            raise RuntimeError(f"washouts ran {sample_count(rows)} steps for {n} recorded samples")
        flight_prov = {k: v for k, v in prov.items() if k in _FLIGHT_PROVENANCE}
        write_flight(folder, flight, str(manoeuvre_path), flight_prov)
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
        extra = {"created_utc": created, "provenance": prov, "algorithms": lockstep.reports()}
        summary = write_cued_folder(folder, summary, rows, opts, ac_q, flight.phases, start, extra, prov)
    return summary


_FLIGHT_PROVENANCE = ("software", "manoeuvre", "aircraft", "pilot_profile", "turbulence", "config")
"""What ``flight.parquet``'s provenance records (as ``washbench fly`` writes it): no washout, platform or ranking."""


def write_cued_folder(
    folder: Path,
    summary: RunSummary,
    rows: list[np.ndarray],
    options: RunOptions,
    aircraft_q: np.ndarray,
    phases: list[tuple[str, float, float]],
    start: float,
    extra: dict[str, object] | None = None,
    provenance: dict[str, Any] | None = None,
) -> RunSummary:
    """Everything after the flight, into ``folder`` (which already holds ``flight.parquet``): the chain
    (:func:`washbench.runs.chain.from_lockstep`) on the flight read back (as ``washbench cue`` reads it),
    traces.parquet, metrics.csv, recording.rrd, run.json, ranking.csv, report.md and figures/. Returns ``summary``
    completed with the steps, metrics and saturations. ``provenance`` (no date) goes into traces.parquet's
    metadata; ``extra`` into run.json. A washout that needs the whole recording (the oracle bound) is cued here
    on the flight read back, and with the bound ``ceiling.csv`` is written (:mod:`washbench.runs.bound_stage`)."""

    motion = read_motion(folder / FLIGHT_FILE)
    result = lockstep_result(motion, rows, options)
    if result.algorithms:  # the whole-only washouts' own statistics, beside the lockstep's, in the listed order
        both = {**dict((extra or {}).get("algorithms") or {}), **result.algorithms}
        order = [n for n in options.washout_order if n in both]
        extra = {**(extra or {}), "algorithms": {n: both[n] for n in order}}
    write_results(folder, result, provenance)
    bound = bound_outputs(folder, result, options.washouts, options.limits, options.vestibular_params,
                          options.rank_rule, options.filter_start)  # fmt: skip
    extra = {**(extra or {}), "bound": bound} if bound else extra
    ac = result.perceived["aircraft"]
    summary = dataclasses.replace(
        summary,
        steps=motion.n,
        dt_s=motion.dt_s,
        metrics=list(result.metrics),
        motion=perceived_motion(ac.f_mps2, ac.omega_radps, motion.dt_s, options.rank_rule.measure),
        saturations={w: dict(result.traces[w].saturation_counts) for w in options.washout_order},
    )
    write_run_json(folder / RUN_FILE, summary, time.perf_counter() - start, extra)
    review = functools.partial(write_run_review, folder, dataclasses.replace(summary, run_dir=folder),
                               table=result.columns(), figures=options.outputs.figures,
                               recording=options.outputs.recording)  # fmt: skip
    # the figures and report are drawn in a child process while the recording is written here (runs.beside)
    with beside(review, fork=options.outputs.figures and options.outputs.recording):
        if options.outputs.recording:
            title = f"{summary.aircraft} / {summary.manoeuvre}"
            props = flat_strings(provenance, str((extra or {}).get("created_utc") or "")) if provenance else None
            write_run_recording(folder / RECORDING_FILE, title, motion, result, options.limits, aircraft_q, phases,
                                props, options.rank_rule, bound,
                                {w.name: tilt_rate_limit_radps(w) for w in options.washouts})  # fmt: skip
    return summary


def run_script(script_path: Path, out_root: Path, options: RunOptions | None = None) -> list[RunSummary]:
    """Fly a JSBSim script (:mod:`washbench.flight.scripts`) with the washouts in lockstep, one result per run.

    Writes ``OUT/<aircraft>/<script>/`` (one run) or ``OUT/<aircraft>/<script>/<run_i>/`` (a script that
    resets), published whole as one result entry (:func:`washbench.io.outfolder.result_entry`). A crash still
    writes what was flown, with ``ok`` False and the reason. ``options.max_time_s`` caps the simulated time
    (None: the script's own end, at most
    :data:`washbench.flight.scripts.DEFAULT_MAX_TIME_S`).
    """

    opts = options if options is not None else load_options()
    info = load_script_info(script_path, opts.aircraft_dirs)
    max_time_s = opts.max_time_s
    if max_time_s is None and info.end_s > plan_limit_s(None):  # announced by the commands (script_plan)
        max_time_s = plan_limit_s(None)
    prov = opts.provenance_for(script_path)
    created = utc_now()
    final = run_dir(Path(out_root), info.aircraft, info.name)
    marker = {"aircraft": info.aircraft}  # one run.json, or one per run of a script that resets
    banks: list[list[np.ndarray]] = []
    hooks: list[Any] = []

    stepped = split_whole(opts.washouts)[0]  # a whole-only washout (the bound) is cued after the flight

    def segment_hook(i: int, dt_s: float) -> Any:
        rows, hook = lockstep_washouts(stepped, opts.limits, dt_s, opts.filter_start)
        banks.append(rows)
        hooks.append(hook)
        return hook

    summaries = []
    # entered before flying: a folder or file in the way fails now, not after
    with result_entry(final, run_place_check(marker, nested=True)) as built:
        start = time.perf_counter()
        flight = fly_script(script_path, max_time_s=max_time_s, segment_hook=segment_hook,
                            aircraft_dirs=opts.aircraft_dirs)  # fmt: skip
        several = len(flight.segments) > 1
        for seg, rows, hook in zip(flight.segments, banks, hooks, strict=True):
            folder = built / seg.name if several else built
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
            extra |= {"created_utc": created, "provenance": prov, "algorithms": hook.reports()}
            summaries.append(write_cued_folder(folder, summary, rows, opts, ac_q, [], start, extra, prov))
    return summaries


def announce_script(path: Path, options: RunOptions) -> None:
    """Before a long JSBSim script run (or one the default cap cuts short): one line on standard error with the
    simulated time, the steps, the expected size and wall time, and the cap (:func:`washbench.flight.scripts.
    script_plan`)."""

    max_time_s = options.max_time_s
    info = load_script_info(path, options.aircraft_dirs)
    plan = script_plan(info, max_time_s, len(options.washouts), options.outputs.recording)
    span_s = min(info.end_s, plan_limit_s(max_time_s))
    # beyond what washbench allocates for one time series: refused (one line) before anything is announced
    check_samples(span_s / info.dt_s, f"<run end={info.end_s:g} dt={info.dt_s:g}> (give --max-time-s)", info.path)
    if plan.long:
        print(f"washbench: {plan.text()}", file=sys.stderr, flush=True)


def run_command(manoeuvre_path: Path, out_root: Path, options: RunOptions, *, progress: bool = True) -> int:
    """CLI entry of ``washbench run`` (a YAML manoeuvre or a JSBSim script): 0 if every run was ok, else 1.

    Holds the lock of ``out_root`` (:func:`washbench.io.lock.output_lock`) while it runs.
    """

    start = time.perf_counter()
    refuse_nested(out_root, "run")  # OUT inside other results (a suite's aircraft folder): before anything
    with output_lock(out_root) as out_dir:  # held while it runs: a second writer gets one line at once
        refuse_other_owner(out_dir, "run")  # a folder of fly, cue ... results is not mixed with runs
        if is_script(manoeuvre_path):
            announce_script(manoeuvre_path, options)
            runs = run_script(manoeuvre_path, out_root, options)
        else:
            if options.max_time_s is not None:
                raise WashbenchError(
                    "--max-time-s applies to JSBSim scripts only (a manoeuvre's phases set its length)"
                )
            runs = [run_manoeuvre(manoeuvre_path, out_root, options, progress=progress)]
    wall = time.perf_counter() - start
    for s in runs:
        state = "ok" if s.ok else f"FAILED ({s.reason})"
        checks = f"; checks {s.checks_passed}/{s.checks_total}" if s.checks_total else ""
        print(
            f"{s.aircraft}/{s.manoeuvre}: {state}{checks}; {s.steps * s.dt_s:.1f} s flown in {wall:.1f} s; "
            f"results in {printable(str(s.run_dir))}"
            + (f"; report: {printable(str(s.run_dir / REPORT_FILE))}" if s.run_dir and s.steps else "")
        )
        for w, kinds in s.saturations.items():
            sat = ", ".join(
                f"{k} {sig(v * s.dt_s)} s ({pct(100.0 * v / s.steps, False)})" for k, v in kinds.items() if v
            )
            print(f"  {w}: time at a limit: {sat or 'none'}", file=sys.stdout)
    return 0 if all(s.ok for s in runs) else 1
