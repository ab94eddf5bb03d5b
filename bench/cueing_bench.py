"""Per-step cost of the three washouts (+ Atlas model + head motion) against JSBSim's bare fdm.run().

Both are measured in this process, on the same number of steps, and the ratio is printed:

    .venv/bin/python bench/cueing_bench.py [--steps 20000] [--trace-minutes 30]

Streaming: ``CueingBank.step`` called from Python once per sample with all three washouts. JSBSim: c172p,
dt 1/120 s, initialised in the air at 4000 ft and 100 kt (not trimmed), ``fdm.run()`` per step. Whole
trace: ``cue_trace`` over a synthetic 120 Hz recording of ``--trace-minutes`` minutes.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from baseline import DT_S, c172p_in_air, run_wall_s

from washbench.cueing import WASHOUT_NAMES, CueingBank, cue_trace, load_washout_params
from washbench.platform import load_platform_limits


def synthetic_motion(n: int, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """A deterministic manoeuvre-like input: gusty specific force about 1 g, slowly varying body rates."""
    t = np.arange(n) * dt_s
    f = np.empty((n, 3))
    f[:, 0] = 1.5 * np.sin(0.3 * t) + 0.3 * np.sin(7.1 * t)
    f[:, 1] = 0.8 * np.sin(0.17 * t + 1.0)
    f[:, 2] = -9.80665 * (1.0 + 0.3 * np.sin(0.11 * t)) + 0.5 * np.sin(5.3 * t)
    w = np.empty((n, 3))
    w[:, 0] = 0.3 * np.sin(0.5 * t)
    w[:, 1] = 0.1 * np.sin(0.23 * t + 0.4)
    w[:, 2] = 0.05 * np.sin(0.07 * t)
    return f, w


def time_cueing(n: int) -> float:
    """Seconds per step of CueingBank.step with all three washouts (after a warm-up)."""
    bank = CueingBank(WASHOUT_NAMES, load_washout_params(), load_platform_limits(), DT_S)
    f, w = synthetic_motion(n, DT_S)
    rows = [f[k] for k in range(n)]
    rates = [w[k] for k in range(n)]
    bank.step(rows[0], rates[0])
    step = bank.step
    t0 = time.perf_counter()
    for k in range(n):
        step(rows[k], rates[k])
    return (time.perf_counter() - t0) / n


def time_jsbsim(n: int) -> float:
    """Seconds per step of bare fdm.run() on c172p in the air (after one second of warm-up)."""
    fdm = c172p_in_air()
    run_wall_s(fdm, 120)
    return run_wall_s(fdm, n) / n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20000, help="steps timed for each (default 20000)")
    parser.add_argument("--trace-minutes", type=float, default=30.0, help="whole-trace length at 120 Hz")
    args = parser.parse_args()

    cue = time_cueing(args.steps)
    fdm = time_jsbsim(args.steps)
    print(f"steps: {args.steps}")
    print(f"CueingBank.step, 3 washouts + Atlas + head: {cue * 1e6:8.2f} us/step")
    print(f"JSBSim c172p fdm.run():                    {fdm * 1e6:8.2f} us/step")
    print(f"ratio cueing / fdm.run:                    {cue / fdm:8.3f}  (goal <= 1.0)")

    n = round(args.trace_minutes * 60.0 / DT_S)
    f, w = synthetic_motion(n, DT_S)
    params, limits = load_washout_params(), load_platform_limits()
    cue_trace(f[:10], w[:10], DT_S, WASHOUT_NAMES, params, limits)  # warm-up (compile or cache load)
    t0 = time.perf_counter()
    cue_trace(f, w, DT_S, WASHOUT_NAMES, params, limits)
    whole = time.perf_counter() - t0
    print(
        f"cue_trace, {args.trace_minutes:g} min at 120 Hz ({n} samples, 3 washouts): {whole:.3f} s "
        f"({whole / n * 1e6:.2f} us/sample, {args.trace_minutes * 60.0 / whole:.0f}x real time)"
    )


if __name__ == "__main__":
    main()
