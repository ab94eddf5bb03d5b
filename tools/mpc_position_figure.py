"""Figure: platform position against its limits, classical washouts vs the MPC, from a run's traces.parquet.

    python tools/mpc_position_figure.py RUN_DIR OUT.png [--washouts small-angle unrestricted optimal mpc bound]

Each washout's legend entry gives its time with the stage on a position limit, from the positions themselves (any
axis within 0.5 % of its travel limit: a limiter braking there (``sat_pos``) and a constraint met with equality (the
MPC, the bound) count alike); the oracle bound (if the run has it: ``--washout bound``) is drawn dotted.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pyarrow.parquet as pq

from washbench.platform.limits import load_platform_limits


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("run", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--washouts", nargs="+", default=["small-angle", "unrestricted", "optimal", "mpc", "bound"])
    args = ap.parse_args()
    t = pq.read_table(args.run / "traces.parquet")
    ts = t.column("t_s").to_numpy()
    dt = float(ts[1] - ts[0])
    washouts = [w for w in args.washouts if f"{w}.pos_x_m" in t.column_names]
    lim = np.asarray(load_platform_limits().translation.position_limit_m.xyz, dtype=float)

    def on_limit_s(w: str) -> float:
        pos = np.column_stack([t.column(f"{w}.pos_{a}_m").to_numpy() for a in "xyz"])
        return float(np.any(np.abs(pos) >= 0.995 * lim, axis=1).sum() * dt)

    label = {w: f"{w} ({on_limit_s(w):.1f} s on a position limit)" for w in washouts}
    style = {"mpc": {"lw": 1.6, "color": "tab:red"}, "bound": {"lw": 1.1, "color": "0.35", "ls": ":"}}
    fig, axes = plt.subplots(3, 1, figsize=(10, 7.5), sharex=True)
    for i, (ax, name) in enumerate(zip(axes, ("x (north)", "y (east)", "z (down)"), strict=True)):
        for w in washouts:
            ax.plot(ts, t.column(f"{w}.pos_{'xyz'[i]}_m").to_numpy(), label=label[w], **style.get(w, {"lw": 0.9}))
        for s in (-1, 1):
            ax.axhline(s * lim[i], color="k", ls="--", lw=0.8)
        ax.set_ylabel(f"{name}, m")
        ax.grid(alpha=0.3)
    fig.legend(*axes[0].get_legend_handles_labels(), ncol=3, fontsize=8, loc="lower center")
    axes[-1].set_xlabel("time, s")
    fig.suptitle(f"Platform position against its limits (dashed): {args.run.parent.name}/{args.run.name}")
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
