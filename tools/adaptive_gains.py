"""Print the adaptive washouts' gains every 10 s over a recorded flight (a run's flight.parquet).

    python tools/adaptive_gains.py results/c172p/takeoff/flight.parquet [adaptive.rate_tilt=2 ...]

p: translational gains per inertial axis; k: tilt gains per body axis (1/s). See docs/washouts.md.
"""

from __future__ import annotations

import sys

import numpy as np
import pyarrow.parquet as pq

from washbench.cueing import CueingBank
from washbench.cueing.params import ADAPTIVE_KINDS
from washbench.cueing.variants import Washout, apply_overrides, load_param_file, parse_value
from washbench.platform import load_platform_limits


def main() -> None:
    t = pq.read_table(sys.argv[1])
    f = np.column_stack([t[c].to_numpy() for c in ("f_x_mps2", "f_y_mps2", "f_z_mps2")])
    w = np.radians(np.column_stack([t[c].to_numpy() for c in ("omega_x_degps", "omega_y_degps", "omega_z_degps")]))
    dt = float(t["t_s"][1].as_py() - t["t_s"][0].as_py()) if "t_s" in t.column_names else 1 / 120
    base, _ = load_param_file(None)
    overrides = {k: parse_value(v) for k, v in (a.split("=", 1) for a in sys.argv[2:])}
    base = apply_overrides(base, overrides, "command line")
    bank = CueingBank([Washout(k, k, base) for k in ADAPTIVE_KINDS], None, load_platform_limits(), dt)
    every = round(10 / dt)
    for i in range(len(f)):
        bank.step(f[i], w[i])
        if i % every == 0 or i == len(f) - 1:
            parts = [f"{k}: p={np.round(v['p'], 2)} k={np.round(v['k'], 2)}" for k, v in bank.adaptation().items()]
            print(f"t={i * dt:6.1f} s  " + "  ".join(parts))


if __name__ == "__main__":
    main()
