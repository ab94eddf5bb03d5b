"""``washbench tune``: tune a washout's parameters on training manoeuvres, check them on test manoeuvres.

Minimises ``mean score over the training flights + saturation_weight * mean fraction of time at a platform limit``
(:mod:`washbench.analysis.tune` says why a penalty and why differential evolution) within ``--budget``
evaluations, deterministic for ``--seed``. Flights are flown once (or read with ``--from``); every evaluation is a
batch member of one compiled call per flight. Writes, each atomically:

- ``DIR/tuned.yaml``: a complete parameter file (loadable with ``--params``) with the tuned values;
- ``DIR/tune.csv``: every evaluation (index 0 is the starting set): ``index``, the tuned keys, ``score`` (mean
  over the training flights), ``saturated_s`` (summed over them), ``objective``;
- ``DIR/report.md`` and ``DIR/convergence.png``: the base set (e.g. CW1) against the tuned set on the training and
  the test manoeuvres.

With ``--pilot TASK`` the objective adds ``pilot_weight x D / 100``: the distance from flight of the pilot model's
measures on the tracking task (:mod:`washbench.pilot.surrogate`, predicted by its adaptation, no flight per
evaluation; an unstable loop counts as infinitely far); ``tune.csv`` gains a column ``pilot_distance_pct`` and the
report the distance of the starting and the tuned set.
"""

from __future__ import annotations

import csv
import io
import sys
import time
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from washbench.analysis.sweep import format_value
from washbench.analysis.tune import EDGE_FRACTION, Bound, at_edges, minimise, parse_tune
from washbench.cueing import registry
from washbench.cueing.params import WashoutParams
from washbench.cueing.variants import (
    Washout,
    apply_overrides,
    check_kind,
    check_platform,
    load_param_file,
    value_of,
)
from washbench.errors import WashbenchError, printable
from washbench.io import cost
from washbench.io.atomic import write_text_atomic
from washbench.io.csv_numbers import csv_number
from washbench.io.outfolder import result_set
from washbench.io.progress import Progress, duration_text
from washbench.io.result_files import REPORT_FILE
from washbench.pilot.surrogate import PilotObjective
from washbench.pilot.task import load_task
from washbench.platform.model import load_platform_model
from washbench.review.study_figures import convergence_figure
from washbench.runs.inputs import find_manoeuvres
from washbench.runs.study import evaluate, load_flights


def params_yaml(params: WashoutParams, header: str) -> str:
    """A complete parameter file for ``params`` (switched-off limits written ``off``), after a comment header."""

    def off(v: object) -> object:
        if isinstance(v, dict):
            return {k: off(x) for k, x in v.items()}
        return "off" if v is None else v

    data = off(params.model_dump(mode="json"))
    data.update(data.pop("sections", None) or {})  # the Python algorithms' sections as top-level keys (optimal:, mpc:)
    body = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
    comment = "".join(f"# {line}\n" if line else "#\n" for line in header.splitlines())
    return comment + body


def tune_command(
    manoeuvres: Sequence[Path],
    out_dir: Path,
    *,
    washout: str,
    tunes: Sequence[str],
    test: Sequence[Path] = (),
    budget: int = 200,
    seed: int = 0,
    saturation_weight: float = 1.0,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    from_dir: Path | None = None,
    jobs: int | None = None,
    dask: str | None = None,
    progress: bool = True,
    aircraft_dirs: Sequence[Path] = (),
    pilot: Path | None = None,
    pilot_weight: float = 1.0,
) -> int:
    """CLI entry of ``washbench tune``; 0 on success (the flights' own check results are reported, not fatal)."""
    start = time.perf_counter()
    kind = check_kind(washout, "--washout")
    if not tunes:
        raise WashbenchError("tune: give at least one --tune KEY=LOW:HIGH")
    if not (saturation_weight >= 0.0 and np.isfinite(saturation_weight)):
        raise WashbenchError(f"--saturation-weight: expected a number >= 0, got {saturation_weight}")
    if not (pilot_weight >= 0.0 and np.isfinite(pilot_weight)):
        raise WashbenchError(f"--pilot-weight: expected a number >= 0, got {pilot_weight}")
    if pilot is not None:
        load_task(pilot, aircraft_dirs)  # a bad task file fails before anything is flown
    if budget < 6:
        raise WashbenchError(f"--budget: expected at least 6 evaluations (1 for the starting set), got {budget}")
    if not 0 <= seed < 2**32:
        raise WashbenchError(f"--seed: expected a whole number from 0 to {2**32 - 1}, got {seed}")
    bounds = [parse_tune(t) for t in tunes]
    keys = [b.key for b in bounds]
    if len(set(keys)) != len(keys):
        raise WashbenchError(f"--tune: a key is tuned twice: {', '.join(keys)}")
    if budget < 1 + 5 * len(keys):
        raise WashbenchError(
            f"--budget {budget} is too small for {len(keys)} tuned key(s): differential evolution needs a first "
            f"population of at least 5 evaluations per key besides the starting set (--budget {1 + 5 * len(keys)} "
            "or more)"
        )
    base, _ = load_param_file(params_path)
    for b in bounds:  # both ends must be valid values of the key
        for v in (b.low, b.high):
            apply_overrides(base, {b.key: v}, f"--tune {b.key}={b.low}:{b.high}")
    limits = load_platform_model(platform_path)
    check_platform([Washout(kind, kind, base, registry.plugin_spec(kind))], limits)
    train_files = find_manoeuvres(manoeuvres)
    test_files = [p for p in (find_manoeuvres(test) if test else []) if p not in train_files]
    with result_set(out_dir, "tune") as stage:  # the whole set replaces the previous one at once
        objective = None
        if pilot is not None:
            if progress:
                print(f"tune: the pilot model on {pilot}: calibrating and flying the aircraft condition",
                      file=sys.stderr, flush=True)  # fmt: skip
            objective = (PilotObjective.prepare(pilot, aircraft_dirs), pilot_weight)
        best_x, best, base_obj, train, table = _tune(
            stage, base, kind, bounds, keys, train_files, test_files, limits, budget, seed, saturation_weight,
            manoeuvres, from_dir, jobs, dask, progress, aircraft_dirs, objective,
        )  # fmt: skip
    print(
        f"tune: {kind}, {best[4]} evaluations on {len(train)} training flight(s) in "
        f"{time.perf_counter() - start:.1f} s; objective {base.name} {base_obj:.4f} -> tuned {best[3]:.4f} "
        f"({', '.join(f'{k}={v:.6g}' for k, v in zip(keys, best_x, strict=True))}); "
        f"wrote {printable(str(Path(out_dir) / 'tuned.yaml'))}"
    )
    for line in score_lines(base.name, table):
        print(line)
    x0 = np.array([_value(base, k) for k in keys])
    for line in start_outside(bounds, x0, base_obj, best[3]):
        if line:
            print(f"tune: note: {line}")
    for line in at_edges(bounds, best_x):  # the optimum may lie beyond what was searched: say so
        print(f"tune: note: {line}: the best may lie outside it; widen --tune {line.split(' ')[0]}=LOW:HIGH")
    return 0


def _announce(each_s: float, left: int, train: Sequence[Any]) -> None:
    """Before the optimiser's evaluations, when they take long (:data:`washbench.io.cost.LONG_S`): how many, on how
    much flight, and at most how long at the starting set's time each (a population is evaluated at once, on the
    processes of ``--jobs``: less)."""
    if each_s * left > cost.LONG_S:
        samples = sum(f.evaluator.n for f in train)
        cost.note(f"tune: {left} more evaluation(s) on {len(train)} training flight(s) ({samples:,} samples): at most "
                  f"about {duration_text(each_s * left)} at the starting set's {each_s:.2g} s each (a population "
                  "at once on the --jobs processes takes less; a smaller --budget, fewer or shorter flights, less)")


def _tune(
    out_dir: Path, base: Any, kind: str, bounds: list[Any], keys: list[str], train_files: list[Path],
    test_files: list[Path], limits: Any, budget: int, seed: int, saturation_weight: float,
    manoeuvres: Sequence[Path], from_dir: Path | None, jobs: int | None, dask: str | None, progress: bool,
    aircraft_dirs: Sequence[Path], pilot: tuple[PilotObjective, float] | None = None,
) -> tuple[Any, ...]:  # fmt: skip
    """Fly, tune and write into ``out_dir`` (the stage); (best_x, best history row + count, base objective, ...)."""
    flights = load_flights(
        [*train_files, *test_files],
        out_dir,
        limits,
        from_dir=from_dir,
        jobs=jobs,
        dask=dask,
        progress=progress,
        aircraft_dirs=aircraft_dirs,
    )
    train, tests = flights[: len(train_files)], flights[len(train_files) :]
    durations = np.array([f.evaluator.n * f.evaluator.dt_s for f in train])

    def candidate(x: np.ndarray) -> Washout:
        point = dict(zip(keys, (float(v) for v in x), strict=True))
        return Washout(kind, kind, apply_overrides(base, point, "--tune"), registry.plugin_spec(kind))

    history: list[tuple[np.ndarray, float, float, float]] = []
    pilot_distance: list[float] = []  # with --pilot: per evaluation, in the history's order
    shown = Progress("tune", budget, "evaluations") if progress else None

    def objective(xs: np.ndarray) -> np.ndarray:
        results = evaluate(train, [candidate(x) for x in xs], dask)
        score = np.mean([r.score for r in results], axis=0)
        sat = np.sum([r.saturated_s for r in results], axis=0)
        frac = np.mean([r.saturated_s / d for r, d in zip(results, durations, strict=True)], axis=0)
        obj = score + saturation_weight * frac
        if pilot is not None:
            d = np.array([pilot[0].measures(candidate(x), limits)["distance_pct"] for x in xs])
            pilot_distance.extend(float(v) for v in d)
            obj = obj + pilot[1] * d / 100.0
        history.extend((x.copy(), float(s), float(t), float(o)) for x, s, t, o in zip(xs, score, sat, obj, strict=True))
        if shown is not None:
            shown.update(len(history), f"best objective {min(h[3] for h in history):.4f}")
        return obj

    x0 = np.array([_value(base, k) for k in keys])
    try:
        t0 = time.perf_counter()
        [base_obj] = objective(x0[None, :])  # evaluation 0: the starting set
        _announce(time.perf_counter() - t0, budget - 1, train)
        best_x = minimise(objective, bounds, budget - 1, seed, x0)
    finally:
        if shown is not None:
            shown.close()
    tuned = candidate(best_x).params
    label = f"{base.name} tuned for {kind}"
    tuned = tuned.model_copy(update={"name": label})
    _write(out_dir, base, tuned, kind, bounds, history, budget, seed, saturation_weight, manoeuvres, base_obj,
           pilot_distance)  # fmt: skip

    spec = registry.plugin_spec(kind)
    both = [Washout(base.name, kind, base, spec), Washout("tuned", kind, tuned, spec)]
    table = []
    for group, fl in (("training", train), ("test", tests)):
        for f, r in zip(fl, evaluate(fl, both, dask) if fl else [], strict=True):
            table.append((group, f.aircraft, f.manoeuvre, r))
    chosen = tuned_index(history, best_x)
    notes = [*_pilot_note(pilot, pilot_distance, chosen), *start_outside(bounds, x0, base_obj, history[chosen][3])]
    _report(out_dir, base, tuned, kind, bounds, best_x, table, history, base_obj, budget, seed, saturation_weight,
            notes)  # fmt: skip
    best = (*history[chosen], len(history))
    return best_x, best, base_obj, train, table


def tuned_index(history: list, best_x: np.ndarray) -> int:
    """The evaluation (index into ``history``, whose 0 is the starting set as given) of the tuned set ``best_x``:
    the search's own evaluation of it (1 on), or its least objective when none is equal (not expected)."""
    same = [i for i in range(1, len(history)) if np.array_equal(history[i][0], best_x)]
    if same:
        return same[0]
    return min(range(1, len(history)), key=lambda i: history[i][3]) if len(history) > 1 else 0


def start_outside(bounds: list[Bound], x0: np.ndarray, base_obj: float, tuned_obj: float) -> list[str]:
    """A note when the starting set lies outside an interval searched and scores better than the tuned set (the
    search starts from its nearest point inside the intervals, so the tuned set is never worse than that one, but
    may be worse than the start itself); none otherwise."""
    out = [f"{b.key} = {x:.6g} outside {b.low:g}..{b.high:g}" for b, x in zip(bounds, x0, strict=True)
           if not b.low <= x <= b.high]  # fmt: skip
    if not out or not base_obj < tuned_obj:
        return []
    return [f"The starting set scores better ({base_obj:.4f}) than the best set inside the intervals searched "
            f"({tuned_obj:.4f}): it lies outside them ({'; '.join(out)}); widen the interval to include it.", ""]


def _pilot_note(pilot: tuple[PilotObjective, float] | None, distances: list[float], best: int) -> list[str]:
    """The report's lines on the pilot objective (none without ``--pilot``)."""
    if pilot is None or not distances:
        return []
    return [
        f"Pilot objective: {pilot[1]:g} x the distance from flight (%) / 100 of the pilot model's measures on "
        f"the tracking task {pilot[0].label} ({pilot[0].task_path}), as its adaptation predicts them "
        "(washbench/pilot/surrogate.py; docs/pilot-model.md).",
        f"Distance from flight: starting set {distances[0]:.3g} %, tuned set {distances[best]:.3g} %.",
        "",
    ]


def score_lines(base_name: str, table: list) -> list[str]:
    """``tune: mean score on the training manoeuvres: CW1 0.595 -> tuned 0.512 (better)``, then the same for the
    test manoeuvres when there are any, and a warning line when the tuned set scored worse on them (it fits the
    training manoeuvres, not the motion in general). ``table``: (group, aircraft, manoeuvre, evaluation) rows
    whose ``score`` holds the starting and the tuned set's scores (lower is better)."""
    out = []
    for group in ("training", "test"):
        pairs = [(float(r.score[0]), float(r.score[1])) for g, _, _, r in table if g == group]
        if not pairs:
            continue
        a, b = np.mean(pairs, axis=0)
        verdict = "better" if b < a else "worse" if b > a else "unchanged"
        out.append(f"tune: mean score on the {len(pairs)} {group} manoeuvre(s): {base_name} {a:.4f} -> tuned {b:.4f} "
                   f"({verdict})")  # fmt: skip
        if group == "test" and b > a:
            out.append(
                f"tune: warning: the tuned set scores worse than {base_name} on the held-out test manoeuvres "
                f"({a:.4f} -> {b:.4f}): it fits the training manoeuvres, not the motion in general"
            )
    return out


def _value(params: WashoutParams, key: str) -> float:
    node = value_of(params, key)
    if node is None or isinstance(node, bool | str):
        raise WashbenchError(f"--tune {key}: the base value is {format_value(node)}, not a number to start from")
    return float(node)  # type: ignore[arg-type]


def _write(
    out_dir: Path,
    base: WashoutParams,
    tuned: WashoutParams,
    kind: str,
    bounds: list[Bound],
    history: list[tuple[np.ndarray, float, float, float]],
    budget: int,
    seed: int,
    weight: float,
    manoeuvres: Sequence[Path],
    base_obj: float,
    pilot_distance: Sequence[float] = (),
) -> None:
    keys = [b.key for b in bounds]
    header = (
        f"{tuned.name}: written by washbench tune ({datetime.now(UTC):%Y-%m-%d}).\n"
        f"Differential evolution (scipy), seed {seed}, budget {budget} evaluations, starting from {base.name}.\n"
        f"Minimised: mean score over {len(manoeuvres)} training input(s) of the {kind} washout\n"
        f"+ {weight:g} x mean fraction of time at a platform limit (objective {base.name} {base_obj:.6g}).\n"
        f"Tuned: " + ", ".join(f"{b.key} in [{b.low:g}, {b.high:g}]" for b in bounds) + ".\n"
        "Every other value is the starting set's; see washbench/data/cw1.yaml for what each key means."
    )
    out_dir.mkdir(parents=True, exist_ok=True)
    write_text_atomic(out_dir / "tuned.yaml", params_yaml(tuned, header))
    rows = [["index", *keys, "score", "saturated_s", "objective", *(["pilot_distance_pct"] if pilot_distance else [])]]
    for i, (x, s, t, o) in enumerate(history):
        extra = [csv_number(pilot_distance[i])] if pilot_distance else []
        rows.append([str(i), *(csv_number(float(v)) for v in x), csv_number(s), csv_number(t), csv_number(o), *extra])
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    write_text_atomic(out_dir / "tune.csv", buf.getvalue())


def _report(
    out_dir: Path,
    base: WashoutParams,
    tuned: WashoutParams,
    kind: str,
    bounds: list[Bound],
    best_x: np.ndarray,
    table: list,
    history: list,
    base_obj: float,
    budget: int,
    seed: int,
    weight: float,
    pilot_lines: Sequence[str] = (),
) -> None:

    objective = np.array([h[3] for h in history])
    convergence_figure(out_dir / "convergence.png", objective, base_obj, base.name)
    lines = [
        f"# Tuning the {kind} washout",
        "",
        f"Differential evolution (scipy), seed {seed}, {len(history)} of {budget} evaluations (0: {base.name}).",
        f"Objective: mean score over the training manoeuvres + {weight:g} x mean fraction of time at a platform",
        "limit (a penalty: see washbench/analysis/tune.py). Score: the ranking rule (lower is better, 1 = no better",
        "than a simulator that stands still). Saturation: seconds at any platform limit.",
        "",
        *pilot_lines,
        "| key | bounds | " + base.name + " | tuned |",
        "|---|---|---|---|",
    ]
    for b, x in zip(bounds, best_x, strict=True):
        lines.append(f"| `{b.key}` | {b.low:g} .. {b.high:g} | {_value(base, b.key):.6g} | {x:.6g} |")
    edges = at_edges(bounds, best_x)
    if edges:
        lines += ["", f"**At an end of its interval** (within {100 * EDGE_FRACTION:g} % of its width): "
                  + "; ".join(edges) + ". The best may lie outside the interval searched: widen it and tune again."]
    lines += [
        "",
        f"| set | aircraft | manoeuvre | score {base.name} | score tuned | saturated s {base.name} "
        "| saturated s tuned |",
        "|---|---|---|---|---|---|---|",
    ]
    means: dict[str, list[tuple[float, float]]] = {}
    for group, aircraft, manoeuvre, r in table:
        means.setdefault(group, []).append((float(r.score[0]), float(r.score[1])))
        lines.append(
            f"| {group} | {aircraft} | {manoeuvre} | {r.score[0]:.4f} | {r.score[1]:.4f} | "
            f"{r.saturated_s[0]:.2f} | {r.saturated_s[1]:.2f} |"
        )
    lines.append("")
    for group, pairs in means.items():
        a, b = np.mean(pairs, axis=0)
        lines.append(f"Mean score on the {group} manoeuvres: {base.name} {a:.4f}, tuned {b:.4f}.")
    lines += ["", "![convergence](convergence.png)", "", "Tuned parameter file: [tuned.yaml](tuned.yaml).", ""]
    write_text_atomic(out_dir / REPORT_FILE, "\n".join(lines))
