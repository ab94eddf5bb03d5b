"""numba's start-up without the scipy import it does not need here.

The first time numba loads or compiles any function it imports ``numba.np.arraymath``, which probes for a
BLAS by importing ``scipy.linalg.cython_blas``: 0.3-0.5 s of every ``washbench cue`` and ``run`` start-up,
for a probe whose answer only chooses how numba-compiled ``np.convolve``/``np.correlate`` do their inner
products. washbench's compiled code uses neither (nor any BLAS call), so :func:`prepare` lets that first
import run with the probe failing fast; numba then uses its own loop for those two functions. If scipy's BLAS
is already loaded, or numba's array maths already imported, nothing is changed. Functions that really need
BLAS (``np.dot`` and ``np.linalg`` in numba code) still import it when they are compiled.
"""

from __future__ import annotations

import sys

_PROBE = "scipy.linalg.cython_blas"


def prepare() -> None:
    """Import ``numba.np.arraymath`` once, with its scipy BLAS probe answered "absent" (idempotent)."""
    if "numba.np.arraymath" in sys.modules or _PROBE in sys.modules:
        return
    sys.modules[_PROBE] = None  # type: ignore[assignment]  # an import of it raises ImportError at once
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if sys.modules.get(_PROBE, 0) is None:
            del sys.modules[_PROBE]
