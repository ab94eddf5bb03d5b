"""The report's lines on the oracle bound (``bound.csv``) and on the Python washouts' own statistics (``run.json``:
``algorithms``, e.g. the MPC's solves and fallbacks), from a result folder's files (docs/optimal-mpc.md)."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

from washbench.review.numbers import sig

BOUND_FILE = "bound.csv"

BOUND_CAVEAT = (
    "The bound is the platform motion that minimises this cost (each pilot's perceived specific force and angular "
    "velocity through the vestibular models, squared error, rotation weighted {rate:g} against force {force:g}) under "
    "the platform's limits with the whole flight known in advance: no washout can do better **on this cost**. It is "
    "optimal for this cost only, not for every metric: its score and metrics above (the `bound` rows: its motion "
    "replayed through the platform model from rest, so its cost there is a little above the optimum) can be beaten "
    "by a washout on a metric it does not minimise."
)


def _read_bound(folder: Path) -> list[dict[str, str]]:
    path = folder / BOUND_FILE
    if not path.is_file():
        return []
    try:
        with path.open(newline="") as f:
            return [r for r in csv.DictReader(f) if r.get("washout")]
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


def bound_lines(folder: Path) -> list[str]:
    """"This washout recovers X % of what is recoverable on this platform": every washout's cost beside the
    bound's, from ``bound.csv``; empty when the bound did not run."""
    rows = _read_bound(folder)
    if not rows:
        return []
    j_bound = _float(rows[0].get("cost_bound"))
    j_still = _float(rows[0].get("cost_still"))
    rec = _run_json(folder).get("bound") or {}
    weights = rec.get("weights") or {"force": 1.0, "rate": 10.0}
    lines = [
        "| washout | cost J (-) | recovers (of what is recoverable on this platform) |",
        "|---|---|---|",
    ]
    above = []
    for r in rows:
        j = _float(r.get("cost"))
        name = r["washout"]
        label = f"{name} (replayed)" if name == "bound" else name
        lines.append(f"| {label} | {sig(j)} | {recovered_text(_float(r.get('recovered')))} |")
        if math.isfinite(j) and j < j_bound * (1.0 - 1e-6):
            above.append(name)
    lines += [
        f"| **oracle bound** (optimum) | **{sig(j_bound)}** | 100 % |",
        f"| _platform standing still_ | {sig(j_still)} | 0 % |",
        "",
    ]
    best = [(r["washout"], _float(r.get("recovered"))) for r in rows if r["washout"] != "bound"]
    best = [b for b in best if math.isfinite(b[1])]
    if best:
        name, frac = max(best, key=lambda b: b[1])
        share = sig(100 * j_bound / j_still)
        lines += [f"**{name} recovers {recovered_text(frac)} of what is recoverable on this platform** "
                  f"(recovered = (J_still - J) / (J_still - J_bound); the bound's cost is {share} % of a still "
                  "platform's).", ""]  # fmt: skip
    elif j_still > 0 and math.isfinite(j_bound):
        lines += ["Nothing is recoverable on this platform: the bound is no better than standing still.", ""]
    status = rec.get("solver_status") or {}
    bad = {k: v for k, v in status.items() if v != "Solved"}
    if bad:
        lines += ["**The bound's solver did not converge on every channel** (" +
                  ", ".join(f"{k}: {v}" for k, v in bad.items()) + "): its cost is not a proven bound.", ""]
    if above:
        lines += [f"**{', '.join(above)} below the bound**: one of them is wrong (the bound is a lower bound on "
                  "every washout's cost).", ""]  # fmt: skip
    force, rate = float(weights.get("force", 1.0)), float(weights.get("rate", 10.0))
    return [*lines, BOUND_CAVEAT.format(force=force, rate=rate), ""]


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


__all__ = ["BOUND_CAVEAT", "algorithm_lines", "bound_lines", "recovered_text"]
