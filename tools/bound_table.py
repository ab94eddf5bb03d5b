"""The oracle bound beside every washout of finished runs: scores, costs, recovered fractions, as Markdown tables.

    python tools/bound_table.py RESULTS_DIR [RESULTS_DIR ...]

Each RESULTS_DIR is a run's folder with traces.parquet, or a suite folder searched for them. A run made with
``--washout bound`` has ``bound.csv`` and a ``bound`` row in ``ranking.csv`` (written by washbench itself:
washbench/runs/bound_stage.py); for an older run without them the bound is solved here from traces.parquet and
``bound.csv`` written beside it (``washout,cost,cost_bound,cost_still,recovered``). Prints two tables: the ranking
score per manoeuvre and washout (rank in brackets; the bound's score without a rank) and the fraction of the
recoverable cost each washout recovers, with the bound's and a still platform's cost (docs/optimal-mpc.md).
"""

from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

import pyarrow.parquet as pq

from washbench.analysis.bound import costs_from_columns
from washbench.io.atomic import write_text_atomic
from washbench.io.csv_numbers import csv_number
from washbench.platform.limits import load_platform_limits

G = 9.80665


def read_csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def bound_rows(run: Path) -> list[dict[str, str]]:
    """bound.csv of ``run``, computed and written first when the run has none."""
    if not (run / "bound.csv").is_file():
        table = pq.read_table(run / "traces.parquet")
        cols = {name: table.column(name).to_numpy() for name in table.column_names}
        dt = float(cols["t_s"][1] - cols["t_s"][0])
        res, costs = costs_from_columns(cols, dt, load_platform_limits(), G)
        lines = ["washout,cost,cost_bound,cost_still,recovered"]
        for name, cost in costs.items():
            cells = (cost, res.cost, res.cost_still, res.recovered(cost))
            lines.append(",".join([name, *(csv_number(float(x)) for x in cells)]))
        write_text_atomic(run / "bound.csv", "\n".join(lines) + "\n")
    return read_csv(run / "bound.csv")


def main() -> None:
    runs: list[Path] = []
    for arg in sys.argv[1:]:
        p = Path(arg)
        found = [p / "traces.parquet"] if (p / "traces.parquet").is_file() else sorted(p.rglob("traces.parquet"))
        runs += [t.parent for t in found]
    scores: dict[str, dict[str, tuple[float, str]]] = {}
    bounds: dict[str, list[dict[str, str]]] = {}
    for run in runs:
        name = f"{run.parent.name}/{run.name}"
        bounds[name] = bound_rows(run)
        if (run / "ranking.csv").is_file():
            scores[name] = {r["washout"]: (float(r["score"]), r["rank"]) for r in read_csv(run / "ranking.csv")}
    names = list(dict.fromkeys(r["washout"] for rows in bounds.values() for r in rows))
    washouts = [n for n in names if n != "bound"]
    if scores:
        cols = [*washouts, "bound"]
        print("| manoeuvre | " + " | ".join(cols) + " |")
        print("|---|" + "---:|" * len(cols))
        for man, sc in scores.items():
            cells = [f"{sc[w][0]:.3f} ({sc[w][1]})" if sc.get(w, (0, ""))[1] else
                     (f"{sc[w][0]:.3f}" if w in sc else "-") for w in cols]  # fmt: skip
            print(f"| {man} | " + " | ".join(cells) + " |")
        print()
    print("| manoeuvre | " + " | ".join(names) + " | J_bound | J_still | J_bound / J_still |")
    print("|---|" + "---:|" * (len(names) + 3))
    for man, rows in bounds.items():
        rec = {r["washout"]: float(r["recovered"]) if r["recovered"] else math.nan for r in rows}
        cells = [f"{100 * rec[n]:.0f} %" if math.isfinite(rec.get(n, math.nan)) else "-" for n in names]
        jb, js = float(rows[0]["cost_bound"]), float(rows[0]["cost_still"])
        print(f"| {man} | " + " | ".join(cells) + f" | {jb:.3g} | {js:.3g} | {100 * jb / js:.0f} % |")


if __name__ == "__main__":
    main()
