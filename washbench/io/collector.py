"""The cyclic garbage collector's settings for a washbench process (the command, the suite's process server) and
while a figure is drawn.

CPython collects its youngest generation after every 700 net allocations of container objects (``gc``'s default
threshold ``(700, 10, 10)``), and every tenth young collection also the middle one. A washbench command imports about
280,000 tracked objects (numba, matplotlib, rerun, pyarrow, pydantic) and its flight, figures and recording allocate
small containers all the time, so the collector kept scanning: in a ``washbench run`` of the C172 takeoff 362 young,
33 middle and 3 full collections, and the command took 0.1 to 0.15 s more CPU (of about 2 s) than with the collector
off (issue 21; the figures in docs/development.md).

* :func:`tune`, at the start of every washbench process: the young generation is collected after
  :data:`YOUNG_THRESHOLD` allocations instead of 700. Cycles are still collected, only less often; a young
  collection of 10,000 objects takes about 0.1 ms here. Outputs do not depend on when the collector runs.
* :func:`freeze_loaded`, in each pool worker as it starts (``washbench.runs.pool``), before its first collection:
  what it has loaded (forked from the process server with the preloaded modules) is never scanned by its
  collector, nor written by it, so those pages stay shared with the server (the ``gc.freeze`` documentation's
  advice for forked children).
* :func:`paused`, around each figure writer (``washbench.review``): no collection at all while a figure is drawn.
"""

from __future__ import annotations

import functools
import gc
from collections.abc import Callable
from typing import ParamSpec, TypeVar

YOUNG_THRESHOLD = 10_000
"""Net container allocations between two collections of the youngest generation (CPython's default: 700)."""

P = ParamSpec("P")
R = TypeVar("R")


def tune() -> None:
    """Collect the youngest generation every :data:`YOUNG_THRESHOLD` allocations; the older ones as by default."""
    _, middle, old = gc.get_threshold()
    gc.set_threshold(YOUNG_THRESHOLD, middle, old)


def freeze_loaded() -> None:
    """Move every object tracked now to the permanent generation, which the collector never scans."""
    gc.freeze()


def paused(func: Callable[P, R]) -> Callable[P, R]:
    """``func`` (a figure writer) run with Python's cyclic garbage collector paused, then restored as it was.

    Drawing a figure allocates some 10^5 short-lived container objects (artists, transforms, paths); with the
    collector on, that sets off generation-2 collections that walk every object of the process (a flight's, a
    cue's) about once per figure: 0.03 to 0.1 s of CPU per figure measured (issue 21). Paused, the garbage is
    collected afterwards by the collector's own schedule; reference counting frees the rest at once as usual.
    """

    @functools.wraps(func)
    def run(*args: P.args, **kwargs: P.kwargs) -> R:
        was = gc.isenabled()
        gc.disable()
        try:
            return func(*args, **kwargs)
        finally:
            if was:
                gc.enable()

    return run
