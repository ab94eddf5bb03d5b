"""Parameter sweeps: grids of washout parameter sets, and the tables they give (pure functions, no files).

A grid is every combination of the values listed per key (``--set KEY=V1,V2,...``), the keys being dotted keys of
the parameter file (:func:`washbench.cueing.variants.check_key`). Each grid point is a complete parameter set: the
base set with the point's values. Values are numbers, ``off`` for a limit that can be switched off, or a word for
a choice (``norm``, ``axis``, ``before_cross_product`` ...).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from washbench.analysis.metrics import DOFS
from washbench.cueing import registry
from washbench.cueing.params import WashoutParams
from washbench.cueing.variants import Washout, apply_overrides, check_key, check_kind, parse_value
from washbench.errors import WashbenchError
from washbench.io.csv_numbers import csv_number

if TYPE_CHECKING:  # the compiled evaluator (numba) is imported by what evaluates, not by what parses a --set
    from washbench.analysis.evaluate import Evaluation


@dataclass(frozen=True)
class Axis:
    """One swept key and its values, in the order given."""

    key: str
    values: tuple[Any, ...]


def parse_set(text: str) -> Axis:
    """``KEY=V1,V2,...`` (one ``--set``) into an Axis; WashbenchError naming the key if it is bad."""
    key, eq, values = text.partition("=")
    key = key.strip()
    where = f"--set {text}"
    if not eq or not values.strip():
        raise WashbenchError(f"{where}: expected KEY=V1,V2,...")
    check_key(key, where)
    parsed = tuple(parse_value(v) for v in values.split(","))
    same = [float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else repr(v) for v in parsed]
    if len(set(same)) != len(same):  # 1 and 1.0 are the same value
        raise WashbenchError(f"{where}: a value is listed twice")
    return Axis(key, parsed)


def grid(axes: Sequence[Axis]) -> list[dict[str, Any]]:
    """Every combination of the axes' values (the last axis varies fastest)."""
    keys = [a.key for a in axes]
    if len(set(keys)) != len(keys):
        raise WashbenchError(f"--set: a key is swept twice: {', '.join(keys)}")
    return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*(a.values for a in axes))]


def point_washouts(kind: str, base: WashoutParams, points: Sequence[Mapping[str, Any]]) -> list[Washout]:
    """One Washout of ``kind`` per grid point (named after the kind), each validated like a parameter file."""
    check_kind(kind, "--washout")
    out = []
    for point in points:
        where = "--set " + ",".join(f"{k}={format_value(v)}" for k, v in point.items())
        out.append(Washout(kind, kind, apply_overrides(base, point, where), registry.plugin_spec(kind)))
    return out


def format_value(value: Any) -> str:
    """A grid value as written in the CSV and on figures (``off`` for a switched-off limit)."""
    if value is False or value is None:
        return "off"
    if isinstance(value, float):
        return csv_number(value)
    return str(value)


@dataclass(frozen=True)
class SweepRow:
    """One grid point of one washout on one flight."""

    point: Mapping[str, Any]
    washout: str
    aircraft: str
    manoeuvre: str
    evaluation: Evaluation
    index: int  # the candidate's index in the evaluation


def sweep_csv(keys: Sequence[str], rows: Sequence[SweepRow]) -> list[list[str]]:
    """``sweep.csv``: one row per grid point and manoeuvre (swept keys, washout, aircraft, manoeuvre, score,
    saturated_s)."""
    out = [[*keys, "washout", "aircraft", "manoeuvre", "score", "saturated_s"]]
    for r in rows:
        ev, i = r.evaluation, r.index
        out.append(
            [
                *(format_value(r.point[k]) for k in keys),
                r.washout,
                r.aircraft,
                r.manoeuvre,
                csv_number(float(ev.score[i])),
                csv_number(float(ev.saturated_s[i])),
            ]
        )
    return out


def sweep_metrics_csv(keys: Sequence[str], rows: Sequence[SweepRow]) -> list[list[str]]:
    """``sweep_metrics.csv``: the rows of sweep.csv times DOF, with npc, integral_error, max_error."""
    out = [[*keys, "washout", "aircraft", "manoeuvre", "dof", "npc", "integral_error", "max_error"]]
    for r in rows:
        ev, i = r.evaluation, r.index
        for j, d in enumerate(DOFS):
            out.append(
                [
                    *(format_value(r.point[k]) for k in keys),
                    r.washout,
                    r.aircraft,
                    r.manoeuvre,
                    d,
                    csv_number(float(ev.npc[i, j])),
                    csv_number(float(ev.integral_error[i, j])),
                    csv_number(float(ev.max_error[i, j])),
                ]
            )
    return out
