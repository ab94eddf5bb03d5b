"""Worker processes end when their parent dies, however it dies (SIGKILL included).

On Linux, :func:`die_with_parent` asks the kernel for SIGKILL when the parent process ends (``prctl`` with
``PR_SET_PDEATHSIG``, through ctypes). The suite's and the studies' process server (forkserver) calls it as it
imports its preload modules (its parent is the washbench command), and every worker calls it first (its
parent is the server): a washbench command killed with SIGKILL takes its server and workers with it, so no
worker goes on writing into a stage folder and no process is left. Elsewhere (macOS, Windows) it does
nothing: there the pool's own pipes end idle workers.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys

_PR_SET_PDEATHSIG = 1


def die_with_parent() -> bool:
    """Have this process killed when its parent ends (Linux); True if the kernel accepted it."""
    if not sys.platform.startswith("linux"):
        return False
    parent = os.getppid()
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        ok = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False
    if ok and os.getppid() != parent:  # the parent died before the request was made
        os._exit(1)
    return ok
