"""Automatic tuning: minimise the ranking rule's mean score over training flights (pure functions, no files).

Optimiser: scipy's differential evolution (``scipy.optimize.differential_evolution``). Why: it is already a
dependency (no new package), it searches a box of bounds natively (each ``--tune KEY=LOW:HIGH``), it evaluates a
whole population per generation in one call (``vectorized=True``), which is exactly the shape of the compiled batch
evaluation, it is deterministic for a seed, and it is robust on the non-smooth objective the platform limits make
(no gradients). CMA-ES (``cma``) adapts faster on smooth problems but would add a dependency and handles bounds
by repair.

Saturation: a PENALTY, not a constraint. ``objective = mean score + saturation_weight * mean fraction of time at a
platform limit``. Why: the platform model never exceeds a limit (it brakes and catches up), so saturation is not an
infeasible state but a degraded cue; the score already measures part of that cost through the perceived error, and
the penalty adds the rest smoothly. A hard "no saturation" constraint would make CW1 itself infeasible on flights
where it saturates (the Columbia aerobatics, the take-offs), and differential evolution's constraint handling
ranks every feasible point above every infeasible one, which leaves little to search.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from washbench.cueing.variants import check_key
from washbench.errors import WashbenchError


@dataclass(frozen=True)
class Bound:
    """One tuned key and its search interval [low, high]."""

    key: str
    low: float
    high: float


def parse_tune(text: str) -> Bound:
    """``KEY=LOW:HIGH`` (one ``--tune``); WashbenchError naming the key if it is bad."""
    key, eq, rng = text.partition("=")
    key = key.strip()
    where = f"--tune {text}"
    low, colon, high = rng.partition(":")
    if not eq or not colon:
        raise WashbenchError(f"{where}: expected KEY=LOW:HIGH")
    check_key(key, where)
    try:
        lo, hi = float(low), float(high)
    except ValueError:
        raise WashbenchError(f"{where}: LOW and HIGH must be numbers") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise WashbenchError(f"{where}: expected finite LOW < HIGH")
    return Bound(key, lo, hi)


def population_plan(n_params: int, budget: int) -> tuple[int, int]:
    """(population multiplier, generations after the first) so that the evaluations stay within ``budget``.

    The population is ``multiplier * n_params`` (at least 5, at most 15 per parameter); the total number of
    evaluations is the population times (generations + 1).
    """
    if budget < 5:
        raise WashbenchError(f"--budget: expected at least 5 evaluations, got {budget}")
    mult = max(math.ceil(5 / n_params), min(15, budget // (5 * n_params)))
    size = mult * n_params
    if size > budget:
        mult = max(1, budget // n_params)
        size = mult * n_params
    return mult, max(0, budget // size - 1)


def minimise(
    objective: Callable[[np.ndarray], np.ndarray],
    bounds: list[Bound],
    budget: int,
    seed: int,
    x0: np.ndarray | None = None,
) -> np.ndarray:
    """Differential evolution of ``objective`` (candidates (S, n) -> objectives (S,)) within ``budget`` evaluations.

    ``x0`` (the starting parameter set, clipped into the bounds) is a member of the first population, so the
    result is never worse than it. Deterministic for ``seed``. Returns the best parameter vector found.
    """
    from scipy.optimize import differential_evolution

    mult, maxiter = population_plan(len(bounds), budget)
    box = [(b.low, b.high) for b in bounds]
    start = None if x0 is None else np.clip(np.asarray(x0, dtype=float), [b[0] for b in box], [b[1] for b in box])
    result = differential_evolution(
        lambda x: objective(np.atleast_2d(x.T)),  # vectorized: x is (n, S)
        box,
        popsize=mult,
        maxiter=maxiter,
        tol=0.0,
        atol=0.0,
        polish=False,
        init="latinhypercube",
        updating="deferred",
        vectorized=True,
        rng=np.random.default_rng(seed),
        x0=start,
    )
    return np.asarray(result.x, dtype=float)


#: How close to an end of its interval a tuned value counts as at that end: this fraction of the interval's width.
#: Chosen (not published): 1 % is far below the spread of a differential-evolution population over its budget, so a
#: value that close to an end was pushed there, and the best may lie beyond it.
EDGE_FRACTION = 0.01


def at_edges(bounds: list[Bound], x: np.ndarray) -> list[str]:
    """One line for each tuned value within :data:`EDGE_FRACTION` of an end of its interval, e.g. ``tilt.gain_per_s
    = 0.200343 is at the lower end of its interval 0.2..5``: the optimum may lie outside the interval searched."""
    lines = []
    for b, v in zip(bounds, np.asarray(x, dtype=float), strict=True):
        margin = EDGE_FRACTION * (b.high - b.low)
        end = "lower" if v - b.low <= margin else "upper" if b.high - v <= margin else None
        if end is not None:
            lines.append(f"{b.key} = {v:.6g} is at the {end} end of its interval {b.low:g}..{b.high:g}")
    return lines
