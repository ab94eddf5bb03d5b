"""Shared numerics, on the floor below ``cueing``, ``platform`` and ``perception``.

- :mod:`washbench.numerics.rotations`: quaternion and Euler kinematics (scalar-first quaternions, body to
  inertial, Hamilton product), compiled with numba;
- :mod:`washbench.numerics.jitcache`: numba's on-disk cache (where it lives, when it is stale, saying so);
- :mod:`washbench.numerics.numbastart`: numba's start-up without the scipy import it does not need;
- :mod:`washbench.numerics.jit`: ``njit`` and ``prange`` for the modules compiled at their import, numba's start
  prepared first;
- :mod:`washbench.numerics.statespace`: a transfer function's state space as ``scipy.signal.tf2ss`` gives it, in
  numpy (without that import's second).

Importing the package points numba's cache at a writable folder before any jitted module is compiled.
"""

from __future__ import annotations

from washbench.numerics.jitcache import configure_cache

configure_cache()  # before any jitted module is imported (numba reads its cache folder at decoration)
