"""Imported once by the suite's process server before it forks workers.

Importing this module loads what every run needs and is slow to start: JSBSim, pyarrow and the
compiled cueing step and vestibular filter (numba loads them from its on-disk cache, about
0.4 s); the suite adds rerun to the preload list when it writes recordings. Workers forked afterwards
start with all of it in memory. Nothing here starts a thread
(rerun's recording streams are created in the workers), so forking stays safe.
"""

from __future__ import annotations

import jsbsim  # noqa: F401
import numpy as np
import pyarrow.parquet  # noqa: F401

from washbench.cueing.bank import _warm_up
from washbench.perception.vestibular import VestibularModel

_warm_up()
VestibularModel(1.0 / 120.0).perceive(np.zeros((2, 3)), np.zeros((2, 3)))
