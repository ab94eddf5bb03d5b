"""One writer per output folder: an exclusive lock on ``OUT/.washbench.lock``.

Two commands writing into the same ``--out`` at once would mix their results; the second one gets a
clear error instead. The lock is an ``fcntl.flock`` on a file that stays in the folder (removing it would
let two processes lock different files); the kernel releases it when the process ends, however it ends.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
from collections.abc import Iterator
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.publish import prepare_output_dir

LOCK_NAME = ".washbench.lock"


@contextlib.contextmanager
def output_lock(out_dir: str | Path) -> Iterator[Path]:
    """Hold the exclusive lock of folder ``out_dir`` (created and checked writable first); yield the folder.

    Raises WashbenchError at once (no waiting) if another process holds it, naming that process.
    """
    out_dir = prepare_output_dir(out_dir)
    path = out_dir / LOCK_NAME
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot create the lock {LOCK_NAME}: {exc.strerror}")) from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "another process"
            problem = f"another washbench command (PID {holder}) is writing into this folder; wait or use another --out"
            raise WashbenchError(located(out_dir, problem)) from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield out_dir
    finally:
        os.close(fd)
