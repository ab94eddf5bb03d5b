"""Flight speed: steps per second of a whole flown manoeuvre against bare ``fdm.run()``.

Both are measured in this process on the same aircraft and step, so the printed ratio does
not depend on the machine. The flight includes the set-up (trim, or a flying start's
settling), the pilot, the monitor, the recording and the check evaluation; the baseline is
JSBSim alone, started as the manoeuvre starts. Without arguments: every bundled manoeuvre
(``manoeuvres/<aircraft>/*.yaml``).

    .venv/bin/python bench/flight_bench.py [MANOEUVRE.yaml ...]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from baseline import manoeuvre_start, run_wall_s

from washbench.flight.fly import fly
from washbench.flight.manoeuvre import Manoeuvre, load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR


def flight_steps_per_s(m: Manoeuvre) -> tuple[float, int]:
    t0 = time.perf_counter()
    result = fly(m)
    wall = time.perf_counter() - t0
    return len(result.t_s) / wall, len(result.t_s)


def main(argv: list[str]) -> int:
    paths = [Path(a) for a in argv] or sorted(MANOEUVRES_DIR.glob("*/*.yaml"))
    print(f"{'manoeuvre':34s} {'steps':>7s} {'flight/s':>10s} {'bare/s':>10s} {'slowdown':>9s}")
    worst = 0.0
    for path in paths:
        m = load_manoeuvre(path)
        best_flight, n = max(flight_steps_per_s(m) for _ in range(3))
        best_bare = max(n / run_wall_s(manoeuvre_start(m), n) for _ in range(3))
        ratio = best_bare / best_flight
        worst = max(worst, ratio)
        print(f"{path.parent.name + '/' + path.stem:34s} {n:7d} {best_flight:10.0f} {best_bare:10.0f} {ratio:8.2f}x")
    print(f"worst slowdown of the whole flight against bare JSBSim: {worst:.2f}x (target <= 3x)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
