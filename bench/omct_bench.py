"""Cost of ``washbench omct`` (three washouts, ten tests, twelve frequencies at 120 Hz), without the plots.

    .venv/bin/python bench/omct_bench.py

Baselines measured in the same run, printed as ratios:

* the measurement (``washbench.runs.omct.measure``) per washout-step against bare JSBSim ``fdm.run()`` per step
  on the c172p (what one FDM step of a flight costs);
* the compiled kernel alone: ``cue_trace`` on the same number of samples in ONE call, so the difference is what
  the 120 separate runs cost in set-up (filter discretisation, trace copies, signal generation, Fourier fits).
"""

from __future__ import annotations

import time

import numpy as np
from baseline import DT_S, c172p_in_air, run_wall_s

from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.cueing.variants import Washout
from washbench.platform import load_platform_limits
from washbench.runs.omct import measure


def fdm_step_s(n: int = 20000) -> float:
    """Seconds per bare ``fdm.run()`` of the c172p in cruise (best of three blocks)."""
    fdm = c172p_in_air(altitude_ft=3000.0)
    return min(run_wall_s(fdm, n // 3) for _ in range(3)) / (n // 3)


def main() -> None:
    params, limits = load_washout_params(), load_platform_limits()
    entries = [Washout(n, n, params) for n in WASHOUT_NAMES]
    measure(entries, limits, tests=[], frequencies_radps=[1.0])  # imports, numba cache
    t0 = time.perf_counter()
    points, settings = measure(entries, limits)
    t_omct = time.perf_counter() - t0
    # samples: per test and frequency, settle + whole periods, the same input for the three washouts
    from washbench.analysis.omct import FREQUENCIES_RADPS, TESTS, timing

    n_samples = sum(
        round(timing(w, settings.slowest_decay_radps).duration_s / DT_S) + 1 for _ in TESTS for w in FREQUENCIES_RADPS
    )
    f = np.zeros((n_samples, 3))
    f[:, 2] = -9.80665
    f[:, 0] = 0.5 * np.sin(np.arange(n_samples) * DT_S)
    t0 = time.perf_counter()
    cue_trace(f, np.zeros_like(f), DT_S, WASHOUT_NAMES, params, limits)
    t_kernel = time.perf_counter() - t0
    fdm = fdm_step_s()
    steps = n_samples * len(WASHOUT_NAMES)
    print(f"OMCT: {len(points)} points, {n_samples} samples x {len(WASHOUT_NAMES)} washouts = {steps} washout-steps")
    print(f"  measure: {t_omct:.2f} s, {t_omct / steps * 1e6:.2f} us per washout-step")
    print(f"  one cue_trace call on all samples: {t_kernel:.2f} s, {t_kernel / steps * 1e6:.2f} us per washout-step")
    print(f"  bare fdm.run(): {fdm * 1e6:.2f} us per step")
    print(f"  ratios: measure / fdm.run = {t_omct / steps / fdm:.2f} per washout-step; "
          f"measure / one cue_trace call = {t_omct / t_kernel:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
