"""MPC washouts (mpc, mpc-unrestricted): time per step (median, 99th percentile), real-time factor at 120 Hz.

Input: a real flight (the bundled C172 ``steep_turn`` unless ``--manoeuvre`` names another), flown once by JSBSim;
its pilot-head motion then drives each MPC washout (``washbench.cueing.mpc``, ``washbench.cueing.mpc_unrestricted``)
step by step, for the default horizon and for the horizons in ``--horizons``. Per step: wall time (``perf_counter``,
what a real-time loop sees on this shared machine, with preemption by other processes) and CPU time of the thread
(``thread_time``, without it). Baseline in the same run: bare JSBSim ``fdm.run()`` (bench/baseline.py). The optimal
washout's step is timed too.

    python bench/mpc_bench.py [--seconds 30] [--horizons 10 20 40] [--manoeuvre PATH] [--platform FILE]

``--platform FILE``: the washouts are made for that platform file (as ``washbench run --platform``: the limits they
plan against and the loaded file in their context); mpc-unrestricted is skipped on a platform it cannot drive.

The real-time factor is (sample interval) / (time per step): above 1 the washout keeps up; at 120 Hz a step must
take under 8.33 ms (issue 35's aim: at most 1 ms at the 99th percentile of CPU).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from baseline import DT_S, c172p_in_air, run_cpu_s

from washbench.cueing.algorithm import WashoutContext
from washbench.cueing.mpc import MpcParams, MpcWashout
from washbench.cueing.mpc_unrestricted import MpcUnrestrictedParams, MpcUnrestrictedWashout
from washbench.cueing.optimal import OptimalWashout
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR
from washbench.platform.model import load_platform_model, planning_limits, platform_kind


def head_motion(path: Path, seconds: float) -> tuple[np.ndarray, np.ndarray, float]:
    res = fly(load_manoeuvre(path))
    c = res.columns
    n = min(len(c["t_s"]), round(seconds / res.dt_s))
    f = np.column_stack([c[f"f_{a}_mps2"][:n] for a in "xyz"])
    w = np.radians(np.column_stack([c[f"omega_{a}_degps"][:n] for a in "xyz"]))
    return f, w, res.dt_s


def time_steps(alg, f: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    alg.start(f[0], w[0])
    wall = np.empty(len(f))
    cpu = np.empty(len(f))
    step = alg.step
    for k in range(len(f)):
        t0 = time.perf_counter()
        c0 = time.thread_time()
        step(f[k], w[k])
        cpu[k] = time.thread_time() - c0
        wall[k] = time.perf_counter() - t0
    return wall, cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--horizons", type=int, nargs="*", default=[10, 20, 40])
    ap.add_argument("--manoeuvre", type=Path, default=MANOEUVRES_DIR / "c172" / "steep_turn.yaml")
    ap.add_argument("--platform", type=Path, default=None, help="platform file (default: the bundled Atlas)")
    args = ap.parse_args()
    f, w, dt = head_motion(args.manoeuvre, args.seconds)
    platform = load_platform_model(args.platform)
    ctx = WashoutContext(dt, 9.80665, planning_limits(platform), "steady", (0.0, 0.0, 0.0), platform=platform)
    fdm = c172p_in_air(dt_s=dt)
    jsb_us = run_cpu_s(fdm, len(f)) / len(f) * 1e6
    print(f"input: {args.manoeuvre.name}, {len(f)} samples at {1 / dt:.0f} Hz; platform: {platform.name} "
          f"({platform_kind(platform)})")  # fmt: skip
    print(f"bare JSBSim fdm.run(): {jsb_us:.1f} us CPU per step")
    wall, cpu = time_steps(OptimalWashout(None, ctx), f, w)
    print(f"optimal: median {np.median(wall) * 1e6:.1f} us wall, {np.median(cpu) * 1e6:.1f} us CPU "
          f"({np.median(cpu) * 1e6 / jsb_us:.2f} x fdm.run())")  # fmt: skip
    header = ("  N  horizon_s  variables  wall_med_ms  wall_p99_ms  cpu_med_ms  cpu_p99_ms  realtime_x  iters_med  "
              "fallbacks  x_fdm.run")  # fmt: skip
    for name, cls, params in (("mpc", MpcWashout, MpcParams), ("mpc-unrestricted", MpcUnrestrictedWashout,
                                                               MpcUnrestrictedParams)):  # fmt: skip
        if name == "mpc-unrestricted" and platform_kind(platform) != "atlas":
            print(f"{name}: skipped (it cannot drive a {platform_kind(platform)})")
            continue
        default_n = params().horizon_steps
        tp = params().prediction_step_s
        print(f"{name} (prediction step {tp} s; default horizon {default_n} steps = {default_n * tp:.1f} s):")
        print(header)
        for n in sorted(set([default_n, *args.horizons])):
            alg = cls(params(horizon_steps=n), ctx)
            wall, cpu = time_steps(alg, f, w)
            rep = alg.report()
            mark = " (default)" if n == default_n else ""
            nz = alg.nz if hasattr(alg, "nz") else alg.qp.n
            ms = [np.median(wall) * 1e3, np.percentile(wall, 99) * 1e3, np.median(cpu) * 1e3,
                  np.percentile(cpu, 99) * 1e3]  # fmt: skip
            cols = f"{n:3d}  {n * tp:9.1f}  {nz:9d}  {ms[0]:11.3f}  {ms[1]:11.3f}  {ms[2]:10.3f}  {ms[3]:10.3f}"
            cols += f"  {DT_S / np.median(wall):10.1f}  {rep['iterations_median']:9.0f}  {rep['fallbacks']:9.0f}"
            print(f"{cols}  {np.median(cpu) * 1e6 / jsb_us:9.1f}{mark}")


if __name__ == "__main__":
    main()
