"""Tables of every washout and naive reference under the felt error and under the score (the rule before it), from a
suite's result folder: which ranks where, per manoeuvre, and where a reference wins.

    washbench suite --out results --washout small-angle ... --washout replay --washout replay-rotation --washout still
    python tools/measure_tables.py results [--markdown]

Prints, per manoeuvre, each washout's value under both rules (the bound's replay scored, not ranked) and, for the
felt error, the share of its numerator that is jolts; then the count of manoeuvres on which a naive reference beats
every causal washout under each rule. The numbers in docs/metrics.md ("The felt error against the score") come from
this tool on the bundled manoeuvres.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from washbench.analysis.felt import FeltMeasure, felt_total
from washbench.analysis.ranking import BOUND_WASHOUT, DOFS, RankRule, felt_of, rule_from_record, rule_values
from washbench.cueing.registry import REFERENCE_KINDS
from washbench.io.metrics_csv import read_metrics_csv


def _runs(root: Path) -> list[Path]:
    return sorted(p.parent for p in root.glob("*/*/metrics.csv"))


def _measure(run: dict) -> FeltMeasure:
    record = ((run.get("provenance") or {}).get("ranking")) or {}
    return rule_from_record(record).measure


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("suite", type=Path, help="a suite's --out folder")
    ap.add_argument("--markdown", action="store_true", help="Markdown tables (as in docs/metrics.md)")
    args = ap.parse_args(argv)
    runs = _runs(args.suite)
    if not runs:
        print(f"{args.suite}: no result folders (OUT/<aircraft>/<manoeuvre>/metrics.csv)", file=sys.stderr)
        return 2
    wins = {"felt": 0, "score": 0}
    best_gap: list[tuple[str, float, float]] = []
    for folder in runs:
        rows = read_metrics_csv(folder / "metrics.csv")
        run = json.loads((folder / "run.json").read_text())
        motion = {d: float(v["value"]) for d, v in run["perceived_motion"].items()}
        measure = _measure(run)
        felt_values, _ = rule_values(rows, motion, RankRule(by="felt", measure=measure))
        score_values, _ = rule_values(rows, motion, RankRule(by="score"))
        names = [w for w in dict.fromkeys(r.washout for r in rows)]
        causal = [w for w in names if w not in REFERENCE_KINDS and w != BOUND_WASHOUT]
        refs = [w for w in names if w in REFERENCE_KINDS]
        title = f"{folder.parent.name}/{folder.name}"
        felt = felt_of(motion)
        total = felt_total(felt, measure) if felt is not None else math.nan
        by = {(r.washout, r.dof): r for r in rows}
        if args.markdown:
            print(f"\n**{title}**\n\n| washout | felt | jolt share | score |\n|---|---|---|---|")
        else:
            print(f"\n{title}  (felt motion {total:.1f} threshold-s)")
        for w in sorted(names, key=lambda x: (felt_values[x], x)):
            jolt = sum(measure.jolt_time_s * np.nan_to_num(by[(w, d)].jolt) / u
                       for d, u in zip(DOFS[:3], measure.units()[:3], strict=True))  # fmt: skip
            share = jolt / (felt_values[w] * total) if felt_values[w] > 0 else 0.0
            mark = " (reference)" if w in refs else ""
            if args.markdown:
                print(f"| {w}{mark} | {felt_values[w]:.3f} | {100 * share:.0f} % | {score_values[w]:.3f} |")
            else:
                print(f"  {w:24s} felt {felt_values[w]:8.3f}  (jolts {100 * share:3.0f} %)   "
                      f"score {score_values[w]:7.3f}")
        for rule, values in (("felt", felt_values), ("score", score_values)):
            if refs and causal and min(values[r] for r in refs) < min(values[c] for c in causal):
                wins[rule] += 1
        if refs and causal:
            best_gap.append((title, min(felt_values[c] for c in causal), min(felt_values[r] for r in refs)))
    print()
    n = len(runs)
    for rule in ("score", "felt"):
        print(f"a naive reference beats every causal washout under {rule}: {wins[rule]} of {n} manoeuvres")
    lost = [t for t, c, r in best_gap if r < c]
    if lost:
        print("under felt, a reference wins on: " + ", ".join(lost))
    return 0


if __name__ == "__main__":
    sys.exit(main())
