"""Whole-suite wall time against bare JSBSim ``fdm.run()`` for the same steps, on the same cores.

Runs ``washbench suite`` (flight with the scripted pilot, three washouts in lockstep, Atlas model,
vestibular models, metrics, traces.parquet and recording.rrd, report) on the bundled manoeuvres
with ``--jobs`` processes and times it. Then, for every manoeuvre, it sets JSBSim up at the
manoeuvre's own start (the same set-up the flight uses) and times bare ``fdm.run()`` for as many
steps as the flight recorded, spread over the same number of processes. It prints both, their
ratio, and the per-step figures.

    .venv/bin/python bench/suite_bench.py [--jobs 2] [--no-recording] [--no-figures] [MANOEUVRE_OR_DIR ...]
"""

from __future__ import annotations

import argparse
import multiprocessing
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from baseline import manoeuvre_wall_s

from washbench.io.cpus import usable_cpus
from washbench.io.pages import small_pages


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="*", type=Path)
    parser.add_argument("--jobs", type=int, default=usable_cpus())
    parser.add_argument("--no-recording", action="store_true", help="run the suite without recording.rrd files")
    parser.add_argument("--no-figures", action="store_true", help="run the suite without the reports' figures")
    args = parser.parse_args()
    small_pages()  # as a washbench command does (washbench.io.pages): the stages timed in this process

    from washbench.runs.inputs import find_manoeuvres
    from washbench.runs.options import load_options
    from washbench.runs.outputs import Outputs
    from washbench.runs.suite import run_suite, suite_pool, write_suite_results

    outputs = Outputs(recording=not args.no_recording, figures=not args.no_figures)
    options = load_options(outputs=outputs)

    files = find_manoeuvres(args.inputs)
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        # as `washbench suite` does it: the workers that ran the manoeuvres draw the suite report's figures
        with suite_pool(options, args.jobs) as pool:
            outcomes = run_suite(files, Path(tmp), options, jobs=args.jobs, progress=False, pool=pool)
            write_suite_results(outcomes, Path(tmp), figures=outputs.figures, pool=pool)
        suite_s = time.perf_counter() - start
    failed = [o for o in outcomes if not o.run.ok]
    work = [(o.path, o.run.steps) for o in outcomes if o.run.steps]
    steps = sum(s for _, s in work)
    ctx = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(max_workers=args.jobs, mp_context=ctx) as pool:
        bare = list(pool.map(manoeuvre_wall_s, *zip(*work, strict=True)))
    # the bare runs are independent: on `jobs` processes their wall time is their sum over `jobs`
    bare_s = sum(bare) / args.jobs
    made = ", ".join(k for k, v in (("recordings", outputs.recording), ("figures", outputs.figures)) if v) or "neither"
    print(f"manoeuvres: {len(outcomes)} ({len(failed)} failed), JSBSim steps: {steps}, processes: {args.jobs}; "
          f"with {made}")  # fmt: skip
    print(f"washbench suite wall time: {suite_s:8.2f} s  ({suite_s / steps * args.jobs * 1e6:6.1f} us per step)")
    print(f"bare fdm.run() wall time:  {bare_s:8.2f} s  ({bare_s / steps * args.jobs * 1e6:6.1f} us per step)")
    print(f"ratio suite / bare JSBSim: {suite_s / bare_s:8.2f}")
    per_run = sum(o.wall_s for o in outcomes)
    print(f"of which inside the runs:  {per_run / args.jobs:8.2f} s (the rest: process start, suite files)")


if __name__ == "__main__":
    main()
