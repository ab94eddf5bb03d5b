"""Work done beside the command in a forked child process, so that a single ``run`` or ``cue`` does not leave a
core idle for seconds (issue 39).

Once a result's traces, metrics and run.json are written, its figures and report (matplotlib, about 4 s of CPU
for a 30-minute log) and its recording (rerun, about 2 s) depend on nothing but those: :func:`beside` draws the
first in a child forked from the command while the command writes the second. A fork shares the command's
arrays as they are (nothing is pickled or copied) and imports nothing again.

The child is forked only where that is safe and useful, else the work is done in this process, after the block,
in the order it had before (the same files, byte for byte, either way):

* on Linux (a fork elsewhere is not safe with the libraries loaded: macOS's frameworks);
* with at least two usable CPUs (:func:`washbench.io.cpus.usable_cpus`);
* from the main thread of a process with no other Python thread (a lock held by another thread at the fork
  would stay held in the child), and not in a process that :mod:`multiprocessing` started (a suite's or a
  study's worker: the pool already keeps every core busy, one process per manoeuvre; forking there made the
  bundled suite 16 % slower);
* unless ``WASHBENCH_NO_BESIDE`` is set (to measure, or to debug the drawing in one process).

The child ignores SIGINT (the command receives it too and ends the child), dies with the command (SIGKILL
included: :func:`washbench.runs.parent_death.die_with_parent`), writes nothing to the terminal and ends with
``os._exit``: no atexit handler and no buffered output of the command's runs twice. An exception in the child is
raised again in the command when the block ends, with the child's traceback as a note: a
:class:`washbench.errors.WashbenchError` stays the one-line error it is, an OSError stays an OSError (the
command's "cannot write results" line).
"""

from __future__ import annotations

import contextlib
import functools
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import traceback
from collections.abc import Callable, Iterator
from typing import Any

from washbench.io.cpus import usable_cpus
from washbench.runs.parent_death import die_with_parent
from washbench.runs.pool import worker_init

NO_BESIDE_ENV = "WASHBENCH_NO_BESIDE"
"""Set (to anything but empty): :func:`beside` does its work in this process, after the block."""


def can_fork() -> bool:
    """Whether :func:`beside` forks a child here (see the module's conditions)."""
    return (
        sys.platform.startswith("linux")
        and not os.environ.get(NO_BESIDE_ENV)
        and usable_cpus() >= 2
        and threading.current_thread() is threading.main_thread()
        and threading.active_count() == 1
        and multiprocessing.parent_process() is None
    )


@contextlib.contextmanager
def beside(work: Callable[[], Any], fork: bool = True) -> Iterator[bool]:
    """``work()`` in a forked child while the block runs here; when the block ends, wait for the child and raise
    its exception, if any, here. If the block raises, the child is killed and reaped, and the block's exception
    goes on. Yields whether a child was forked; where none can be (:func:`can_fork`) or with ``fork`` False
    (work too small to be worth a process), ``work`` runs in this process after the block, as if written there.
    """
    if not (fork and can_fork()):
        yield False
        work()
        return
    child = _fork(work)
    try:
        yield True
    except BaseException:
        child.kill()
        raise
    child.wait()


class _Child:
    """A forked child: its PID and the read end of the pipe its exception (pickled) comes back by."""

    def __init__(self, pid: int, fd: int) -> None:
        self.pid, self.fd = pid, fd

    def kill(self) -> None:
        """End the child now and reap it (its half-written files are in the command's stage, discarded)."""
        with contextlib.suppress(ProcessLookupError):
            os.kill(self.pid, signal.SIGKILL)
        self._reap()

    def wait(self) -> None:
        """Wait for the child's end; raise its exception here (or a RuntimeError if it died without one)."""
        try:
            data = b""
            while chunk := os.read(self.fd, 1 << 16):
                data += chunk
        except BaseException:
            self.kill()
            raise
        status = self._reap()
        if data:
            exc, tb = pickle.loads(data)
            exc.add_note(f"raised in the child process beside the command (washbench.runs.beside):\n{tb}")
            raise exc
        if status != 0:
            code = os.waitstatus_to_exitcode(status)
            how = f"signal {-code}" if code < 0 else f"exit code {code}"
            raise RuntimeError(f"the child process beside the command (its figures) ended with {how}")

    def _reap(self) -> int:
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1
        try:
            return os.waitpid(self.pid, 0)[1]
        except ChildProcessError:  # reaped already
            return 0


def _fork(work: Callable[[], Any]) -> _Child:
    read_fd, write_fd = os.pipe()
    for stream in (sys.stdout, sys.stderr):  # what is buffered is written once, by the command
        with contextlib.suppress(Exception):
            stream.flush()
    parent = os.getpid()
    pid = os.fork()
    if pid:
        os.close(write_fd)
        return _Child(pid, read_fd)
    code = 0
    try:  # the child: never returns
        os.close(read_fd)
        # as a pool worker starts: SIGINT ignored, SIGTERM stops it, dies with the command, and the command's objects
        # are never scanned (nor their pages copied) by its collector
        worker_init(functools.partial(die_with_parent, parent))
        work()
    except BaseException as exc:  # every error goes back to the command
        code = 1
        tb = traceback.format_exc()
        try:
            payload = pickle.dumps((exc, tb))
            pickle.loads(payload)  # an exception class whose arguments do not rebuild it fails here, not there
        except Exception:  # an exception that cannot be pickled: its text
            payload = pickle.dumps((RuntimeError(f"{type(exc).__name__}: {exc}"), tb))
        with contextlib.suppress(OSError):
            view = memoryview(payload)
            while view:
                view = view[os.write(write_fd, view) :]
    finally:
        os._exit(code)
