"""One writer per output folder: an exclusive lock on ``OUT/.washbench.lock`` while a command writes.

Two commands writing into the same ``--out`` at once would mix their results; the second one gets a
clear error at once instead. The lock is an ``fcntl.flock`` on ``.washbench.lock`` (holding the
holder's PID), which the kernel releases when the process ends, however it ends. The file is removed
when the command finishes; a lock taken on a file that was removed meanwhile is detected (inode check)
and taken again on the new file, so two processes never both hold it.
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


def _acquire(out_dir: Path, path: Path) -> int:
    for _ in range(5):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            raise WashbenchError(located(out_dir, f"cannot create the lock {LOCK_NAME}: {exc.strerror}")) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "?"
            os.close(fd)
            problem = f"another washbench command (PID {holder}) is writing into this folder; wait or use another --out"
            raise WashbenchError(located(out_dir, problem)) from None
        try:
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)  # the holder removed the file as we opened it: lock the new one
    raise WashbenchError(located(out_dir, f"cannot take the lock {LOCK_NAME}: it keeps being replaced"))


@contextlib.contextmanager
def output_lock(out_dir: str | Path) -> Iterator[Path]:
    """Hold the exclusive lock of folder ``out_dir`` (created and checked writable first); yield the folder.

    Raises WashbenchError at once (no waiting) if another process holds it, naming that process. A folder
    created here and still empty at the end (the command failed before writing) is removed again.
    """
    existed = Path(out_dir).is_dir()
    out_dir = prepare_output_dir(out_dir)
    path = out_dir / LOCK_NAME
    fd = _acquire(out_dir, path)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield out_dir
    finally:
        with contextlib.suppress(OSError):
            os.unlink(path)  # while still holding it: a waiting process then finds the inode changed
        os.close(fd)
        if not existed:
            with contextlib.suppress(OSError):
                out_dir.rmdir()  # only if empty
