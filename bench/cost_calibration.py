"""Calibration of :mod:`washbench.io.cost`: each expensive computation measured at several sizes, against its model.

    .venv/bin/python bench/cost_calibration.py [--quick] [--only bound|ceiling|mpc|mpc-hexapod|mpc-unrestricted]

Each point runs in a fresh process (so its peak is its own): the resident memory before the computation and the
peak during it (``/proc/self/status`` polled every millisecond, and ``ru_maxrss``), the wall and CPU time. Parts:

* ``attitude``, ``translation``: the bound's replay's two programmes (:func:`washbench.analysis.bound.oracle_bound`
  with pitch, roll and yaw; :func:`washbench.analysis.bound_replay.translation_plan`), and ``ceiling`` (the six
  LPs of :func:`washbench.analysis.ceiling.ceiling`), on n samples of the 120 Hz multi-axis signal of
  ``bench/cue_bench.py``;
* ``mpc``, ``mpc-hexapod``, ``mpc-unrestricted``: the washout built with a horizon of N intervals (``horizon_steps``,
  ``prediction_step_s`` 0.1 s), its first sample (the solver's set-up: DAQP factorises the QP at its first solve)
  timed alone, then samples 6 to 40 of the same signal timed per sample. The model's building time is the two
  first parts.

Printed per point: what was measured, what the model says, and their ratio (measured / model): memory ratios must
stay below 1 (the models are upper estimates), time ratios near 1. Time is CPU time (this process, every thread):
on a shared machine wall time counts the other processes (measured here: up to 8 times the CPU time); on a quiet one
it is about the CPU time, less where BLAS uses a second core. ``bench/cost_calibration.md`` keeps
the figures the constants in :mod:`washbench.io.cost` were set from.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import threading
import time

import numpy as np

DT_S = 1.0 / 120.0
BOUND_SIZES = (3600, 7200, 14400, 28800)
MPC_SIZES = (50, 100, 200, 300)
HEXAPOD_SIZES = (50, 100, 200)
UNRESTRICTED_SIZES = (50, 100, 200)


def signal(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The multi-axis signal of bench/cue_bench.py: f (n, 3) m/s^2, omega (n, 3) rad/s."""
    t = np.arange(n) * DT_S
    f = np.column_stack([1.5 * np.sin(0.3 * t) + 0.3 * np.sin(7.1 * t), 0.8 * np.sin(0.17 * t + 1.0),
                         -9.80665 * (1.0 + 0.3 * np.sin(0.11 * t))])  # fmt: skip
    w = np.radians(np.column_stack([15.0 * np.sin(0.5 * t), 5.0 * np.sin(0.23 * t + 0.4), 3.0 * np.sin(0.07 * t)]))
    return f, w


class Peak:
    """The largest resident memory seen while inside (polled every millisecond, and the process's ru_maxrss)."""

    def __enter__(self) -> Peak:
        from washbench.io.cost import resident_bytes

        self.rss = resident_bytes
        self.before = resident_bytes()
        self.maxrss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        self.top = self.before
        self.done = False
        self.thread = threading.Thread(target=self._poll, daemon=True)
        self.thread.start()
        return self

    def _poll(self) -> None:
        while not self.done:
            self.top = max(self.top, self.rss())
            time.sleep(0.001)

    def __exit__(self, *exc: object) -> None:
        self.done = True
        self.thread.join()
        maxrss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        if maxrss > self.maxrss0:
            self.top = max(self.top, maxrss)
        self.extra = self.top - self.before


def one(kind: str, size: int) -> dict[str, float]:
    """Measure one point in this process."""
    from washbench.platform.model import load_platform_model, planning_limits
    from washbench.runs.options import load_options

    out: dict[str, float] = {}
    if kind in ("attitude", "translation", "ceiling"):
        from washbench.analysis.bound import BoundParams, oracle_bound
        from washbench.analysis.bound_replay import translation_plan
        from washbench.analysis.ceiling import ceiling
        from washbench.perception.vestibular import VestibularModel

        limits = load_options().limits
        f, w = signal(size)
        q = np.tile([1.0, 0.0, 0.0, 0.0], (size, 1))
        perceived = VestibularModel(DT_S).perceive(f, w) if kind == "ceiling" else None
        import piqp  # noqa: F401  (loaded before the baseline is taken)

        c0, t0 = time.process_time(), time.perf_counter()
        with Peak() as peak:
            if kind == "attitude":
                oracle_bound(f, w, DT_S, limits, 9.80665, BoundParams(), start_at_rest=True,
                             channels=("pitch", "roll", "yaw"))  # fmt: skip
            elif kind == "translation":
                translation_plan(f, q, DT_S, limits, 9.80665, 1e-3, position_weight=0.01, tolerance=1e-4)
            else:
                ceiling(perceived.f_mps2, perceived.omega_radps, DT_S, limits, 9.80665, None, "steady",
                        (0.0, 0.0, 0.0), f, w)  # fmt: skip
        out.update(memory=peak.extra, wall=time.perf_counter() - t0, cpu=time.process_time() - c0)
        return out
    from washbench.cueing.algorithm import WashoutContext
    from washbench.io.paths import DATA_DIR

    hexapod = kind == "mpc-hexapod"
    model = load_platform_model(DATA_DIR / "hexapod.yaml" if hexapod else None)
    ctx = WashoutContext(DT_S, 9.80665, planning_limits(model), "steady", (0.0, 0.0, 0.0), platform=model)
    if kind == "mpc-unrestricted":
        from washbench.cueing.mpc_unrestricted import MpcUnrestrictedParams as Params
        from washbench.cueing.mpc_unrestricted import MpcUnrestrictedWashout as Washout
    else:
        from washbench.cueing.mpc import MpcParams as Params
        from washbench.cueing.mpc import MpcWashout as Washout
    import daqp  # noqa: F401

    top = 200 if kind == "mpc-unrestricted" else 500
    section = {"horizon_steps": min(size, top), "prediction_step_s": 0.1}
    if size > top:
        section["preview_s"] = size * 0.1
    params = Params.model_validate(section)
    f, w = signal(40)
    c0, t0 = time.process_time(), time.perf_counter()
    with Peak() as peak:
        washout = Washout(params, ctx)
        out.update(build_wall=time.perf_counter() - t0, build_cpu=time.process_time() - c0)
        step = washout._step if hasattr(washout, "_step") else washout._advance
        washout.start(f[0], w[0])
        c1, t1 = time.process_time(), time.perf_counter()
        step(f[0], w[0])  # the solver's set-up (DAQP factorises the QP at its first solve)
        out.update(first_wall=time.perf_counter() - t1, first_cpu=time.process_time() - c1)
        for k in range(1, 5):
            step(f[k], w[k])
        c1, t1 = time.process_time(), time.perf_counter()
        for k in range(5, 40):
            step(f[k], w[k])
        out.update(step_wall=(time.perf_counter() - t1) / 35, step_cpu=(time.process_time() - c1) / 35)
    out.update(memory=peak.extra, horizon=float(washout.N))
    return out


def model(kind: str, size: int) -> dict[str, float]:
    """What :mod:`washbench.io.cost` says of the same point."""
    from washbench.io import cost

    if kind in ("attitude", "translation", "ceiling"):
        part = {"attitude": cost.BOUND_ATTITUDE, "translation": cost.BOUND_TRANSLATION, "ceiling": cost.CEILING_LP}
        mem, sec = cost._part(part[kind], size)
        return {"memory": mem, "seconds": sec}
    k = "mpc-unrestricted" if kind == "mpc-unrestricted" else "mpc"
    hexapod = kind == "mpc-hexapod"
    est = cost.mpc(k, size, DT_S, hexapod=hexapod)
    return {"memory": est.memory_bytes, "build_s": est.seconds, "step_s": cost.mpc_step_s(k, size, hexapod)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the two smallest sizes of each part")
    parser.add_argument("--only", help="one part: attitude, translation, ceiling, mpc, mpc-hexapod, mpc-unrestricted")
    parser.add_argument("--one", nargs=2, metavar=("KIND", "SIZE"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(one(args.one[0], int(args.one[1]))))
        return
    plan = {"attitude": BOUND_SIZES, "translation": BOUND_SIZES, "ceiling": BOUND_SIZES, "mpc": MPC_SIZES,
            "mpc-hexapod": HEXAPOD_SIZES, "mpc-unrestricted": UNRESTRICTED_SIZES}  # fmt: skip
    for kind, sizes in plan.items():
        if args.only and kind != args.only:
            continue
        for size in sizes[:2] if args.quick else sizes:
            proc = subprocess.run([sys.executable, __file__, "--one", kind, str(size)], capture_output=True, text=True)
            if proc.returncode != 0:
                print(f"{kind} {size}: failed: {proc.stderr.strip().splitlines()[-1:]}")
                continue
            got = json.loads(proc.stdout.strip().splitlines()[-1])
            want = model(kind, size)
            cells = [f"{kind:16s} {size:6d}"]
            if "build_cpu" in got:
                got["setup_cpu"] = got["build_cpu"] + got["first_cpu"]
            for key, model_key in (("memory", "memory"), ("cpu", "seconds"), ("setup_cpu", "build_s"),
                                   ("step_cpu", "step_s")):  # fmt: skip
                if key in got and model_key in want:
                    scale, unit = (1e6, "MB") if key == "memory" else (1e-3, "ms") if key == "step_cpu" else (1, "s")
                    cells.append(f"{key} {got[key] / scale:8.3g} {unit} (model {want[model_key] / scale:8.3g}, "
                                 f"ratio {got[key] / want[model_key]:5.2f})")  # fmt: skip
            for key in ("wall", "build_wall", "first_wall", "step_wall", "build_cpu", "first_cpu"):
                if key in got:
                    cells.append(f"{key} {got[key]:.3g} s")
            print("  ".join(cells), flush=True)


if __name__ == "__main__":
    main()
