"""One wide table of the felt error of every washout on every manoeuvre of a suite (a row per manoeuvre), the best
naive reference beside them, and how one washout fares against the references and the others (docs/optimal-mpc.md,
"mpc-unrestricted": "Against the naive references and the other washouts" comes from this tool).

    washbench suite --out SUITE --washout mpc-unrestricted --washout mpc ... --washout replay --washout still
    python tools/felt_table.py SUITE [--focus mpc-unrestricted] [--washouts W1,W2,...] [--before LABEL=SUITE]

Each value is the ranking's felt error (``--rank-by felt``, with the measure recorded in each run.json); **bold**: the
best causal washout of the row (the bound's replay, which knows the whole flight, and the references are not
candidates), within 3 % counts as a tie; a ``*`` marks a causal washout at or above the best naive reference (replay,
replay-rotation, still) on that manoeuvre. The lines after the table count, for the focus washout, the manoeuvres on
which it is below every reference, first or tied first among the causal washouts, and its median ratio to each of
the others. ``--before LABEL=SUITE`` adds a column: the focus washout's felt error in another suite (an earlier
version of it, the same manoeuvres).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

from washbench.analysis.ranking import BOUND_WASHOUT, RankRule, rule_from_record, rule_values
from washbench.cueing.references import REFERENCE_KINDS
from washbench.io.metrics_csv import read_metrics_csv

TIE = 0.03
"""Relative difference within which two washouts share first place (the ranking's own tie)."""


def felt_values(folder: Path) -> dict[str, float]:
    """washout -> felt error on one run folder (metrics.csv, run.json)."""
    rows = read_metrics_csv(folder / "metrics.csv")
    run = json.loads((folder / "run.json").read_text())
    motion = {d: float(v["value"]) for d, v in run["perceived_motion"].items()}
    record = ((run.get("provenance") or {}).get("ranking")) or {}
    values, _ = rule_values(rows, motion, RankRule(by="felt", measure=rule_from_record(record).measure))
    return {w: float(v) for w, v in values.items()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("suite", type=Path, help="a suite's --out folder")
    ap.add_argument("--focus", default="mpc-unrestricted", help="the washout the summary is about")
    ap.add_argument("--washouts", default="", help="comma-separated columns (default: every causal washout)")
    ap.add_argument("--before", default="", help="LABEL=SUITE: the focus washout's column from another suite")
    args = ap.parse_args(argv)
    before: dict[str, float] = {}
    label = ""
    if args.before:
        label, _, other = args.before.partition("=")
        for r in sorted(p.parent for p in Path(other).glob("*/*/metrics.csv")):
            v = felt_values(r)
            if args.focus in v:
                before[f"{r.parent.name}/{r.name}"] = v[args.focus]
    runs = sorted(p.parent for p in args.suite.glob("*/*/metrics.csv"))
    if not runs:
        print(f"{args.suite}: no result folders (OUT/<aircraft>/<manoeuvre>/metrics.csv)", file=sys.stderr)
        return 2
    table = {f"{r.parent.name}/{r.name}": felt_values(r) for r in runs}
    every = list(dict.fromkeys(w for v in table.values() for w in v))
    causal = [w for w in every if w not in REFERENCE_KINDS and w != BOUND_WASHOUT]
    cols = [w for w in args.washouts.split(",") if w] or causal
    extra = [BOUND_WASHOUT] if BOUND_WASHOUT in every else []
    head = cols + extra + ([f"{args.focus} ({label})"] if label else [])
    print("| manoeuvre | best reference | " + " | ".join(head) + " |")
    print("|---|---|" + "---|" * len(head))
    below = first = 0
    ratios: dict[str, list[float]] = {w: [] for w in causal if w != args.focus}
    for name, v in table.items():
        refs = {w: v[w] for w in REFERENCE_KINDS if w in v}
        ref_name = min(refs, key=refs.__getitem__) if refs else ""
        best = min((v[w] for w in causal if w in v), default=float("nan"))
        cells = []
        for w in cols:
            x = v.get(w)
            if x is None:
                cells.append("")
                continue
            text = f"{x:.3f}" + ("*" if refs and x >= refs[ref_name] else "")
            cells.append(f"**{text}**" if x <= best * (1 + TIE) else text)
        cells += [f"{v[w]:.3f}" for w in extra if w in v]
        if label:
            b = before.get(name)
            cells.append("" if b is None else f"{b:.3f}" + ("*" if refs and b >= refs[ref_name] else ""))
        ref_cell = f"{refs[ref_name]:.3f} ({ref_name})" if refs else ""
        print(f"| {name} | {ref_cell} | " + " | ".join(cells) + " |")
        f = v.get(args.focus)
        if f is None:
            continue
        below += bool(refs) and f < refs[ref_name]
        first += f <= best * (1 + TIE)
        for w in ratios:
            if w in v and v[w] > 0:
                ratios[w].append(f / v[w])
    print()
    n = len(table)
    print(f"{args.focus}: below every naive reference on {below} of {n} manoeuvres; first or tied first (within "
          f"{100 * TIE:.0f} %) among the causal washouts on {first} of {n}.")  # fmt: skip
    med = ", ".join(f"{w} {statistics.median(r):.2f}" for w, r in ratios.items() if r)
    print(f"Median ratio of its felt error to each other washout's: {med}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
