"""Per-sample cost of each platform kind behind the same washouts, against the Atlas's timed in the same run.

    .venv/bin/python bench/platform_bench.py [--minutes 10]

Whole trace (``cue_trace``) of a synthetic 120 Hz recording (bench/cueing_bench.py's) with small-angle, large-angle
and adaptive, on the bundled Atlas, hexapod (SIMONA) and 2-DOF rig; the hexapod also on a gentle copy of the input
(a tenth of the motion: mostly inside its workspace, no forward kinematics) to show the cost of the IK alone.
Prints us/sample and the ratio to the Atlas's.
"""

from __future__ import annotations

import argparse
import time

from baseline import DT_S
from cueing_bench import synthetic_motion

from washbench.cueing import cue_trace, load_washout_params
from washbench.io.paths import DATA_DIR
from washbench.platform.model import load_platform_model

WASHOUTS = ("small-angle", "large-angle", "adaptive")


def timed(f, w, platform) -> float:
    params = load_washout_params()
    cue_trace(f[:10], w[:10], DT_S, WASHOUTS, params, platform)  # compile or load from the cache
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        cue_trace(f, w, DT_S, WASHOUTS, params, platform)
        best = min(best, time.perf_counter() - t0)
    return best / len(f) * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0, help="length of the synthetic recording")
    args = parser.parse_args()
    f, w = synthetic_motion(round(args.minutes * 60.0 / DT_S), DT_S)
    gentle_f = f.copy()
    gentle_f[:, :2] *= 0.1
    gentle_f[:, 2] = -9.80665 + 0.1 * (f[:, 2] + 9.80665)
    cases = [
        ("atlas", f, w, load_platform_model(None)),
        ("hexapod", f, w, load_platform_model(DATA_DIR / "hexapod.yaml")),
        ("hexapod, gentle input", gentle_f, 0.1 * w, load_platform_model(DATA_DIR / "hexapod.yaml")),
        ("rig (2-DOF)", f, w, load_platform_model(DATA_DIR / "rig2dof.yaml")),
    ]
    base = None
    for name, ff, ww, platform in cases:
        us = timed(ff, ww, platform)
        base = base or us
        print(f"{name:24s} {us:7.2f} us/sample ({len(WASHOUTS)} washouts)   ratio to the Atlas {us / base:5.2f}")


if __name__ == "__main__":
    main()
