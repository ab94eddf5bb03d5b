"""The metric tables of one run as Markdown, for the recording's Metrics panel (a narrow column beside the plots).

First the ranking (rank, washout, score by the run's rule, lower is better; the oracle bound last, scored and not
ranked: a reference, not a washout) and, when the bound ran, the ceiling (the least score any motion of the platform
can reach on this flight, ``ceiling.csv``) as the table's last row with each washout's share recovered between a
still platform and the ceiling; then for each metric (NPC, integral of |error|, max |error|) a table with one
row per washout and one column per DOF: the width does not grow with the number of washouts (with seven the
washout-by-column layout ran off the panel). The best washout per DOF is in bold; the bound, a reference, is in
italics and never bold. Numbers have four significant digits. How much better than small-angle each washout is
(the paper's Table 4) is in the report.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import BOUND_WASHOUT, RankRow
from washbench.io.metrics_csv import MetricRow

__all__ = ["metrics_table_markdown"]

_UNITS = {"npc": ("", ""), "integral_error": ("m/s^2*s", "deg"), "max_error": ("m/s^2", "deg/s")}
_TITLES = {"npc": "NPC (1 perfect, larger worse)", "integral_error": "integral of |error|", "max_error": "max |error|"}


def _num(x: float) -> str:
    return "" if math.isnan(x) else f"{x:.4g}"


def _recovered(x: float | None) -> str:
    return "" if x is None or not math.isfinite(x) else f"{100.0 * x:.0f} %"


def _ranking_lines(ranking: Sequence[RankRow], rule_label: str, ceiling: Mapping[str, Any] | None = None
                   ) -> list[str]:  # fmt: skip
    """The ranking table; with ``ceiling`` (run.json's ``bound`` record) a column of the share recovered and the
    ceiling as the last row."""
    score = ((ceiling or {}).get("ceiling") or {}).get("score")
    recovered = (ceiling or {}).get("recovered") or {}
    with_ceiling = isinstance(score, int | float) and math.isfinite(score)
    column = "felt error" if rule_label.startswith("felt error") else "score"
    head = f"| rank | washout | {column} | recovered |" if with_ceiling else f"| rank | washout | {column} |"
    lines = ["", f"**Ranking** by {rule_label}; lower is better", "", head, "|---" * (head.count("|") - 1) + "|"]
    for r in ranking:
        got = _recovered((recovered.get(r.washout) or {}).get("score")) if with_ceiling else None
        extra = f" {got} |" if with_ceiling else ""
        if r.washout == BOUND_WASHOUT:
            shown = f" *{got}* |" if with_ceiling and got else extra
            lines.append(f"| - | *{r.washout}* (not ranked) | *{_num(r.score)}* |{shown}")
        else:
            lines.append(f"| {r.rank}{' (tie)' if r.tied else ''} | {r.washout} | {_num(r.score)} |{extra}")
    if with_ceiling:
        lines.append(f"| - | **ceiling** | **{_num(float(score))}** | 100 % |")
        lines += ["", "Ceiling: the least score any motion of the platform can reach on this flight (no washout scores "
                  "lower; report.md explains it). Recovered: the share of what a platform standing still leaves "
                  "that the washout recovers (100 %: the ceiling, 0 %: no better than standing still, below 0: "
                  "worse)."]  # fmt: skip
    if any(r.washout == BOUND_WASHOUT for r in ranking):
        lines += ["", "*bound*: the best achieved, a motion searched for with the whole flight known: a reference, not "
                  "ranked."]  # fmt: skip
    return lines


def metrics_table_markdown(
    title: str,
    rows: Sequence[MetricRow],
    ranking: Sequence[RankRow] = (),
    rule_label: str = "score",
    ceiling: Mapping[str, Any] | None = None,
) -> str:
    """Markdown: a heading, the ranking (when given; with the ceiling when ``ceiling``, run.json's ``bound``
    record, is given), and one washout-by-DOF table per metric."""
    washouts = list(dict.fromkeys(r.washout for r in rows))
    by = {(r.washout, r.dof): r for r in rows}
    lines = [f"# {title}"]
    if ranking:
        lines += _ranking_lines(ranking, rule_label, ceiling)
    reference = " (the oracle bound, in italics, is a reference)" if BOUND_WASHOUT in washouts else ""
    lines += ["", "Perceived motion of each simulator pilot against the aircraft pilot's; lower is better. Best "
              f"washout per DOF in bold{reference}."]  # fmt: skip
    for metric in ("npc", "integral_error", "max_error"):
        f_unit, w_unit = _UNITS[metric]
        unit = f" [{f_unit} / {w_unit}]" if f_unit else ""
        lines += ["", f"**{_TITLES[metric]}**{unit}", "", "| washout | " + " | ".join(DOFS) + " |"]
        lines.append("|" + "---|" * (1 + len(DOFS)))
        best = {}
        for dof in DOFS:
            finite = [getattr(by[(w, dof)], metric) for w in washouts if (w, dof) in by and w != BOUND_WASHOUT]
            finite = [v for v in finite if not math.isnan(v)]
            best[dof] = min(finite) if len(finite) > 1 else math.nan
        for w in washouts:
            cells = [f"*{w}*" if w == BOUND_WASHOUT else w]
            for dof in DOFS:
                v = getattr(by[(w, dof)], metric) if (w, dof) in by else math.nan
                if w == BOUND_WASHOUT:
                    cells.append(f"*{_num(v)}*" if not math.isnan(v) else "")
                else:
                    cells.append(f"**{_num(v)}**" if v == best[dof] else _num(v))
            lines.append("| " + " | ".join(cells) + " |")
        if metric == "npc" and any(math.isnan(getattr(r, metric)) for r in rows if r.washout != BOUND_WASHOUT):
            lines += ["", "A blank NPC: not defined (a simulator pilot who perceives no change there, as on a "
                      "platform standing still, has nothing to correlate)."]  # fmt: skip
    return "\n".join(lines) + "\n"
