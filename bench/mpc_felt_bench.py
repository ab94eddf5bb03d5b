"""mpc-unrestricted with the felt error in its QP: CPU per sample against the same washout with the quadratic cost
alone (``felt_weight: 0``, the QP of before issue 51: 54 variables, no slacks), on real flights.

Input: bundled manoeuvres flown once by JSBSim (default: the C172 steep turn, which turns steadily, and the
Columbia aileron 3211, which rolls back and forth and so re-linearises most); their pilot-head motion drives the
washout step by step. Per step: CPU time of the thread (``thread_time``: without preemption by other processes;
wall time on this shared machine is printed too). Baseline in the same run: bare JSBSim ``fdm.run()``
(bench/baseline.py); the last column is the ratio of the felt QP's median to the quadratic one's.

    python bench/mpc_felt_bench.py [--seconds 30] [--manoeuvre PATH ...]

At 120 Hz a step must take under 8.33 ms to keep up with real time.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from baseline import DT_S, c172p_in_air, run_cpu_s
from mpc_bench import head_motion, time_steps

from washbench.cueing.algorithm import WashoutContext
from washbench.cueing.mpc_unrestricted import MpcUnrestrictedParams, MpcUnrestrictedWashout
from washbench.io.paths import MANOEUVRES_DIR
from washbench.platform.model import load_platform_model, planning_limits

DEFAULT_INPUTS = [MANOEUVRES_DIR / "c172" / "steep_turn.yaml", MANOEUVRES_DIR / "columbia400" / "aileron_3211.yaml"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--manoeuvre", type=Path, nargs="*", default=DEFAULT_INPUTS)
    args = ap.parse_args()
    platform = load_platform_model(None)
    fdm = c172p_in_air(dt_s=DT_S)
    n_base = round(args.seconds / DT_S)
    jsb_us = run_cpu_s(fdm, n_base) / n_base * 1e6
    print(f"bare JSBSim fdm.run(): {jsb_us:.1f} us CPU per step")
    header = ("input                  cost       variables  rows  cpu_med_ms  cpu_p99_ms  wall_med_ms  realtime_x  "
              "iters_med  relin_per_s  fallbacks  x_fdm.run  x_quadratic")  # fmt: skip
    print(header)
    for path in args.manoeuvre:
        f, w, dt = head_motion(path, args.seconds)
        ctx = WashoutContext(dt, 9.80665, planning_limits(platform), "steady", (0.0, 0.0, 0.0), platform=platform)
        base = None
        for label, params in (("quadratic", MpcUnrestrictedParams(felt_weight=0.0)), ("felt", MpcUnrestrictedParams())):
            alg = MpcUnrestrictedWashout(params, ctx)
            wall, cpu = time_steps(alg, f, w)
            rep = alg.report()
            med = float(np.median(cpu))
            base = med if base is None else base
            rows = alg.qp.A.shape[0]
            print(f"{path.stem[:22]:22s} {label:10s} {alg.nz:9d}  {rows:4d}  {med * 1e3:10.3f}  "
                  f"{np.percentile(cpu, 99) * 1e3:10.3f}  {np.median(wall) * 1e3:11.3f}  {dt / np.median(wall):10.1f}  "
                  f"{rep['iterations_median']:9.0f}  {rep['relinearisations'] / (len(f) * dt):11.1f}  "
                  f"{rep['fallbacks']:9.0f}  {med * 1e6 / jsb_us:9.1f}  {med / base:11.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
