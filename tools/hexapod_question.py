"""The paper's question on a hexapod: two suite folders (the same manoeuvres and washouts, one on the Atlas, one on
a hexapod) side by side, as the Markdown tables of docs/platforms.md.

    .venv/bin/python tools/hexapod_question.py ATLAS_SUITE HEXAPOD_SUITE

Reads each folder's ``ranking.csv`` (scores) and every result's ``run.json`` (steps at each limit). Prints, per
washout, the mean score on each platform, the manoeuvres won (a shared first place counts for each) and, on the
hexapod, the mean share of the time its workspace / leg stroke held the set point (``sat_pos``); then the score per
manoeuvre and washout on both.
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
    names = {w for k in keys for w in hexa[k]}
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


if __name__ == "__main__":
    main()
