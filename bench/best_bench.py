"""The bracket's cost: the ceiling and the best achieved (the ``bound`` washout: the replay, every motion known for the
flight flown again and scored, the search) on a real flight, against bare JSBSim timed in the same run; and the
search's cost model (``washbench.io.cost.BOUND_SEARCH``) measured on pieces of it.

Input: a real flight (the bundled Columbia 400 ``aerobatics``, 70 s at 120 Hz, unless ``--manoeuvre`` names
another), flown once by JSBSim; every other built-in washout and the naive references cued on it (not timed: they
run in any suite) and given to the bound as the run gives them. Then, CPU seconds (``process_time``) and the peak
resident memory above what the process held before (``VmHWM`` reset through ``/proc/self/clear_refs``) of:

- the ceiling on the felt error (``washbench.analysis.ceiling.ceiling`` with the measure);
- the best achieved (``BoundWashout``: ``consider`` then ``trace``, its default settings);
- bare JSBSim ``fdm.run()`` for as many steps (bench/baseline.py), the ratio's baseline.

With ``--calibrate``, one programme of the search on the first 2,000, 4,000 and 8,000 samples (started from a still
platform): its CPU seconds per sample and its peak memory, the figures ``BOUND_SEARCH`` holds (a + b bytes per
sample, b the slope measured; c seconds per sample and programme).

    python bench/best_bench.py [--manoeuvre PATH] [--calibrate]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from baseline import c172p_in_air, run_cpu_s

from washbench.analysis import best_motion
from washbench.analysis.bound import BoundParams
from washbench.analysis.bound_replay import BoundWashout
from washbench.analysis.ceiling import ceiling
from washbench.analysis.felt import DEFAULT_MEASURE
from washbench.cueing.algorithm import Alongside, WashoutContext
from washbench.cueing.bank import cue_trace, flyer
from washbench.cueing.variants import EVERY_BUILTIN, Washout, as_washouts, load_washout_params
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io import cost
from washbench.io.paths import MANOEUVRES_DIR
from washbench.perception.vestibular import VestibularModel
from washbench.platform.limits import load_platform_limits

G = 9.80665


def _status_kb(key: str) -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1])
    return 0


def measured(fn):
    """(result, CPU seconds, peak resident memory above the start, MB) of ``fn()``."""
    Path("/proc/self/clear_refs").write_text("5")  # resets VmHWM to the current resident size
    before = _status_kb("VmRSS")
    t0 = time.process_time()
    out = fn()
    cpu = time.process_time() - t0
    return out, cpu, (_status_kb("VmHWM") - before) / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--manoeuvre", type=Path, default=MANOEUVRES_DIR / "columbia400" / "aerobatics.yaml")
    ap.add_argument("--calibrate", action="store_true")
    args = ap.parse_args()
    res = fly(load_manoeuvre(args.manoeuvre))
    c = res.columns
    f = np.column_stack([c[f"f_{a}_mps2"] for a in "xyz"])
    w = np.radians(np.column_stack([c[f"omega_{a}_degps"] for a in "xyz"]))
    dt = res.dt_s
    n = len(f)
    limits = load_platform_limits()
    params = load_washout_params()
    others = as_washouts([k for k in EVERY_BUILTIN if k != "bound"], params)
    motions = cue_trace(f, w, dt, others, None, limits)
    fly_bound = flyer(Washout("bound", "bound", params), limits, dt)
    p = VestibularModel(dt).perceive(f, w)

    ce, t_ceiling, m_ceiling = measured(lambda: ceiling(p.f_mps2, p.omega_radps, dt, limits, G, f_mps2=f,
                                                        omega_radps=w, measure=DEFAULT_MEASURE))
    ctx = WashoutContext(dt_s=dt, gravity_mps2=G, limits=limits, filter_start="steady", head_offset_m=(0.0, 0.0, 0.0),
                         platform=limits)  # fmt: skip
    bound = BoundWashout(BoundParams(), ctx)
    bound.consider(Alongside(motions, fly_bound, best_motion.Scoring()))
    _, t_best, m_best = measured(lambda: bound.trace(f, w))
    jsb = run_cpu_s(c172p_in_air(dt_s=dt), n)
    rep = bound.report()
    total = t_ceiling + t_best
    print(f"{args.manoeuvre.name}: {n} samples at {1 / dt:.0f} Hz ({n * dt:.1f} s); the bound given "
          f"{len(motions)} other motions")
    print(f"  bare JSBSim fdm.run() (baseline): {jsb:6.2f} s CPU")
    print(f"  ceiling (felt error):             {t_ceiling:6.2f} s CPU ({t_ceiling / jsb:5.1f}x JSBSim), peak "
          f"+{m_ceiling:5.0f} MB; {ce.felt_score(_felt(p, dt)):.4f}")
    print(f"  best achieved (bound):            {t_best:6.2f} s CPU ({t_best / jsb:5.1f}x JSBSim), peak "
          f"+{m_best:5.0f} MB; {rep['value']:.4f} from {rep['start_value']:.4f} ({rep['steps']} programmes, "
          f"{rep['accepted']} taken, {rep['iterations']} PIQP iterations)")
    print(f"  together:                         {total:6.2f} s CPU ({total / jsb:5.1f}x JSBSim), peak "
          f"+{max(m_ceiling, m_best):5.0f} MB (aim: 60 s, 2,000 MB)")
    est = cost.bound(n, dt, with_ceiling=True, search_steps=BoundParams().search_steps)
    print(f"  the estimate before it starts (washbench.io.cost.bound, the ceiling included): {est.seconds:.1f} s "
          f"CPU, {est.memory_bytes / 1e6:.0f} MB at the peak ({est.peak})")
    if args.calibrate:
        calibrate(f, w, dt, limits, fly_bound)


def _felt(p, dt):
    from washbench.analysis.ranking import perceived_motion

    return perceived_motion(p.f_mps2, p.omega_radps, dt)


def calibrate(f: np.ndarray, w: np.ndarray, dt: float, limits, fly_bound) -> None:
    """One programme of the search on pieces of the flight: CPU per sample, peak memory (module docstring)."""
    from washbench.cueing.references import StillWashout, tilt_of

    print("  one programme of the search (from a still platform):")
    points = []
    for m in (2000, 4000, 8000):
        if m > len(f):
            break
        fm, wm = f[:m], w[:m]
        yard = best_motion.Yardstick(fm, wm, dt)
        q0 = tilt_of(fm[0])
        still = best_motion.Candidate("still", np.zeros(3), q0, np.zeros((m, 3)), np.tile(q0, (m, 1)))
        _ = StillWashout  # the reference the candidate stands for
        result, cpu, mem = measured(lambda fm=fm, yard=yard, still=still: best_motion.search(
            yard, [still], fly_bound, limits, G, best_motion.Settings(steps=1)))
        points.append((m, cpu, mem))
        print(f"    {m:5d} samples: {cpu:6.2f} s CPU ({1e3 * cpu / m:.2f} ms per sample), peak +{mem:6.0f} MB "
              f"({1e3 * mem * 1.048576 / m:.1f} kB per sample); {result.iterations} PIQP iterations")
    if len(points) >= 2:
        (m0, _, b0), (m1, _, b1) = points[0], points[-1]
        slope = (b1 - b0) * 1.048576e6 / (m1 - m0)
        print(f"    memory: about {b0 * 1.048576e6 - slope * m0:.3g} + {slope:.3g} bytes per sample")


if __name__ == "__main__":
    main()
