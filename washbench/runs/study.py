"""What the studies (``sweep``, ``tune``) share: the flights, flown once, and batches of evaluations on them.

Flights are flown once per study (in parallel processes, or on a Dask cluster) and written as
``DIR/flights/<aircraft>/<manoeuvre>/flight.parquet`` + ``flight.json`` (what ``washbench fly`` writes), or read
from earlier results (``--from RESULTS_DIR``: a ``suite`` or ``run`` results folder, or a study's ``flights/``).
Each flight is read back exactly as ``washbench cue`` reads it, so an evaluation equals ``washbench cue`` on that
file. Evaluations never fly JSBSim and write nothing: :class:`washbench.analysis.evaluate.FlightEvaluator` runs a
batch of candidates in one compiled call over the whole trace, parallel over candidates on every core.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from washbench.analysis.evaluate import Evaluation, FlightEvaluator
from washbench.cueing.variants import Washout
from washbench.errors import WashbenchError, located
from washbench.flight.fly import fly, write_flight
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.cpus import usable_cpus
from washbench.io.motion_file import read_motion
from washbench.io.outfolder import STAGE_PREFIX
from washbench.io.progress import Progress
from washbench.io.result_files import FLIGHT_FILE
from washbench.runs.cluster import client, dask_map
from washbench.runs.pool import submit_all, worker_pool

FLIGHTS_DIR = "flights"


@dataclass(frozen=True)
class StudyFlight:
    """One recorded flight of a study, ready to evaluate."""

    aircraft: str
    manoeuvre: str
    source: str  # the flight.parquet read
    ok: bool  # flown and passed its checks (True for flights read with --from)
    reason: str
    evaluator: FlightEvaluator


def _fly_one(path: str, flights_dir: str, aircraft_dirs: tuple[str, ...] = ()) -> tuple[str, str, bool, str]:
    """Worker: fly one manoeuvre (no washouts, no recording) and write its flight; (aircraft, name, ok, reason)."""

    m = load_manoeuvre(Path(path), [Path(d) for d in aircraft_dirs])
    result = fly(m)
    write_flight(Path(flights_dir) / m.aircraft / m.name, result, path)
    return m.aircraft, m.name, result.ok, result.reason


def _identify(paths: Sequence[Path], aircraft_dirs: Sequence[Path]) -> list[tuple[str, str, str]]:
    """(path, aircraft, name) of every manoeuvre file, validated (bad files stop the study before any work)."""

    out = []
    for p in paths:
        m = load_manoeuvre(p, aircraft_dirs)
        out.append((str(p), m.aircraft, m.name))
    names = [(a, n) for _, a, n in out]
    if len(set(names)) != len(names):
        raise WashbenchError("two manoeuvre files have the same aircraft and name: results would overwrite")
    return out


def load_flights(
    manoeuvres: Sequence[Path],
    out_dir: Path,
    limits: object,
    *,
    from_dir: Path | None = None,
    jobs: int | None = None,
    dask: str | None = None,
    progress: bool = True,
    aircraft_dirs: Sequence[Path] = (),
) -> list[StudyFlight]:
    """The study's flights: flown once into ``out_dir/flights/`` or read from ``from_dir``; in manoeuvre order."""
    ids = _identify(manoeuvres, aircraft_dirs)
    status: dict[tuple[str, str], tuple[bool, str]] = {}
    if from_dir is not None:
        root = Path(from_dir)
        for _, aircraft, name in ids:
            status[(aircraft, name)] = (True, "")
    else:
        root = Path(out_dir) / FLIGHTS_DIR
        dirs = tuple(str(d) for d in aircraft_dirs)
        args = [(p, str(root), dirs) for p, _, _ in ids]
        if progress:
            shown = root.parent.parent / FLIGHTS_DIR if root.parent.name.startswith(STAGE_PREFIX) else root
            print(f"study: flying {len(args)} manoeuvre(s) once -> {shown}", file=sys.stderr, flush=True)
        for aircraft, name, ok, reason in _map(_fly_one, args, jobs, dask):
            status[(aircraft, name)] = (ok, reason)
            if progress:
                print(f"  {aircraft}/{name}: {'ok' if ok else 'FAILED (' + reason + ')'}", file=sys.stderr, flush=True)
    flights = []
    for _, aircraft, name in ids:
        src = root / aircraft / name / FLIGHT_FILE
        if not src.is_file():
            raise WashbenchError(located(src, f"no flight for {aircraft}/{name} (run or suite it first)"))
        motion = read_motion(src)
        ok, reason = status[(aircraft, name)]
        ev = FlightEvaluator(motion.f_mps2, motion.omega_radps, motion.dt_s, limits)
        flights.append(StudyFlight(aircraft, name, str(src), ok, reason, ev))
    return flights


def _map(fn, args: list[tuple], jobs: int | None, dask: str | None) -> list:
    """``fn(*a)`` for each ``a``: on the Dask cluster, in forked worker processes, or here (one job)."""
    if dask:
        return list(dask_map(dask, fn, args))
    jobs = max(1, min(jobs or usable_cpus(), len(args)))
    if jobs == 1:
        return [fn(*a) for a in args]
    # As the suite's pool: the workers ignore Ctrl-C (no traceback from each), the main process stops them at once
    # on SIGINT/SIGTERM, a signal while they start is acted on once they exist, and they die with their parent.
    with worker_pool(jobs) as pool:
        return [f.result() for f in submit_all(pool, fn, args)]


def _evaluate_task(
    evaluator: FlightEvaluator, cfg: np.ndarray, coef: np.ndarray, washouts: Sequence[Washout] = ()
) -> Evaluation:
    """Cluster task: one batch of candidates (compiled arrays) on one flight."""
    return evaluator.evaluate_arrays(cfg, coef, washouts)


def _concat(parts: Sequence[Evaluation]) -> Evaluation:
    fields = Evaluation.__dataclass_fields__
    return Evaluation(**{k: np.concatenate([getattr(p, k) for p in parts]) for k in fields})


def evaluate(
    flights: Sequence[StudyFlight],
    candidates: Sequence[Washout],
    dask: str | None = None,
    progress: Progress | None = None,
) -> list[Evaluation]:
    """Every candidate on every flight: one Evaluation (M candidates) per flight, in flight order.

    ``progress`` (:mod:`washbench.io.progress`) is told the steps done (samples x candidates) after each flight.

    Locally one compiled call per flight uses every core (threads over candidates); with ``dask`` the batches go
    to the cluster as tasks (each flight sent to every worker once) and give the same numbers.
    """
    if not candidates:
        raise WashbenchError("no candidate to evaluate")
    if not dask:
        out, steps = [], 0
        for f in flights:
            out.append(f.evaluator.evaluate(candidates))
            steps += f.evaluator.n * len(candidates)
            if progress is not None:
                progress.update(steps)
        return out

    c = client(dask)
    n_workers = max(1, len(c.scheduler_info().get("workers", {})))
    chunk = max(1, math.ceil(len(candidates) / (2 * n_workers)))
    futures = []
    for f in flights:
        cfg, coef = f.evaluator.arrays(candidates)
        # hash=False: a fresh key per call. With content-hash keys each tune generation scattered the same key
        # while the scheduler was still releasing the previous generation's copy: "lost dependencies".
        [ev] = c.scatter([f.evaluator], broadcast=True, hash=False)
        futures.append(
            [
                c.submit(
                    _evaluate_task,
                    ev,
                    cfg[i : i + chunk],
                    coef[i : i + chunk],
                    list(candidates[i : i + chunk]),
                    pure=False,
                )
                for i in range(0, len(candidates), chunk)
            ]
        )
    out, steps = [], 0
    for f, fs in zip(flights, futures, strict=True):
        out.append(_concat(c.gather(fs)))
        steps += f.evaluator.n * len(candidates)
        if progress is not None:
            progress.update(steps)
    return out
