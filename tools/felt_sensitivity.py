"""How the felt error's chosen values change the verdict: each one varied alone, on a suite's traces.

    washbench suite --out results --washout all --no-recording --no-figures
    python tools/felt_sensitivity.py results

For each setting (the default, then the false-cue weight lambda, the jolt time tau_j, the jerk dead band J_T, the
thresholds off) the felt error of every washout and reference is computed again from ``traces.parquet`` (the
perceived signals and the head specific forces it holds) and the tool prints: the washout with the least median
value, on how many manoeuvres a naive reference beats every washout, and on how many the replay ranks below its
rotation-only form (its jolts counted). docs/metrics.md ("Chosen values and their effect") shows its output.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from washbench.analysis.felt import DEFAULT_MEASURE, FeltMeasure, felt_errors, felt_motion, felt_score, jolt
from washbench.cueing.registry import REFERENCE_KINDS as REFERENCES
from washbench.io.columns import AIRCRAFT, f_columns, perceived_f_columns, perceived_omega_columns


def _arrays(table: dict, pilot: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pf = np.column_stack([table[c] for c in perceived_f_columns(pilot)])
    pw = np.radians(np.column_stack([table[c] for c in perceived_omega_columns(pilot)]))
    head = np.column_stack([table[c] for c in f_columns(pilot)])
    return pf, pw, head


def _load(folder: Path) -> tuple[float, dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]]:
    table = pq.read_table(folder / "traces.parquet").to_pydict()
    t = np.asarray(table["t_s"])
    pilots = sorted({c.split(".", 1)[0] for c in table if c.endswith(".perceived_f_x_mps2")})
    return float(t[1] - t[0]), {p: _arrays(table, p) for p in pilots}


def _scores(dt: float, data: dict, measure: FeltMeasure) -> dict[str, float]:
    af, aw, ah = data[AIRCRAFT]
    m = felt_motion(af, aw, dt, measure)
    out = {}
    for p, (sf, sw, sh) in data.items():
        if p == AIRCRAFT:
            continue
        e, fa = felt_errors(af, aw, sf, sw, dt, measure)
        out[p] = felt_score(e, fa, jolt(sh, ah, dt, measure), m, measure)
    return out


SETTINGS: list[tuple[str, FeltMeasure]] = [
    ("default (lambda 1, tau_j 1 s, J_T 50 m/s^3, Zacharias)", DEFAULT_MEASURE),
    ("lambda 0 (false cues counted once)", dataclasses.replace(DEFAULT_MEASURE, false_weight=0.0)),
    ("lambda 2", dataclasses.replace(DEFAULT_MEASURE, false_weight=2.0)),
    ("tau_j 0 (no jolt term)", dataclasses.replace(DEFAULT_MEASURE, jolt_time_s=0.0)),
    ("tau_j 0.25 s", dataclasses.replace(DEFAULT_MEASURE, jolt_time_s=0.25)),
    ("tau_j 4 s", dataclasses.replace(DEFAULT_MEASURE, jolt_time_s=4.0)),
    ("J_T 10 m/s^3", dataclasses.replace(DEFAULT_MEASURE, jerk_deadband_mps3=10.0)),
    ("J_T 200 m/s^3", dataclasses.replace(DEFAULT_MEASURE, jerk_deadband_mps3=200.0)),
    ("no thresholds (no dead band)", dataclasses.replace(DEFAULT_MEASURE, deadband=False)),
]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("suite", type=Path, help="a suite's --out folder with traces.parquet in each result")
    args = ap.parse_args(argv)
    folders = sorted(p.parent for p in args.suite.glob("*/*/traces.parquet"))
    if not folders:
        print(f"{args.suite}: no traces.parquet below it", file=sys.stderr)
        return 2
    loaded = [(f, *_load(f)) for f in folders]
    print(f"{len(loaded)} manoeuvres\n")
    print("| setting | least median (washouts) | a reference beats every washout | replay below replay-rotation |")
    print("|---|---|---|---|")
    for label, measure in SETTINGS:
        per = [(f, _scores(dt, data, measure)) for f, dt, data in loaded]
        names = list(per[0][1])
        causal = [w for w in names if w not in REFERENCES and w != "bound"]
        med = {w: statistics.median(s[w] for _, s in per) for w in causal}
        best = min(causal, key=lambda w: med[w])
        ref_wins = sum(1 for _, s in per if min(s[r] for r in REFERENCES if r in s) < min(s[c] for c in causal))
        below = sum(1 for _, s in per
                    if "replay" in s and "replay-rotation" in s and s["replay"] > s["replay-rotation"])  # fmt: skip
        print(f"| {label} | {best} {med[best]:.3f} | {ref_wins} of {len(per)} | {below} of {len(per)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
