"""The best achieved's chosen settings and their effect (docs/yardstick.md, "The best achieved"), on results of a
suite run with ``--washout all``.

For each result folder named: the flight read back, every other washout's motion read from ``traces.parquet`` (as the
run gave them to the bound), the bound's replay planned again, and the search (``washbench.analysis.best_motion``)
from the best of them with each setting in turn; printed: the value after each programme (the search's history:
predicted and flown), the programmes taken and the CPU seconds.

    python tools/search_settings.py RESULT_FOLDER [RESULT_FOLDER ...]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pyarrow.parquet as pq

from washbench.analysis import best_motion
from washbench.analysis.bound import BoundParams
from washbench.analysis.bound_replay import reference_candidates, replay
from washbench.cueing.algorithm import WashoutContext
from washbench.cueing.bank import flyer
from washbench.cueing.variants import Washout, load_washout_params
from washbench.io.motion_file import read_motion
from washbench.platform.limits import load_platform_limits

G = 9.80665
SETTINGS = (
    ("default (3 programmes, trust 0.05 rad)", best_motion.Settings()),
    ("6 programmes", best_motion.Settings(steps=6)),
    ("trust 0.02 rad", best_motion.Settings(trust_rad=0.02)),
    ("trust 0.2 rad", best_motion.Settings(trust_rad=0.2)),
    ("60 PIQP iterations, tolerance 1e-5", best_motion.Settings(iterations=60, tolerance=1e-5)),
)


def motions_of(folder: Path) -> dict[str, SimpleNamespace]:
    """Every washout's motion but the bound's from a result's traces.parquet (SI, as a trace)."""
    table = pq.read_table(folder / "traces.parquet")
    order = [c.split(".")[0] for c in table.column_names if c.endswith(".pos_x_m") and not c.startswith("bound.")]

    def cols(name: str, fmt: str, axes: str) -> np.ndarray:
        return np.column_stack([table.column(fmt.format(name=name, a=a)).to_numpy() for a in axes])

    return {n: SimpleNamespace(pos_m=cols(n, "{name}.pos_{a}_m", "xyz"), q=cols(n, "{name}.q_{a}", "wxyz"),
                               omega_radps=np.radians(cols(n, "{name}.omega_platform_{a}_degps", "xyz")))
            for n in order}  # fmt: skip


def main(folders: list[str]) -> int:
    if not folders:
        print(__doc__.strip().split("\n\n")[-1], file=sys.stderr)
        return 2
    limits = load_platform_limits()
    params = load_washout_params()
    for name in folders:
        folder = Path(name)
        m = read_motion(folder / "flight.parquet")
        dt = m.dt_s
        ctx = WashoutContext(dt_s=dt, gravity_mps2=G, limits=limits, filter_start="steady",
                             head_offset_m=(0.0, 0.0, 0.0), platform=limits)  # fmt: skip
        fly_it = flyer(Washout("bound", "bound", params), limits, dt)
        motions = motions_of(folder)
        cands = best_motion.flown_candidates(motions, dt)
        cands += [c for c in reference_candidates(m.f_mps2, m.omega_radps, ctx) if c.name not in motions]
        pos, q_sp, _ = replay(m.f_mps2, m.omega_radps, dt, limits, G, BoundParams())
        cands.append(best_motion.Candidate(best_motion.REPLAY, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]), pos,
                                           q_sp))  # fmt: skip
        yard = best_motion.Yardstick(m.f_mps2, m.omega_radps, dt)
        print(f"{folder}: {m.n} samples ({m.n * dt:.1f} s), {len(cands)} motions to start from")
        for label, st in SETTINGS:
            t0 = time.process_time()
            res = best_motion.search(yard, cands, fly_it, limits, G, st)
            cpu = time.process_time() - t0
            steps = " ".join(f"{flown:.4f}{'' if taken else 'x'}" for _, flown, taken in res.history)
            print(f"  {label:38s} {res.candidates[res.start_from]:.4f} ({res.start_from}) -> {res.value:.4f}: "
                  f"{steps} ({res.accepted} of {res.steps} taken, {res.iterations} PIQP iterations, {cpu:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
