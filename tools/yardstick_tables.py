"""The yardstick's numbers of one suite run, as Markdown, written into a documentation page between its markers.

    python tools/yardstick_tables.py SUITE_FOLDER [PAGE.md]

SUITE_FOLDER: a ``washbench suite`` folder made with ``--washout bound`` (every result has ``ceiling.csv``). Without
PAGE the tables are printed; with it, the text between ``<!-- yardstick:begin -->`` and ``<!-- yardstick:end -->``
is replaced (the page written atomically), so the page says what this run shows and nothing typed by hand.

Tables: per manoeuvre the bracket [ceiling, best achieved] (the ceiling marked vacuous below 5 % of the best
achieved, as the verdict marks it), its width, the motion the best achieved's search started from, the best causal
washout and the best naive reference; every washout's value per manoeuvre with its rank; per DOF the median relative
error of each washout and of the ceiling over the manoeuvres that felt it; and the counts (the best achieved at or
below every washout and reference, its gain over the best causal washout, vacuous ceilings, first places, a
reference below every causal washout, values below the ceiling, which must be none).
"""

from __future__ import annotations

import csv
import json
import math
import statistics
import sys
from pathlib import Path

from washbench.analysis.best_motion import REPLAY as REPLAY_NAME
from washbench.analysis.felt import DEFAULT_MEASURE
from washbench.analysis.ranking import BOUND_WASHOUT as BOUND
from washbench.analysis.ranking import TIE_ABSOLUTE
from washbench.cueing.registry import REFERENCE_KINDS as REFERENCES
from washbench.io.atomic import write_text_atomic
from washbench.review.bound_section import VACUOUS
from washbench.review.numbers import sig

BEGIN = "<!-- yardstick:begin -->"
END = "<!-- yardstick:end -->"
DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
UNITS = tuple(float(u) for u in DEFAULT_MEASURE.units())
"""The felt motion's units per DOF (m/s^2, deg/s): its total in threshold-seconds (the default thresholds)."""


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


def _value(ranking: dict[str, dict[str, str]], w: str) -> float:
    r = ranking.get(w)
    return num(r["score"]) if r else math.nan


def _least(ranking: dict[str, dict[str, str]], names: list[str]) -> tuple[str, float]:
    """The name and value of the least value among ``names`` (ties: the first listed)."""
    vals = [(w, _value(ranking, w)) for w in names if w in ranking and math.isfinite(_value(ranking, w))]
    return min(vals, key=lambda x: x[1]) if vals else ("-", math.nan)


def tables(suite: Path) -> str:
    doc = json.loads((suite / "suite.json").read_text())
    runs = [(e, suite / e["result"]) for e in doc["manoeuvres"] if e.get("result")]
    missing = [str(r) for _, r in runs if not (r / "ceiling.csv").is_file()]
    if missing:
        raise SystemExit(f"yardstick_tables: no ceiling.csv in {missing[0]} (run the suite with --washout bound)")
    prov = doc.get("provenance") or {}
    software = prov.get("software") or {}
    rule = (prov.get("ranking") or {}).get("by", "score")
    washouts: list[str] = []
    rows = []
    for e, run in runs:
        ranking = {r["washout"]: r for r in read_csv(run / "ranking.csv")}
        ceiling = {(r["washout"], r["dof"]): r for r in read_csv(run / "ceiling.csv")}
        info = json.loads((run / "run.json").read_text())
        search = (info.get("algorithms") or {}).get(BOUND) or {}
        felt = sum(float(v["value"]) / unit for d, unit in zip(DOFS, UNITS, strict=True)
                   for k, v in (info.get("perceived_motion") or {}).items() if k == f"felt_{d}")  # fmt: skip
        for w in dict.fromkeys(r["washout"] for r in read_csv(run / "metrics.csv")):  # as listed
            if w not in washouts:
                washouts.append(w)
        rows.append((f"{e.get('aircraft')}/{e.get('manoeuvre')}", ranking, ceiling, search, felt))
    causal = [w for w in washouts if w != BOUND and w not in REFERENCES]
    refs = [w for w in washouts if w in REFERENCES]
    out = [
        f"Suite of {len(rows)} manoeuvres made {doc.get('created_utc', '?')} by washbench "
        f"{software.get('washbench', '?')} (git `{str(software.get('washbench_git', '?'))[:12]}`), JSBSim "
        f"{software.get('jsbsim', '?')}; washouts {', '.join(washouts)}; ranking rule `{rule}`. Command: "
        "`washbench suite --washout all --out SUITE`" + (" (every washout, the naive references and the bound)."
                                                         if set(washouts) >= set(REFERENCES) else "."),
        "",
        "**The bracket per manoeuvre** (lower is better; 1 = a platform standing still): the ceiling (certified; "
        f"*vacuous* below {100 * VACUOUS:.0f} % of the best achieved, where that is above the ranking's tie margin "
        f"{TIE_ABSOLUTE:g}: below it the bracket is closed), the best achieved (the `bound`: its search's "
        "value, the motion it started from and that motion's value flown again), the bracket's width (best achieved "
        "- ceiling), the best causal washout, the best naive reference and the bound's replay:",
        "",
        "| manoeuvre | felt (threshold-s) | ceiling | best achieved | started from | width | best causal | best "
        "reference | replay |",
        "|---|---:|---:|---:|---|---:|---|---|---:|",
    ]
    widths, gains, vacuous, beaten, at_best, replay_beaten = [], [], 0, [], 0, []
    for label, ranking, ceiling, search, felt in rows:
        best = _value(ranking, BOUND)
        ceil = num(ceiling[(BOUND, "score")]["ceiling"]) if (BOUND, "score") in ceiling else math.nan
        # vacuous as the verdict says (below 5 % of the best achieved), unless the best achieved is itself within the
        # ranking's absolute tie margin of 0: then the bracket is closed
        loose = math.isfinite(ceil) and best > TIE_ABSOLUTE and ceil < VACUOUS * best
        vacuous += loose
        cands = {k.split(":", 1)[1]: float(v) for k, v in search.items() if k.startswith("candidate:")}
        start = min(cands, key=lambda k: cands[k]) if cands else "-"
        cw, cv = _least(ranking, causal)
        rw, rv = _least(ranking, refs)
        others = [_value(ranking, w) for w in washouts if w != BOUND and w in ranking]
        beaten += [f"{label} {w}" for w in washouts if w != BOUND and _value(ranking, w) < best - 1e-9 * max(1, best)]
        at_best += all(best <= v * (1 + 1e-9) for v in others)
        width = best - ceil
        widths.append(width)
        if math.isfinite(cv) and cv > 0:
            gains.append((cv - best) / cv)
        replay = search.get("candidate:" + REPLAY_NAME, math.nan)
        if math.isfinite(cv) and cv < float(replay):
            replay_beaten.append(f"{label} ({cw})")
        out.append(f"| {label} | {felt:.0f} | {sig(ceil)}{' *vacuous*' if loose else ''} | {sig(best)} | "
                   f"{start} ({sig(cands.get(start, math.nan))}) | {sig(width)} | {cw} ({sig(cv)}) | {rw} ({sig(rv)}) "
                   f"| {sig(float(replay))} |")  # fmt: skip
    out += ["", f"**Every washout's value per manoeuvre** (rank in brackets; the best achieved has none; `{rule}`):",
            "", "| manoeuvre | " + " | ".join(washouts) + " | ceiling |",
            "|---|" + "---:|" * (len(washouts) + 1)]  # fmt: skip
    for label, ranking, ceiling, _, _ in rows:
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
    out += ["", "**Per DOF: median relative error** over the manoeuvres that felt the DOF (the rule's terms of the DOF "
            "over what the aircraft pilot felt there; 1 = standing still), and the median ceiling:", "",
            "| DOF | felt on | " + " | ".join(washouts) + " | ceiling |", "|---|---:|" + "---:|" * (len(washouts) + 1)]
    below = []
    for d in DOFS:
        vals: dict[str, list[float]] = {w: [] for w in washouts}
        ceils = []
        for label, _, ceiling, _, _ in rows:
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
    for label, _, ceiling, _, _ in rows:
        for w in washouts:
            r = ceiling.get((w, "score"))
            if r and r["ceiling"] != "" and num(r["relative_error"]) < num(r["ceiling"]) - 1e-9:
                below.append(f"{label} {w} score")
    alone = dict.fromkeys(causal, 0)
    shared = 0
    ref_wins = []
    for label, ranking, _, _, _ in rows:
        firsts = [w for w, r in ranking.items() if r["rank"] == "1"]
        if len(firsts) == 1 and firsts[0] in alone:
            alone[firsts[0]] += 1
        else:
            shared += 1
        if refs and _least(ranking, refs)[1] < _least(ranking, causal)[1]:
            ref_wins.append(label)
    out += [
        "",
        f"The best achieved is at or below every washout's and every reference's value on {at_best} of {len(rows)} "
        f"manoeuvres" + (f" (beaten: {'; '.join(beaten)})" if beaten else "") + f"; below the best causal washout by "
        f"a median {pct(median(gains))} (least {pct(min(gains) if gains else math.nan)}, most "
        f"{pct(max(gains) if gains else math.nan)}). Median bracket's width {sig(median(widths))}; vacuous ceilings "
        f"{vacuous} of {len(rows)}. First place alone: {', '.join(f'{w} {n}' for w, n in alone.items())}; shared "
        f"or a reference's: {shared}. The bound's replay alone beaten by a causal washout: {len(replay_beaten)} of "
        f"{len(rows)}" + (f" ({', '.join(replay_beaten)})" if replay_beaten else "") + ". A naive reference below "
        f"every causal washout: {len(ref_wins)} of {len(rows)}"
        + (f" ({', '.join(ref_wins)})" if ref_wins else "") + f". Values or relative errors below the ceiling: "
        f"{len(below)}" + (f" ({'; '.join(below)})" if below else "") + ".",
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
