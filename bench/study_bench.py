"""Marginal cost of one study evaluation against JSBSim's bare fdm.run() for the same steps, in the same run.

    .venv/bin/python bench/study_bench.py [--steps 12000] [--few 4] [--many 36] [--trace-minutes 30]

An evaluation is one washout candidate on one recorded flight: washout, Atlas platform, head motion, vestibular
models, metrics and score (``FlightEvaluator.evaluate``, one compiled call for the whole batch, parallel over the
candidates on every core). The marginal cost is (time for ``--many`` candidates - time for ``--few``) / (many -
few), so fixed costs (building arrays, the aircraft pilot's perception) cancel; it is printed per step and as a
ratio to bare ``fdm.run()`` (c172p at 120 Hz, :func:`cueing_bench.time_jsbsim`). Goal: at most 0.1.

Also the whole-trace cueing path of ``washbench cue`` (``cue_trace`` + ``analyse``: three washouts, perception,
metrics, tables) on a ``--trace-minutes`` 120 Hz input, against bare JSBSim for the same number of steps.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from baseline import best_of
from cueing_bench import DT_S, synthetic_motion, time_jsbsim

from washbench.analysis.evaluate import FlightEvaluator
from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.cueing.variants import Washout, apply_overrides
from washbench.io.motion import Motion
from washbench.platform import load_platform_limits
from washbench.runs.chain import analyse


def candidates(m: int) -> list[Washout]:
    """m distinct candidates cycling through the three kinds, tilt gains spread over 0.2..5 1/s."""
    base = load_washout_params()
    kinds = WASHOUT_NAMES
    return [
        Washout(f"c{i}", kinds[i % 3], apply_overrides(base, {"tilt.gain_per_s": 0.2 + 4.8 * i / max(1, m - 1)}, "b"))
        for i in range(m)
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=12000, help="samples in the evaluated flight (default 12000)")
    parser.add_argument("--few", type=int, default=4, help="candidates in the small batch (default 4)")
    parser.add_argument("--many", type=int, default=36, help="candidates in the large batch (default 36)")
    parser.add_argument("--trace-minutes", type=float, default=30.0, help="whole-trace cue input length")
    args = parser.parse_args()
    limits = load_platform_limits()
    f, w = synthetic_motion(args.steps, DT_S)
    ev = FlightEvaluator(f, w, DT_S, limits)
    few = ev.arrays(candidates(args.few))
    many = ev.arrays(candidates(args.many))
    ev.evaluate_arrays(*few)  # compile or load from the cache
    t_few = best_of(lambda: ev.evaluate_arrays(*few))
    t_many = best_of(lambda: ev.evaluate_arrays(*many))
    per_eval_step = (t_many - t_few) / (args.many - args.few) / args.steps
    jsb = time_jsbsim(20000)
    print(f"cores: {os.cpu_count()}; numba threads: {__import__('numba').get_num_threads()}")
    print(f"bare JSBSim fdm.run():           {jsb * 1e6:8.3f} us/step")
    print(
        f"one evaluation (marginal):       {per_eval_step * 1e6:8.3f} us/step  = {per_eval_step / jsb:.3f} x bare "
        f"JSBSim (goal <= 0.1); {args.few} candidates {t_few:.3f} s, {args.many} candidates {t_many:.3f} s "
        f"on {args.steps} steps"
    )
    print(f"evaluations per second on a 100 s flight at 120 Hz: {1.0 / (per_eval_step * 12000):.0f}")

    n = int(args.trace_minutes * 60 / DT_S)
    f, w = synthetic_motion(n, DT_S)
    params = load_washout_params()
    motion = Motion(t_s=np.arange(n) * DT_S, dt_s=DT_S, f_mps2=f, omega_radps=w)
    cue_trace(f[:100], w[:100], DT_S, WASHOUT_NAMES, params, limits)

    def whole() -> None:
        analyse(motion, cue_trace(f, w, DT_S, WASHOUT_NAMES, params, limits))

    t_cue = best_of(lambda: cue_trace(f, w, DT_S, WASHOUT_NAMES, params, limits), 2)
    t_all = best_of(whole, 2)
    print(
        f"whole-trace cue path, {n} samples x 3 washouts: cue_trace {t_cue:.3f} s, + perception, metrics, tables "
        f"{t_all:.3f} s = {t_all / (n * jsb):.2f} x bare JSBSim for {n} steps ({t_all / n * 1e6:.2f} us/sample)"
    )


if __name__ == "__main__":
    main()
