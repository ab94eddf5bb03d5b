"""Where each washout's felt error comes from, for a run's report: its part per DOF and the shares of false cues and
of the platform's jolts (:mod:`washbench.analysis.felt`).

The felt error is ``S = sum_d (E_d + lambda F_d + tau_j J_d) / T_d / max(sum_d M_d / T_d, D_min)``; the part of DOF
``d`` is that sum's term ``d`` over the same denominator, so a row's parts add up to the washout's felt error (the
ranking's value). The false share is ``sum_d lambda F_d / T_d`` over the numerator, the jolts' share
``sum_d tau_j J_d / T_d`` over it: what the false part counted once more and the jolts add to the perceived error
beyond the thresholds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from washbench.analysis.felt import FeltMeasure, dof_terms, felt_total
from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import BOUND_WASHOUT, RankRow, felt_of
from washbench.io.metrics_csv import MetricRow
from washbench.review.numbers import sig

__all__ = ["felt_breakdown", "felt_breakdown_lines"]

NOTE = (
    "Each DOF's part of the felt error (the parts add up to it): its perceived error beyond the thresholds, its false "
    "part once more and (surge, sway, heave) the platform's jolts, in threshold units, over the motion the aircraft "
    "pilot felt above threshold. False and jolts: their shares of the washout's felt error."
)


def felt_breakdown(
    rows: Sequence[MetricRow], motion: Mapping[str, float], measure: FeltMeasure
) -> dict[str, tuple[np.ndarray, float, float]]:
    """washout -> (its part per DOF (6,), the false share, the jolts' share) of its felt error; empty for a result
    written before the felt error (no felt motion or no felt columns)."""
    felt = felt_of(motion)
    if felt is None:
        return {}
    total = felt_total(felt, measure)
    by = {(r.washout, r.dof): r for r in rows}
    out: dict[str, tuple[np.ndarray, float, float]] = {}
    for w in dict.fromkeys(r.washout for r in rows):
        if not all((w, d) in by for d in DOFS):
            continue
        e = np.array([by[(w, d)].felt_error for d in DOFS], dtype=float)
        f = np.array([by[(w, d)].felt_false for d in DOFS], dtype=float)
        j = np.nan_to_num(np.array([by[(w, d)].jolt for d in DOFS[:3]], dtype=float))
        if not (np.all(np.isfinite(e)) and np.all(np.isfinite(f))):
            continue
        terms = dof_terms(e, f, j, measure)
        numerator = float(np.sum(terms))
        units = measure.units()
        false = float(np.sum(measure.false_weight * f / units))
        jolts = float(np.sum(measure.jolt_time_s * j / units[:3]))
        scale = 1.0 / numerator if numerator > 0.0 else 0.0
        out[w] = (terms / total, false * scale, jolts * scale)
    return out


def _part(x: float) -> str:
    """A DOF's part: three significant digits, a part below 0.00005 (nothing a reader would weigh) as ``< 0.0001``."""
    return "< 0.0001" if 0.0 < x < 5e-5 else sig(x)


def felt_breakdown_lines(
    rows: Sequence[MetricRow], motion: Mapping[str, float], measure: FeltMeasure, ranking: Sequence[RankRow]
) -> list[str]:
    """The breakdown as a Markdown table, the washouts in the ranking's order (the bound in italics); no lines for a
    result written before the felt error."""
    parts = felt_breakdown(rows, motion, measure)
    if not parts:
        return []
    order = [r.washout for r in ranking if r.washout in parts] or list(parts)
    lines = ["**Where the felt error comes from**", "",
             "| washout | " + " | ".join(DOFS) + " | felt error | false | jolts |",
             "|---|" + "---|" * (len(DOFS) + 3)]  # fmt: skip

    def pct(x: float) -> str:
        return f"{100.0 * x:.0f} %" if math.isfinite(x) else ""

    for w in order:
        terms, false, jolts = parts[w]
        name = f"*{w}*" if w == BOUND_WASHOUT else w
        cells = [_part(float(v)) for v in terms] + [sig(float(np.sum(terms))), pct(false), pct(jolts)]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return [*lines, "", NOTE, ""]
