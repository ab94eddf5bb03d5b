"""``washbench sweep``: a grid of parameter sets for one or more washout kinds, on every manoeuvre.

Flights are flown once (or read with ``--from``, :mod:`washbench.runs.study`); per grid point only the cueing,
perception, metrics and score are recomputed, in one compiled call per flight. Writes, each atomically:

- ``DIR/sweep.csv``: one row per grid point, washout and manoeuvre: the swept keys (one column each, named by the
  key), ``washout``, ``aircraft``, ``manoeuvre``, ``score`` (the ranking rule's, lower is better), ``saturated_s``
  (time at any platform limit);
- ``DIR/sweep_metrics.csv``: the same rows times DOF with ``npc,integral_error,max_error`` (units of metrics.csv);
- ``DIR/sweep.png``: the mean score over the manoeuvres against each swept key, one line per washout;
- ``DIR/flights/``: the flights flown (reusable with ``--from DIR/flights``);
- with ``--pilot TASK``, ``DIR/sweep_pilot.csv``: one row per grid point and washout: the swept keys,
  ``washout``, and the pilot model's measures on the tracking task as its adaptation predicts them
  (:mod:`washbench.pilot.surrogate`: error and control variances, crossovers and phase margins, its parameters,
  the motion filter's gain at 1 rad/s, ``distance_pct`` from flight).
"""

from __future__ import annotations

import csv
import io
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from washbench.analysis.sweep import (
    SweepRow,
    format_value,
    grid,
    parse_set,
    point_washouts,
    sweep_csv,
    sweep_metrics_csv,
)
from washbench.cueing.params import WASHOUT_NAMES
from washbench.cueing.variants import Washout, check_platform, load_param_file
from washbench.errors import WashbenchError, printable
from washbench.io.atomic import write_text_atomic
from washbench.io.csv_numbers import csv_number
from washbench.io.outfolder import result_set
from washbench.io.progress import Progress
from washbench.pilot.surrogate import PREDICTED, PilotObjective
from washbench.pilot.task import load_task
from washbench.platform.model import load_platform_model
from washbench.review.study_figures import sweep_figure
from washbench.runs.inputs import find_manoeuvres
from washbench.runs.study import StudyFlight, evaluate, load_flights


def _csv(rows: list[list[str]]) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()


#: Largest grid (points times washouts) a sweep runs without ``--force``.
MAX_POINTS = 2000
#: Largest grid even with ``--force`` (its parameter sets alone would fill the memory).
MAX_POINTS_FORCED = 1_000_000


def check_grid_size(n_points: int, n_flights: int, force: bool, say: bool = True) -> None:
    """Say how big the grid is (and refuse one beyond :data:`MAX_POINTS` without ``force``) before any work."""
    if n_points > MAX_POINTS_FORCED:
        raise WashbenchError(f"sweep: the grid has {n_points} points, more than the {MAX_POINTS_FORCED} washbench runs")
    if n_points > MAX_POINTS and not force:
        raise WashbenchError(
            f"sweep: the grid has {n_points} points (x {n_flights} flight(s)), more than {MAX_POINTS}: give --force "
            "to run it anyway, or fewer --set values"
        )
    if say:
        print(f"sweep: {n_points} grid point(s) x {n_flights} flight(s)", file=sys.stderr, flush=True)


#: Point-samples (grid points x samples of the shortest flight) timed to estimate a sweep's time.
PROBE_POINT_SAMPLES = 300_000


def say_estimate(flights: Sequence[StudyFlight], candidates: Sequence[Washout], dask: str | None) -> float | None:
    """Print (stderr) how many evaluations the sweep runs and, for a grid of 20 points or more evaluated here, its
    estimated time: the first points on the shortest flight (about :data:`PROBE_POINT_SAMPLES` point-samples, at
    most 1/20 of the grid; results discarded) timed and scaled to the whole grid. Returns the estimate in s."""
    samples = sum(f.evaluator.n for f in flights)
    line = f"sweep: {len(candidates)} candidate(s) x {len(flights)} flight(s) ({samples} samples in all)"
    estimate = None
    if flights and not dask:
        shortest = min(flights, key=lambda f: f.evaluator.n)
        # at most 1/20 of the grid: the probe's work (thrown away) adds at most 5 % for a slow washout (mpc)
        k = min(math.ceil(PROBE_POINT_SAMPLES / max(shortest.evaluator.n, 1)), len(candidates) // 20)
        if k >= 1:
            t0 = time.perf_counter()
            shortest.evaluator.evaluate(candidates[:k])
            probe_s = time.perf_counter() - t0
            estimate = probe_s * (samples * len(candidates)) / (shortest.evaluator.n * k)
            line += f": about {_duration(estimate)} (timed on the first {k} points)"
    print(line, file=sys.stderr, flush=True)
    return estimate


def pilot_rows(task: Path, keys: Sequence[str], points: Sequence[Any], kinds: Sequence[str],
               candidates: Sequence[Washout], limits: Any, aircraft_dirs: Sequence[Path],
               progress: bool) -> list[list[str]]:  # fmt: skip
    """``sweep_pilot.csv``'s rows: the pilot model's predicted measures of every candidate on ``task``."""
    if progress:
        print(f"sweep: the pilot model on {task}: calibrating and flying the aircraft condition", file=sys.stderr,
              flush=True)  # fmt: skip
    objective = PilotObjective.prepare(task, aircraft_dirs)
    rows = [[*keys, "washout", *PREDICTED]]
    for i, c in enumerate(candidates):
        m = objective.measures(c, limits)
        point = points[i % len(points)]
        rows.append([*(format_value(point[k]) for k in keys), kinds[i // len(points)],
                     *(csv_number(m[k]) for k in PREDICTED)])  # fmt: skip
    return rows


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def sweep_command(
    manoeuvres: Sequence[Path],
    out_dir: Path,
    *,
    washouts: Sequence[str] | None,
    sets: Sequence[str],
    params_path: Path | None = None,
    platform_path: Path | None = None,
    from_dir: Path | None = None,
    jobs: int | None = None,
    dask: str | None = None,
    progress: bool = True,
    aircraft_dirs: Sequence[Path] = (),
    force: bool = False,
    pilot: Path | None = None,
) -> int:
    """CLI entry of ``washbench sweep``; 0 when every flight ran and passed its checks, 1 otherwise.

    A grid of more than :data:`MAX_POINTS` points (over all washouts) needs ``force`` (``--force``)."""
    start = time.perf_counter()
    if not sets:
        raise WashbenchError("sweep: give at least one --set KEY=V1,V2,...")
    axes = [parse_set(s) for s in sets]
    kinds = list(dict.fromkeys(washouts or WASHOUT_NAMES))
    files = find_manoeuvres(manoeuvres)
    n_points = math.prod(len(a.values) for a in axes) * len(kinds)
    check_grid_size(n_points, len(files), force, progress)  # before building the grid
    points = grid(axes)
    keys = [a.key for a in axes]
    base, _ = load_param_file(params_path)
    candidates = [w for k in kinds for w in point_washouts(k, base, points)]
    limits = load_platform_model(platform_path)
    check_platform(candidates, limits)
    if pilot is not None:
        load_task(pilot, aircraft_dirs)  # a bad task file fails before anything is flown
    with result_set(out_dir, "sweep") as stage:  # the whole set replaces the previous one at once
        flights = load_flights(files, stage, limits, from_dir=from_dir, jobs=jobs, dask=dask, progress=progress,
            aircraft_dirs=aircraft_dirs,
        )
        if progress or n_points > MAX_POINTS:  # a big grid (--force) is told its time even with --quiet
            say_estimate(flights, candidates, dask)
        t_eval = time.perf_counter()
        total = sum(f.evaluator.n for f in flights) * len(candidates)
        shown = Progress("sweep", total, "steps") if progress else None
        try:
            results = evaluate(flights, candidates, dask, shown)
        finally:
            if shown is not None:
                shown.close()
        t_eval = time.perf_counter() - t_eval
        rows = [
            SweepRow(points[i % len(points)], kinds[i // len(points)], f.aircraft, f.manoeuvre, ev, i)
            for f, ev in zip(flights, results, strict=True)
            for i in range(len(candidates))
        ]
        rows.sort(key=lambda r: (r.index, r.aircraft, r.manoeuvre))  # grid point by grid point
        write_text_atomic(stage / "sweep.csv", _csv(sweep_csv(keys, rows)))
        write_text_atomic(stage / "sweep_metrics.csv", _csv(sweep_metrics_csv(keys, rows)))

        sweep_figure(stage / "sweep.png", keys, rows)
        if pilot is not None:
            table = pilot_rows(pilot, keys, points, kinds, candidates, limits, aircraft_dirs, progress)
            write_text_atomic(stage / "sweep_pilot.csv", _csv(table))
    out_dir = Path(out_dir)
    n_eval = len(candidates) * len(flights)
    steps = sum(f.evaluator.n for f in flights) * len(candidates)
    print(
        f"sweep: {len(points)} grid point(s) x {len(kinds)} washout(s) x {len(flights)} flight(s) = {n_eval} "
        f"evaluations ({steps / max(t_eval, 1e-9) / 1e6:.2f} M steps/s) in {time.perf_counter() - start:.1f} s; "
        f"wrote {printable(str(out_dir / 'sweep.csv'))}, sweep_metrics.csv, sweep.png"
        + (", sweep_pilot.csv" if pilot is not None else "")
    )
    failed = [f for f in flights if not f.ok]
    for f in failed:
        print(f"sweep: warning: {f.aircraft}/{f.manoeuvre} did not pass its checks: {f.reason}", file=sys.stderr)
    return 0 if not failed else 1
