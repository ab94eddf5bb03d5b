"""The metric table of one run as Markdown, laid out like the paper's Table 4: one row per DOF, one column per washout.

For each metric (NPC, integral of |error|, max |error|) a table with the DOFs as rows and, per washout, its value and,
for every washout after the first (the reference, small-angle in the bundled order), how much better it is than the
reference: ``reference - washout``, positive means closer to the aircraft pilot (every metric is lower-is-better). The
best value in each row is in bold. Numbers have four significant digits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from washbench.analysis.metrics import DOFS
from washbench.io.metrics_csv import MetricRow

__all__ = ["metrics_table_markdown"]

_UNITS = {"npc": ("", ""), "integral_error": ("m/s^2*s", "deg"), "max_error": ("m/s^2", "deg/s")}
_TITLES = {"npc": "NPC (1 perfect, larger worse)", "integral_error": "integral of |error|", "max_error": "max |error|"}


def _num(x: float) -> str:
    return "" if math.isnan(x) else f"{x:.4g}"


def _diff(x: float) -> str:
    return "" if math.isnan(x) else f"{x:+.3g}"


def metrics_table_markdown(title: str, rows: Sequence[MetricRow]) -> str:
    """Markdown: a heading, one line on how to read it, and one DOF-by-washout table per metric."""
    washouts = list(dict.fromkeys(r.washout for r in rows))
    by = {(r.washout, r.dof): r for r in rows}
    ref = washouts[0] if washouts else ""
    lines = [
        f"# {title}",
        "",
        f"Perceived motion of each simulator pilot against the aircraft pilot's; lower is better. "
        f"*better by* = {ref} minus that washout (positive: closer to the aircraft than {ref}). Best per row in bold.",
    ]
    for metric in ("npc", "integral_error", "max_error"):
        f_unit, w_unit = _UNITS[metric]
        unit = f" [{f_unit} / {w_unit}]" if f_unit else ""
        header = ["DOF"]
        for w in washouts:
            header.append(w)
            if w != ref:
                header.append("better by")
        lines += ["", f"**{_TITLES[metric]}**{unit}", "", "| " + " | ".join(header) + " |"]
        lines.append("|" + "---|" * len(header))
        for dof in DOFS:
            values = {w: getattr(by[(w, dof)], metric) for w in washouts if (w, dof) in by}
            finite = [v for v in values.values() if not math.isnan(v)]
            best = min(finite) if finite else math.nan
            cells = [dof]
            for w in washouts:
                v = values.get(w, math.nan)
                cells.append(f"**{_num(v)}**" if v == best and len(finite) > 1 else _num(v))
                if w != ref:
                    cells.append(_diff(values.get(ref, math.nan) - v))
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
