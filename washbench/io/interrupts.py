"""SIGINT and SIGTERM as exceptions in the main thread, held back over a critical section, and a signal that
Python swallowed sent again.

:func:`terminate` is the SIGTERM handler (it raises :class:`washbench.errors.Terminated`, so cleanup code runs as
for Ctrl-C). :func:`signal_in_finalizer` is the ``sys.unraisablehook``: a KeyboardInterrupt or Terminated raised
while Python runs a finalizer (a ``__del__``, such as the rerun SDK's RecordingStream as a recording is closed, or
a weakref callback, such as importlib's module locks while ``washbench.cli`` loads) is swallowed by Python with an
"Exception ignored" traceback, and the command would go on as if never signalled (and publish); the hook sends
the signal again a few milliseconds later, so that it acts in the command itself (one line, 130 or 143).

:func:`signals_held` (and :func:`uninterrupted`, for a function) holds both back for a short critical section
(the swap that publishes results, a figure being drawn, worker processes being started): noted, and acted on once
it is over.

On the lowest floor (stdlib and :mod:`washbench.errors` only): ``washbench/__main__.py`` installs both before it
imports the command line, so a Ctrl-C in the first fraction of a second is never lost either.
"""

from __future__ import annotations

import contextlib
import functools
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any, ParamSpec, TypeVar

from washbench.errors import Terminated

P = ParamSpec("P")
R = TypeVar("R")

#: Signals swallowed in a finalizer and not yet sent again (see :func:`signal_in_finalizer`).
PENDING: list[int] = []

#: SIGINT and SIGTERM received by this process's handlers so far (:func:`received`).
_RECEIVED = [0]


def received() -> int:
    """How many SIGINT/SIGTERM this process's handlers (:func:`terminate`, :func:`interrupt`) have received.

    A KeyboardInterrupt or Terminated raised while this count did not change was raised by code (a washout
    plugin's ``raise KeyboardInterrupt``), not by a signal (:mod:`washbench.io.plugin_guard`).
    """
    return _RECEIVED[0]


def note_received() -> None:
    """Count a SIGINT/SIGTERM received by a handler of a command's own (``washbench live``'s), for :func:`received`."""
    _RECEIVED[0] += 1


def terminate(signum: int, frame: object) -> None:
    """The SIGTERM handler: raise :class:`washbench.errors.Terminated` in the main thread."""
    _RECEIVED[0] += 1
    raise Terminated()


def interrupt(signum: int, frame: object) -> None:
    """The SIGINT handler: Python's own (raise KeyboardInterrupt), counted (:func:`received`)."""
    _RECEIVED[0] += 1
    raise KeyboardInterrupt


def signal_in_finalizer(unraisable: object) -> None:
    """``sys.unraisablehook``: a KeyboardInterrupt or Terminated raised inside a finalizer is noted in
    :data:`PENDING` and its signal sent again 10 ms later from a timer thread; anything else goes to Python's own
    hook."""
    exc = getattr(unraisable, "exc_value", None)
    if not isinstance(exc, (KeyboardInterrupt, Terminated)):
        sys.__unraisablehook__(unraisable)  # type: ignore[arg-type]
        return
    signum = signal.SIGINT if isinstance(exc, KeyboardInterrupt) else signal.SIGTERM
    PENDING.append(signum)  # a command that ends before the timer fires still reports it (cli.main)
    while True:
        try:
            timer = threading.Timer(0.01, _send_again, (signum,))
            timer.daemon = True
            timer.start()
            return
        except (KeyboardInterrupt, Terminated):  # signalled again in here: still one to send
            continue


def _send_again(signum: int) -> None:
    if PENDING:
        PENDING.clear()
        os.kill(os.getpid(), signum)


def signal_beneath(exc: BaseException, since: int) -> BaseException | None:
    """The KeyboardInterrupt or Terminated that a signal raised beneath ``exc`` (its ``__cause__`` or
    ``__context__``, at any depth), if this process's handlers have received a signal since :func:`received` was
    ``since``; else None.

    Python wraps an exception raised in some of its own machinery: a signal's exception raised while a class is
    being created (a module imported mid-command, a pydantic model's ``__set_name__``) reaches the command as
    ``RuntimeError: Error calling __set_name__ ...``, the interrupt as its cause.
    """
    if received() == since:
        return None
    seen: set[int] = set()
    inner: BaseException | None = exc
    while inner is not None and id(inner) not in seen:
        if isinstance(inner, (KeyboardInterrupt, Terminated)):
            return inner
        seen.add(id(inner))
        inner = inner.__cause__ or inner.__context__
    return None


def raise_pending() -> None:
    """Raise KeyboardInterrupt or Terminated now if a signal swallowed in a finalizer has not been sent again yet
    (a command that finished its work before the timer fired: it still ends as signalled)."""
    if PENDING:
        last = PENDING[-1]
        PENDING.clear()
        raise KeyboardInterrupt if last == signal.SIGINT else Terminated()


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back for a short critical section: noted, and acted on once it is over as the handler
    the section replaced would have acted (washbench's: KeyboardInterrupt or :class:`washbench.errors.Terminated`;
    an ignored signal stays ignored, a default one ends the process as it would have: a suite's process server and
    workers, which leave SIGINT to the main process and die of SIGTERM, build models under this too); never lost,
    never in the middle. A section that fails after a signal was noted ends as signalled, the failure as its cause
    (the signal likely caused it)."""
    if threading.current_thread() is not threading.main_thread():  # handlers run in the main thread only
        yield
        return
    noted: list[int] = []

    def note(signum: int, frame: object) -> None:
        _RECEIVED[0] += 1
        noted.append(signum)

    saved = {sig: signal.signal(sig, note) for sig in (signal.SIGINT, signal.SIGTERM)}

    def restore() -> None:
        for sig, handler in saved.items():
            signal.signal(sig, handler)

    try:
        yield
    except BaseException as exc:
        restore()
        # the section failed after a signal was noted: the signal wins. A service manager's SIGTERM reaches the whole
        # process group: the suite's process server dies of it while this process starts workers from it, whose
        # start then fails (EOFError from multiprocessing's forkserver); the command ends as signalled, 143
        if noted and not isinstance(exc, KeyboardInterrupt | Terminated):
            try:
                _act(noted[0], saved[noted[0]])
            except BaseException as signalled:
                raise signalled from exc
        raise
    restore()
    if noted:
        _act(noted[0], saved[noted[0]])


def _act(signum: int, handler: Any) -> None:
    """Act on a held signal as ``handler`` (what was installed before the section) would have."""
    if handler is signal.SIG_IGN:
        return
    if handler is signal.SIG_DFL or handler is None:  # (None: installed from C) sent again: the process ends as it
        os.kill(os.getpid(), signum)  # would have (a signal sent to itself is delivered before kill returns)
        return
    handler(signum, None)


def uninterrupted(func: Callable[P, R]) -> Callable[P, R]:
    """``func`` run under :func:`signals_held`: for the figure writers, whose drawing a Ctrl-C must not cut.

    matplotlib's compiled parts (pybind11) turn a KeyboardInterrupt raised while they convert their arguments into
    a ``TypeError: incompatible function arguments`` traceback; held back, the signal acts as soon as the figure
    is written (a few tenths of a second).
    """

    @functools.wraps(func)
    def held(*args: P.args, **kwargs: P.kwargs) -> R:
        with signals_held():
            return func(*args, **kwargs)

    return held


def explain(exc: BaseException, text: str) -> None:
    """Say what a KeyboardInterrupt or Terminated cost: ``text`` ends the command's one last line, ``washbench:
    interrupted: TEXT`` (:func:`explanation`; a suite's "8 of 10 manoeuvres had finished; ... nothing was written")."""
    exc.washbench_explanation = text  # type: ignore[attr-defined]


def explanation(exc: BaseException) -> str:
    """What :func:`explain` attached to ``exc`` (empty when nothing was)."""
    return str(getattr(exc, "washbench_explanation", ""))
