"""``washbench suite``: many manoeuvres in parallel processes, then a comparison of the washouts.

Each manoeuvre runs through :func:`washbench.runs.pipeline.run_manoeuvre` in its own worker process
and writes ``<aircraft>/<manoeuvre>/`` (published whole, as ``washbench run`` publishes it:
:func:`washbench.io.outfolder.result_entry`). A manoeuvre
that fails (bad file, crash, divergence, failed check, or an unexpected error) is reported with its
reason; the others still complete and are kept. Then the suite writes, each file atomically:

- ``OUT/metrics.csv``: ``aircraft,manoeuvre,washout,dof,npc,integral_error,max_error``
- ``OUT/comparison.csv``: every metric per washout and DOF with its difference from the reference washout
  (small-angle when it runs, otherwise the first listed; positive = better), like the paper's Table 4
- ``OUT/ranking.csv``: the washouts (built-in or variants) ranked per manoeuvre by the rule of
  :mod:`washbench.analysis.ranking`
- ``OUT/report.md`` and ``OUT/figures/``: all of it, with the failures first, a score heatmap, the Table-4 figure
  and each manoeuvre's section, built from the files by :mod:`washbench.review.suite_report`;
- ``OUT/suite.json`` (written last): every manoeuvre file with its status and reason, the suite's provenance, and
  what the suite wrote at the top level (how the next suite recognises it).

The output folder holds exactly one suite's results. The suite builds them in a hidden stage inside
``OUT`` (``OUT/.washbench-stage-PID/``) and, once complete, replaces the previous results as a whole
(:func:`washbench.io.outfolder.staged`, the one way washbench publishes: journalled, signals held): the
previous suite's files and every ``washbench run`` result folder. Anything in ``OUT`` that washbench did
not write makes the suite refuse to start (nothing is ever deleted that washbench did not write). An
interrupted or failed suite leaves the previous results untouched. A lock on ``OUT`` keeps a second
writer out (:mod:`washbench.io.lock`). Two files with the same aircraft and name are refused before
flying. On SIGINT or SIGTERM the workers are stopped at once and the hidden folder removed.

The exit status is 0 only if every manoeuvre ran and passed its checks.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import signal
import sys
import time
import traceback
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path

from washbench.analysis.ranking import (
    DOFS,
    METRICS,
    compare,
    rank,
    reference_washout,
    rule_from_record,
)
from washbench.cueing import registry
from washbench.errors import Terminated, WashbenchError, printable
from washbench.flight.scripts import bundled_script, is_script
from washbench.io import interrupts
from washbench.io.atomic import write_text_atomic
from washbench.io.cpus import usable_cpus
from washbench.io.csv_numbers import csv_number
from washbench.io.lock import output_lock
from washbench.io.metrics_csv import METRICS_COLUMNS, METRICS_TEXT_COLUMNS
from washbench.io.outfolder import recover, recover_shared, staged
from washbench.io.owners import announce, refuse_nested
from washbench.io.progress import Progress
from washbench.io.provenance import utc_now
from washbench.io.publish import read_marker
from washbench.io.result_files import (
    COMPARISON_FILE,
    METRICS_FILE,
    RANKING_FILE,
    REPORT_FILE,
    STAGE_PREFIX,
)
from washbench.review.suite_report import write_suite_json, write_suite_report
from washbench.runs.cluster import dask_map
from washbench.runs.inputs import check_unique_names, find_manoeuvres
from washbench.runs.options import RunOptions, load_options
from washbench.runs.pipeline import announce_script, run_manoeuvre, run_script
from washbench.runs.pool import start_server, submit_all, worker_pool
from washbench.runs.result_folder import RunSummary, csv_text, ranking_table
from washbench.runs.suite_place import SUITE_MARKER, previous_results, replacing


@dataclass
class Outcome:
    """What one manoeuvre's run gave the suite (picklable, sent back from the worker)."""

    path: str
    wall_s: float
    run: RunSummary


def _run_one(path: str, out_dir: str, options: RunOptions) -> list[Outcome]:
    """Worker: run one manoeuvre or JSBSim script (one outcome per run segment); never raises (failures
    come back as an Outcome). The washout plugins of ``options`` (``FILE.py:NAME``) are loaded first (a worker
    process has only what its parent loaded before it started)."""

    start = time.perf_counter()
    try:
        for spec in options.plugins:
            registry.load_plugin(spec)
        if is_script(Path(path)):
            runs = run_script(Path(path), Path(out_dir), options)
        else:
            runs = [run_manoeuvre(Path(path), Path(out_dir), options)]
    except WashbenchError as exc:
        runs = [RunSummary(ok=False, reason=str(exc))]
    except Exception as exc:  # an unexpected bug in one run must not take the suite down
        tb = traceback.format_exc(limit=-3).strip().splitlines()
        where = tb[-3].strip() if len(tb) >= 3 else ""
        runs = [RunSummary(ok=False, reason=f"internal error: {type(exc).__name__}: {exc} ({where})")]
    wall = time.perf_counter() - start
    return [Outcome(path=path, wall_s=wall / len(runs), run=r) for r in runs]


def run_suite(
    files: Sequence[Path],
    out_dir: Path,
    options: RunOptions | None = None,
    *,
    jobs: int | None = None,
    progress: bool = True,
    dask: str | None = None,
    pool: ProcessPoolExecutor | None = None,
    finished: list[Outcome] | None = None,
) -> list[Outcome]:
    """Run every file in parallel processes (or on the Dask cluster at ``dask``); outcomes in the order of ``files``
    (a JSBSim script that resets gives one outcome per run segment, in order). ``options``: the runs' options
    (:func:`washbench.runs.options.load_options`, handed to each worker as they are; None: the defaults).
    ``pool``: the worker processes to run them in (:func:`suite_pool`, kept for the report); None: a pool of
    ``jobs`` started here and stopped on return. ``finished``: a list the outcomes are appended to as they come
    (what an interruption leaves to count).

    On any exception (KeyboardInterrupt and :class:`washbench.errors.Terminated` included) the local workers are
    stopped before it propagates, so no worker writes anything afterwards (a ``pool`` passed in: by the
    :func:`suite_pool` block that holds it, as :func:`suite_command` does).
    """
    opts = options if options is not None else load_options()
    jobs = _jobs(jobs, len(files))
    out_dir.mkdir(parents=True, exist_ok=True)
    args = [(str(f), str(out_dir), opts) for f in files]
    outcomes: dict[str, list[Outcome]] = {}
    start = time.perf_counter()
    shown = Progress("suite", len(files), "manoeuvres") if progress else None
    if progress:
        loading = ", ".join(["JSBSim", *(["matplotlib"] if opts.outputs.figures else []),
                             *(["rerun"] if opts.outputs.recording else [])])  # fmt: skip
        print(
            f"suite: {len(files)} manoeuvre{'s' if len(files) != 1 else ''} on {jobs} "
            f"process{'es' if jobs > 1 else ''} -> {_destination(out_dir)}\n"
            f"suite: loading {loading} and the compiled kernels",
            file=sys.stderr,
        )

    def arrived(path: str, runs: list[Outcome], timed: bool = True) -> None:
        outcomes[path] = runs  # counted before its line: a signal after the line finds it counted
        _report(runs, len(outcomes), len(files), start, shown, timed=timed)

    try:
        if dask:
            for runs in dask_map(dask, _run_one, args):
                arrived(runs[0].path, runs, timed=False)
        elif jobs == 1:
            for a in args:
                arrived(a[0], _run_one(*a))
        else:
            with contextlib.ExitStack() as own:
                if pool is None:
                    pool = own.enter_context(suite_pool(opts, jobs))
                futures = dict(zip(submit_all(pool, _run_one, args), args, strict=True))
                lost = []  # runs whose worker process died, or that were queued when one did
                for fut in as_completed(futures):
                    try:
                        runs = fut.result()
                    except BrokenProcessPool:
                        lost.append(futures[fut])
                        continue
                    arrived(runs[0].path, runs)
                for a in sorted(lost, key=args.index):  # each alone: the one whose worker dies again is the one
                    runs = _run_alone(a, opts)  # a fresh worker's start in its time: not a run's
                    arrived(a[0], runs, timed=False)
                if lost:  # what the dead workers were publishing (OUT/<aircraft>/.washbench-stage-PID)
                    for entry in sorted(out_dir.iterdir()):
                        if entry.is_dir() and not entry.is_symlink():
                            recover_shared(entry, only_dead=True)
    finally:
        if shown is not None:
            shown.close()
        if finished is not None:
            finished.extend(o for runs in outcomes.values() for o in runs)
    return [o for a in args for o in outcomes[a[0]]]


def _run_alone(a: tuple[str, str, RunOptions], opts: RunOptions) -> list[Outcome]:
    """:func:`_run_one` in a pool of one fresh worker process: the run again after a worker process died (a plugin's
    ``os._exit``, a SIGKILL, the OOM killer); if its worker dies again, a failed outcome saying how."""
    with suite_pool(opts, 1) as one:
        fut = one.submit(_run_one, *a)
        processes = list((getattr(one, "_processes", None) or {}).values())  # the executor keeps no public list
        try:
            return fut.result()
        except BrokenProcessPool:
            pass
    # the pool's own thread has joined its dead worker by now (leaving the block waits for it); joining it here while
    # that thread does would race for the exit status (a forkserver's child reports it once: the loser reads 255)
    for p in processes:
        p.join(5.0)
    code = processes[0].exitcode if processes else None
    return [Outcome(path=a[0], wall_s=0.0, run=RunSummary(ok=False, reason=worker_died(code)))]


def worker_died(exitcode: int | None) -> str:
    """Why a run failed whose worker process ended in the middle of it (``exitcode``: negative for a signal)."""
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        how = f"was killed by {name}" + (" (the out-of-memory killer sends it too)" if name == "SIGKILL" else "")
    elif exitcode is not None:
        how = f"exited with status {exitcode} (a washout plugin's os._exit()?)"
    else:
        how = "ended"
    return f"the worker process running it {how}; the other runs went on"


def pool_broken(pool: ProcessPoolExecutor | None) -> bool:
    """Whether a worker of ``pool`` died (the pool takes no more work: the suite's figures are drawn here then)."""
    return bool(pool is not None and getattr(pool, "_broken", False))


def _jobs(jobs: int | None, n_files: int) -> int:
    """Worker processes for ``n_files`` runs: ``jobs`` (None: the usable CPUs), at most one per file, at least 1."""
    return max(1, min(jobs or usable_cpus(), n_files))


def suite_pool(options: RunOptions, jobs: int) -> contextlib.AbstractContextManager[ProcessPoolExecutor]:
    """The suite's worker processes (:func:`washbench.runs.pool.worker_pool`), loaded for ``options``' outputs."""
    return worker_pool(jobs, recording=options.outputs.recording, figures=options.outputs.figures)


def _destination(out_dir: Path) -> Path:
    """Where the results end up: the suite folder, not the hidden one they are built in."""
    return out_dir.parent if out_dir.name.startswith(STAGE_PREFIX) else out_dir


def _report(
    runs: list[Outcome], done: int, total: int, start: float, progress: Progress | None, timed: bool = True
) -> list[Outcome]:
    """Say that a file's runs are done; ``timed``: their wall time, measured in the worker, dates the start of the
    work for the expected end, which then leaves out the pool's start (and a first compile) (not on a Dask
    cluster, whose queue the workers' times do not date, nor for a run again after its worker died)."""
    for outcome in runs:
        _report_one(outcome, done, total, start, progress)
    if progress is not None:
        if timed:
            progress.timed(sum(o.wall_s for o in runs))
        progress.update(done)
    return runs


def _report_one(outcome: Outcome, done: int, total: int, start: float, progress: Progress | None) -> None:
    if progress is not None:
        name = f"{outcome.run.aircraft}/{outcome.run.manoeuvre}" if outcome.run.aircraft else _short(outcome.path)
        state = "ok  " if outcome.run.ok else "FAIL"
        extra = f"checks {outcome.run.checks_passed}/{outcome.run.checks_total}" if outcome.run.checks_total else ""
        line = f"[{done:>2}/{total}] {state} {name:<40} {outcome.wall_s:6.1f} s  {extra}"
        if not outcome.run.ok:
            line += f"\n        {outcome.run.reason}"
        progress.message(f"{line}   (elapsed {time.perf_counter() - start:.0f} s)")


def _short(path: str) -> str:
    try:
        return str(Path(path).relative_to(Path.cwd()))
    except ValueError:
        return path


def _runs_with_metrics(outcomes: Sequence[Outcome]) -> list[Outcome]:
    return [o for o in outcomes if o.run.metrics]


def metrics_table(outcomes: Sequence[Outcome]) -> str:
    """``metrics.csv`` of the suite (every run that produced metrics, failed checks included)."""
    rows = [["aircraft", "manoeuvre", *METRICS_COLUMNS]]
    for o in _runs_with_metrics(outcomes):
        for m in o.run.metrics:
            cells = [getattr(m, c) if c in METRICS_TEXT_COLUMNS else csv_number(getattr(m, c)) for c in METRICS_COLUMNS]
            rows.append([o.run.aircraft, o.run.manoeuvre, *cells])
    return csv_text(rows)


def comparison_table(outcomes: Sequence[Outcome]) -> str:
    """``comparison.csv``: each metric per washout and DOF and its improvement over the reference washout
    (small-angle when it runs, otherwise the first listed: ``<washout>_better_by`` = reference - washout)."""
    washouts = _washouts(outcomes)
    reference = reference_washout(washouts)
    others = [w for w in washouts if w != reference]
    header = ["aircraft", "manoeuvre", "dof", "metric", *washouts, *[f"{w}_better_by" for w in others]]
    rows = [header]
    for o in _runs_with_metrics(outcomes):
        for c in compare(o.run.metrics, reference):
            rows.append(
                [o.run.aircraft, o.run.manoeuvre, c.dof, c.metric]
                + [csv_number(c.values.get(w, math.nan)) for w in washouts]
                + [csv_number(c.better_than_reference.get(w, math.nan)) for w in others]
            )
    return csv_text(rows)


def _washouts(outcomes: Sequence[Outcome]) -> list[str]:
    """Every washout of the suite in the order the configuration listed them."""
    return list(dict.fromkeys(m.washout for o in outcomes for m in o.run.metrics))


def write_suite_results(
    outcomes: Sequence[Outcome], out_dir: Path, provenance: dict[str, object] | None = None, figures: bool = True,
    pool: ProcessPoolExecutor | None = None,
) -> None:  # fmt: skip
    """Write metrics.csv, comparison.csv, ranking.csv, suite.json and (last) report.md with its figures (unless
    ``figures`` is False), atomically.

    The report is built from the files (:mod:`washbench.review.suite_report`), as ``washbench report`` builds it;
    ``pool``: the suite's workers, which then draw its figures (None: drawn in this process).
    """
    rule = rule_from_record((provenance or {}).get("ranking"))
    rankings = {
        (o.run.aircraft, o.run.manoeuvre): rank(o.run.metrics, o.run.motion, rule)
        for o in _runs_with_metrics(outcomes)
    }
    write_text_atomic(out_dir / METRICS_FILE, metrics_table(outcomes))
    write_text_atomic(out_dir / COMPARISON_FILE, comparison_table(outcomes))
    write_text_atomic(out_dir / RANKING_FILE, ranking_table(rankings, rule))
    entries = [
        {
            "file": _short(o.path),
            "ok": o.run.ok,
            "reason": o.run.reason,
            "aircraft": o.run.aircraft,
            "manoeuvre": o.run.manoeuvre,
            "result": os.path.relpath(o.run.run_dir, out_dir) if o.run.run_dir and o.run.run_dir.is_dir() else None,
            "checks_passed": o.run.checks_passed,
            "checks_total": o.run.checks_total,
            "wall_s": round(o.wall_s, 3),
        }
        for o in outcomes
    ]
    created = utc_now()
    write_suite_json(out_dir / SUITE_MARKER, entries, dict(provenance or {}), created)
    write_suite_report(out_dir, figures=figures, pool=pool)
    # last: the same document with every top-level entry written (what the next suite may replace)
    top = sorted(e.name for e in out_dir.iterdir() if not e.name.startswith(".") and e.name != SUITE_MARKER)
    write_suite_json(out_dir / SUITE_MARKER, entries, dict(provenance or {}), created, top)


def suite_command(
    inputs: Sequence[Path],
    out_dir: Path,
    options: RunOptions,
    *,
    jobs: int | None = None,
    progress: bool = True,
    dask: str | None = None,
    jsbsim_scripts: Sequence[str] = (),
) -> int:
    """CLI entry: run the suite, write its results, print where they are; 0 if all succeeded, else 1.

    ``options``: the runs' options (:func:`washbench.runs.options.load_options`: a bad parameter, variant or
    platform file has failed there, before any run). ``jsbsim_scripts``: names of scripts shipped with JSBSim
    (``c1723``) run besides ``inputs``. See the module docstring for the output folder policy (lock, whole
    replacement, interruption).
    """

    if jobs is not None and jobs < 1:
        raise WashbenchError(f"--jobs: expected a whole number of at least 1, got {jobs}")
    files = find_manoeuvres(inputs, [bundled_script(n) for n in jsbsim_scripts])
    n_jobs = _jobs(jobs, len(files))
    local_pool = dask is None and n_jobs > 1
    if local_pool:  # the workers' server loads JSBSim, the kernels, ... while the files are checked
        start_server(options.outputs.recording, options.outputs.figures)
    check_unique_names(files, options.aircraft_dirs)
    for f in files:
        if is_script(f):
            announce_script(f, options)
    start = time.perf_counter()
    refuse_nested(out_dir, "suite")  # not inside other results (a suite's results/c172p): before anything
    with output_lock(out_dir):
        # under the lock every leftover is stale; a publication cut by a kill is finished. In a folder that holds
        # no suite (no suite.json), only washbench's own leftovers: a hidden file there is the user's.
        recover(out_dir, only_washbench=read_marker(out_dir, SUITE_MARKER) is None)
        previous = previous_results(out_dir)
        for entry in previous:  # what runs killed while publishing into OUT/<aircraft>/ left (all stale here)
            if entry.is_dir() and not entry.is_symlink():
                recover_shared(entry, only_dead=False)
        if previous:  # replacing is never silent (io.owners)
            announce(replacing(out_dir, previous, len(files)))
        # the local workers, idle after the runs, draw the suite's figures too
        workers = suite_pool(options, n_jobs) if local_pool else contextlib.nullcontext()
        finished: list[Outcome] = []
        # swapped in whole (journalled, signals held), or not at all
        try:
            with staged(out_dir, previous) as stage, workers as pool:
                outcomes = run_suite(files, stage, options, jobs=n_jobs, progress=progress, dask=dask, pool=pool,
                                     finished=finished)  # fmt: skip
                for o in outcomes:  # a failure names the files where they were going, not the hidden stage
                    if not o.run.ok and str(stage) in o.run.reason:
                        o.run = dataclasses.replace(o.run, reason=o.run.reason.replace(str(stage), str(out_dir)))
                figure_pool = None if pool_broken(pool) else pool  # a worker died: the figures are drawn here
                write_suite_results(outcomes, stage, dict(options.provenance), options.outputs.figures, figure_pool)
        except (KeyboardInterrupt, Terminated) as exc:  # what was lost, on the command's last line
            done = len({o.path for o in finished})
            kept = "its earlier results stay as they were" if previous else "nothing was left there"
            interrupts.explain(exc, f"{done} of {len(files)} manoeuvres had finished; their runs are discarded and "
                               f"nothing was written to {out_dir} ({kept})")  # fmt: skip
            raise
    n_ok = sum(o.run.ok for o in outcomes)
    report = printable(str(out_dir / REPORT_FILE))
    print(f"suite: {n_ok}/{len(outcomes)} runs ok in {time.perf_counter() - start:.1f} s; report: {report}")
    return 0 if n_ok == len(outcomes) else 1


__all__ = [
    "DOFS",
    "METRICS",
    "Outcome",
    "previous_results",
    "run_suite",
    "suite_command",
    "write_suite_results",
]
