"""Print the adaptive washouts' gains every 10 s over a recorded flight (a run's flight.parquet).

    python tools/adaptive_gains.py results/c172p/takeoff/flight.parquet [adaptive.rate_tilt=2 ...] [--png FILE]

p: translational gains per inertial axis; k: tilt gains per body axis (1/s). See docs/washouts.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from washbench.cueing import CueingBank
from washbench.cueing.params import ADAPTIVE_KINDS
from washbench.cueing.variants import Washout, apply_overrides, load_param_file, parse_value
from washbench.platform import load_platform_limits


def main() -> None:
    args = sys.argv[1:]
    png = None
    if "--png" in args:
        i = args.index("--png")
        png = args[i + 1]
        del args[i : i + 2]
    t = pq.read_table(args[0])
    f = np.column_stack([t[c].to_numpy() for c in ("f_x_mps2", "f_y_mps2", "f_z_mps2")])
    w = np.radians(np.column_stack([t[c].to_numpy() for c in ("omega_x_degps", "omega_y_degps", "omega_z_degps")]))
    dt = float(t["t_s"][1].as_py() - t["t_s"][0].as_py()) if "t_s" in t.column_names else 1 / 120
    base, _ = load_param_file(None)
    overrides = {k: parse_value(v) for k, v in (a.split("=", 1) for a in args[1:])}
    base = apply_overrides(base, overrides, "command line")
    bank = CueingBank([Washout(k, k, base) for k in ADAPTIVE_KINDS], None, load_platform_limits(), dt)
    every = round(10 / dt)
    hist = {k: np.empty((len(f), 6)) for k in ADAPTIVE_KINDS}
    for i in range(len(f)):
        bank.step(f[i], w[i])
        state = bank.adaptation()
        for k, v in state.items():
            hist[k][i, :3] = v["p"]
            hist[k][i, 3:] = v["k"]
        if i % every == 0 or i == len(f) - 1:
            parts = [f"{k}: p={np.round(v['p'], 2)} k={np.round(v['k'], 2)}" for k, v in state.items()]
            print(f"t={i * dt:6.1f} s  " + "  ".join(parts))
    if png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        tt = np.arange(len(f)) * dt
        fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
        styles = {"adaptive": "-", "adaptive-large-angle": "--", "adaptive-unrestricted": ":"}
        for k, h in hist.items():
            for j, (ax_name, colour) in enumerate(zip("xyz", ("tab:blue", "tab:orange", "tab:green"), strict=True)):
                axes[0].plot(tt, h[:, j], styles[k], color=colour, lw=1.2, label=f"{k} p_{ax_name}")
                axes[1].plot(tt, h[:, 3 + j], styles[k], color=colour, lw=1.2, label=f"{k} k_{ax_name}")
        axes[0].set_ylabel("translational gain p (-)")
        axes[1].set_ylabel("tilt gain k (1/s)")
        axes[1].set_xlabel("time (s)")
        where = "/".join(Path(args[0]).parts[-3:-1])
        axes[0].set_title(f"Adapted gains (CW1, default adaptation): {where}", fontsize=9)
        for ax in axes:
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=6, ncol=3, loc="upper right")
        fig.tight_layout()
        fig.savefig(png, dpi=110)
        print(f"wrote {png}")


if __name__ == "__main__":
    main()
