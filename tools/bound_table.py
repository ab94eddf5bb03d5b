"""The oracle bound beside every washout of finished runs: cost, recovered fraction; writes bound.csv per run.

    python tools/bound_table.py RESULTS_DIR [RESULTS_DIR ...]

Each RESULTS_DIR (a run's folder with traces.parquet, or a suite folder searched for them) gets ``bound.csv``:
``washout,cost,cost_still,recovered`` with a ``bound`` row (see washbench/analysis/bound.py and docs/optimal-mpc.md).
Prints one Markdown table: manoeuvre | each washout's recovered % | bound cost | still cost.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from washbench.analysis.bound import costs_from_columns
from washbench.io.atomic import write_text_atomic
from washbench.platform.limits import load_platform_limits

G = 9.80665


def one(trace: Path) -> tuple[str, dict[str, float], float, float]:
    table = pq.read_table(trace)
    cols = {name: table.column(name).to_numpy() for name in table.column_names}
    dt = float(cols["t_s"][1] - cols["t_s"][0])
    res, costs = costs_from_columns(cols, dt, load_platform_limits(), G)
    lines = ["washout,cost,cost_still,recovered"]
    for name, cost in {**costs, "bound": res.cost}.items():
        lines.append(f"{name},{cost:.9g},{res.cost_still:.9g},{res.recovered(cost):.6f}")
    write_text_atomic(trace.parent / "bound.csv", "\n".join(lines) + "\n")
    return trace.parent.name, {k: res.recovered(v) for k, v in costs.items()}, res.cost, res.cost_still


def main() -> None:
    traces = []
    for arg in sys.argv[1:]:
        p = Path(arg)
        traces += [p / "traces.parquet"] if (p / "traces.parquet").is_file() else sorted(p.rglob("traces.parquet"))
    rows = [one(t) for t in traces]
    names = list(rows[0][1]) if rows else []
    print("| manoeuvre | " + " | ".join(names) + " | bound cost | still cost |")
    print("|---|" + "---:|" * (len(names) + 2))
    for man, rec, jb, js in rows:
        cells = " | ".join(f"{100 * rec[n]:.0f} %" if np.isfinite(rec[n]) else "-" for n in names)
        print(f"| {man} | {cells} | {jb:.3g} | {js:.3g} |")


if __name__ == "__main__":
    main()
