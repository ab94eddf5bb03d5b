"""Figure: platform position against its limits, classical washouts vs the MPC, from a run's traces.parquet.

    python tools/mpc_position_figure.py RUN_DIR OUT.png [--washouts large-angle unrestricted mpc]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pyarrow.parquet as pq

from washbench.platform.limits import load_platform_limits


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("run", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--washouts", nargs="+", default=["large-angle", "unrestricted", "optimal", "mpc"])
    args = ap.parse_args()
    t = pq.read_table(args.run / "traces.parquet")
    ts = t.column("t_s").to_numpy()
    lim = load_platform_limits().translation.position_limit_m.xyz
    fig, axes = plt.subplots(3, 1, figsize=(10, 7.5), sharex=True)
    for i, (ax, name) in enumerate(zip(axes, ("x (north)", "y (east)", "z (down)"), strict=True)):
        for w in args.washouts:
            ax.plot(ts, t.column(f"{w}.pos_{'xyz'[i]}_m").to_numpy(), lw=1.2 if w == "mpc" else 0.9, label=w)
        for s in (-1, 1):
            ax.axhline(s * lim[i], color="k", ls="--", lw=0.8)
        ax.set_ylabel(f"{name}, m")
        ax.grid(alpha=0.3)
    axes[0].legend(ncol=len(args.washouts), fontsize=8, loc="upper right")
    axes[-1].set_xlabel("time, s")
    fig.suptitle(f"Platform position against its limits (dashed): {args.run.parent.name}/{args.run.name}")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
