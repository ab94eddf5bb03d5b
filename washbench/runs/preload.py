"""Imported once by the suite's process server before it forks workers.

Importing this module loads what every run needs and is slow to start: JSBSim, pyarrow and the compiled
streaming cueing step (numba loads it from its on-disk cache, about 0.4 s); the suite adds matplotlib's Agg canvas
(``washbench.runs.pool.FIGURE_MODULES``) when it draws figures and rerun when it writes recordings.
Workers forked afterwards start with all of it in memory. Nothing here starts a thread (rerun's
recording streams are created in the workers), so forking stays safe.
"""

from __future__ import annotations

import os

from washbench.io import collector, pages
from washbench.runs import parent_death

# First, before the slow imports: the process server ends with the washbench command that started it (even on
# SIGKILL), and at once if that command already died while the server was starting.
parent_death.die_with_parent(parent_death.main_pid())
parent_death.SERVER_PID = os.getpid()  # the parent every worker forked from here must have
collector.tune()  # the server is a new interpreter: its own settings, before its imports; its workers inherit them
pages.small_pages()  # inherited from the command already; set here too for a suite started from Python

import jsbsim  # noqa: E402, F401
import pyarrow.parquet  # noqa: E402, F401
from numba import types  # noqa: E402

import washbench.perception.vestibular  # noqa: E402, F401
from washbench.analysis.metric_sums import signal_metrics  # noqa: E402
from washbench.cueing.bank import _warm_up, warm_up_block  # noqa: E402
from washbench.cueing.kernel import bank_block, bank_step  # noqa: E402
from washbench.flight.stepper import compiled_flight_step  # noqa: E402
from washbench.numerics.jitcache import announce_compile  # noqa: E402
from washbench.numerics.lazyjit import LazyJit  # noqa: E402
from washbench.perception import svc  # noqa: E402
from washbench.perception.sections import sections_apply  # noqa: E402
from washbench.review.thinning import _changes, _keep  # noqa: E402

# One line for the whole suite when a kernel every run takes is not compiled yet (after an install or upgrade):
# the workers fork from here and inherit that it was said. Only those: a kernel a suite may never run (the
# streamed perception of a cue, the perception from a later start) would never be compiled, so it would be
# announced at every suite; a worker that needs one announces it where it is used.
announce_compile(bank_block, bank_step, sections_apply, signal_metrics, _keep, _changes)

# Only the serial steps are run here: a parallel (prange) kernel would start numba's OpenMP threads, and a process
# using GNU OpenMP must not fork. The block step is the lockstep's; the per-sample step, JSBSim scripts'.
warm_up_block()
_warm_up()


def _compile_run_kernels() -> None:
    """Compile (or load from numba's cache) the serial kernels every run calls besides the cueing step, for the
    argument types a run passes (C-contiguous float64 arrays, as each wrapper makes them), without running them:
    the flight step, the metric sums, the sickness models and the recording's thinning. After an install or upgrade
    each worker would otherwise compile them again in its first run (several seconds each, on every core at once),
    which also made the suite's first runs, and the expected end printed from them, seem slower than the rest."""
    a1, a2, f8, i8 = types.float64[::1], types.float64[:, ::1], types.float64, types.int64
    svc_run = svc._run.compiled() if isinstance(svc._run, LazyJit) else svc._run
    for kernel, signature in (
        (compiled_flight_step(), (a1, a2)),
        (signal_metrics, (a1, a1, f8)),
        (svc_run, (a1, a1, a2, f8, a1, f8, a1, a1)),
        (_keep, (a1, a2, a1, f8)),
        (_changes, (a2, a1, i8)),
    ):
        kernel.compile(signature)  # type: ignore[attr-defined]


_compile_run_kernels()
