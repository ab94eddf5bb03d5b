"""Worker processes end when their parent dies, however it dies (SIGKILL included).

On Linux, :func:`die_with_parent` asks the kernel for SIGKILL when the parent process ends (``prctl`` with
``PR_SET_PDEATHSIG``, through ctypes). The suite's and the studies' process server (forkserver) calls it as it
imports its preload modules (its parent is the washbench command), and every worker calls it first (its
parent is the server): a washbench command killed with SIGKILL takes its server and workers with it, so no
worker goes on writing into a stage folder and no process is left. Elsewhere (macOS, Windows) it does
nothing: there the pool's own pipes end idle workers.

The request only covers a parent still alive when it is made; a parent that died earlier (the command killed
while its server was still importing JSBSim and numba, seconds under load) has already handed the process to
init. So the process is told which parent it must have (``expected``): the server is given the command's PID
in the environment (:data:`MAIN_PID_ENV`, set by :func:`note_main_pid`), each worker the server's PID (kept in
:data:`SERVER_PID` when the server starts, inherited by every fork); if the parent is not that one once the
request is made, the process ends at once.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys

_PR_SET_PDEATHSIG = 1
#: Environment variable holding the washbench command's PID for its process server.
MAIN_PID_ENV = "WASHBENCH_MAIN_PID"
#: The process server's PID (set in the server; workers forked from it inherit it). None elsewhere.
SERVER_PID: int | None = None


def note_main_pid() -> None:
    """Tell process servers started from now on that this process is the parent they must die with."""
    os.environ[MAIN_PID_ENV] = str(os.getpid())


def main_pid() -> int | None:
    """The PID :func:`note_main_pid` noted for this process server (None if not given or not a number)."""
    value = os.environ.get(MAIN_PID_ENV, "")
    return int(value) if value.isdigit() else None


def die_with_parent(expected: int | None = None) -> bool:
    """Have this process killed when its parent ends (Linux); True if the kernel accepted it.

    ``expected``: the PID the parent must have; if it is not (or no longer) the parent once the request is made,
    the process ends at once (``os._exit(1)``). Default: the parent at the time of the call.
    """
    if not sys.platform.startswith("linux"):
        return False
    parent = os.getppid() if expected is None else expected
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        ok = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False
    if ok and os.getppid() != parent:  # the parent died before the request was made
        os._exit(1)
    return ok
