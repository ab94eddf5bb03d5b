"""One condition of ``washbench track``'s standard measurement (the task's runs of 90 s: 8.08 s of run-in and the
81.92 s window), against bare JSBSim for the same steps; the aim is under a minute of CPU (issue 53).

    .venv/bin/python bench/track_bench.py [c172/roll columbia400/pitch ...] [--washout large-angle] [--repeat 3]

Per task, in this process (imports and kernels loaded; the calibration flown once, not timed here but printed): the
CPU time (``time.process_time``, this process only; the minimum over the repeats) of one condition, the washout's:
its motion filter (the aircraft condition's head motion cued through it), the adaptation, the runs with JSBSim,
the washout and the pilot in the loop, and the measures; then split into those parts. The baseline is bare
``fdm.run()`` for as many steps as the condition flew, from the task's start, measured in this run.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from baseline import manoeuvre_start, run_cpu_s


def _timed(fn, spent: dict[str, float], label: str):  # type: ignore[no-untyped-def]
    """``fn`` adding its CPU time to ``spent[label]``."""

    def wrapped(*a, **k):  # type: ignore[no-untyped-def]
        t = time.process_time()
        try:
            return fn(*a, **k)
        finally:
            spent[label] += time.process_time() - t

    return wrapped


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("tasks", nargs="*", default=["c172/roll", "columbia400/pitch"])
    parser.add_argument("--washout", default="large-angle")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    from washbench.io.paths import resolve_task
    from washbench.perception.vestibular import model_params
    from washbench.pilot import measure
    from washbench.pilot.compare import measures
    from washbench.pilot.loop import AIRCRAFT, Condition
    from washbench.pilot.params import MultimodalParams
    from washbench.pilot.senses import DEFAULT_VESTIBULAR
    from washbench.pilot.task import load_task
    from washbench.runs.options import load_options

    options = load_options(washouts=[args.washout])
    vestibular = model_params(DEFAULT_VESTIBULAR)
    for name in args.tasks:
        task, manoeuvre = load_task(resolve_task(Path(name)))
        t0 = time.process_time()
        calib, _ = measure.calibrate(task, manoeuvre, MultimodalParams(), vestibular, task.adaptation)
        aircraft = measure.measure_condition(task, manoeuvre, Condition(AIRCRAFT), calib, vestibular,
                                             measure.motion_filter(Condition(AIRCRAFT), [], task))  # fmt: skip
        setup = time.process_time() - t0
        washout = options.washouts[0]
        cond = Condition(washout.name, washout, options.limits)
        best: dict[str, float] = {}
        for _ in range(args.repeat):
            spent = {"adaptation": 0.0, "runs (JSBSim, washout, pilot)": 0.0}
            originals = (measure.adapt, measure.fly_run)

            measure.adapt = _timed(originals[0], spent, "adaptation")
            measure.fly_run = _timed(originals[1], spent, "runs (JSBSim, washout, pilot)")
            try:
                t = time.process_time()
                motion = measure.motion_filter(cond, aircraft.runs, task)
                spent["motion filter"] = time.process_time() - t
                t = time.process_time()
                result = measure.measure_condition(task, manoeuvre, cond, calib, vestibular, motion)
                measures(result, task)
                spent["condition"] = time.process_time() - t + spent["motion filter"]
            finally:
                measure.adapt, measure.fly_run = originals
            best = {k: min(v, best.get(k, v)) for k, v in spent.items()}
        steps = task.runs * task.steps
        bare = min(run_cpu_s(manoeuvre_start(manoeuvre), steps) for _ in range(args.repeat))
        rest = best["condition"] - best["motion filter"] - best["adaptation"] - best["runs (JSBSim, washout, pilot)"]
        print(f"{name} ({task.aircraft}, {task.axis}), {washout.name}: {task.runs} runs of "
              f"{task.run_in_s + task.measurement_s:g} s, {steps} steps; bare fdm.run() {bare:.3f} s CPU; "
              f"calibration and aircraft condition {setup:.2f} s")  # fmt: skip
        for label, v in (("motion filter", best["motion filter"]), ("adaptation", best["adaptation"]),
                         ("runs (JSBSim, washout, pilot)", best["runs (JSBSim, washout, pilot)"]),
                         ("measures and the rest", rest), ("one condition", best["condition"])):  # fmt: skip
            print(f"  {label:32s} {v:7.3f} s  {v / bare:6.2f} x bare JSBSim")
        print(f"  one condition: {best['condition']:.1f} s of CPU, {'under' if best['condition'] < 60 else 'OVER'} a "
              "minute")  # fmt: skip


if __name__ == "__main__":
    main()
