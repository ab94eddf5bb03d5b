"""The ceiling, the bound's replay and the Python washouts' own statistics in the outputs of ``run``, ``cue`` and
``suite``.

``--washout bound`` (opt-in, docs/optimal-mpc.md, docs/metrics.md) adds, once the whole motion is known:

- the bound's replay (:class:`washbench.analysis.bound_replay.BoundWashout`, :mod:`washbench.analysis.bound_replay`): a
  physical platform motion planned with the whole flight known, replayed through the platform model like any
  washout: its rows in ``metrics.csv``, its score in ``ranking.csv`` (no rank: it knows the future) and its columns
  in ``traces.parquet``;
- ``ceiling.csv``: the ceiling of the flight on the ranking's own measure (:mod:`washbench.analysis.ceiling`: the
  least relative error, per DOF and in the score, that any motion of the platform model can reach, certified) and
  every washout's relative errors and recovered fractions beside it; the same in ``run.json`` (``bound``) and the
  report.

A ``run`` flies its washouts in lockstep with JSBSim; a washout that needs the whole recording
(:func:`washbench.cueing.registry.whole_only`) is cued after the flight, on the flight read back
(:func:`split_whole`, :func:`with_whole`), so ``run`` and ``fly`` + ``cue`` give the same numbers.

``algorithms`` (run.json): what the Python washouts report of themselves (``report()``, e.g. the MPC's solves,
fallbacks and iterations), :func:`washbench.cueing.bank.CueingBank.algorithm_reports`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from washbench.analysis.felt import felt_key
from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import BOUND_WASHOUT, DEFAULT_RULE, MOTION_FLOOR, perceived_motion, rule_values
from washbench.analysis.relaxation import observed, relaxation_of, widened
from washbench.cueing.registry import whole_only
from washbench.io.atomic import write_text_atomic
from washbench.io.csv_numbers import csv_number
from washbench.platform.model import platform_kind
from washbench.runs.chain import analyse, from_lockstep, stacked_rows

CEILING_FILE = "ceiling.csv"
CEILING_COLUMNS = ("washout", "dof", "relative_error", "ceiling", "recovered")
"""``ceiling.csv``: per washout (the bound's replay included, as ``bound``) one row for the ranking's value
(``dof`` ``score``) and one per degree of freedom: its relative error (the rule's term of that DOF over what the
aircraft pilot felt there: ``(E_d + lambda F_d + tau_j J_d) / M_d`` for the felt error, ``E_d / M_d`` for the score),
the ceiling there (the least any motion of this platform can reach, :mod:`washbench.analysis.ceiling`) and the
fraction of what a still platform leaves to recover that it recovers, ``(still - value) / (still - ceiling)``
(still: 1 per DOF, the sum of the weights for the score). Empty cells: a DOF the aircraft pilot did not feel (no
weight), or a rule with no ceiling (``false-cue``)."""

def split_whole(specs: Sequence[Any]) -> tuple[list[Any], list[Any]]:
    """The washouts (``Washout`` variants) that run sample by sample, and those that need the whole recording."""

    whole = [s for s in specs if whole_only(s.kind, s.source, s.params.sections.get(s.kind))]
    return [s for s in specs if s not in whole], whole


def with_whole(
    traces: Mapping[str, Any], motion: Any, whole: Sequence[Any], order: Sequence[str], limits: Any, filter_start: str,
    reports: dict[str, Any] | None = None,
) -> dict[str, Any]:  # fmt: skip
    """``traces`` (the lockstep's) and the whole-only washouts cued on ``motion`` (the flight read back), in the
    order ``order`` (every washout's name, as listed); ``reports`` (when given) receives what those washouts report
    of themselves (run.json ``algorithms``: the bound's solves, the MPC's with preview)."""
    from washbench.cueing import cue_trace  # deferred: numba

    if not whole:
        return dict(traces)
    extra = cue_trace(motion.f_mps2, motion.omega_radps, motion.dt_s, whole, None, limits, filter_start,
                      reports=reports)  # fmt: skip
    both = {**traces, **extra}
    return {name: both[name] for name in order}


def lockstep_result(motion: Any, rows: list[Any], options: Any) -> Any:
    """:func:`washbench.runs.chain.from_lockstep` with the whole-only washouts of ``options`` (a
    :class:`washbench.runs.options.RunOptions`; they were not in the lockstep) cued here on ``motion``, the flight
    read back, and put in their listed order; the result's ``algorithms`` hold what those report of themselves (the
    lockstep's own washouts report through the lockstep's ``reports``)."""
    from washbench.cueing import WashoutTrace  # deferred: numba

    stepped, whole = split_whole(options.washouts)
    if not whole:
        return from_lockstep(motion, rows, options.washout_order, options.vestibular_params, options.filter_start,
                             platform_kind(options.limits), options.rank_rule.measure)  # fmt: skip
    block = stacked_rows(rows)  # (washouts, N, fields)
    kind = platform_kind(options.limits)
    traces = {w.name: WashoutTrace.from_rows(block[i], platform=kind) for i, w in enumerate(stepped)}
    del block
    reports: dict[str, Any] = {}
    traces = with_whole(traces, motion, whole, options.washout_order, options.limits, options.filter_start, reports)
    result = analyse(motion, traces, options.vestibular_params, options.filter_start, options.rank_rule.measure)
    return dataclasses.replace(result, algorithms=reports)


def bound_spec(specs: Sequence[Any]) -> Any | None:
    """The washout named ``bound`` (kind ``bound``) among ``specs``, or None."""
    return next((s for s in specs if s.name == BOUND_WASHOUT and s.kind == BOUND_WASHOUT), None)


def bound_outputs(
    folder: Path,
    result: Any,
    specs: Sequence[Any],
    limits: Any,
    vestibular: Any = None,
    rule: Any = None,
    filter_start: str = "steady",
) -> dict[str, Any] | None:
    """When the bound runs: compute the ceiling of the flight (:func:`washbench.analysis.ceiling.ceiling`) on the
    ranking's own measure, write ``folder/ceiling.csv`` (atomically) with every washout's relative errors, the
    ceiling and the recovered fractions (total and per DOF), and return the ``bound`` record for run.json; else
    None. ``result``: the run's :class:`washbench.runs.chain.CueResult` (metrics and the aircraft pilot's perceived
    motion); ``rule``: the run's ranking rule (None: the default score)."""
    spec = bound_spec(specs)
    if spec is None:
        (folder / CEILING_FILE).unlink(missing_ok=True)  # an earlier run's ceiling would not be this run's
        return None
    from washbench.analysis.ceiling import ceiling  # deferred: scipy.sparse

    rule = DEFAULT_RULE if rule is None else rule
    dt_s = result.motion.dt_s
    ac = result.perceived["aircraft"]
    motion = perceived_motion(ac.f_mps2, ac.omega_radps, dt_s, rule.measure)
    felt_rule = rule.by == "felt"
    # the relaxation must hold every washout's head: the largest head offset any of them uses
    offsets = [tuple(s.params.head.offset_m) for s in specs if hasattr(s.params, "head")]
    offset = max(offsets, key=lambda o: math.hypot(*o)) if offsets else (0.0, 0.0, 0.0)
    head = result.motion  # the aircraft pilot's head motion: a DOF it can follow exactly needs no programme
    gravity = spec.params.gravity_mps2
    # the relaxation of this platform (docs/yardstick.md), widened to every washout's own motion where a hexapod's
    # numerically found bounds missed it (recorded: ``relaxation.widened``)
    relax, grown = relaxation_of(limits, dt_s, gravity), []
    if relax.kind != "atlas":  # (the Atlas's bounds are its limits; a streamed cue keeps no attitudes for it)
        relax, grown = widened(relax, observed(result.traces, dt_s, gravity))
    ceil = ceiling(ac.f_mps2, ac.omega_radps, dt_s, relax, gravity, vestibular, filter_start, offset, head.f_mps2,
                   head.omega_radps, rule.measure if felt_rule else None)  # fmt: skip
    floor = ceil.relative(motion)
    values, weights = rule_values(result.metrics, motion, rule)
    scored = rule.by != "false-cue"
    still = sum(weights.values()) if scored else math.nan
    if felt_rule:
        total_ceiling = ceil.felt_score(motion)
    else:
        total_ceiling = sum(weights[d] * floor[d] for d in DOFS if weights[d] > 0.0) if scored else math.nan
    by_key = {(r.washout, r.dof): r for r in result.metrics}
    names = [s.name for s in specs]

    def relative(n: str, d: str) -> float:
        """The washout's relative error in DOF d under the rule (NaN where the pilot felt nothing there)."""
        if felt_rule:
            m = motion[felt_key(d)]
            if m <= 0.0:
                return math.nan
            r, ms = by_key[(n, d)], rule.measure
            jolt = 0.0 if math.isnan(r.jolt) else r.jolt
            return (r.felt_error + ms.false_weight * r.felt_false + ms.jolt_time_s * jolt) / m
        return by_key[(n, d)].integral_error / motion[d] if motion[d] >= MOTION_FLOOR[d] else math.nan

    def recovered(value: float, top: float, low: float) -> float:
        span = top - low
        return (top - value) / span if math.isfinite(value) and span > 0.0 else math.nan

    table: dict[str, dict[str, dict[str, float]]] = {}
    for n in names:
        rows = {"score": {"relative_error": values[n], "ceiling": total_ceiling,
                          "recovered": recovered(values[n], still, total_ceiling)}}  # fmt: skip
        for d in DOFS:
            rel = relative(n, d)
            low = floor[d] if math.isfinite(rel) else math.nan
            rows[d] = {"relative_error": rel, "ceiling": low, "recovered": recovered(rel, 1.0, low)}
        table[n] = rows
    lines = [",".join(CEILING_COLUMNS)]
    for n, rows in table.items():
        for dof, cells in rows.items():
            lines.append(",".join([n, dof, *(csv_number(float(cells[c])) if math.isfinite(cells[c]) else ""
                                             for c in CEILING_COLUMNS[2:])]))  # fmt: skip
    write_text_atomic(folder / CEILING_FILE, "\n".join(lines) + "\n")

    def num(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None

    below = sorted({n for n, rows in table.items() for cells in rows.values()
                    if math.isfinite(cells["relative_error"]) and math.isfinite(cells["ceiling"])
                    and cells["relative_error"] < cells["ceiling"] - 1e-9 * max(1.0, cells["ceiling"])})  # fmt: skip
    return {
        "measure": rule.by,
        "ceiling": {"score": num(total_ceiling), **{d: num(floor[d]) for d in DOFS}},
        "floor_integral_error": {d: num(ceil.floor[d]) for d in DOFS},
        "solver_status": ceil.status,
        "relative_error": {n: {k: num(v["relative_error"]) for k, v in rows.items()} for n, rows in table.items()},
        "recovered": {n: {k: num(v["recovered"]) for k, v in rows.items()} for n, rows in table.items()},
        "below_ceiling": below,
        "relaxation": {**relax.record(), "widened": grown},
    }


__all__ = [
    "CEILING_COLUMNS",
    "CEILING_FILE",
    "bound_outputs",
    "bound_spec",
    "lockstep_result",
    "split_whole",
    "with_whole",
]
