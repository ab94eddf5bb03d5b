"""Imported once by the suite's process server before it forks workers.

Importing this module loads what every run needs and is slow to start: JSBSim, pyarrow, matplotlib's
Agg canvas (the report's figures) and the compiled streaming cueing step (numba loads it from its
on-disk cache, about 0.4 s); the suite adds rerun to the preload list when it writes recordings.
Workers forked afterwards start with all of it in memory. Nothing here starts a thread (rerun's
recording streams are created in the workers), so forking stays safe.
"""

from __future__ import annotations

import jsbsim  # noqa: F401
import matplotlib.backends.backend_agg
import matplotlib.figure  # noqa: F401
import pyarrow.parquet  # noqa: F401

import washbench.perception.vestibular  # noqa: F401
from washbench.cueing.bank import _warm_up

# Only the serial streaming step is run here: a parallel (prange) kernel would start numba's OpenMP threads,
# and a process using GNU OpenMP must not fork.
_warm_up()
