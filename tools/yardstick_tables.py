"""The yardstick's numbers of one suite run, as Markdown, written into a documentation page between its markers.

    python tools/yardstick_tables.py SUITE_FOLDER [PAGE.md]

SUITE_FOLDER: a ``washbench suite`` folder made with ``--washout bound`` (every result has ``ceiling.csv``). Without
PAGE the tables are printed; with it, the text between ``<!-- yardstick:begin -->`` and ``<!-- yardstick:end -->``
is replaced (the page written atomically), so the page says what this run shows and nothing typed by hand.

Tables: every washout's score per manoeuvre with its rank, the replay's and the ceiling's; the recovered fraction
(``(1 - score) / (1 - ceiling)``); per DOF the median relative error of each washout and of the ceiling over the
manoeuvres that felt it; and the counts (first places alone and shared, manoeuvres at least 20 % better than CW1,
washouts below the ceiling, which must be none).
"""

from __future__ import annotations

import csv
import json
import math
import statistics
import sys
from pathlib import Path

from washbench.io.atomic import write_text_atomic
from washbench.review.numbers import sig

BEGIN = "<!-- yardstick:begin -->"
END = "<!-- yardstick:end -->"
DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
REFERENCE = "small-angle"


def read_csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def num(text: str | None) -> float:
    return float(text) if text not in (None, "") else math.nan


def pct(x: float, signed: bool = False) -> str:
    if not math.isfinite(x):
        return "-"
    return f"{100 * x:+.0f} %" if signed else f"{100 * x:.0f} %"


def median(xs: list[float]) -> float:
    xs = [x for x in xs if math.isfinite(x)]
    return statistics.median(xs) if xs else math.nan


def tables(suite: Path) -> str:
    doc = json.loads((suite / "suite.json").read_text())
    runs = [(e, suite / e["result"]) for e in doc["manoeuvres"] if e.get("result")]
    missing = [str(r) for _, r in runs if not (r / "ceiling.csv").is_file()]
    if missing:
        raise SystemExit(f"yardstick_tables: no ceiling.csv in {missing[0]} (run the suite with --washout bound)")
    prov = doc.get("provenance") or {}
    software = prov.get("software") or {}
    washouts: list[str] = []
    rows = []
    for e, run in runs:
        ranking = {r["washout"]: r for r in read_csv(run / "ranking.csv")}
        ceiling = {(r["washout"], r["dof"]): r for r in read_csv(run / "ceiling.csv")}
        for w in dict.fromkeys(r["washout"] for r in read_csv(run / "metrics.csv")):  # as listed
            if w not in washouts:
                washouts.append(w)
        rows.append((f"{e.get('aircraft')}/{e.get('manoeuvre')}", ranking, ceiling))
    causal = [w for w in washouts if w != "bound"]
    out = [
        f"Suite of {len(rows)} manoeuvres made {doc.get('created_utc', '?')} by washbench "
        f"{software.get('washbench', '?')} (git `{str(software.get('washbench_git', '?'))[:12]}`), JSBSim "
        f"{software.get('jsbsim', '?')}; washouts {', '.join(washouts)}; ranking rule "
        f"`{(prov.get('ranking') or {}).get('by', 'score')}`. Command: `washbench suite "
        + " ".join(f"--washout {w}" for w in washouts) + " --out SUITE`.",
        "",
        "**Score per manoeuvre** (rank in brackets; the replay has none; lower is better, 1 = standing still):",
        "",
        "| manoeuvre | " + " | ".join(washouts) + " | ceiling |",
        "|---|" + "---:|" * (len(washouts) + 1),
    ]
    for label, ranking, ceiling in rows:
        cells = []
        for w in washouts:
            r = ranking.get(w)
            if r is None:
                cells.append("-")
                continue
            rank = f" ({r['rank']}{'=' if r.get('tied') == 'true' else ''})" if r["rank"] else ""
            cells.append(sig(num(r["score"])) + rank)
        ceil = num(next(iter(v for (w, d), v in ceiling.items() if d == "score"))["ceiling"])
        out.append(f"| {label} | " + " | ".join(cells) + f" | {sig(ceil)} |")
    out += ["", "**Recovered fraction of the score** ((1 - score) / (1 - ceiling): 100 % = the ceiling, 0 % = "
            "standing still):", "", "| manoeuvre | " + " | ".join(washouts) + " |",
            "|---|" + "---:|" * len(washouts)]  # fmt: skip
    rec: dict[str, list[float]] = {w: [] for w in washouts}
    for label, _, ceiling in rows:
        cells = []
        for w in washouts:
            r = ceiling.get((w, "score"))
            x = num(r["recovered"]) if r else math.nan
            rec[w].append(x)
            cells.append(pct(x))
        out.append(f"| {label} | " + " | ".join(cells) + " |")
    out.append("| **median** | " + " | ".join(pct(median(rec[w])) for w in washouts) + " |")
    out += ["", "**Per DOF: median relative error** over the manoeuvres that felt the DOF (the integral error over the "
            "aircraft pilot's own perceived motion; 1 = standing still), and the median ceiling:", "",
            "| DOF | felt on | " + " | ".join(washouts) + " | ceiling |", "|---|---:|" + "---:|" * (len(washouts) + 1)]
    below = []
    for d in DOFS:
        vals = {w: [] for w in washouts}
        ceils = []
        for label, _, ceiling in rows:
            first = ceiling.get((washouts[0], d))
            if first is None or first["ceiling"] == "":
                continue
            ceils.append(num(first["ceiling"]))
            for w in washouts:
                r = ceiling.get((w, d))
                if r and r["relative_error"] != "":
                    vals[w].append(num(r["relative_error"]))
                    if num(r["relative_error"]) < num(r["ceiling"]) - 1e-9:
                        below.append(f"{label} {w} {d}")
        out.append(f"| {d} | {len(ceils)} | " + " | ".join(sig(median(vals[w])) for w in washouts)
                   + f" | {sig(median(ceils))} |")  # fmt: skip
    for label, _, ceiling in rows:
        for w in washouts:
            r = ceiling.get((w, "score"))
            if r and num(r["relative_error"]) < num(r["ceiling"]) - 1e-9:
                below.append(f"{label} {w} score")
    alone = dict.fromkeys(causal, 0)
    shared = 0
    at_aim = dict.fromkeys(causal, 0)
    for _, ranking, _ in rows:
        firsts = [w for w, r in ranking.items() if r["rank"] == "1"]
        if len(firsts) == 1:
            alone[firsts[0]] += 1
        else:
            shared += 1
        ref = num(ranking[REFERENCE]["score"]) if REFERENCE in ranking else math.nan
        for w in causal:
            if w in ranking and ref > 0 and (ref - num(ranking[w]["score"])) / ref >= 0.2:
                at_aim[w] += 1
    out += [
        "",
        f"First place alone: {', '.join(f'{w} {n}' for w, n in alone.items())}; shared: {shared} (together "
        f"{sum(alone.values()) + shared} of {len(rows)}). At least 20 % better than {REFERENCE} (CW1): "
        + ", ".join(f"{w} {n} of {len(rows)}" for w, n in at_aim.items() if w != REFERENCE)
        + f". Scores or relative errors below the ceiling: {len(below)}"
        + (f" ({'; '.join(below)})" if below else "") + ".",
    ]
    return "\n".join(out) + "\n"


def main(argv: list[str]) -> int:
    if len(argv) not in (1, 2):
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 2
    text = tables(Path(argv[0]))
    if len(argv) == 1:
        sys.stdout.write(text)
        return 0
    page = Path(argv[1])
    old = page.read_text()
    if BEGIN not in old or END not in old:
        print(f"yardstick_tables: {page}: no {BEGIN} ... {END} markers", file=sys.stderr)
        return 2
    head, rest = old.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    write_text_atomic(page, f"{head}{BEGIN}\n{text}{END}{tail}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
