"""The MPC washouts against CW1 and the ceiling, and the preview curve, as Markdown tables (docs/optimal-mpc.md).

    python tools/mpc_tables.py CEILING_SUITE [NAME=SUITE ...]

``CEILING_SUITE``: a ``washbench suite`` folder run with ``--washout small-angle --washout bound`` (its
``ceiling.csv`` per manoeuvre gives CW1's score and the ceiling). Each ``NAME=SUITE``: a suite folder of the same
manoeuvres whose ``ranking.csv`` holds the MPC washouts' scores, labelled NAME (e.g. ``none=results/preview_0``,
``1 s=results/preview_1``). Printed: per label and washout the number of manoeuvres better than CW1 and at least 20 %
better, the median gain over CW1 and the median share of the CW1-to-ceiling gap recovered, ``(cw1 - score) / (cw1 -
ceiling)``, and the same for the bound's replay (the whole flight known); then the scores per manoeuvre.
"""

from __future__ import annotations

import csv
import statistics
import sys
from pathlib import Path


def ceiling_rows(suite: Path) -> dict[str, tuple[float, float, float | None]]:
    """manoeuvre -> (CW1's score, the ceiling, the bound replay's score or None)."""
    out = {}
    for path in sorted(suite.glob("*/*/ceiling.csv")):
        rows = [r for r in csv.DictReader(path.open()) if r["dof"] == "score"]
        scores = {r["washout"]: float(r["relative_error"]) for r in rows}
        out[f"{path.parent.parent.name}/{path.parent.name}"] = (scores["small-angle"], float(rows[0]["ceiling"]),
                                                               scores.get("bound"))  # fmt: skip
    return out


def scores(suite: Path) -> dict[str, dict[str, float]]:
    """manoeuvre -> washout -> score, from each run's ranking.csv."""
    out: dict[str, dict[str, float]] = {}
    for path in sorted(suite.glob("*/*/ranking.csv")):
        key = f"{path.parent.parent.name}/{path.parent.name}"
        out[key] = {r["washout"]: float(r["score"]) for r in csv.DictReader(path.open())}
    return out


def main(argv: list[str]) -> int:
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    base = ceiling_rows(Path(argv[0]))
    runs = []
    for item in argv[1:]:
        label, _, folder = item.partition("=")
        runs.append((label, scores(Path(folder))))
    print("| preview | washout | better than CW1 | at least 20 % better | median gain | median gap recovered |")
    print("|---|---|---|---|---|---|")
    names = sorted({w for _, s in runs for m in s.values() for w in m if w.startswith("mpc")})
    for label, sc in runs:
        for w in names:
            gains, rec = [], []
            for m, (cw1, ceil, _) in base.items():
                if m not in sc or w not in sc[m]:
                    continue
                v = sc[m][w]
                gains.append(1.0 - v / cw1)
                rec.append((cw1 - v) / (cw1 - ceil))
            if not gains:
                continue
            print(f"| {label} | {w} | {sum(g > 0 for g in gains)} of {len(gains)} | "
                  f"{sum(g >= 0.2 for g in gains)} of {len(gains)} | {100 * statistics.median(gains):.1f} % | "
                  f"{100 * statistics.median(rec):.1f} % |")  # fmt: skip
    gains = [1.0 - b / cw1 for cw1, _, b in base.values() if b is not None]
    rec = [(cw1 - b) / (cw1 - ceil) for cw1, ceil, b in base.values() if b is not None]
    if gains:
        print(f"| the whole flight | bound (replay) | {sum(g > 0 for g in gains)} of {len(gains)} | "
              f"{sum(g >= 0.2 for g in gains)} of {len(gains)} | {100 * statistics.median(gains):.1f} % | "
              f"{100 * statistics.median(rec):.1f} % |")  # fmt: skip
    print()
    head = " | ".join(f"{w} ({label})" for label, _ in runs for w in names)
    print(f"| manoeuvre | CW1 | ceiling | bound replay | {head} |")
    print("|---" * (4 + len(runs) * len(names)) + "|")
    for m, (cw1, ceil, bound) in base.items():
        cells = []
        for _, sc in runs:
            for w in names:
                v = sc.get(m, {}).get(w)
                cells.append("" if v is None else f"{v:.3f}")
        b = "" if bound is None else f"{bound:.3f}"
        print(f"| {m} | {cw1:.3f} | {ceil:.3f} | {b} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
