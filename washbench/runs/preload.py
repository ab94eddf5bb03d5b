"""Imported once by the suite's process server before it forks workers.

Importing this module loads what every run needs and is slow to start: JSBSim, pyarrow and the compiled
streaming cueing step (numba loads it from its on-disk cache, about 0.4 s); the suite adds matplotlib's Agg canvas
(``washbench.runs.pool.FIGURE_MODULES``) when it draws figures and rerun when it writes recordings.
Workers forked afterwards start with all of it in memory. Nothing here starts a thread (rerun's
recording streams are created in the workers), so forking stays safe.
"""

from __future__ import annotations

import jsbsim  # noqa: F401
import pyarrow.parquet  # noqa: F401

import washbench.perception.vestibular  # noqa: F401
from washbench.analysis.metric_sums import signal_metrics
from washbench.cueing.bank import _warm_up, warm_up_block
from washbench.cueing.kernel import bank_block, bank_step
from washbench.numerics.jitcache import announce_compile
from washbench.perception.sections import sections_apply, sections_apply_from, sections_run
from washbench.review.thinning import _changes, _keep
from washbench.runs.parent_death import die_with_parent

# One line for the whole suite when a kernel its workers run is not compiled yet (after an install or upgrade):
# the workers fork from here and inherit that it was said.
announce_compile(bank_block, bank_step, sections_apply, sections_apply_from, sections_run, signal_metrics, _keep,
                 _changes)  # fmt: skip
die_with_parent()  # the process server ends with the washbench command that started it (even on SIGKILL)

# Only the serial steps are run here: a parallel (prange) kernel would start numba's OpenMP threads, and a process
# using GNU OpenMP must not fork. The block step is the lockstep's; the per-sample step, JSBSim scripts'.
warm_up_block()
_warm_up()
