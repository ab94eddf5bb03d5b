"""One writer per output folder: an exclusive lock on ``OUT/.washbench.lock`` while a command writes.

Two commands writing into the same ``--out`` at once would mix their results; the second one gets a
clear error at once instead. The lock is an ``fcntl.flock`` on ``.washbench.lock`` (holding the
holder's PID), which the kernel releases when the process ends, however it ends. The file is created with
``O_CREAT|O_EXCL|O_NOFOLLOW`` and an existing one is opened with ``O_NOFOLLOW`` and must be a small plain file
with one name: a symbolic link (or hard link) planted as the lock is refused, never followed or truncated.
The file is removed when the command finishes; a lock taken on a file that was removed meanwhile is detected
(inode check) and taken again on the new file, so two processes never both hold it.

A child forked while the lock is held (:mod:`washbench.runs.beside`'s, or any other ``os.fork``) inherits the
lock's descriptor, and the kernel keeps an ``flock`` while any copy of it is open: a command killed outright would
leave its folder locked until its children had died too, and a command started at once in the same folder was
refused (seen in the test of exactly that). Every forked child therefore closes its copies at once
(:func:`close_inherited`, registered with :func:`os.register_at_fork`): the lock is the command's alone and ends
with it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import stat
from collections.abc import Iterator
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.publish import prepare_output_dir
from washbench.io.result_files import LOCK_NAME

_HELD: set[int] = set()
"""The lock descriptors this process holds (:func:`output_lock`)."""


def close_inherited() -> None:
    """In a child forked while a lock was held: close this process's copies of the lock's descriptors (the parent's
    stay open, so the lock holds while the parent lives, and ends with it)."""
    for fd in tuple(_HELD):
        with contextlib.suppress(OSError):
            os.close(fd)
    _HELD.clear()


if hasattr(os, "register_at_fork"):  # POSIX: run in every child this process forks, before anything else
    os.register_at_fork(after_in_child=close_inherited)


def _open_lock(out_dir: Path, path: Path) -> int:
    """Open ``path`` as the lock file: created with ``O_CREAT|O_EXCL|O_NOFOLLOW`` (never through a link), or,
    when one exists (a finished or killed command's), opened with ``O_NOFOLLOW`` and proven a plain file."""
    flags = os.O_RDWR | os.O_CLOEXEC | os.O_NOFOLLOW
    try:
        return os.open(path, flags | os.O_CREAT | os.O_EXCL, 0o666)
    except FileExistsError:
        pass
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot create the lock {LOCK_NAME}: {exc.strerror}")) from None
    try:
        fd = os.open(path, flags | os.O_NONBLOCK)
    except FileNotFoundError:
        return -1  # removed meanwhile: try again
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            problem = f"{LOCK_NAME} is a symbolic link (not washbench's lock): not followed; remove it"
        else:
            problem = f"cannot open the lock {LOCK_NAME}: {exc.strerror}"
        raise WashbenchError(located(out_dir, problem)) from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode) or st.st_nlink != 1 or st.st_size > 64:
        os.close(fd)
        problem = f"{LOCK_NAME} is not washbench's lock (not a small plain file with one name): remove it"
        raise WashbenchError(located(out_dir, problem))
    os.set_blocking(fd, True)
    return fd


def _acquire(out_dir: Path, path: Path) -> int:
    for _ in range(5):
        fd = _open_lock(out_dir, path)
        if fd < 0:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "?"
            os.close(fd)
            holder = holder if holder.isdigit() else "?"
            problem = f"another washbench command (PID {holder}) is writing into this folder; wait or use another --out"
            raise WashbenchError(located(out_dir, problem)) from None
        try:
            same = os.lstat(path).st_ino == os.fstat(fd).st_ino
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
    _HELD.add(fd)
    try:
        try:
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        except OSError as exc:  # a full disk: the folder could be made, not one byte written
            raise WashbenchError(located(out_dir, f"cannot write the lock {LOCK_NAME}: {exc.strerror}")) from None
        yield out_dir
    finally:
        with contextlib.suppress(OSError):
            os.unlink(path)  # while still holding it: a waiting process then finds the inode changed
        _HELD.discard(fd)
        os.close(fd)
        if not existed:
            with contextlib.suppress(OSError):
                out_dir.rmdir()  # only if empty
