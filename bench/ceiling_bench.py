"""The yardstick's cost: the ceiling's programmes and the bound's replay, against the previous oracle bound and bare
JSBSim, timed in the same run.

Input: a real flight (the bundled Columbia 400 ``aerobatics``, 70 s, unless ``--manoeuvre`` names another), flown
once by JSBSim. Then, CPU seconds (``process_time``) of:

- the previous oracle bound, as the issue measured "today's" cost: the linearised QP of all four channels at the
  old tolerance 1e-8 (``oracle_bound``), the baseline;
- the ceiling (``washbench.analysis.ceiling.ceiling``: a DOF's LP, or none where the relaxation follows exactly);
- the replay (``BoundWashout.trace``: the attitude QP of three channels, the attitude tracking, the translation
  programme);
- bare JSBSim ``fdm.run()`` for as many steps (bench/baseline.py).

    python bench/ceiling_bench.py [--manoeuvre PATH]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from baseline import c172p_in_air, run_cpu_s

from washbench.analysis.bound import BoundParams, oracle_bound
from washbench.analysis.bound_replay import BoundWashout
from washbench.analysis.ceiling import ceiling
from washbench.cueing.algorithm import WashoutContext
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR
from washbench.perception.vestibular import VestibularModel
from washbench.platform.limits import load_platform_limits

G = 9.80665


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--manoeuvre", type=Path, default=MANOEUVRES_DIR / "columbia400" / "aerobatics.yaml")
    args = ap.parse_args()
    res = fly(load_manoeuvre(args.manoeuvre))
    c = res.columns
    f = np.column_stack([c[f"f_{a}_mps2"] for a in "xyz"])
    w = np.radians(np.column_stack([c[f"omega_{a}_degps"] for a in "xyz"]))
    dt = res.dt_s
    n = len(f)
    limits = load_platform_limits()
    p = VestibularModel(dt).perceive(f, w)

    t0 = time.process_time()
    oracle_bound(f, w, dt, limits, G, BoundParams(eps=1e-8))
    old = time.process_time() - t0
    t0 = time.process_time()
    ce = ceiling(p.f_mps2, p.omega_radps, dt, limits, G, f_mps2=f, omega_radps=w)
    t_ceiling = time.process_time() - t0
    ctx = WashoutContext(dt_s=dt, gravity_mps2=G, limits=limits, filter_start="steady", head_offset_m=(0.0, 0.0, 0.0))
    t0 = time.process_time()
    BoundWashout(BoundParams(), ctx).trace(f, w)
    t_replay = time.process_time() - t0
    jsb = run_cpu_s(c172p_in_air(dt_s=dt), n)
    print(f"{args.manoeuvre.name}: {n} samples at {1 / dt:.0f} Hz ({n * dt:.1f} s)")
    print(f"  bare JSBSim fdm.run():            {jsb:6.2f} s CPU")
    print(f"  previous oracle bound (baseline): {old:6.2f} s CPU ({old / jsb:.1f}x JSBSim)")
    status = ", ".join(f"{d} {s}" for d, s in ce.status.items())
    print(f"  ceiling:                          {t_ceiling:6.2f} s CPU ({t_ceiling / old:.2f}x baseline; {status})")
    print(f"  replay:                           {t_replay:6.2f} s CPU ({t_replay / old:.2f}x baseline)")
    total = t_ceiling + t_replay
    print(f"  ceiling + replay:                 {total:6.2f} s CPU ({total / old:.2f}x baseline)")


if __name__ == "__main__":
    main()
