"""numba compilation deferred to the first call: a module's compiled functions without importing numba at import.

``@lazy_njit(cache=True)`` stands for ``@numba.njit(cache=True)``. The decorated function stays a plain Python
function until something calls one of the module's lazy functions; then every lazy function of that module is
handed to ``numba.njit`` at once (compiled functions call each other: each must be a numba dispatcher when the
first is compiled) and put in the module's namespace in its place, so later calls go straight to the dispatcher.
Same options, same machine code, same on-disk cache as the plain decorator: the results are the same bits.

Why: ``import numba`` costs about 0.2-0.3 s of CPU. A module on the import path of every command (the perception
and sickness models the chain imports) would otherwise make a command that refuses its input in a second pay it.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

from washbench.numerics.numbastart import prepare


class LazyJit:
    """A function to be compiled by ``numba.njit(**options)`` when its module's first lazy function is called."""

    def __init__(self, fn: Callable[..., Any], options: dict[str, Any]) -> None:
        self.py_func = fn
        self.options = options
        functools.update_wrapper(self, fn)

    def compiled(self) -> Any:
        """This function's numba dispatcher (the module's lazy functions all replaced by theirs first)."""
        from numba import njit  # (numba's cache folder was set when this package was imported)

        prepare()  # numba's cache loads made light

        namespace = self.py_func.__globals__
        for name, obj in list(namespace.items()):
            if isinstance(obj, LazyJit):
                namespace[name] = njit(**obj.options)(obj.py_func)
        return namespace[self.py_func.__name__]

    def __call__(self, *args: Any) -> Any:
        return self.compiled()(*args)


def lazy_njit(**options: Any) -> Callable[[Callable[..., Any]], LazyJit]:
    """``numba.njit(**options)``, applied at the first call of any lazy function of the decorated one's module."""

    def decorate(fn: Callable[..., Any]) -> LazyJit:
        return LazyJit(fn, options)

    return decorate
