"""The report's lines on the ceiling (``ceiling.csv``) and on the Python washouts' own statistics (``run.json``:
``algorithms``, e.g. the MPC's solves and fallbacks), from a result folder's files (docs/optimal-mpc.md)."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

from washbench.review.numbers import sig

CEILING_FILE = "ceiling.csv"

CEILING_NOTE = (
    "The ceiling is the least relative error that **any** motion of this platform could reach on this flight, with "
    "the whole flight known: a certified lower bound on the ranking's own measure, per degree of freedom and for the "
    "{measure} (a convex relaxation of everything the platform model can fly, docs/yardstick.md: no washout can score "
    "below it). It is loose where the relaxation is generous (no convex relaxation can charge for the rotation a "
    "sustained tilt needs; each DOF has the whole of gravity), so the best any motion can do lies between the "
    "ceiling and the best value achieved (the least of every motion run: the washouts, the references, the `bound` "
    "row). Recovered = (still - value) / (still - ceiling): the share of what a platform standing still leaves that a "
    "washout recovers (100 %: the ceiling; below 0: worse than standing still); where the ceiling is below "
    "{vacuous:.0f} % of the best achieved it is vacuous and no fraction of it is shown (it would only be 1 - value)."
)

VACUOUS = 0.05
"""A ceiling below this fraction of the best value achieved is vacuous: no recovered fraction of it is shown (the
suite verdict's threshold too, :data:`washbench.review.verdict.VACUOUS`)."""


def vacuous(ceiling: float, best: float) -> bool:
    """Whether a ceiling says nothing the best achieved does not: below :data:`VACUOUS` of it."""
    return math.isfinite(ceiling) and math.isfinite(best) and best > 0.0 and ceiling < VACUOUS * best

_ORDER = ("score", "surge", "sway", "heave", "roll", "pitch", "yaw")


def _read_ceiling(folder: Path) -> list[dict[str, str]]:
    path = folder / CEILING_FILE
    if not path.is_file():
        return []
    try:
        with path.open(newline="") as f:
            return [r for r in csv.DictReader(f) if r.get("washout") and r.get("dof")]
    except (OSError, csv.Error, UnicodeDecodeError):
        return []


def _float(text: str | None) -> float:
    try:
        return float(text) if text not in (None, "") else math.nan
    except ValueError:
        return math.nan


def _run_json(folder: Path) -> dict:
    try:
        doc = json.loads((folder / "run.json").read_text())
    except (OSError, ValueError):
        return {}
    return doc if isinstance(doc, dict) else {}


def recovered_text(recovered: float) -> str:
    """``62 %``, or ``-`` when nothing is recoverable (the bound no better than a still platform)."""
    return "-" if not math.isfinite(recovered) else f"{100.0 * recovered:.0f} %"


def read_ceiling(folder: Path) -> dict[str, dict[str, dict[str, float]]]:
    """``ceiling.csv`` of a result folder: washout -> dof (``score`` and the six DOFs) -> ``relative_error``,
    ``ceiling``, ``recovered`` (NaN where empty); empty when the bound did not run."""
    out: dict[str, dict[str, dict[str, float]]] = {}
    for r in _read_ceiling(folder):
        out.setdefault(r["washout"], {})[r["dof"]] = {k: _float(r.get(k)) for k in ("relative_error", "ceiling",
                                                                                      "recovered")}  # fmt: skip
    return out


def _cell(cells: dict[str, float] | None, loose: bool = False) -> str:
    if not cells or not math.isfinite(cells["relative_error"]):
        return "-"
    if loose:  # a fraction of a vacuous ceiling is 1 - value: not information
        return sig(cells["relative_error"])
    return f"{sig(cells['relative_error'])} ({recovered_text(cells['recovered'])})"


def bound_lines(folder: Path, order: list[str] | None = None, explain: bool = True) -> list[str]:
    """Every washout's relative error and recovered fraction, in total and per DOF, beside the ceiling, from
    ``ceiling.csv``, the washouts in ``order`` (the ranking's; default the file's); empty when the bound did not
    run. ``explain=False`` (the suite report, which explains once): without :data:`CEILING_NOTE`."""
    table = read_ceiling(folder)
    if not table:
        return []
    rec = _run_json(folder).get("bound") or {}
    measure = {"felt": "felt error"}.get(str(rec.get("measure") or "score"), str(rec.get("measure") or "score"))
    names = [w for w in (order or []) if w in table] + [w for w in table if w not in (order or [])]
    first = next(iter(table.values()))
    dofs = [d for d in _ORDER if d in first and math.isfinite(first[d]["ceiling"])]

    def best(d: str) -> tuple[float, str]:
        vals = [(table[n][d]["relative_error"], n) for n in names if d in table[n]
                and math.isfinite(table[n][d]["relative_error"])]  # fmt: skip
        return min(vals) if vals else (math.nan, "")

    loose = {d: vacuous(first[d]["ceiling"], best(d)[0]) for d in dofs}
    what = ("each DOF's felt error over what the aircraft pilot felt there above threshold" if measure == "felt error"
            else "per DOF the integral error over what the aircraft pilot felt there")  # fmt: skip

    lines = [
        f"Relative error (recovered): {what} (1 = standing still), and the {measure}; DOFs the aircraft pilot did not "
        "feel are left out; no recovered fraction where the ceiling is vacuous.",
        "",
    ] if explain else []
    lines += [
        "| washout | " + " | ".join(dofs) + " |",
        "|---|" + "---|" * len(dofs),
    ]
    for n in names:
        label = f"{n} (replayed plan)" if n == "bound" else n
        lines.append(f"| {label} | " + " | ".join(_cell(table[n].get(d), loose[d]) for d in dofs) + " |")
    lines.append("| **ceiling** | " + " | ".join(f"**{sig(first[d]['ceiling'])}** (vacuous)" if loose[d] else
                                               f"**{sig(first[d]['ceiling'])}** (100 %)" for d in dofs) + " |")
    lines += ["| _platform standing still_ | " + " | ".join("1" if loose[d] else "1 (0 %)" for d in dofs) + " |", ""]
    ranked = [(n, table[n]["score"]["relative_error"]) for n in names if n != "bound" and "score" in table[n]]
    ranked = [r for r in ranked if math.isfinite(r[1])]
    if ranked and "score" in dofs:
        name, value = min(ranked, key=lambda r: r[1])
        achieved, by = best("score")
        ceiling = first["score"]["ceiling"]
        if loose["score"]:
            lines += [f"**The bracket: [{sig(ceiling)}, {sig(achieved)}]** (the ceiling, and the best achieved, by "
                      f"{by}). The ceiling is vacuous here (below {100 * VACUOUS:.0f} % of the best achieved: "
                      "docs/yardstick.md, \"What the ceiling cannot say\"); how much better a washout could be is "
                      f"known from the best achieved alone: {name} ({sig(value)}) is at least "
                      f"{sig(max(value - achieved, 0.0))} above it.", ""]  # fmt: skip
        else:
            frac = table[name]["score"]["recovered"]
            lines += [f"**The bracket: [{sig(ceiling)}, {sig(achieved)}]** (the ceiling, and the best achieved, by "
                      f"{by}). **{name} recovers {recovered_text(frac)} of what this platform could recover on this "
                      f"flight**; the best any motion can do lies inside the bracket.", ""]  # fmt: skip
    status = rec.get("solver_status") or {}
    bad = {k: v for k, v in status.items() if v not in ("Solved", "Exact")}
    if bad:
        lines += ["**The ceiling's solver did not converge on every DOF** (" +
                  ", ".join(f"{k}: {v}" for k, v in bad.items()) + "): those ceilings are not certified.", ""]
    below = rec.get("below_ceiling") or []
    if below:
        lines += [f"**{', '.join(below)} below the ceiling**: a defect (the ceiling is a lower bound on every "
                  "motion of this platform); please report it.", ""]  # fmt: skip
    relax = rec.get("relaxation") if isinstance(rec.get("relaxation"), dict) else {}
    if explain and relax.get("kind") == "hexapod":
        widened = [str(w) for w in relax.get("widened") or []]
        seen = (f"widened to what the washouts did where they went beyond ({', '.join(widened)}: the search missed "
                "them)" if widened else "every washout's motion was within them")  # fmt: skip
        lines += ["On a hexapod the relaxation's workspace and rate bounds (its largest tilt, travel, speeds and "
                  "rates) are found numerically, not proved (docs/yardstick.md), and " + seen + "; its rate bounds are "
                  "the leg Jacobian's worst pose, which makes this ceiling looser than the Atlas's.", ""]  # fmt: skip
        open_ = [name for name, key in (("rate", "rate_radps"), ("speed", "vel_mps"), ("acceleration", "acc_mps2"))
                 if None in (relax.get(key) or [])]  # fmt: skip
        if open_:
            lines += [f"**This hexapod reaches singular poses inside its legs' stroke** (its leg Jacobian cannot be "
                      f"inverted there): its {', '.join(open_)} bounds are unbounded (null in run.json), and the "
                      "ceiling does not limit them.", ""]  # fmt: skip
    return [*lines, CEILING_NOTE.format(measure=measure, vacuous=100 * VACUOUS), ""] if explain else lines


def _stat(v: object) -> str:
    """A count in full (``3865``), any other number to 3 significant digits, ``-`` when missing."""
    if isinstance(v, bool) or not isinstance(v, int | float):
        return "-"
    return str(int(v)) if float(v).is_integer() else sig(float(v))


def algorithm_lines(folder: Path) -> list[str]:
    """The Python washouts' own statistics (run.json ``algorithms``): the MPC's solves, fallbacks, brakes,
    inaccurate solves and iterations; empty when none reported any."""
    algs = _run_json(folder).get("algorithms") or {}
    algs = {k: v for k, v in algs.items() if isinstance(v, dict) and v}
    if not algs:
        return []
    keys = list(dict.fromkeys(k for v in algs.values() for k in v))
    lines = ["| washout | " + " | ".join(k.replace("_", " ") for k in keys) + " |", "|---|" + "---|" * len(keys)]
    for name, v in algs.items():
        lines.append(f"| {name} | " + " | ".join(_stat(v.get(k)) for k in keys) + " |")
    lines.append("")
    if any(float(v.get("fallbacks", 0.0)) > 0 for v in algs.values()):
        lines += ["A fallback is a step whose solve failed or whose first move failed the safety check: the last "
                  "accepted plan was continued, or (none left) the platform braked (`brakes`).", ""]  # fmt: skip
    return lines


__all__ = ["CEILING_NOTE", "algorithm_lines", "bound_lines", "read_ceiling", "recovered_text"]
