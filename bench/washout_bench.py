"""Per-step cost of each washout family (washout + Atlas model + head motion) against bare JSBSim ``fdm.run()``.

    .venv/bin/python bench/washout_bench.py [--steps 60000]

Each washout runs alone in a bank over the same synthetic 120 Hz input in blocks of 1,024 samples
(``CueingBank.steps``, as the lockstep feeds them); CPU time per sample, best of 3, divided by bare JSBSim's CPU time
per step on c172p measured in the same run. Prints the adaptive washouts' cost against their classical washout (the
aim: at most 2x) and the worked plugin example's (docs/examples/first_order_washout.py, Python per step).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from baseline import DT_S, best_of, c172p_in_air, run_cpu_s
from cueing_bench import synthetic_motion

from washbench.cueing import CueingBank, registry
from washbench.cueing.params import ADAPTIVE_KINDS, CLASSICAL_KINDS
from washbench.cueing.variants import builtin, load_param_file
from washbench.platform import load_platform_limits

EXAMPLE = Path(__file__).resolve().parent.parent / "docs" / "examples" / "first_order_washout.py"


def per_sample_cpu_s(kind: str, f, w, block: int = 1024) -> float:
    base, _ = load_param_file(None)
    limits = load_platform_limits()

    def once() -> None:
        bank = CueingBank(builtin([kind], base), None, limits, DT_S)
        for i in range(0, len(f), block):
            bank.steps(f[i : i + block], w[i : i + block])

    once()  # compile / load
    return best_of(lambda: _cpu(once)) / len(f)


def _cpu(fn) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=60000)
    args = ap.parse_args()
    f, w = synthetic_motion(args.steps, DT_S)
    fdm = c172p_in_air()
    jsb = best_of(lambda: run_cpu_s(fdm, args.steps)) / args.steps
    registry.load_plugin(f"{EXAMPLE}:FirstOrder")
    print(f"bare JSBSim fdm.run(): {jsb * 1e6:.2f} us/step (CPU, best of 3)")
    cost = {}
    for kind in (*CLASSICAL_KINDS, *ADAPTIVE_KINDS, "first-order"):
        cost[kind] = per_sample_cpu_s(kind, f, w)
        print(f"{kind:24s} {cost[kind] * 1e6:7.2f} us/sample = {cost[kind] / jsb:6.3f}x bare JSBSim")
    for classical, adaptive in zip(CLASSICAL_KINDS, ADAPTIVE_KINDS, strict=True):
        print(f"{adaptive} / {classical}: {cost[adaptive] / cost[classical]:.2f}x (aim <= 2)")
    print(f"plugin first-order (Python per step) / large-angle: {cost['first-order'] / cost['large-angle']:.1f}x")


if __name__ == "__main__":
    main()
