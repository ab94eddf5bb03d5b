"""Marginal per-step cost of a flight (pilot, monitor, recorder) and of flight + three washouts, against bare JSBSim.

A long and a short flight of the same manoeuvre (c172p, trimmed level flight in light turbulence, then a
30 deg banked turn) are timed; their difference over the difference in steps is the cost of one more
step, with every fixed cost (model load, trim, imports, check evaluation) cancelled. The baseline is bare
``fdm.run()`` from the same start, long minus short the same way, measured in this process. Times are
this process's CPU time (``time.process_time``: on a shared machine it does not count the time other
processes hold the core), minimum of ``--repeat`` runs each.

    .venv/bin/python bench/marginal_bench.py [--seconds 120] [--repeat 5]

Three figures: flight alone (``washbench fly``'s loop), flight + the three washouts in lockstep (the
``washbench run`` loop: :func:`washbench.runs.chain.lockstep_blocks`), and the washouts alone called once per
sample (``CueingBank.step``, the streaming form a simulator would call).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
from baseline import manoeuvre_start, run_cpu_s

from washbench.cueing import WASHOUT_NAMES, CueingBank, load_washout_params
from washbench.cueing.variants import select_washouts
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.platform import load_platform_limits
from washbench.runs.chain import LOCKSTEP_BLOCK, lockstep_blocks, sample_count

TEMPLATE = """\
name: marginal
description: level flight then a turn, in light turbulence (benchmark)
aircraft: c172p
start:
  air: {{altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}}
environment:
  turbulence: {{severity: light, seed: 1}}
phases:
  - name: level
    hold: {{wings_level: true, altitude_ft: 4000, airspeed_kts: 95}}
    until: {{duration_s: {level}}}
  - name: turn
    hold: {{bank_deg: 30, altitude_ft: 4000, airspeed_kts: 95}}
    until: {{duration_s: {turn}, timeout_s: 3600}}
checks:
  - {{name: altitude held, signal: altitude_ft, stat: max_deviation, max: 200}}
"""


def manoeuvre_file(folder: Path, seconds: float) -> Path:
    path = folder / f"m{seconds:g}.yaml"
    path.write_text(TEMPLATE.format(level=seconds / 2, turn=seconds / 2))
    return path


def time_fly(path: Path, washouts: bool) -> tuple[float, int]:
    """Wall time of ``fly`` (with the lockstep washouts when asked) and the steps it recorded."""
    m = load_manoeuvre(path)
    hook = None
    if washouts:
        rows, hook = lockstep_blocks(select_washouts(), load_platform_limits(), m.dt_s)
    t0 = time.process_time()
    result = fly(m, block_hook=hook, block_size=LOCKSTEP_BLOCK)
    if washouts and sample_count(rows) != len(result.t_s):
        raise SystemExit(f"the washouts ran {sample_count(rows)} steps for {len(result.t_s)} samples")
    wall = time.process_time() - t0
    if not result.ok:
        raise SystemExit(f"benchmark flight failed: {result.reason}")
    return wall, len(result.t_s)


def time_bank(steps: int) -> float:
    bank = CueingBank(WASHOUT_NAMES, load_washout_params(), load_platform_limits(), 1.0 / 120.0)
    f, w = np.array([0.5, 0.1, -9.8]), np.array([0.01, 0.02, 0.0])
    rows: list[np.ndarray] = []
    step = bank.step
    t0 = time.process_time()
    for _ in range(steps):
        rows.append(step(f, w).copy())
    return time.process_time() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=120.0, help="flight time of the long flight (default 120)")
    parser.add_argument("--repeat", type=int, default=5, help="runs of each; the minimum counts")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        short, long = manoeuvre_file(Path(tmp), 4.0), manoeuvre_file(Path(tmp), args.seconds)
        time_fly(short, True)  # warm-up: imports, numba cache
        n_short, n_long = time_fly(short, False)[1], time_fly(long, False)[1]
        dn = n_long - n_short
        best: dict[str, float] = {}

        def keep(key: str, seconds: float) -> None:
            best[key] = min(best.get(key, float("inf")), seconds)

        for _ in range(args.repeat):  # interleaved, so that every figure sees the same load
            for label, washouts in (("flight", False), ("flight + 3 washouts", True)):
                keep(label + " short", time_fly(short, washouts)[0])
                keep(label + " long", time_fly(long, washouts)[0])
            keep("bare short", run_cpu_s(manoeuvre_start(long), n_short))
            keep("bare long", run_cpu_s(manoeuvre_start(long), n_long))
            keep("bank", time_bank(dn))
        figures = {label: (best[label + " long"] - best[label + " short"]) / dn
                   for label in ("flight", "flight + 3 washouts")}  # fmt: skip
        bare = (best["bare long"] - best["bare short"]) / dn
        bank = best["bank"] / dn
    print(f"marginal cost per step, {n_long} - {n_short} steps, c172p at 120 Hz (minimum of {args.repeat} runs)")
    print(f"  bare JSBSim fdm.run()      {bare * 1e6:7.2f} us   1.00x")
    for label, per_step in figures.items():
        print(f"  {label:26s} {per_step * 1e6:7.2f} us  {per_step / bare:5.2f}x")
    print(f"  3 washouts alone (streaming) {bank * 1e6:5.2f} us  {bank / bare:5.2f}x")
    print("aim: flight + 3 washouts <= 1.5x")


if __name__ == "__main__":
    main()
