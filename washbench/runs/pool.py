"""The process pool of ``suite``, ``sweep`` and ``tune``, and what it does with signals.

* :func:`pool_context`: the start method (``forkserver`` where it exists, with the heavy modules preloaded by the
  process server, :mod:`washbench.runs.preload`; ``spawn`` elsewhere) and the worker initializer;
* :func:`worker_pool`: a :class:`~concurrent.futures.ProcessPoolExecutor` whose workers ignore Ctrl-C (the main
  process stops them: no traceback from each), die with their parent (:mod:`washbench.runs.parent_death`), and are
  stopped at once (SIGTERM, then SIGKILL) when anything (KeyboardInterrupt, :class:`washbench.errors.Terminated`)
  leaves the ``with`` block;
* :func:`submit_all`: submitting starts the workers; a SIGINT/SIGTERM meanwhile is acted on once they exist
  (:func:`washbench.io.outfolder.signals_held`).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any

from washbench.io import collector
from washbench.io.outfolder import signals_held
from washbench.runs import parent_death
from washbench.runs.parent_death import note_main_pid

_QUIET_TRACKER = "ignore:resource_tracker:UserWarning"

FIGURE_MODULES = ("matplotlib.figure", "matplotlib.backends.backend_agg")
"""Preloaded by the process server besides :mod:`washbench.runs.preload` when the runs draw figures."""


def worker_init(then: Callable[[], None] | None = None) -> None:
    """In each worker (and each child of :mod:`washbench.runs.beside`): Ctrl-C is for the main process (it stops
    the workers); SIGTERM stops a worker at once.

    ``then``: the start method's own initializer (:func:`pool_context`). Then what the worker has loaded (the
    process server's preloaded modules, forked) is frozen: the worker's collector never scans it
    (:mod:`washbench.io.collector`).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if then is not None:
        then()
    collector.freeze_loaded()


@contextlib.contextmanager
def signals_ignored() -> Iterator[None]:
    """Ignore SIGINT and SIGTERM for a short critical section (stopping the workers)."""
    saved = {sig: signal.signal(sig, signal.SIG_IGN) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in saved.items():
            signal.signal(sig, handler)


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """Stop every worker now (SIGTERM, then SIGKILL after 5 s) and drop the queued tasks."""
    processes = list((getattr(pool, "_processes", None) or {}).values())  # the executor keeps no public list
    for p in processes:
        with contextlib.suppress(Exception):
            p.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        p.join(5.0)
        if p.is_alive():
            p.kill()
            p.join(5.0)


def _preload() -> None:
    """Worker initializer where there is no forkserver: load the heavy modules once per worker."""
    import washbench.runs.preload  # deferred: jsbsim  # noqa: F401


def _die_with_parent() -> None:
    """Worker initializer: the worker ends when its parent (the process server) does."""

    parent_death.die_with_parent(parent_death.SERVER_PID)  # the server's PID: ends at once if it died meanwhile


def pool_context(
    recording: bool = True, main_stops_workers: bool = False, figures: bool = True
) -> tuple[multiprocessing.context.BaseContext, Callable[[], None] | None]:
    """The process pool's start method and worker initializer.

    ``forkserver`` (Linux, macOS) where it exists: workers fork from a server that has already imported the heavy
    modules (JSBSim, the numba kernels, pyarrow; matplotlib with ``figures``, rerun with ``recording``), so each
    starts in milliseconds. Elsewhere (Windows)
    ``spawn``, with every worker importing them once at its start. With ``main_stops_workers`` (the suite, which
    stops its workers itself on Ctrl-C) the server and its workers ignore SIGINT.
    """
    # An interrupted suite stops its workers at once; the resource tracker then removes the pool's semaphores itself
    # but warns about each on stderr ("leaked semaphore objects"). Its warning filters come from ours when it starts.
    if _QUIET_TRACKER not in sys.warnoptions:
        sys.warnoptions.append(_QUIET_TRACKER)
    if "forkserver" in multiprocessing.get_all_start_methods():
        ctx = multiprocessing.get_context("forkserver")
        first = ["washbench.runs.worker_signals"] if main_stops_workers else []
        optional = [*(FIGURE_MODULES if figures else ()), *(["rerun"] if recording else [])]
        ctx.set_forkserver_preload([*first, "washbench.runs.preload", *optional])

        note_main_pid()  # the server (started with the pool) must die with this process
        return ctx, _die_with_parent
    return multiprocessing.get_context("spawn"), _preload


def start_server(recording: bool = True, figures: bool = True) -> None:
    """Start the process server now (where the start method is ``forkserver``; else nothing), so that it loads its
    modules (:func:`pool_context`, about a second) while this process goes on with other work; the
    :func:`worker_pool` opened later with the same outputs forks its workers from it."""
    ctx, _ = pool_context(recording, main_stops_workers=True, figures=figures)
    if ctx.get_start_method() == "forkserver":
        from multiprocessing import forkserver

        with signals_held():  # a signal while the server process starts is acted on once it exists
            forkserver.ensure_running()


@contextlib.contextmanager
def worker_pool(jobs: int, *, recording: bool = True, figures: bool = True) -> Iterator[ProcessPoolExecutor]:
    """A pool of ``jobs`` worker processes the main process stops itself (module docstring).

    Leaving the block normally waits for the workers; leaving it by any exception stops them at once first.
    """
    ctx, initializer = pool_context(recording, main_stops_workers=True, figures=figures)
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=worker_init, initargs=(initializer,))
    try:
        yield pool
    except BaseException:
        with signals_ignored():
            stop_pool(pool)
        raise
    pool.shutdown(wait=True)


def submit_all(pool: ProcessPoolExecutor, fn: Callable[..., Any], args: Sequence[tuple[Any, ...]]) -> list[Future]:
    """``pool.submit(fn, *a)`` for each ``a``; a signal while the workers start is acted on once they exist."""
    with signals_held():  # submitting starts the workers (up to ``jobs``)
        return [pool.submit(fn, *a) for a in args]
