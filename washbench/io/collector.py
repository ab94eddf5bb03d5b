"""The cyclic garbage collector's settings for a washbench process: the command, and the suite's process server.

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
"""

from __future__ import annotations

import gc

YOUNG_THRESHOLD = 10_000
"""Net container allocations between two collections of the youngest generation (CPython's default: 700)."""


def tune() -> None:
    """Collect the youngest generation every :data:`YOUNG_THRESHOLD` allocations; the older ones as by default."""
    _, middle, old = gc.get_threshold()
    gc.set_threshold(YOUNG_THRESHOLD, middle, old)


def freeze_loaded() -> None:
    """Move every object tracked now to the permanent generation, which the collector never scans."""
    gc.freeze()
