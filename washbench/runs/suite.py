"""``washbench suite``: many manoeuvres in parallel processes, then a comparison of the washouts.

Each manoeuvre runs through :func:`washbench.runs.pipeline.run_manoeuvre` in its own worker process
and writes ``<aircraft>/<manoeuvre>/`` (published atomically as a whole folder). A manoeuvre
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

The output folder holds exactly one suite's results. The suite builds them in a hidden folder inside
``OUT`` (``OUT/.suite.partial-PID/``) and, once complete, replaces the previous results as a whole: the
previous suite's files and every ``washbench run`` result folder. Anything in ``OUT`` that washbench did
not write makes the suite refuse to start (nothing is ever deleted that washbench did not write). An
interrupted or failed suite leaves the previous results untouched. A lock on ``OUT`` keeps a second
writer out (:mod:`washbench.io.lock`). Two files with the same aircraft and name are refused before
flying. On SIGINT or SIGTERM the workers are stopped at once and the hidden folder removed.

The exit status is 0 only if every manoeuvre ran and passed its checks.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import multiprocessing
import os
import signal
import sys
import time
import traceback
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from washbench.analysis.ranking import (
    DEFAULT_RULE,
    DOFS,
    METRICS,
    RankRow,
    RankRule,
    compare,
    rank,
    reference_washout,
    rule_from_record,
)
from washbench.errors import WashbenchError, located
from washbench.io.atomic import write_text_atomic
from washbench.io.cpus import usable_cpus
from washbench.io.csv_numbers import csv_number
from washbench.io.lock import output_lock
from washbench.io.outfolder import discard_stage, is_own_hidden, recover, signals_held, swap_in
from washbench.io.paths import MANOEUVRES_DIR, bundled_names, resolve_manoeuvre
from washbench.io.progress import Progress
from washbench.io.publish import clean_partials, is_leftover, is_washbench_result, read_marker
from washbench.runs.outputs import DEFAULT_OUTPUTS, Outputs
from washbench.runs.pipeline import RUN_MARKER, RunSummary

#: The suite's own files in ``OUT`` (``suite.json`` lists everything a suite wrote at the top level).
SUITE_FILES = ("metrics.csv", "comparison.csv", "ranking.csv", "report.md")
SUITE_MARKER = "suite.json"


@dataclass
class Outcome:
    """What one manoeuvre's run gave the suite (picklable, sent back from the worker)."""

    path: str
    wall_s: float
    run: RunSummary


def find_manoeuvres(inputs: Sequence[Path], scripts: Sequence[Path] = ()) -> list[Path]:
    """Manoeuvre files and JSBSim scripts from files and folders (folders are searched recursively for
    ``*.yaml`` manoeuvres and ``*.xml`` JSBSim scripts), then ``scripts``; no inputs at all: the bundled
    manoeuvres."""
    from washbench.flight.scripts import is_runscript

    if not inputs and not scripts:
        inputs = [MANOEUVRES_DIR]
    found: list[Path] = []
    for item in map(resolve_manoeuvre, inputs):
        if item.is_dir():
            found.extend(sorted(p for p in item.rglob("*.yaml") if p.is_file()))
            found.extend(sorted(p for p in item.rglob("*.xml") if p.is_file() and is_runscript(p)))
        elif item.is_file():
            found.append(item)
        else:
            raise WashbenchError(
                located(item, f"no such file or folder, nor a bundled manoeuvre ({', '.join(bundled_names())})")
            )
    found.extend(scripts)
    unique = list(dict.fromkeys(p.resolve() for p in found))
    if not unique:
        raise WashbenchError(located(inputs[0], "no manoeuvre files (*.yaml) or JSBSim scripts (*.xml) found"))
    return unique


def _worker_init(then: Callable[[], None] | None = None) -> None:
    """In each worker: Ctrl-C is for the main process (it stops the workers); SIGTERM stops a worker at once.

    ``then``: the start method's own initializer (:func:`pool_context`).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if then is not None:
        then()


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Ignore SIGINT and SIGTERM for a short critical section (stopping workers, swapping results in)."""
    saved = {sig: signal.signal(sig, signal.SIG_IGN) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in saved.items():
            signal.signal(sig, handler)


def _stop_pool(pool: ProcessPoolExecutor) -> None:
    """Stop every worker now (SIGTERM, then SIGKILL after 5 s) and drop the queued runs."""
    processes = list((getattr(pool, "_processes", None) or {}).values())  # the executor keeps no public list
    for p in processes:
        with contextlib.suppress(Exception):
            p.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        p.join(5.0)
        if p.is_alive():
            p.kill()
            p.join(5.0)


def _run_one(
    path: str,
    out_dir: str,
    params_path: str | None,
    platform_path: str | None,
    washouts: tuple[str, ...] | None = None,
    variants: tuple[str, ...] = (),
    aircraft_dirs: tuple[str, ...] = (),
    max_time_s: float | None = None,
    outputs: Outputs = DEFAULT_OUTPUTS,
    rank_by: str | None = None,
    vestibular: str | None = None,
    plugins: tuple[str, ...] = (),
) -> list[Outcome]:
    """Worker: run one manoeuvre or JSBSim script (one outcome per run segment); never raises (failures
    come back as an Outcome). ``plugins``: the washout plugins' ``FILE.py:NAME`` to load first (a worker process
    has only what its parent loaded before it started)."""
    from washbench.cueing import registry
    from washbench.flight.scripts import is_script
    from washbench.runs.pipeline import run_manoeuvre, run_script

    start = time.perf_counter()
    params = Path(params_path) if params_path else None
    platform = Path(platform_path) if platform_path else None
    try:
        for spec in plugins:
            registry.load_plugin(spec)
        dirs = [Path(d) for d in aircraft_dirs]
        common = {"params_path": params, "platform_path": platform, "aircraft_dirs": dirs}
        common |= {"washouts": washouts, "variants": variants, "outputs": outputs, "rank_by": rank_by}
        common |= {"vestibular": vestibular}
        if is_script(Path(path)):
            runs = run_script(Path(path), Path(out_dir), max_time_s=max_time_s, **common)
        else:
            runs = [run_manoeuvre(Path(path), Path(out_dir), **common)]
    except WashbenchError as exc:
        runs = [RunSummary(ok=False, reason=str(exc))]
    except Exception as exc:  # an unexpected bug in one run must not take the suite down
        tb = traceback.format_exc(limit=-3).strip().splitlines()
        where = tb[-3].strip() if len(tb) >= 3 else ""
        runs = [RunSummary(ok=False, reason=f"internal error: {type(exc).__name__}: {exc} ({where})")]
    wall = time.perf_counter() - start
    return [Outcome(path=path, wall_s=wall / len(runs), run=r) for r in runs]


def _preload() -> None:
    """Worker initializer where there is no forkserver: load the heavy modules once per worker."""
    import washbench.runs.preload  # noqa: F401


def _die_with_parent() -> None:
    """Worker initializer: the worker ends when its parent (the process server) does."""
    from washbench.runs.parent_death import die_with_parent

    die_with_parent()


_QUIET_TRACKER = "ignore:resource_tracker:UserWarning"

FIGURE_MODULES = ("matplotlib.figure", "matplotlib.backends.backend_agg")
"""Preloaded by the process server besides :mod:`washbench.runs.preload` when the runs draw figures."""


def pool_context(
    recording: bool = True, main_stops_workers: bool = False, figures: bool = True
) -> tuple[multiprocessing.context.BaseContext, Callable[[], None] | None]:
    """The process pool's start method and worker initializer.

    ``forkserver`` (Linux, macOS) where it exists: workers fork from a server that has already imported the heavy
    modules (JSBSim, the numba kernels, pyarrow; matplotlib with ``figures``, rerun with ``recording``), so each
    starts in milliseconds. Elsewhere (Windows)
    ``spawn``, with every worker importing them once at its start. With ``main_stops_workers`` (the suite, which
    stops its workers itself on Ctrl-C) the server and its workers ignore SIGINT.
    """
    # An interrupted suite stops its workers at once; the resource tracker then removes the pool's semaphores itself
    # but warns about each on stderr ("leaked semaphore objects"). Its warning filters come from ours when it starts.
    if _QUIET_TRACKER not in sys.warnoptions:
        sys.warnoptions.append(_QUIET_TRACKER)
    if "forkserver" in multiprocessing.get_all_start_methods():
        ctx = multiprocessing.get_context("forkserver")
        first = ["washbench.runs.worker_signals"] if main_stops_workers else []
        optional = [*(FIGURE_MODULES if figures else ()), *(["rerun"] if recording else [])]
        ctx.set_forkserver_preload([*first, "washbench.runs.preload", *optional])
        return ctx, _die_with_parent
    return multiprocessing.get_context("spawn"), _preload


def run_suite(
    files: Sequence[Path],
    out_dir: Path,
    *,
    jobs: int | None = None,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    progress: bool = True,
    washouts: Sequence[str] | None = None,
    variants: Sequence[str] = (),
    dask: str | None = None,
    aircraft_dirs: Sequence[Path] = (),
    max_time_s: float | None = None,
    outputs: Outputs = DEFAULT_OUTPUTS,
    rank_by: str | None = None,
    vestibular: str | None = None,
) -> list[Outcome]:
    """Run every file in parallel processes (or on the Dask cluster at ``dask``); outcomes in the order of ``files``
    (a JSBSim script that resets gives one outcome per run segment, in order). ``outputs``: whether the
    run folders get ``recording.rrd`` and figures (:class:`washbench.runs.outputs.Outputs`).

    On any exception (KeyboardInterrupt and :class:`washbench.errors.Terminated` included) the local workers are
    stopped before it propagates, so no worker writes anything afterwards.
    """
    jobs = max(1, min(jobs or usable_cpus(), len(files)))
    out_dir.mkdir(parents=True, exist_ok=True)
    dirs = tuple(str(d) for d in aircraft_dirs)
    params = str(params_path) if params_path else None
    platform = str(platform_path) if platform_path else None
    chosen = tuple(washouts) if washouts else None
    from washbench.cueing import registry

    plugins = registry.plugin_specs()
    args = [(str(f), str(out_dir), params, platform, chosen, tuple(variants), dirs, max_time_s, outputs, rank_by,
             vestibular, plugins) for f in files]  # fmt: skip
    outcomes: dict[str, list[Outcome]] = {}
    start = time.perf_counter()
    shown = Progress("suite", len(files), "manoeuvres") if progress else None
    if progress:
        print(
            f"suite: {len(files)} manoeuvres on {jobs} process{'es' if jobs > 1 else ''} -> {_destination(out_dir)}\n"
            "suite: loading JSBSim, rerun and the compiled kernels",
            file=sys.stderr,
        )
    try:
        if dask:
            from washbench.runs.cluster import dask_map

            for runs in dask_map(dask, _run_one, args):
                outcomes[runs[0].path] = _report(runs, len(outcomes) + 1, len(files), start, shown)
        elif jobs == 1:
            for a in args:
                outcomes[a[0]] = _report(_run_one(*a), len(outcomes) + 1, len(files), start, shown)
        else:
            ctx, initializer = pool_context(outputs.recording, main_stops_workers=True, figures=outputs.figures)
            pool = ProcessPoolExecutor(
                max_workers=jobs, mp_context=ctx, initializer=_worker_init, initargs=(initializer,)
            )
            try:
                with signals_held():  # submitting starts the workers (up to ``jobs``)
                    futures = [pool.submit(_run_one, *a) for a in args]
                for fut in as_completed(futures):
                    runs = fut.result()
                    outcomes[runs[0].path] = _report(runs, len(outcomes) + 1, len(files), start, shown)
            except BaseException:
                with _signals_held():
                    _stop_pool(pool)
                raise
            pool.shutdown(wait=True)
    finally:
        if shown is not None:
            shown.close()
    return [o for a in args for o in outcomes[a[0]]]


def _destination(out_dir: Path) -> Path:
    """Where the results end up: the suite folder, not the hidden one they are built in."""
    return out_dir.parent if is_leftover(out_dir.name) else out_dir


def _report(runs: list[Outcome], done: int, total: int, start: float, progress: Progress | None) -> list[Outcome]:
    for outcome in runs:
        _report_one(outcome, done, total, start, progress)
    if progress is not None:
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


def _csv(rows: list[list[str]]) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()


def _runs_with_metrics(outcomes: Sequence[Outcome]) -> list[Outcome]:
    return [o for o in outcomes if o.run.metrics]


def metrics_table(outcomes: Sequence[Outcome]) -> str:
    """``metrics.csv`` of the suite (every run that produced metrics, failed checks included)."""
    from washbench.io.metrics_csv import METRICS_COLUMNS, METRICS_TEXT_COLUMNS

    rows = [["aircraft", "manoeuvre", *METRICS_COLUMNS]]
    for o in _runs_with_metrics(outcomes):
        for m in o.run.metrics:
            cells = [getattr(m, c) if c in METRICS_TEXT_COLUMNS else csv_number(getattr(m, c)) for c in METRICS_COLUMNS]
            rows.append([o.run.aircraft, o.run.manoeuvre, *cells])
    return _csv(rows)


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
    return _csv(rows)


def ranking_table(rankings: dict[tuple[str, str], list[RankRow]], rule: RankRule = DEFAULT_RULE) -> str:
    """``ranking.csv``: rank, washout and the rule's value (``score``, lower is better) per manoeuvre; ``tied``
    (true when the rank is shared: values within the tie margin) and ``rule`` (``--rank-by``)."""
    rows = [["aircraft", "manoeuvre", "rank", "washout", "score", "tied", "rule"]]
    for (aircraft, manoeuvre), ranking in rankings.items():
        for r in ranking:
            tied = "true" if r.tied else "false"
            place = str(r.rank) if r.rank else ""  # empty: the oracle bound, scored but not ranked
            rows.append([aircraft, manoeuvre, place, r.washout, csv_number(r.score), tied, rule.by])
    return _csv(rows)


def _washouts(outcomes: Sequence[Outcome]) -> list[str]:
    """Every washout of the suite in the order the configuration listed them."""
    return list(dict.fromkeys(m.washout for o in outcomes for m in o.run.metrics))


def write_suite_results(
    outcomes: Sequence[Outcome], out_dir: Path, provenance: dict[str, object] | None = None, figures: bool = True
) -> None:
    """Write metrics.csv, comparison.csv, ranking.csv, suite.json and (last) report.md with its figures (unless
    ``figures`` is False), atomically.

    The report is built from the files (:mod:`washbench.review.suite_report`), as ``washbench report`` builds it.
    """
    from washbench.io.provenance import utc_now
    from washbench.review.suite_report import write_suite_json, write_suite_report

    rule = rule_from_record((provenance or {}).get("ranking"))
    rankings = {
        (o.run.aircraft, o.run.manoeuvre): rank(o.run.metrics, o.run.motion, rule)
        for o in _runs_with_metrics(outcomes)
    }
    write_text_atomic(out_dir / "metrics.csv", metrics_table(outcomes))
    write_text_atomic(out_dir / "comparison.csv", comparison_table(outcomes))
    write_text_atomic(out_dir / "ranking.csv", ranking_table(rankings, rule))
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
    write_suite_report(out_dir, figures=figures)
    # last: the same document with every top-level entry written (what the next suite may replace)
    top = sorted(e.name for e in out_dir.iterdir() if not e.name.startswith(".") and e.name != SUITE_MARKER)
    write_suite_json(out_dir / SUITE_MARKER, entries, dict(provenance or {}), created, top)


def check_unique_names(files: Sequence[Path], aircraft_dirs: Sequence[Path] = ()) -> None:
    """Refuse two manoeuvre files with the same aircraft and name (they would share a result folder).

    Files that do not load are left for the run to report. Raises WashbenchError naming both files.
    """
    from washbench.flight.manoeuvre import load_manoeuvre
    from washbench.flight.scripts import is_script, load_script_info

    seen: dict[tuple[str, str], Path] = {}
    for path in files:
        try:
            if is_script(path):  # a JSBSim script's result folder is named after its file
                info = load_script_info(path, aircraft_dirs)
                key, where = (info.aircraft, info.name), f"{path}: the script's file name:"
            else:
                m = load_manoeuvre(path, aircraft_dirs)
                key, where = (m.aircraft, m.name), m.located(("name",), "")[:-1]
        except WashbenchError:
            continue
        if key in seen:
            raise WashbenchError(
                f"{where} '{key[1]}' ({key[0]}) is also the name of {seen[key]}: both would write "
                f"{key[0]}/{key[1]}/; give each its own name"
            )
        seen[key] = path


def _is_run_folder(entry: Path, aircraft: str) -> bool:
    """A ``run`` result of this aircraft (a JSBSim script that resets: a folder of such results)."""
    return is_washbench_result(entry, RUN_MARKER, {"aircraft": aircraft}, nested=True)


def previous_results(out_dir: Path) -> list[Path]:
    """The entries of ``out_dir`` a new suite replaces: a previous suite's files and run result folders.

    Raises WashbenchError naming the first entry washbench did not write (the suite then does not start).
    """
    marker = read_marker(out_dir, SUITE_MARKER) or {}
    listed = marker.get("entries", []) if marker.get("washbench") == "suite" else []
    listed = {n for n in listed if isinstance(n, str) and "/" not in n and n not in ("", ".", "..")}
    found: list[Path] = []
    for entry in sorted(out_dir.iterdir()):
        name = entry.name
        if is_own_hidden(name) or is_leftover(name):
            continue
        if entry.is_symlink():  # never followed, never replaced (nor anything deleted through it)
            raise WashbenchError(located(entry, "is a symbolic link: washbench never follows or replaces a link in "
                                         "its output folder; remove it or choose another --out"))  # fmt: skip
        if name in SUITE_FILES or name == SUITE_MARKER or name in listed:
            found.append(entry)
            continue
        if entry.is_dir():
            subs = [e for e in entry.iterdir() if not is_leftover(e.name)]
            if subs and all(_is_run_folder(e, name) for e in subs):  # an empty folder is the user's
                found.append(entry)
                continue
            entry = next((e for e in subs if not _is_run_folder(e, name)), entry)
        raise WashbenchError(
            located(entry, "washbench did not write this: a suite replaces only a previous washbench result as a "
                    "whole; choose an empty or new --out folder")
        )  # fmt: skip
    return found


def write_run_review(
    run_dir: Path,
    summary: RunSummary,
    source: str = "",
    table: Mapping[str, Any] | None = None,
    figures: bool = True,
) -> None:
    """``ranking.csv`` and ``report.md`` of one result folder (the same tables as a suite's, for one run).

    The one call site for a result folder's report (``washbench run`` and ``washbench cue``); the report and its
    figures are built from the folder's files (:func:`washbench.review.report.write_result_report`), with the
    traces.parquet columns taken from ``table`` when the caller still holds them; ``figures=False``: none drawn.
    """
    from washbench.review.report import write_result_report

    prov = (read_marker(run_dir, RUN_MARKER) or {}).get("provenance")
    rule = rule_from_record(prov.get("ranking") if isinstance(prov, dict) else None)
    rankings = (
        {(summary.aircraft, summary.manoeuvre): rank(summary.metrics, summary.motion, rule)} if summary.metrics else {}
    )
    write_text_atomic(run_dir / "ranking.csv", ranking_table(rankings, rule))
    write_result_report(run_dir, table, figures=figures)


def suite_command(
    inputs: Sequence[Path],
    out_dir: Path,
    *,
    jobs: int | None = None,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    progress: bool = True,
    washouts: Sequence[str] | None = None,
    variants: Sequence[str] = (),
    dask: str | None = None,
    aircraft_dirs: Sequence[Path] = (),
    jsbsim_scripts: Sequence[str] = (),
    max_time_s: float | None = None,
    outputs: Outputs = DEFAULT_OUTPUTS,
    rank_by: str | None = None,
    vestibular: str | None = None,
) -> int:
    """CLI entry: run the suite, write its results, print where they are; 0 if all succeeded, else 1.

    ``jsbsim_scripts``: names of scripts shipped with JSBSim (``c1723``) run besides ``inputs``. See the module
    docstring for the output folder policy (lock, whole replacement, interruption).
    """
    from washbench.flight.scripts import bundled_script

    if jobs is not None and jobs < 1:
        raise WashbenchError(f"--jobs: expected a whole number of at least 1, got {jobs}")
    from washbench.runs.pipeline import check_max_time

    check_max_time(max_time_s)
    files = find_manoeuvres(inputs, [bundled_script(n) for n in jsbsim_scripts])
    # Fail fast on a bad parameter, variant or platform file: every run would fail the same way.
    from washbench.cueing import load_washout_params
    from washbench.cueing.params import DEFAULT_PARAMS_PATH
    from washbench.cueing.variants import select_washouts
    from washbench.io.provenance import build_provenance
    from washbench.perception.vestibular import model_record
    from washbench.platform import load_platform_limits
    from washbench.platform.limits import DEFAULT_LIMITS_PATH
    from washbench.runs.rank_rule import load_rank_rule

    provenance = build_provenance(
        params_path=params_path or DEFAULT_PARAMS_PATH,
        params=load_washout_params(params_path),
        washouts=select_washouts(washouts, variants, params_path),
        platform_path=platform_path or DEFAULT_LIMITS_PATH,
        platform=load_platform_limits(platform_path),
        ranking=load_rank_rule(params_path, rank_by).record(),
        vestibular=model_record(vestibular),
    )
    check_unique_names(files, aircraft_dirs)
    from washbench.flight.scripts import is_script
    from washbench.runs.pipeline import announce_script

    for f in files:
        if is_script(f):
            announce_script(f, max_time_s, aircraft_dirs, washouts, variants, params_path, outputs)
    start = time.perf_counter()
    with output_lock(out_dir):
        # under the lock every leftover is stale; a publication cut by a kill is finished. In a folder that holds
        # no suite (no suite.json), only washbench's own leftovers: a hidden file there is the user's.
        recover(out_dir, only_washbench=read_marker(out_dir, SUITE_MARKER) is None)
        previous = previous_results(out_dir)
        for entry in previous:
            if entry.is_dir() and not entry.is_symlink():
                clean_partials(entry, only_dead=False)
        stage = out_dir / f".suite.partial-{os.getpid()}"
        stage.mkdir()
        try:
            outcomes = run_suite(
                files,
                stage,
                jobs=jobs,
                params_path=params_path,
                platform_path=platform_path,
                progress=progress,
                washouts=washouts,
                variants=variants,
                dask=dask,
                aircraft_dirs=aircraft_dirs,
                max_time_s=max_time_s,
                outputs=outputs,
                rank_by=rank_by,
                vestibular=vestibular,
            )
            write_suite_results(outcomes, stage, provenance, outputs.figures)
            swap_in(stage, out_dir, previous)  # journalled, signals held: whole or not at all
        finally:
            discard_stage(stage)  # unless a journal says it is being published (recover finishes it)
    n_ok = sum(o.run.ok for o in outcomes)
    print(
        f"suite: {n_ok}/{len(outcomes)} runs ok in {time.perf_counter() - start:.1f} s; report: {out_dir / 'report.md'}"
    )
    return 0 if n_ok == len(outcomes) else 1


__all__ = [
    "DOFS",
    "METRICS",
    "Outcome",
    "check_unique_names",
    "find_manoeuvres",
    "previous_results",
    "run_suite",
    "suite_command",
    "write_suite_results",
]
