"""The metric tables of one run as Markdown, for the recording's Metrics panel (a narrow column beside the plots).

First the ranking (rank, washout, score by the run's rule, lower is better; the oracle bound last, scored and not
ranked: a reference, not a washout), then for each metric (NPC, integral of |error|, max |error|) a table with one
row per washout and one column per DOF: the width does not grow with the number of washouts (with seven the
washout-by-column layout ran off the panel). The best washout per DOF is in bold; the bound, a reference, is in
italics and never bold. Numbers have four significant digits. How much better than small-angle each washout is
(the paper's Table 4) is in the report.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import BOUND_WASHOUT, RankRow
from washbench.io.metrics_csv import MetricRow

__all__ = ["metrics_table_markdown"]

_UNITS = {"npc": ("", ""), "integral_error": ("m/s^2*s", "deg"), "max_error": ("m/s^2", "deg/s")}
_TITLES = {"npc": "NPC (1 perfect, larger worse)", "integral_error": "integral of |error|", "max_error": "max |error|"}


def _num(x: float) -> str:
    return "" if math.isnan(x) else f"{x:.4g}"


def _ranking_lines(ranking: Sequence[RankRow], rule_label: str) -> list[str]:
    lines = ["", f"**Ranking** by {rule_label}; lower is better", "", "| rank | washout | score |", "|---|---|---|"]
    for r in ranking:
        if r.washout == BOUND_WASHOUT:
            lines.append(f"| - | *{r.washout} (oracle bound, not ranked)* | *{_num(r.score)}* |")
        else:
            lines.append(f"| {r.rank}{' (tie)' if r.tied else ''} | {r.washout} | {_num(r.score)} |")
    return lines


def metrics_table_markdown(
    title: str, rows: Sequence[MetricRow], ranking: Sequence[RankRow] = (), rule_label: str = "score"
) -> str:
    """Markdown: a heading, the ranking (when given), and one washout-by-DOF table per metric."""
    washouts = list(dict.fromkeys(r.washout for r in rows))
    by = {(r.washout, r.dof): r for r in rows}
    lines = [f"# {title}"]
    if ranking:
        lines += _ranking_lines(ranking, rule_label)
    lines += ["", "Perceived motion of each simulator pilot against the aircraft pilot's; lower is better. Best "
              "washout per DOF in bold (the oracle bound, in italics, is a reference)."]  # fmt: skip
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
    return "\n".join(lines) + "\n"
