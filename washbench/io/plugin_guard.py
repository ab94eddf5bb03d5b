"""One guard around every call into a user's plugin (a washout, a platform): whatever it raises becomes one line.

A plugin is any Python code: besides exceptions it can call ``sys.exit()``, raise ``KeyboardInterrupt`` with no
Ctrl-C pressed, return objects whose ``__float__``, ``__bool__``, ``__len__`` or ``__iter__`` raise (so converting
the result raises too). :func:`plugin_call` runs the call *and the conversion of its result* and turns any
:class:`BaseException` into a :class:`washbench.errors.WashbenchError` naming the plugin and the call, except a
real SIGINT or SIGTERM (one this process's handlers received while the call ran,
:func:`washbench.io.interrupts.received`): that one stops the command as a signal does. What a plugin is given to
read it gets as read-only copies (:func:`read_only`).
"""

from __future__ import annotations

import hashlib
import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, TypeVar

from washbench.errors import Terminated, WashbenchError
from washbench.io import interrupts

if TYPE_CHECKING:
    import numpy as np

R = TypeVar("R")


def plugin_call(where: str, fn: Callable[[], R], passing: tuple[type[BaseException], ...] = (),
                what: str = "a washout") -> R:  # fmt: skip
    """``fn()`` (a plugin's call and the conversion of what it returned) with any BaseException as one line
    ``WHERE: raised TYPE: message`` (WashbenchError); a WashbenchError, one of ``passing`` (handled by the caller)
    and a real signal pass unchanged. ``what``: the kind of plugin, for ``sys.exit()`` (``a platform``)."""
    seen = interrupts.received()
    try:
        return fn()
    except WashbenchError:
        raise
    except BaseException as exc:  # a user's code: anything it raises is one line
        signalled = isinstance(exc, KeyboardInterrupt | Terminated) and interrupts.received() != seen
        if signalled or isinstance(exc, passing):
            raise  # the caller's to handle, or a real Ctrl-C or SIGTERM that arrived meanwhile
        raise plugin_error(where, exc, what) from None


def plugin_error(where: str, exc: BaseException, what: str = "a washout") -> WashbenchError:
    """The one line for ``exc`` raised by a plugin (not a signal): ``WHERE: raised TYPE: message``; ``sys.exit()``
    and a KeyboardInterrupt said as what they are."""
    if isinstance(exc, SystemExit):
        code = exception_text(exc) if isinstance(exc.code, str | int | None) else "..."
        return WashbenchError(f"{where}: called sys.exit({code}) ({what} may not end the command)")
    if isinstance(exc, KeyboardInterrupt | Terminated):
        return WashbenchError(f"{where}: raised {type(exc).__name__} (no signal was received)")
    text = exception_text(exc)
    return WashbenchError(f"{where}: raised {type(exc).__name__}" + (f": {text}" if text else ""))


def load_module(path: Path, prefix: str, where: str) -> ModuleType:
    """Import a user's plugin file ``path`` as module ``PREFIX_<hash of its resolved path>`` (the same name in every
    process: a worker loads the module its parent did); whatever importing it raises (``sys.exit()`` too) becomes
    one line ``WHERE: PATH[:LINE]: TYPE: message``, except a real SIGINT or SIGTERM received meanwhile."""
    module_name = f"{prefix}_{hashlib.sha256(str(path.resolve()).encode()).hexdigest()[:16]}"
    seen = interrupts.received()
    try:
        mod_spec = importlib.util.spec_from_file_location(module_name, path)
        if mod_spec is None or mod_spec.loader is None:
            raise WashbenchError(f"{where}: {path}: not a Python file")
        module = importlib.util.module_from_spec(mod_spec)
        sys.modules[module_name] = module
        mod_spec.loader.exec_module(module)
    except WashbenchError:
        sys.modules.pop(module_name, None)
        raise
    except BaseException as exc:  # a user's file: whatever it raises (sys.exit() too) becomes one line
        if isinstance(exc, KeyboardInterrupt | Terminated) and interrupts.received() != seen:
            raise  # a real Ctrl-C or SIGTERM while it loaded
        sys.modules.pop(module_name, None)
        line = ""
        tb = exc.__traceback__
        while tb is not None:
            if tb.tb_frame.f_code.co_filename == str(path):
                line = f":{tb.tb_lineno}"
            tb = tb.tb_next
        if isinstance(exc, SyntaxError) and exc.lineno:
            line = f":{exc.lineno}"
        if isinstance(exc, Exception):
            raise WashbenchError(f"{where}: {path}{line}: {type(exc).__name__}: {exception_text(exc)}") from None
        raise plugin_error(f"{where}: {path}{line}", exc) from None  # sys.exit(), a KeyboardInterrupt without a signal
    return module


def exception_text(exc: BaseException) -> str:
    """``str(exc)`` on one line; a ``__str__`` that raises too gives ``""``."""
    try:
        return " ".join(str(exc).split())
    except BaseException:  # a plugin's exception whose __str__ fails
        return ""


def read_only(a: object) -> np.ndarray:
    """A read-only float64 copy of ``a`` for a plugin: a view could be made writeable again (its base is the bench's
    array) and written into, changing what the other washouts, the recorded set points and the metrics see; a copy
    cannot."""
    import numpy as np  # (numpy only where a plugin is run: the guard is loaded with the plugin registries)

    v = np.array(a, dtype=np.float64, order="C")
    v.flags.writeable = False
    return v


__all__ = ["exception_text", "plugin_call", "plugin_error", "read_only"]
