"""numba's start-up as washbench needs it: kernels loaded from the cache without the compiler's registries, and
without the scipy import numba does not need here.

**Loading a cached kernel.** Before it loads any function from its on-disk cache, numba refreshes its target
context (``numba.core.caching.Cache.load_overload``): it imports and installs every typing and lowering registry
it has (numpy's array functions, random, linear algebra, typed containers, cffi, jitclass: some 2,300
registrations, half of ``import numba`` again) and initialises its runtime (NRT). A cached kernel is machine code
already typed and lowered: loading it needs the runtime's symbols (its allocator), not the registries, which only a
compilation reads. :func:`prepare` makes numba's cache load initialise the runtime only
(``rtsys.initialize``, what the refresh does first); when the cache has nothing for a signature, numba compiles,
and its compiler refreshes the whole context itself (``numba.core.compiler.compile_extra``) as before. The machine
code loaded is the same file, so the results are the same bits (``tests/test_numbastart.py``). Measured on two
idle cores, four alternated pairs: a ``washbench run`` of the 32 s elevator doublet without recording and figures
1.53-1.56 s -> 1.12-1.22 s; a ``cue`` of 30 minutes without them about 0.1-0.2 s less (it loads fewer kernels).
An earlier attempt skipped the refresh altogether and crashed in the first kernel call: the runtime was not
initialised. This reaches into numba's internals, so it is done only for the numba versions it was checked with
(:data:`LIGHT_LOAD_VERSIONS`); with any other, numba loads as it always does.

**The BLAS probe.** When numba first refreshes its context (now: at a compilation) it imports ``numba.np.arraymath``,
which probes for a BLAS by importing ``scipy.linalg.cython_blas``: 0.3-0.5 s, for a probe whose answer only chooses how
numba-compiled ``np.convolve``/``np.correlate`` do their inner products. washbench's compiled code uses neither (nor
any BLAS call), so :func:`prepare` imports it first, with the probe failing fast; numba then uses its own
loop for those two functions. If scipy's BLAS is already loaded, or numba's array maths already imported, nothing
is changed. Functions that really need BLAS (``np.dot`` and ``np.linalg`` in numba code) still import it when they
are compiled.

It is called in two places: :mod:`washbench.numerics.jit`, whose ``njit`` and ``prange`` every module compiled at its
import takes, and :meth:`washbench.numerics.lazyjit.LazyJit.compiled`, for those compiled at their first call.
"""

from __future__ import annotations

import sys
from typing import Any

_PROBE = "scipy.linalg.cython_blas"

LIGHT_LOAD_VERSIONS = ("0.68.",)
"""numba versions whose cache load :func:`prepare` makes light (checked with 0.68.1, the version installed where it
was written: every bundled manoeuvre's flight digest unchanged, the test suite passing)."""


def prepare() -> None:
    """numba's cache loads made light (:func:`light_cache_loads`) and ``numba.np.arraymath`` imported once with its
    scipy BLAS probe answered "absent" (idempotent)."""
    light_cache_loads()
    if "numba.np.arraymath" in sys.modules or _PROBE in sys.modules:
        return
    sys.modules[_PROBE] = None  # type: ignore[assignment]  # an import of it raises ImportError at once
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if sys.modules.get(_PROBE, 0) is None:
            del sys.modules[_PROBE]


def light_cache_loads() -> bool:
    """Make numba's cache load initialise its runtime only, not refresh every registry (module docstring); whether
    it is (False for a numba version not in :data:`LIGHT_LOAD_VERSIONS`, or without the internals it replaces)."""
    import numba
    from numba.core import caching

    cache = caching.Cache
    if getattr(cache.load_overload, "washbench_light", False):
        return True
    if not numba.__version__.startswith(LIGHT_LOAD_VERSIONS) or not all(
        hasattr(cache, name) for name in ("_load_overload", "_guard_against_spurious_io_errors")
    ):
        return False
    from numba.core.runtime import rtsys

    def load_overload(self: Any, sig: Any, target_context: Any) -> Any:
        """numba's ``Cache.load_overload`` with ``rtsys.initialize`` in place of the context's whole refresh."""
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    load_overload.washbench_light = True  # type: ignore[attr-defined]
    cache.load_overload = load_overload
    return True
