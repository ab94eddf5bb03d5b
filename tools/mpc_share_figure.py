"""Figure: how a washout shares the cues between the sphere's rotation, tilt and the stage's translation, from
runs' traces.parquet (issue 35: a steep turn and the aerobatics, ``mpc-unrestricted``).

    python tools/mpc_share_figure.py OUT.png RUN_DIR [RUN_DIR ...] [--washout W] [--reference W]

One column per run. The top rows are the rotational cues: the roll and yaw rates of the aircraft pilot's head and of
the simulator pilot's (the sphere turning). The rows below are the specific force at the simulator pilot's head, in
the cockpit's axes, in surge, sway and heave, split into its sources:

* translation ``R' a``: the stage's acceleration ``a`` (NED, ``acc_*_mps2``) seen in the cockpit's axes,
  ``R`` the cockpit's attitude (``q_*``, body to NED, scalar first);
* tilt ``-R' g``: gravity (``g`` = [0, 0, 9.80665] m/s^2 NED) seen in the tilted cockpit; at level it is
  [0, 0, -g];
* what is left, the head's offset from the sphere's centre (``alpha x r + omega x (omega x r)``), drawn only where it
  exceeds 1e-6 m/s^2 (with the bundled Atlas the head is at the centre and the two sources add up to the force).

The aircraft pilot's specific force is drawn as the target; ``--reference`` adds another washout's total (thin).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pyarrow.parquet as pq
from scipy.spatial.transform import Rotation

G_MPS2 = 9.80665


def split_force(table, washout: str) -> dict[str, np.ndarray]:
    """The washout's head specific force (N, 3) [m/s^2, cockpit axes] and its translation, tilt and rotation parts."""

    def cols(fmt: str, axes: str) -> np.ndarray:
        return np.column_stack([table.column(fmt.format(a)).to_numpy() for a in axes])

    q = cols(f"{washout}.q_{{}}", "wxyz")
    to_body = Rotation.from_quat(q[:, [1, 2, 3, 0]]).inv()  # scipy: scalar last; body to NED, inverted
    total = cols(f"{washout}.f_{{}}_mps2", "xyz")
    translation = to_body.apply(cols(f"{washout}.acc_{{}}_mps2", "xyz"))
    tilt = -to_body.apply(np.array([0.0, 0.0, G_MPS2]))
    return {"total": total, "translation": translation, "tilt": tilt, "rotation": total - translation - tilt}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("out", type=Path)
    ap.add_argument("runs", type=Path, nargs="+")
    ap.add_argument("--washout", default="mpc-unrestricted")
    ap.add_argument("--reference", default="small-angle")
    args = ap.parse_args()
    rows = [("roll rate [deg/s]", "omega", 0), ("yaw rate [deg/s]", "omega", 2),
            ("surge specific force [m/s^2]", "f", 0), ("sway specific force [m/s^2]", "f", 1),
            ("heave specific force [m/s^2]", "f", 2)]  # fmt: skip
    fig, axes = plt.subplots(len(rows), len(args.runs), figsize=(6.4 * len(args.runs), 11.0), sharex="col",
                             squeeze=False, layout="constrained")  # fmt: skip
    parts = (("translation", "translation (stage)", "#d9822b", "--"), ("tilt", "tilt (gravity)", "#2a9d4b", "--"),
             ("rotation", "head offset", "#8e44ad", ":"))  # fmt: skip
    for col, run in enumerate(args.runs):
        table = pq.read_table(run / "traces.parquet")
        t = table.column("t_s").to_numpy()
        split = split_force(table, args.washout)
        ref = args.reference if f"{args.reference}.f_x_mps2" in table.column_names else None
        for row, (label, kind, axis) in enumerate(rows):
            ax = axes[row, col]
            a = "xyz"[axis]
            if kind == "omega":
                ax.plot(t, table.column(f"aircraft.omega_{a}_degps").to_numpy(), color="black", lw=1.3,
                        label="aircraft pilot")  # fmt: skip
                ax.plot(t, table.column(f"{args.washout}.omega_{a}_degps").to_numpy(), color="#1f5fbf", lw=1.1,
                        label=f"{args.washout}: the sphere's rotation")  # fmt: skip
                if ref:
                    ax.plot(t, table.column(f"{ref}.omega_{a}_degps").to_numpy(), color="#999999", lw=0.8,
                            label=f"{ref}")  # fmt: skip
            else:
                ax.plot(t, table.column(f"aircraft.f_{a}_mps2").to_numpy(), color="black", lw=1.3,
                        label="aircraft pilot")  # fmt: skip
                ax.plot(t, split["total"][:, axis], color="#1f5fbf", lw=1.1, label=f"{args.washout}: total")
                for name, label_part, colour, style in parts:
                    if name != "rotation" or np.abs(split[name][:, axis]).max() > 1e-6:
                        ax.plot(t, split[name][:, axis], color=colour, lw=1.0, ls=style,
                                label=f"of which {label_part}")  # fmt: skip
                if ref:
                    ax.plot(t, table.column(f"{ref}.f_{a}_mps2").to_numpy(), color="#999999", lw=0.8,
                            label=f"{ref}: total")  # fmt: skip
            ax.set_ylabel(label)
            ax.grid(True, lw=0.3, alpha=0.6)
            if row in (0, 2):
                ax.legend(fontsize=7, loc="best", ncol=2 if kind == "f" else 1, framealpha=0.85)
        axes[0, col].set_title(f"{run.parent.name}/{run.name}")
        axes[-1, col].set_xlabel("time [s]")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110, metadata={"Software": None})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
