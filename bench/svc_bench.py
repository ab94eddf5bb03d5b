"""Cost of the motion-sickness incidence model (6-DOF SVC, :mod:`washbench.perception.svc`) per pilot.

    .venv/bin/python bench/svc_bench.py [--minutes 60]

One pilot's head motion at 120 Hz for ``--minutes``; printed as ratios against, measured in the same run:

* bare JSBSim ``fdm.run()`` for as many steps (c172p in the air, CPU time);
* one pilot's vestibular models (:meth:`washbench.perception.VestibularModel.perceive`) on the same motion,
  the per-pilot perception ``washbench cue`` already pays.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from baseline import DT_S, c172p_in_air, run_cpu_s

from washbench.perception import VestibularModel
from washbench.perception.svc import svc_msi


def cpu_s(fn: Callable[[], object]) -> float:
    """Shortest CPU time of three calls."""
    best = float("inf")
    for _ in range(3):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=60.0)
    n = int(ap.parse_args().minutes * 60 / DT_S)
    t = np.arange(n) * DT_S
    f = np.column_stack([1.5 * np.sin(0.3 * t), 0.8 * np.sin(0.17 * t + 1.0), -9.80665 * (1 + 0.3 * np.sin(0.11 * t))])
    w = np.radians(np.column_stack([15.0 * np.sin(0.5 * t), 5.0 * np.sin(0.23 * t + 0.4), 3.0 * np.sin(0.07 * t)]))
    svc_msi(f[:10], w[:10], DT_S)  # compile (or load the cache) outside the timing
    model = VestibularModel(DT_S)
    model.perceive(f[:10], w[:10])
    svc = cpu_s(lambda: svc_msi(f, w, DT_S))
    vest = cpu_s(lambda: model.perceive(f, w))
    jsb = run_cpu_s(c172p_in_air(), n)
    print(f"{n} samples ({n * DT_S / 60:g} min at 120 Hz), one pilot, CPU time:")
    print(f"  SVC MSI model     {svc:8.3f} s   {svc / jsb:6.3f} x bare JSBSim   {svc / vest:6.2f} x vestibular models")
    print(f"  vestibular models {vest:8.3f} s   {vest / jsb:6.3f} x bare JSBSim")
    print(f"  bare JSBSim       {jsb:8.3f} s")


if __name__ == "__main__":
    main()
