"""The oracle bound and the Python washouts' own statistics in the outputs of ``run``, ``cue`` and ``suite``.

``--washout bound`` (opt-in, docs/optimal-mpc.md) adds, once the whole motion is known:

- the bound's motion replayed through the platform model like any washout (:class:`washbench.analysis.bound.
  BoundWashout`): its rows in ``metrics.csv``, its score in ``ranking.csv`` (no rank: it knows the future, and it is
  optimal for its own cost, not for the score) and its columns in ``traces.parquet``;
- ``bound.csv``: every washout's value of the bound's cost J (:func:`washbench.analysis.bound.washout_cost`) beside
  the bound's own optimum and a still platform's, and the fraction of the recoverable cost it recovers,
  ``recovered = (J_still - J) / (J_still - J_bound)``; the same in ``run.json`` (``bound``) and the report.

A ``run`` flies its washouts in lockstep with JSBSim; a washout that needs the whole recording
(:func:`washbench.cueing.registry.whole_only`) is cued after the flight, on the flight read back
(:func:`split_whole`, :func:`with_whole`), so ``run`` and ``fly`` + ``cue`` give the same numbers.

``algorithms`` (run.json): what the Python washouts report of themselves (``report()``, e.g. the MPC's solves,
fallbacks and iterations), :func:`washbench.cueing.bank.CueingBank.algorithm_reports`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from washbench.analysis.ranking import BOUND_WASHOUT
from washbench.cueing.registry import whole_only
from washbench.io.atomic import write_text_atomic
from washbench.io.columns import acc_columns, f_columns, omega_columns, omega_platform_columns, q_columns
from washbench.io.csv_numbers import csv_number
from washbench.platform.model import platform_kind
from washbench.runs.chain import analyse, from_lockstep, stacked_rows

BOUND_FILE = "bound.csv"
BOUND_COLUMNS = ("washout", "cost", "cost_bound", "cost_still", "recovered")
"""``bound.csv``: per washout (the bound's replay through the platform included, as ``bound``) its cost J, the
bound's optimum J_bound, a still platform's J_still (the same on every row) and the recovered fraction."""


def split_whole(specs: Sequence[Any]) -> tuple[list[Any], list[Any]]:
    """The washouts (``Washout`` variants) that run sample by sample, and those that need the whole recording."""

    whole = [s for s in specs if whole_only(s.kind, s.source)]
    return [s for s in specs if s not in whole], whole


def with_whole(
    traces: Mapping[str, Any], motion: Any, whole: Sequence[Any], order: Sequence[str], limits: Any, filter_start: str
) -> dict[str, Any]:
    """``traces`` (the lockstep's) and the whole-only washouts cued on ``motion`` (the flight read back), in the
    order ``order`` (every washout's name, as listed)."""
    from washbench.cueing import cue_trace  # deferred: numba

    if not whole:
        return dict(traces)
    extra = cue_trace(motion.f_mps2, motion.omega_radps, motion.dt_s, whole, None, limits, filter_start)
    both = {**traces, **extra}
    return {name: both[name] for name in order}


def lockstep_result(motion: Any, rows: list[Any], options: Any) -> Any:
    """:func:`washbench.runs.chain.from_lockstep` with the whole-only washouts of ``options`` (a
    :class:`washbench.runs.options.RunOptions`; they were not in the lockstep) cued here on ``motion``, the flight
    read back, and put in their listed order."""
    from washbench.cueing import WashoutTrace  # deferred: numba

    stepped, whole = split_whole(options.washouts)
    if not whole:
        return from_lockstep(motion, rows, options.washout_order, options.vestibular_params, options.filter_start,
                             platform_kind(options.limits))  # fmt: skip
    block = stacked_rows(rows)  # (washouts, N, fields)
    kind = platform_kind(options.limits)
    traces = {w.name: WashoutTrace.from_rows(block[i], platform=kind) for i, w in enumerate(stepped)}
    del block
    traces = with_whole(traces, motion, whole, options.washout_order, options.limits, options.filter_start)
    return analyse(motion, traces, options.vestibular_params, options.filter_start)


def bound_spec(specs: Sequence[Any]) -> Any | None:
    """The washout named ``bound`` (kind ``bound``) among ``specs``, or None."""
    return next((s for s in specs if s.name == BOUND_WASHOUT and s.kind == BOUND_WASHOUT), None)


def bound_outputs(
    folder: Path, traces_path: Path, dt_s: float, specs: Sequence[Any], limits: Any, vestibular: Any = None
) -> dict[str, Any] | None:
    """When the bound runs: compute every washout's cost from ``traces_path`` (a finished traces.parquet), write
    ``folder/bound.csv`` (atomically) and return the ``bound`` record for run.json; else None.

    The bound is solved again here with a free start (any position, attitude and rate within the limits), which
    every washout's trajectory satisfies: J_bound <= J of every washout. Its cost weights are the parameter file's
    ``bound:`` section; ``vestibular`` the run's vestibular model (None: the default)."""
    spec = bound_spec(specs)
    if spec is None:
        return None
    import pyarrow.parquet as pq

    from washbench.analysis.bound import BoundParams, costs_from_columns  # deferred: scipy.sparse

    params = BoundParams.model_validate(spec.params.sections.get(BOUND_WASHOUT) or {})
    names = [s.name for s in specs]
    wanted = [*f_columns("aircraft"), *omega_columns("aircraft")]
    for n in names:
        wanted += [*acc_columns(n), *omega_platform_columns(n), *q_columns(n)]
    table = pq.read_table(traces_path, columns=wanted)
    cols = {c: table.column(c).to_numpy() for c in table.column_names}
    res, costs = costs_from_columns(cols, dt_s, limits, spec.params.gravity_mps2, params, vestibular)
    costs = {n: costs[n] for n in names}
    recovered = {n: res.recovered(c) for n, c in costs.items()}
    lines = [",".join(BOUND_COLUMNS)]
    for n in names:
        cells = (costs[n], res.cost, res.cost_still, recovered[n])
        lines.append(",".join([n, *(csv_number(float(x)) for x in cells)]))
    write_text_atomic(folder / BOUND_FILE, "\n".join(lines) + "\n")

    def num(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None

    return {
        "cost_bound": res.cost,
        "cost_still": res.cost_still,
        "channel_costs": res.channel_costs,
        "solver_status": res.statuses,
        "weights": {"force": params.force_weight, "rate": params.rate_weight},
        "costs": costs,
        "recovered": {n: num(v) for n, v in recovered.items()},
        "above_bound": [n for n, c in costs.items() if c < res.cost * (1.0 - 1e-6)],
    }


__all__ = ["BOUND_COLUMNS", "BOUND_FILE", "bound_outputs", "bound_spec", "lockstep_result", "split_whole", "with_whole"]
