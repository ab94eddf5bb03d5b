"""The paper's question on a hexapod: two suite folders (the same manoeuvres and washouts, one on the Atlas, one on
a hexapod) side by side, as the Markdown tables of docs/platforms.md.

    .venv/bin/python tools/hexapod_question.py ATLAS_SUITE HEXAPOD_SUITE
    .venv/bin/python tools/hexapod_question.py --ceiling HEXAPOD_SUITE

Reads each folder's ``ranking.csv`` (scores) and every result's ``run.json`` (steps at each limit). Prints, per
washout, the mean score on each platform, the manoeuvres won (a shared first place counts for each) and, on the
hexapod, the mean share of the time its workspace / leg stroke held the set point (``sat_pos``); then the score per
manoeuvre and washout on both.

``--ceiling``: from a suite run with ``--washout bound`` on a hexapod, each result's ``ceiling.csv`` and
``run.json`` (``bound``): per manoeuvre the ceiling of the score, the DOFs where it is above 0, the replay's score
and each washout's recovered fraction ``(1 - score) / (1 - ceiling)``, with the medians, and what the relaxation
had to widen (``bound.relaxation.widened``) over the suite.
"""

from __future__ import annotations

import csv
import json
import sys
from collections import defaultdict
from pathlib import Path


def scores(folder: Path) -> tuple[dict[tuple[str, str], dict[str, float]], dict[tuple[str, str], set[str]]]:
    out: dict[tuple[str, str], dict[str, float]] = defaultdict(dict)
    best: dict[tuple[str, str], set[str]] = defaultdict(set)
    with open(folder / "ranking.csv", newline="") as fh:
        for row in csv.DictReader(fh):
            key = (row["aircraft"], row["manoeuvre"])
            out[key][row["washout"]] = float(row["score"])
            if row["rank"] == "1":
                best[key].add(row["washout"])
    return out, best


def limit_share(folder: Path, key: tuple[str, str], washout: str, kind: str = "pos") -> float:
    run = json.loads((folder / key[0] / key[1] / "run.json").read_text())
    return run["saturations"][washout][kind] / run["steps"]


def main() -> None:
    atlas_dir, hex_dir = Path(sys.argv[1]), Path(sys.argv[2])
    atlas, atlas_best = scores(atlas_dir)
    hexa, hex_best = scores(hex_dir)
    keys = [k for k in hexa if k in atlas]
    names = {w for k in keys for w in hexa[k] if all(w in atlas[j] and w in hexa[j] for j in keys)}
    # "won" among the washouts both suites ran (a hexapod suite with --washout bound ranks its replay too)
    atlas_best = {k: {w for w in names if atlas[k][w] == min(atlas[k][v] for v in names)} for k in keys}
    hex_best = {k: {w for w in names if hexa[k][w] == min(hexa[k][v] for v in names)} for k in keys}
    order = ("small-angle", "large-angle", "adaptive", "adaptive-large-angle", "optimal", "mpc")
    washouts = [w for w in order if w in names] + sorted(names - set(order))
    print("| washout | mean score, Atlas | mean score, hexapod | won, Atlas | won, hexapod "
          "| hexapod at its workspace |")
    print("|---|---|---|---|---|---|")
    for w in washouts:
        a = sum(atlas[k][w] for k in keys) / len(keys)
        h = sum(hexa[k][w] for k in keys) / len(keys)
        wa = sum(w in atlas_best[k] for k in keys)
        wh = sum(w in hex_best[k] for k in keys)
        share = sum(limit_share(hex_dir, k, w) for k in keys) / len(keys)
        print(f"| {w} | {a:.3f} | {h:.3f} | {wa} | {wh} | {100 * share:.0f} % |")
    print()
    print("| aircraft / manoeuvre | " + " | ".join(washouts) + " | best, Atlas | best, hexapod |")
    print("|---|" + "---|" * (len(washouts) + 2))
    for k in keys:
        cells = [f"{atlas[k][w]:.3g} / {hexa[k][w]:.3g}" for w in washouts]
        print(f"| {k[0]} / {k[1]} | " + " | ".join(cells) + f" | {', '.join(sorted(atlas_best[k]))} | "
              f"{', '.join(sorted(hex_best[k]))} |")


def ceiling_tables(hex_dir: Path) -> None:
    rows = []
    widened: set[str] = set()
    for path in sorted(hex_dir.glob("*/*/ceiling.csv")):
        key = (path.parent.parent.name, path.parent.name)
        with open(path, newline="") as fh:
            table = {(r["washout"], r["dof"]): r for r in csv.DictReader(fh)}
        bound = json.loads((path.parent / "run.json").read_text())["bound"]
        widened |= set(bound["relaxation"]["widened"])
        rows.append((key, table, bound))
    if not rows:
        raise SystemExit(f"{hex_dir}: no ceiling.csv (run the suite with --washout bound)")
    names = list(dict.fromkeys(w for _, t, _ in rows for (w, dof) in t if dof == "score" and w != "bound"))
    print("| aircraft / manoeuvre | ceiling | DOFs above 0 | " + " | ".join(names) + " | bound (replay) |")
    print("|---|---:|---|" + "---:|" * (len(names) + 1))
    shares: dict[str, list[float]] = defaultdict(list)
    for key, table, bound in rows:
        ceil = float(table[(names[0], "score")]["ceiling"])
        above = [d for d, v in bound["ceiling"].items() if d != "score" and v]
        cells = []
        for w in [*names, "bound"]:
            rec = float(table[(w, "score")]["recovered"])
            shares[w].append(rec)
            cells.append(f"{float(table[(w, 'score')]['relative_error']):.3g} ({100 * rec:.0f} %)")
        print(f"| {key[0]} / {key[1]} | {ceil:.3g} | {', '.join(above) or '-'} | " + " | ".join(cells) + " |")
    med = [sorted(v)[len(v) // 2] if len(v) % 2 else 0.5 * sum(sorted(v)[len(v) // 2 - 1 : len(v) // 2 + 1])
           for v in (shares[w] for w in [*names, "bound"])]  # fmt: skip
    print("| **median recovered** | | | " + " | ".join(f"{100 * m:.0f} %" for m in med) + " |")
    print()
    print(f"Relaxation widened over the suite: {', '.join(sorted(widened)) or 'nothing'}.")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--ceiling":
        ceiling_tables(Path(sys.argv[2]))
    else:
        main()
