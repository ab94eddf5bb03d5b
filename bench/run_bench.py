"""Where one ``washbench run`` spends its time, stage by stage, against bare JSBSim for the same steps.

    .venv/bin/python bench/run_bench.py [c172/takeoff columbia400/aerobatics ...] [--repeat 3]

Each manoeuvre is run in this process (imports and the compiled kernels already loaded, as in a suite's worker)
with every output (recording and figures), ``--repeat`` times; the CPU time of each stage is the minimum over the
repeats (``time.process_time``, this process only): the JSBSim model load, initial conditions and trim or flying
start (``make_fdm``), the flight loop (pilot, monitor, recorder and the washouts in lockstep), ``flight.parquet``,
perception + metrics, ``traces.parquet``, the recording, the report (with its figures) and the rest. The baseline
is bare ``fdm.run()`` for as many steps as the flight recorded, from the manoeuvre's own start (the suite bench's
baseline), measured in this run.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections import defaultdict
from pathlib import Path

from baseline import manoeuvre_start, run_cpu_s

STAGES = (
    ("model load + start", "washbench.flight.fly", "make_fdm"),
    ("flight.parquet", "washbench.flight.fly", "write_flight"),
    ("perception + metrics", "washbench.runs.chain", "analyse"),
    ("traces.parquet + metrics.csv", "washbench.runs.pipeline", "write_results"),
    ("recording", "washbench.runs.pipeline", "write_run_recording"),
    ("report + figures", "washbench.runs.pipeline", "write_run_review"),
)


def timed_run(path: Path, out: Path) -> tuple[dict[str, float], int]:
    """CPU seconds per stage of one run (the functions of STAGES wrapped where the pipeline calls them)."""
    import importlib

    from washbench.runs.pipeline import run_manoeuvre

    spent: dict[str, float] = defaultdict(float)
    originals = []
    for label, module, name in STAGES:
        mod = importlib.import_module(module)
        fn = getattr(mod, name)
        originals.append((mod, name, fn))

        def wrapped(*a, _fn=fn, _label=label, **k):  # type: ignore[no-untyped-def]
            t0 = time.process_time()
            try:
                return _fn(*a, **k)
            finally:
                spent[_label] += time.process_time() - t0

        setattr(mod, name, wrapped)
    try:
        t0 = time.process_time()
        summary = run_manoeuvre(path, out)
        spent["whole run"] = time.process_time() - t0
    finally:
        for mod, name, fn in originals:
            setattr(mod, name, fn)
    return dict(spent), summary.steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("manoeuvres", nargs="*", default=["c172/takeoff", "columbia400/aerobatics"])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    import washbench.runs.preload  # noqa: F401  (what a suite worker has loaded before its first run)
    from washbench.io.paths import resolve_manoeuvre
    from washbench.runs.pipeline import run_manoeuvre

    with tempfile.TemporaryDirectory() as tmp:
        run_manoeuvre(resolve_manoeuvre(Path(args.manoeuvres[0])), Path(tmp) / "warm")  # first-call costs first
        for name in args.manoeuvres:
            path = resolve_manoeuvre(Path(name))
            best: dict[str, float] = {}
            steps = 0
            for i in range(args.repeat):
                spent, steps = timed_run(path, Path(tmp) / f"{name.replace('/', '_')}{i}")
                best = {k: min(v, best.get(k, v)) for k, v in spent.items()}
            bare = min(run_cpu_s(manoeuvre_start(path), steps) for _ in range(args.repeat))
            staged = sum(v for k, v in best.items() if k not in ("whole run",))
            flight = best["whole run"] - staged
            print(f"{name}: {steps} steps; bare fdm.run() {bare:.3f} s CPU")
            rows = [(k, best.get(k, 0.0)) for k, _, _ in STAGES[:1]] + [("flight loop + rest", flight)]
            rows += [(k, best.get(k, 0.0)) for k, _, _ in STAGES[1:]] + [("whole run", best["whole run"])]
            for label, v in rows:
                print(f"  {label:30s} {v:7.3f} s  {v / bare:6.2f} x bare JSBSim")


if __name__ == "__main__":
    main()
