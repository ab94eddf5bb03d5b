"""Whole-suite wall time against bare JSBSim ``fdm.run()`` for the same steps, on the same cores.

Runs ``washbench suite`` (flight, scripted pilot, three washouts in lockstep, Atlas model,
vestibular models, metrics, traces.parquet and recording.rrd) on the bundled manoeuvres with
``--jobs`` processes, counts the JSBSim steps it flew per aircraft, then runs bare ``fdm.run()``
for the same number of steps per aircraft, spread over the same number of processes, and prints
both wall times and their ratio (the suite's cost over JSBSim's own).

    .venv/bin/python bench/suite_bench.py [--jobs 2] [MANOEUVRE_OR_DIR ...]
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path


def bare_run(aircraft: str, steps: int, dt_s: float) -> float:
    """Seconds for ``steps`` calls of ``fdm.run()`` on ``aircraft`` flying level at 4000 ft, 100 kt."""
    os.environ["JSBSIM_DEBUG"] = "0"
    import jsbsim

    from washbench.manoeuvre import aircraft_path

    root = aircraft_path(aircraft)
    if root is None:
        raise SystemExit(f"unknown aircraft {aircraft}")
    fdm = jsbsim.FGFDMExec(str(Path(jsbsim.__file__).resolve().parent))
    fdm.set_aircraft_path(str(root))
    fdm.set_debug_level(0)
    fdm.load_model(aircraft)
    fdm.set_dt(dt_s)
    fdm["ic/h-sl-ft"] = 4000.0
    fdm["ic/vc-kts"] = 100.0
    fdm["ic/lat-geod-deg"] = 45.0
    fdm["ic/psi-true-deg"] = 90.0
    fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    fdm["fcs/throttle-cmd-norm"] = 0.7
    fdm["fcs/mixture-cmd-norm"] = 0.9
    run = fdm.run
    start = time.perf_counter()
    for _ in range(steps):
        run()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="*", type=Path)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()

    from washbench.suite import find_manoeuvres, run_suite, write_suite_results

    files = find_manoeuvres(args.inputs)
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        outcomes = run_suite(files, Path(tmp), jobs=args.jobs, progress=False)
        write_suite_results(outcomes, Path(tmp))
        suite_s = time.perf_counter() - start
    failed = [o for o in outcomes if not o.ok]
    work = [(o.aircraft, o.steps, o.dt_s) for o in outcomes if o.steps]
    steps = sum(s for _, s, _ in work)
    ctx = multiprocessing.get_context("forkserver")
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.jobs, mp_context=ctx) as pool:
        list(pool.map(bare_run, *zip(*work, strict=True)))
    bare_s = time.perf_counter() - start
    print(f"manoeuvres: {len(outcomes)} ({len(failed)} failed), JSBSim steps: {steps}, processes: {args.jobs}")
    print(f"washbench suite wall time: {suite_s:8.2f} s")
    print(f"bare fdm.run() wall time:  {bare_s:8.2f} s  (same steps per aircraft, same processes)")
    print(f"ratio suite / bare JSBSim: {suite_s / bare_s:8.2f}")


if __name__ == "__main__":
    main()
