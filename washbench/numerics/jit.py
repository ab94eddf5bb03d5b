"""numba's decorators as every washbench module compiled at its import takes them::

    from washbench.numerics.jit import njit, prange

Importing this module first sets numba's cache folder (:mod:`washbench.numerics.jitcache`, through this package's
``__init__``), then makes numba's start light (:func:`washbench.numerics.numbastart.prepare`: cached kernels loaded
without the compiler's registries, the scipy BLAS probe skipped), before any kernel is defined. It is the one place
that does both for those modules; a module compiled at its first call instead (:mod:`washbench.numerics.lazyjit`,
which must not import numba when it is imported) has numba prepared there, by :meth:`LazyJit.compiled`.
"""

from __future__ import annotations

from numba import njit, prange

from washbench.numerics.numbastart import prepare

prepare()

__all__ = ["njit", "prange"]
